"""Text -> model: the lark parser, friendly parse errors, and loading a robot's spec files."""

from __future__ import annotations

import contextlib
import difflib
import functools
import hashlib
import os
import pickle
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from specc.diagnostics import Diagnostic, error
from specc.model import nodes as m
from specc.model.span import Span
from specc.resources import grammar_path
from specc.syntax.builder import build
from specc.syntax.labels import describe_expected, describe_token

SPEC_SUFFIX = ".spec"
# The builder, the checks and the printer recurse once or twice per level of the parse tree;
# past this depth Python's stack would overflow. The examples nest 15 levels at most.
MAX_NESTING = 150


@dataclass
class ParseResult:
    source: m.SourceFile | None
    diagnostics: list[Diagnostic]
    comments: list[Token] = field(default_factory=list)


class _CommentSink(list[Token]):
    """Collects the comment tokens the lexer skips, so the formatter can keep them."""


_COMMENTS = _CommentSink()


@functools.lru_cache(maxsize=1)
def parser() -> Lark:
    return Lark(
        grammar_path().read_text(encoding="utf-8"),
        parser="lalr",
        lexer="contextual",
        propagate_positions=True,
        maybe_placeholders=True,
        lexer_callbacks={"COMMENT": _COMMENTS.append, "BLOCK_COMMENT": _COMMENTS.append},
        cache=str(cache_file()),
    )


def cache_file() -> Path:
    """Where lark keeps the analysed grammar (keyed by its text): loading it is ~5x faster."""
    folder = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "specc"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        folder = Path(tempfile.gettempdir())
    digest = hashlib.sha256(grammar_path().read_bytes()).hexdigest()[:16]
    return folder / f"grammar-{digest}.lark.cache"


@functools.lru_cache(maxsize=1)
def keyword_texts() -> dict[str, str]:
    """Terminal name -> its literal text, for keywords and punctuation."""
    return {t.name: t.pattern.value for t in parser().terminals if isinstance(t.pattern, PatternStr)}


def parse_text(text: str, path: str) -> ParseResult:
    """Parse one file. On a syntax error: no model and one diagnostic (the parser stops there).
    A file parsed before, by the same front end, is read back from the cache (`parsed_cache`)."""
    cache = parsed_cache()
    key = _parsed_key(text, path)
    if cache is not None:
        try:
            with (cache / key).open("rb") as stream:
                cached = pickle.load(stream)
            if isinstance(cached, ParseResult):
                return cached
        except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ImportError, TypeError, ValueError):
            pass  # absent, or written by another front end after all: parsed again
    result = _parse_text(text, path)
    if cache is not None:
        _keep(cache, key, result)
    return result


# The front end's own sources: a parse read back from the cache must be the one this code would
# make, so the key holds their digest (the grammar, the builder, the model, the diagnostics).
_FRONT_END = ("syntax", "model")
_FRONT_END_FILES = ("diagnostics.py", "codes.py", "resources.py")
PARSED_CACHE_LIMIT = 2000  # parsed files kept; past it, the older half goes


@functools.lru_cache(maxsize=1)
def _front_end_digest() -> str:
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256(grammar_path().read_bytes())
    files = sorted(f for folder in _FRONT_END for f in (package / folder).glob("*.py"))
    for path in [*files, *(package / name for name in _FRONT_END_FILES)]:
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _parsed_key(text: str, path: str) -> str:
    digest = hashlib.sha256(_front_end_digest().encode())
    digest.update(path.encode("utf-8", "surrogatepass"))
    digest.update(b"\0")
    digest.update(text.encode("utf-8", "surrogatepass"))
    return digest.hexdigest() + ".pickle"


@functools.lru_cache(maxsize=1)
def parsed_cache() -> Path | None:
    """Where parsed files are kept (beside lark's grammar cache), or None: SPECC_PARSE_CACHE=0, or
    no folder can be made. A robot's 22 files parse in ~0.3 s and read back in a few ms."""
    if os.environ.get("SPECC_PARSE_CACHE", "1") == "0":
        return None
    folder = cache_file().parent / "parsed"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder


