"""What parsing a file gives (lark-free, so that a parse read back from the cache needs no lark)."""

from __future__ import annotations

from dataclasses import dataclass, field

from specc.diagnostics import Diagnostic
from specc.model import nodes as m


@dataclass(frozen=True)
class Comment:
    """A comment of the source, kept for the formatter: its text (line ends as "\\n") and where
    it starts."""

    text: str
    line: int
    column: int

    def lines(self, pad: str) -> list[str]:
        """The comment at indentation `pad`. A block comment's later lines keep their indentation
        relative to its first line, so re-indenting twice gives the same text."""
        first, *more = self.text.split("\n")
        shown = [pad + first]
        for part in more:
            part = part.rstrip()
            indent = len(part) - len(part.lstrip())
            shown.append(pad + part[min(indent, self.column - 1):] if part else "")
        return shown


@dataclass
class ParseResult:
    """One file's parse: its model (None on a syntax error), diagnostics and comments."""

    source: m.SourceFile | None
    diagnostics: list[Diagnostic]
    comments: list[Comment] = field(default_factory=list)
