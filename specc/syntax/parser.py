"""Text -> model: the lark parser, friendly parse errors, and loading a robot's spec files."""

from __future__ import annotations

import functools
import hashlib
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from lark import Lark, Token
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from specc.diagnostics import Diagnostic, error
from specc.model import nodes as m
from specc.model.span import Span
from specc.resources import grammar_path
from specc.syntax.builder import build
from specc.syntax.labels import describe_expected, describe_token

SPEC_SUFFIX = ".spec"


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
    """Parse one file. On a syntax error: no model and one diagnostic (the parser stops there)."""
    _COMMENTS.clear()
    try:
        tree = parser().parse(text)
    except UnexpectedInput as exc:
        return ParseResult(None, [syntax_error(exc, text, path)])
    comments = list(_COMMENTS)
    source, diagnostics = build(tree, path)
    return ParseResult(source, diagnostics, comments)


def syntax_error(exc: UnexpectedInput, text: str, path: str) -> Diagnostic:
    line = getattr(exc, "line", 1) or 1
    column = getattr(exc, "column", 1) or 1
    if isinstance(exc, UnexpectedToken) and exc.token.type == "$END" or isinstance(exc, UnexpectedEOF):
        last = text.rstrip().splitlines() or [""]
        line, column = max(len(last), 1), len(last[-1]) + 1
        span = Span(path, line, column, line, column + 1)
        expected = describe_expected(getattr(exc, "expected", set()) or set(), keyword_texts())
        return error("unexpected-end", f"the file ends too early: expected {expected}; is a '}}' missing?", span)
    if isinstance(exc, UnexpectedCharacters):
        position = exc.pos_in_stream or 0
        char = text[position] if position < len(text) else "?"
        span = Span(path, line, column, line, column + 1)
        expected = describe_expected(exc.allowed or set(), keyword_texts())
        return error("unexpected-character",
                     f"unexpected character '{char}' here; expected {expected}", span)
    assert isinstance(exc, UnexpectedToken)
    token = exc.token
    width = max(len(str(token)), 1)
    span = Span(path, line, column, line, column + width)
    expected = describe_expected(exc.expected, keyword_texts())
    return error("unexpected-token", f"unexpected {describe_token(token)}; expected {expected}", span)


def spec_files(paths: list[Path]) -> tuple[list[Path], list[Diagnostic]]:
    """The .spec files named, or found (sorted, recursively) in the folders named."""
    files: list[Path] = []
    problems: list[Diagnostic] = []
    for path in paths:
        if path.is_dir():
            found = sorted(p for p in path.rglob("*" + SPEC_SUFFIX) if p.is_file())
            if not found:
                problems.append(error("no-spec-files", f"no {SPEC_SUFFIX} files in folder '{path}'",
                                      Span.unknown(str(path))))
            files.extend(found)
        elif path.is_file():
            files.append(path)
        else:
            problems.append(error("missing-file", f"no such file or folder: '{path}'", Span.unknown(str(path))))
    return files, problems


def display_path(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def read_source(path: Path) -> tuple[str | None, Diagnostic | None]:
    try:
        return path.read_text(encoding="utf-8"), None
    except UnicodeDecodeError as exc:
        return None, error("bad-encoding", f"'{path}' is not UTF-8 text (byte {exc.start}); save it as UTF-8",
                           Span.unknown(display_path(path)))
    except OSError as exc:
        return None, error("unreadable-file", f"cannot read '{path}': {exc.strerror}",
                           Span.unknown(display_path(path)))