def _keep(cache: Path, key: str, result: ParseResult) -> None:
    """Write atomically (another process may write the same key); a cache that cannot be written
    is no error."""
    temporary: str | None = None
    try:
        handle, temporary = tempfile.mkstemp(dir=cache, suffix=".tmp")
        with os.fdopen(handle, "wb") as stream:
            pickle.dump(result, stream, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(temporary, cache / key)
    except (OSError, pickle.PicklingError, RecursionError):
        if temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
        return
    _prune(cache)


@functools.lru_cache(maxsize=1)
def _prune(cache: Path) -> None:
    """Past PARSED_CACHE_LIMIT files the older half goes; looked at once per process (the folder
    listing is not redone at every file written)."""
    with contextlib.suppress(OSError):
        kept = list(cache.glob("*.pickle"))
        if len(kept) > PARSED_CACHE_LIMIT:
            kept.sort(key=lambda f: f.stat().st_mtime)
            for old in kept[:len(kept) // 2]:
                old.unlink(missing_ok=True)


def _parse_text(text: str, path: str) -> ParseResult:
    _COMMENTS.clear()
    try:
        tree = parser().parse(text)
    except UnexpectedInput as exc:
        return ParseResult(None, [syntax_error(exc, text, path)])
    comments = list(_COMMENTS)
    too_deep = nesting_error(tree, path)
    if too_deep is not None:
        return ParseResult(None, [too_deep])
    source, diagnostics = build(tree, path)
    return ParseResult(source, diagnostics, comments)


def nesting_error(tree: Tree, path: str) -> Diagnostic | None:
    """A diagnostic at the first construct nested deeper than MAX_NESTING, if any."""
    stack = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_NESTING:
            meta = node.meta
            line, column = getattr(meta, "line", 1), getattr(meta, "column", 1)
            span = Span(path, line, column, getattr(meta, "end_line", line), getattr(meta, "end_column", column))
            return error("too-deeply-nested",
                         f"this is nested more than {MAX_NESTING} levels deep; "
                         "split it into smaller pieces (sub-goals, shorter expressions)", span)
        stack.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))
    return None


def syntax_error(exc: UnexpectedInput, text: str, path: str) -> Diagnostic:
    line = getattr(exc, "line", 1) or 1
    column = getattr(exc, "column", 1) or 1
    if isinstance(exc, UnexpectedToken) and exc.token.type == "$END" or isinstance(exc, UnexpectedEOF):
        last = text.rstrip().split("\n")  # lines as the lexer counts them: a \x0b or \x0c ends none
        line, column = max(len(last), 1), len(last[-1]) + 1
        span = Span(path, line, column, line, column + 1)
        expected = describe_expected(getattr(exc, "expected", set()) or set(), keyword_texts())
        unclosed = _unclosed_brace(text)
        if unclosed is not None:
            at = Span(path, *unclosed, unclosed[0], unclosed[1] + 1)
            return error("unexpected-end", f"the file ends too early: expected {expected}; the '{{' of line "
                         f"{unclosed[0]} is never closed", span, (at, "opened here: close it with '}'"))
        return error("unexpected-end", f"the file ends too early: expected {expected}; is a '}}' missing?", span)
    position = max(getattr(exc, "pos_in_stream", None) or 0, 0)
    # An unclosed `/*` is lexed as `/` then `*`, and neither may follow the other anywhere.
    opener = position if text.startswith("/*", position) else position - 1
    if opener >= 0 and text.startswith("/*", opener):
        line, column = _line_column(text, opener)
        span = Span(path, line, column, line, column + 2)
        return error("unterminated-comment", "this '/*' comment is never closed by '*/'", span)
    if isinstance(exc, UnexpectedCharacters) and text.startswith('"', position):
        span = Span(path, line, column, line, column + 1)
        return error("unterminated-string", "this string is not closed by '\"' on the same line", span)
    if isinstance(exc, UnexpectedCharacters):
        char = text[position] if position < len(text) else "?"
        if not char.isprintable():  # a stray BOM, line separator or control byte
            char = f"U+{ord(char):04X}"
        span = Span(path, line, column, line, column + 1)
        expected = describe_expected(exc.allowed or set(), keyword_texts())
        return error("unexpected-character",
                     f"unexpected character '{char}' here; expected {expected}", span)
    assert isinstance(exc, UnexpectedToken)
    token = exc.token
    unit = _unit_typo(text, position)
    if unit is not None:
        start, word = unit
        line, column = _line_column(text, start)
        return error("unknown-unit", f"'{word}' is not a unit of time: write us, ms, s or min (e.g. 50 ms)",
                     Span(path, line, column, line, column + len(word)))
    if "SEMICOLON" in exc.expected and _line_column(text, position)[0] > 1:
        end = _end_of_previous_line(text, position)
        if end is not None:  # the statement before ends on an earlier line, without its `;`
            next_line = line
            line, column = _line_column(text, end)
            return error("missing-semicolon", f"expected ';' at the end of this line (before "
                         f"{describe_token(token)} on line {next_line})", Span(path, line, column, line, column + 1))
    width = max(len(str(token)), 1)
    span = Span(path, line, column, line, column + width)
    expected = describe_expected(exc.expected, keyword_texts())
    # A misspelt keyword reads as a name, and where the keyword was optional (a task's preemption
    # after its '}') the parser no longer expects it: say which keyword the word is close to.
    close = _meant(exc, text, position, str(token), token.type == "NAME")
    return error("unexpected-token", f"unexpected {describe_token(token)}{close}; expected {expected}", span)


