"""Loading a robot's spec files: finding them, reading them, and parsing each one, or reading it
back from the cache when the same front end parsed the same text before (the parse itself, lark's,
is `specc.syntax.grammar`: a command on files seen before does not load lark)."""

from __future__ import annotations

import functools
import importlib.util
import os
from pathlib import Path

from specc import disk_cache
from specc.diagnostics import Diagnostic, display_path, error
from specc.model.span import Span
from specc.resources import grammar_path
from specc.syntax.parsed import ParseResult

SPEC_SUFFIX = ".spec"
PARSED = "parsed"  # the cache's kind of entry: a file's ParseResult


def parse_text(text: str, path: str) -> ParseResult:
    """Parse one file. On a syntax error: no model and one diagnostic (the parser stops there).
    A file parsed before, by the same front end, is read back from the cache (a robot's 22 files
    parse in ~0.3 s and read back in a few ms)."""
    key = disk_cache.key(_front_end_digest(), path, text.encode("utf-8", "surrogatepass"))
    kept = disk_cache.read(PARSED, key, ParseResult)
    if kept is not disk_cache.MISSING:
        return kept  # type: ignore[no-any-return]
    from specc.syntax.grammar import parse_uncached

    result = parse_uncached(text, path)
    disk_cache.keep(PARSED, key, result)
    return result


# The front end's own sources: a parse read back from the cache must be the one this code would
# make, so the key holds their digest (the grammar, the builder, the model, the diagnostics).
_FRONT_END = ("syntax", "model")
_FRONT_END_FILES = ("diagnostics.py", "codes.py", "resources.py")


@functools.lru_cache(maxsize=1)
def _front_end_digest() -> str:
    """The front end's sources, and lark's version (its `__init__`, found without importing it: a
    parse read back needs no lark), since another lark may parse or place errors otherwise."""
    package = Path(__file__).resolve().parents[1]
    files = sorted(f for folder in _FRONT_END for f in (package / folder).glob("*.py"))
    lark = importlib.util.find_spec("lark")
    parser_library = [Path(lark.origin)] if lark is not None and lark.origin else []
    return disk_cache.source_digest([grammar_path(), *files, *(package / name for name in _FRONT_END_FILES),
                                     *parser_library])


def spec_files(paths: list[Path]) -> tuple[list[Path], list[Diagnostic]]:
    """The .spec files named, or found (sorted, recursively) in the folders named."""
    files: list[Path] = []
    problems: list[Diagnostic] = []
    for path in paths:
        if path.is_dir():
            found, unreadable = _specs_in(path)
            problems.extend(unreadable)
            if not found and not unreadable:
                problems.append(error("no-spec-files", f"no {SPEC_SUFFIX} files in folder '{path}'",
                                      Span.unknown(str(path))))
            files.extend(found)
        elif path.is_file():
            files.append(path)
        else:
            problems.append(error("missing-file", _why_missing(path), Span.unknown(str(path))))
    # A file named twice (`specc check robot/ robot/loco.spec`, or a link to it) is read once:
    # twice, each of its blocks would be reported as defined twice, by itself.
    unique: dict[Path, Path] = {}
    for file in files:
        unique.setdefault(file.resolve(), file)
    return list(unique.values()), problems


def _why_missing(path: Path) -> str:
    if path.is_symlink() and not path.exists():
        return f"'{path}' is a broken or looping symbolic link"
    if path.exists():
        return f"'{path}' is neither a file nor a folder"
    return f"no such file or folder: '{path}'"


def _specs_in(folder: Path) -> tuple[list[Path], list[Diagnostic]]:
    """Every .spec file under `folder` (symbolic links to folders are not followed, so a link
    loop cannot hang the search), and an error for each folder that cannot be listed: a robot
    silently missing the specs of an unreadable folder would be checked as if they did not exist."""
    unreadable: list[Diagnostic] = []

    def report(exc: OSError) -> None:
        unreadable.append(error("unreadable-folder", f"cannot list folder '{exc.filename}': {exc.strerror}",
                                Span.unknown(str(exc.filename))))

    found = [Path(root) / name
             for root, _, names in os.walk(folder, onerror=report)
             for name in names if name.endswith(SPEC_SUFFIX)]
    return sorted(p for p in found if p.is_file()), unreadable


def read_source(path: Path) -> tuple[str | None, Diagnostic | None]:
    try:
        # utf-8-sig: a byte-order mark some Windows editors write is not part of the text.
        return path.read_text(encoding="utf-8-sig"), None
    except UnicodeDecodeError as exc:
        # Where the first byte that is not UTF-8 sits: its line, and its column in characters (what
        # comes before it on its line is UTF-8).
        before = exc.object[:exc.start]
        line = before.count(b"\n") + 1
        column = len(before[before.rfind(b"\n") + 1:].decode("utf-8", errors="replace")) + 1
        return None, error("bad-encoding", f"'{path}' is not UTF-8 text (byte {exc.start}, "
                           f"0x{exc.object[exc.start]:02x}); save it as UTF-8",
                           Span(display_path(path), line, column, line, column + 1))
    except OSError as exc:
        return None, error("unreadable-file", f"cannot read '{path}': {exc.strerror}",
                           Span.unknown(display_path(path)))
