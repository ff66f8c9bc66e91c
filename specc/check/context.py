"""What every check pass looks things up in: the program's items indexed by kind and name."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from specc.check.symbols import KIND_WORDS, symbols_of
from specc.diagnostics import Diagnostic, did_you_mean, error
from specc.model import nodes as m
from specc.model.span import Span

T = TypeVar("T")
KNOWN_SHOWN = 12  # known names an unknown name's message lists when none is close


@dataclass
class Context:
    """What a check works on: the program, where its files are, and the diagnostics so far."""

    program: m.Program
    base_dirs: dict[str, Path] = field(default_factory=dict)  # file (as in spans) -> its folder
    diagnostics: list[Diagnostic] = field(default_factory=list)

    def __post_init__(self) -> None:
        # The semantic analysis, first: every later pass reads these tables (check/symbols.py).
        self.symbols = symbols_of(self.program)
        self.by_kind = self.symbols.blocks

    # ------------------------------------------------------------ lookups
    def items(self, kind: type[T]) -> Iterator[T]:
        return (item for item in self.program.items if isinstance(item, kind))

    def named(self, kind: type[T]) -> Mapping[str, T]:
        return self.by_kind[kind]

    def lookup(self, kind: type[T], ref: m.Ref | str, span: Span, code: str) -> T | None:
        """The item of `kind` called `ref`, or a diagnostic with a suggestion."""
        name = ref if isinstance(ref, str) else ref.text
        table = self.by_kind[kind]
        if name in table:
            return table[name]  # type: ignore[no-any-return]
        self.unknown(code, KIND_WORDS[kind], name, table, span)
        return None

    def base_dir(self, span: Span) -> Path:
        return self.base_dirs.get(span.file, Path.cwd())

    # ------------------------------------------------------------ reporting
    def report(self, code: str, message: str, span: Span, *notes: tuple[Span, str]) -> None:
        self.diagnostics.append(error(code, message, span, *notes))

    def warn(self, code: str, message: str, span: Span) -> None:
        self.diagnostics.append(Diagnostic(code, message, span, "warning"))

    def unknown(self, code: str, what: str, name: str, candidates: Any, span: Span, where: str = "") -> None:
        """`unknown <what> '<name>'`, with the closest known name, or the known names when none is
        close and they are few enough to read."""
        hint = did_you_mean(name, candidates)
        known = sorted(str(c) for c in candidates) if candidates is not None else []
        if not hint and 0 < len(known) <= KNOWN_SHOWN and "(" not in where:
            hint = f" (known: {', '.join(known)})"
        self.report(code, f"unknown {what} '{name}'{where}{hint}", span)

    def duplicates(self, nodes: Any, what: str, key: str = "name") -> None:
        """Report every node whose `key` was already used by an earlier node of the list."""
        first: dict[str, Any] = {}
        for node in nodes:
            name = getattr(node, key)
            if name in first:
                self.report("duplicate-definition", f"{what} '{name}' is defined twice", node.span,
                            (first[name].span, "first defined here"))
            else:
                first[name] = node