UNITS = ("us", "ms", "s", "min")


def _meant(exc: UnexpectedToken, text: str, position: int, written: str, is_name: bool) -> str:
    """' (did you mean 'X'?)' when writing X instead makes the file parse past this point: a
    misspelt keyword (even one the parser no longer expects: a task's optional preemption after
    its '}') or an operator a character short (`=>` where a rule wants `==>`); else ''."""
    texts = keyword_texts()
    if is_name:
        words = [k for k in texts.values() if k.isidentifier() and len(k) > 2]  # not the units s, ms, us
        expected = [texts[t] for t in exc.expected if t in texts and texts[t] in words]
        close = difflib.get_close_matches(written, expected, n=3) + difflib.get_close_matches(written, words, n=3)
        tried = [(word, len(written)) for word in close]  # (what to write, the length it replaces)
    else:
        operators = [texts[t] for t in exc.expected if t in texts and len(texts[t]) > 1 and not texts[t].isalnum()]
        tried = [(op, len(op) - 1) for op in operators
                 if any(text.startswith(op[:i] + op[i + 1:], position) for i in range(len(op)))]
    for candidate, replaced in dict.fromkeys(tried):
        if _parses_past(text[:position] + candidate + text[position + replaced:], position + len(candidate)):
            return f" (did you mean '{candidate}'?)"
    return ""


def _parses_past(text: str, position: int) -> bool:
    """Does `text` parse, or fail only after `position`?"""
    try:
        parser().parse(text)
    except UnexpectedInput as exc:
        return (getattr(exc, "pos_in_stream", None) or 0) > position
    except Exception:  # a builder's error past the grammar: the text parsed that far
        return True
    return True


def _unit_typo(text: str, position: int) -> tuple[int, str] | None:
    """(start, word) when the unexpected token is inside a word written right after a number
    (`50 mss`, `30 sec`): a unit of time misspelt."""
    start = position
    while start > 0 and text[start - 1].isalpha():
        start -= 1
    end = position
    while end < len(text) and text[end].isalpha():
        end += 1
    word = text[start:end]
    before = text[:start].rstrip(" \t")
    if not word or word in UNITS or not before or not before[-1].isdigit():
        return None
    return start, word


def _end_of_previous_line(text: str, position: int) -> int | None:
    """The position of the last character of the last line before `position`'s that holds
    something other than a comment (None when there is none, or it ends with `;`, `{` or `}`)."""
    line_start = text.rfind("\n", 0, position)
    while line_start > 0:
        previous = text.rfind("\n", 0, line_start) + 1
        content = text[previous:line_start]
        comment = content.find("//")
        if comment >= 0 and content.count('"', 0, comment) % 2 == 0:
            content = content[:comment]
        stripped = content.rstrip()
        if stripped:
            if stripped[-1] in ";{}":
                return None
            return previous + len(stripped) - 1
        line_start = previous - 1
    return None


def _unclosed_brace(text: str) -> tuple[int, int] | None:
    """(line, column) of the last `{` no `}` closes, strings and comments aside."""
    openers: list[int] = []
    k, n = 0, len(text)
    while k < n:
        c = text[k]
        if c == '"':
            k += 1
            while k < n and text[k] not in '"\n':
                k += 2 if text[k] == "\\" else 1
        elif text.startswith("//", k):
            k = text.find("\n", k) if text.find("\n", k) >= 0 else n
        elif text.startswith("/*", k):
            k = text.find("*/", k + 2) + 1 if text.find("*/", k + 2) >= 0 else n
        elif c == "{":
            openers.append(k)
        elif c == "}" and openers:
            openers.pop()
        k += 1
    return _line_column(text, openers[-1]) if openers else None


def _line_column(text: str, position: int) -> tuple[int, int]:
    line = text.count("\n", 0, position) + 1
    return line, position - (text.rfind("\n", 0, position) + 1) + 1


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


def display_path(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


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
