"""Diagnostics: gcc-style messages with stable codes, and the one exception root.

Passes collect `Diagnostic`s and return them; only the CLI decides the exit code.
Tests assert `code`, never the wording.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from specc.model.span import Span
from specc.runtime.hints import did_you_mean as did_you_mean  # re-exported: the checks name it here


class SpeccError(Exception):
    """Root of every exception specc raises on purpose; carries its diagnostics."""

    def __init__(self, diagnostics: list[Diagnostic]):
        self.diagnostics = diagnostics
        super().__init__("\n".join(d.headline() for d in diagnostics))


@dataclass(frozen=True)
class Diagnostic:
    """One message of `specc check`: code, text, where, and notes at other places."""

    code: str
    message: str
    span: Span
    severity: str = "error"  # error | warning | note
    notes: tuple[tuple[Span, str], ...] = field(default=())

    def headline(self) -> str:
        return f"{self.span}: {self.severity}: {self.message} [{self.code}]"

    def as_data(self) -> dict[str, object]:
        """The diagnostic as `specc check --json` writes it (docs/reference.md, "Exit codes")."""
        return {"file": self.span.file, "line": self.span.line, "column": self.span.column,
                "end_line": self.span.end_line, "end_column": self.span.end_column, "severity": self.severity,
                "code": self.code, "message": self.message,
                "notes": [{"file": span.file, "line": span.line, "column": span.column, "message": text}
                          for span, text in self.notes]}


def error(code: str, message: str, span: Span, *notes: tuple[Span, str]) -> Diagnostic:
    return Diagnostic(code, message, span, "error", tuple(notes))


def warning(code: str, message: str, span: Span) -> Diagnostic:
    return Diagnostic(code, message, span, "warning")


def render(diagnostic: Diagnostic, sources: dict[str, str]) -> str:
    """The headline, the source line and a `^~~~` marker under the span. Control characters a
    spec holds never reach the terminal: one line each (a line break as `\\n`), and an ESC or NUL
    in the source line shows as `?` (the marker stays under its column)."""
    lines = [_one_line(diagnostic.headline())]
    lines += _excerpt(diagnostic.span, sources)
    for span, note in diagnostic.notes:
        lines.append(_one_line(f"{span}: note: {note}"))
        lines += _excerpt(span, sources)
    return "\n".join(lines)


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")


def _one_line(text: str) -> str:
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text.replace("\r", "\\r").replace("\n", "\\n"))


def _excerpt(span: Span, sources: dict[str, str]) -> list[str]:
    text = sources.get(span.file)
    if text is None:
        return []
    source_lines = text.split("\n")  # as the lexer counts lines: not at \f, \v or U+2028
    if not 1 <= span.line <= len(source_lines):
        return []
    line = source_lines[span.line - 1].expandtabs(1)
    start = max(span.column - 1, 0)
    if span.end_line == span.line and span.end_column > span.column:
        width = span.end_column - span.column
    else:
        width = max(len(line) - start, 1)
    width = max(1, min(width, max(len(line) - start, 1)))
    return [f"    {_CONTROL.sub('?', line)}", "    " + " " * start + "^" + "~" * (width - 1)]


def sort_key(diagnostic: Diagnostic) -> tuple[str, int, int, str]:
    s = diagnostic.span
    return (s.file, s.line, s.column, diagnostic.code)


def display_path(path: Path) -> str:
    """A file as diagnostics name it: relative to the current folder when inside it."""
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)
