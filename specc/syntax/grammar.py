"""The lark parser of specc's grammar: text -> parse tree -> model, and a friendly message for
each syntax error. Imported only when a file is parsed, not read back from the cache
(`specc.syntax.parser.parse_text`): a command on specs it has seen before does not load lark."""

from __future__ import annotations

import difflib
import functools
import hashlib
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from specc import disk_cache
from specc.diagnostics import Diagnostic, error
from specc.model.span import Span
from specc.resources import grammar_path
from specc.syntax.builder import build
from specc.syntax.labels import describe_expected, describe_token
from specc.syntax.parsed import Comment, ParseResult

# The builder, the checks and the printer recurse once or twice per level of the parse tree;
# past this depth Python's stack would overflow. The examples nest 15 levels at most.
MAX_NESTING = 150


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
        cache=str(kept) if (kept := cache_file()) is not None else False,
    )


def cache_file() -> Path | None:
    """Where lark keeps the analysed grammar (keyed by its text): loading it is ~5x faster. None
    when specc has no cache folder (`specc.disk_cache.root`)."""
    base = disk_cache.root()
    if base is None:
        return None
    digest = hashlib.sha256(grammar_path().read_bytes()).hexdigest()[:16]
    return base / f"grammar-{digest}.lark.cache"


@functools.lru_cache(maxsize=1)
def keyword_texts() -> dict[str, str]:
    """Terminal name -> its literal text, for keywords and punctuation."""
    return {t.name: t.pattern.value for t in parser().terminals if isinstance(t.pattern, PatternStr)}



def parse_uncached(text: str, path: str) -> ParseResult:
    """Parse one file (no cache: `specc.syntax.parser.parse_text` is the entry point)."""
    _COMMENTS.clear()
    try:
        tree = parser().parse(text)
    except UnexpectedInput as exc:
        return ParseResult(None, [syntax_error(exc, text, path)])
    comments = [Comment(str(c).replace("\r\n", "\n").rstrip(), c.line or 1, c.column or 1) for c in _COMMENTS]
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
        ascii_form = TYPOGRAPHIC.get(char)
        hint = f" (a word processor's character: write '{ascii_form}')" if ascii_form else ""
        return error("unexpected-character",
                     f"unexpected character '{char}' here{hint}; expected {expected}", span)
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
    if str(token) == "-" and "NUMBER" in exc.expected and text[position + 1:position + 2].isdigit() \
            and text[:position].rstrip().endswith(":"):
        # `wheel_base: -0.5;`: a property's value is a count, a length or a duration, never below 0.
        # (In a list, `[-5, 0]` or `{-1, 0}`, a negative value may mean something: no such hint.)
        close = " (a negative number has no meaning here: this value must be 0 or more)"
    braces = "" if close else _brace_hint(text, position)  # one guess at a time: a word misspelt first
    return error("unexpected-token", f"unexpected {describe_token(token)}{close}; expected {expected}{braces}", span)


UNITS = ("us", "ms", "s", "min")
# Characters an editor or a document puts for the ASCII ones the language reads.
TYPOGRAPHIC = {"\u201c": '"', "\u201d": '"', "\u201e": '"', "\u00ab": '"', "\u00bb": '"', "\u2018": "'",
               "\u2019": "'", "\u2264": "<=", "\u2265": ">=", "\u2260": "!=", "\u2192": "=>",
               "\u21d2": "=>", "\u2212": "-", "\u2013": "-", "\u2014": "-", "\u00d7": "*", "\u2026": "..."}


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
    if is_name:  # `requst Goto {`: the misspelt keyword is the word before, read as a property's name
        before = text[:position].rstrip(" \t")
        start = len(before)
        while start > 0 and (before[start - 1].isalnum() or before[start - 1] == "_"):
            start -= 1
        previous = before[start:]
        words = [k for k in texts.values() if k.isidentifier() and len(k) > 2]
        if previous.isidentifier() and previous not in words:
            for candidate in difflib.get_close_matches(previous, words, n=3):
                if _parses_past(text[:start] + candidate + text[len(before):], start + len(candidate) + 1):
                    return f" after '{previous}' (did you mean '{candidate}'?)"
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
    openers, _ = _braces(text, len(text))
    return _line_column(text, openers[-1]) if openers else None


def _brace_hint(text: str, position: int) -> str:
    """Where the braces before `position` disagree with the indentation of its line: a `{` still
    open although the line is no deeper than the line that opened it (a `}` missing above), or
    none open although the line is indented (a `}` too many above); else ''."""
    if text.startswith("}", position):  # the brace itself is what came too early: nothing above to blame
        return ""
    openers, closed = _braces(text, position)
    line_start = text.rfind("\n", 0, position) + 1
    indent = _indentation(text, line_start)
    # Each guess is kept only when the file, so mended, parses past the error: a layout of one's own
    # (every line flush left) is no mistake.
    if openers and openers[-1] < line_start and indent <= _indentation(text, text.rfind("\n", 0, openers[-1]) + 1) \
            and _parses_past(text[:line_start] + "}\n" + text[line_start:], position + 2):
        line = _line_column(text, openers[-1])[0]
        return f"; is a '}}' missing above? the '{{' of line {line} is still open here"
    if not openers and indent > 0 and closed is not None \
            and _parses_past(text[:closed[0]] + text[closed[0] + 1:], position - 1):
        closer, opener = closed
        return (f"; is the '}}' of line {_line_column(text, closer)[0]} one too many? It closed the '{{' of line "
                f"{_line_column(text, opener)[0]}")
    return ""


def _indentation(text: str, line_start: int) -> int:
    end = line_start
    while end < len(text) and text[end] in " \t":
        end += 1
    return len(text[line_start:end].expandtabs(4))


def _braces(text: str, stop: int) -> tuple[list[int], tuple[int, int] | None]:
    """The positions of the `{` still open at `stop`, and the last `}` before it with the `{` it
    closed, strings and comments aside."""
    openers: list[int] = []
    closed: tuple[int, int] | None = None
    k, n = 0, stop
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
            closed = (k, openers.pop())
        k += 1
    return openers, closed


def _line_column(text: str, position: int) -> tuple[int, int]:
    line = text.count("\n", 0, position) + 1
    return line, position - (text.rfind("\n", 0, position) + 1) + 1
