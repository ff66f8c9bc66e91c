"""Back end `supervisor`: each `procedures` block becomes a module holding its KA library, its
predicate declarations and the bindings of primitive actions and evaluable predicates, ready for
the PRS interpreter of `specc.runtime.supervisor` (seed 000 ch. 4)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from specc.analysis.procedures import library
from specc.backends.env import render
from specc.backends.manifest import HEADER, Output
from specc.backends.rules import python_name
from specc.model import nodes as m
from specc.runtime import procedures as rp

BACKEND = "supervisor"
WIDTH = 110


# Records short enough to read positionally: Var('$X'), Compound('EXECUTION', ('GO',)), Step(Goal(...)).
POSITIONAL = (rp.Var, rp.Compound, rp.Goal, rp.Step)


def literal(value: Any, indent: int = 0, prefix: int = 0) -> str:
    """Deterministic Python source for a library record, for a line indented by `indent` whose
    first `prefix` characters are taken; fields left at their default are omitted and what does
    not fit on one line is laid out one item per line."""
    flat = _flat(value)
    if indent + prefix + len(flat) <= WIDTH:
        return flat
    pad = " " * (indent + 4)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        items = [f"{name}={literal(v, indent + 4, len(name) + 1)}" for name, v in _fields(value)]
        return f"{type(value).__name__}(\n" + "".join(f"{pad}{item},\n" for item in items) + " " * indent + ")"
    if isinstance(value, tuple) and value:
        return "(\n" + "".join(f"{pad}{literal(v, indent + 4)},\n" for v in value) + " " * indent + ")"
    return flat


def _fields(record: Any) -> list[tuple[str, Any]]:
    shown = []
    for f in dataclasses.fields(record):
        value = getattr(record, f.name)
        if f.default is not dataclasses.MISSING and value == f.default:
            continue
        shown.append((f.name, value))
    return shown


def _flat(value: Any) -> str:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = _fields(value)
        if isinstance(value, POSITIONAL):
            return f"{type(value).__name__}({', '.join(_flat(v) for _, v in fields)})"
        return f"{type(value).__name__}({', '.join(f'{n}={_flat(v)}' for n, v in fields)})"
    if isinstance(value, tuple):
        inner = ", ".join(_flat(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    return repr(value)


@dataclass
class SupervisorView:
    procedures: m.Procedures
    library: rp.Library

    @property
    def header(self) -> str:
        return HEADER.format(sources=self.procedures.span.file)

    @property
    def name(self) -> str:
        return self.procedures.name

    @property
    def summary(self) -> str:
        kas = self.library.kas
        primitive = sum(1 for k in kas if k.action is not None and not k.is_meta)
        meta = sum(1 for k in kas if k.is_meta)
        return (f"{len(kas)} KAs ({primitive} primitive, {meta} meta), {len(self.library.predicates)} predicates, "
                f"{len(self.library.primitives)} primitive actions")

    def records(self, values: tuple[Any, ...]) -> list[str]:
        return [literal(v, 4) for v in values]

    @property
    def bindings(self) -> list[str]:
        return rp.bindings(self.library)


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    blocks = sorted((i for i in program.items if isinstance(i, m.Procedures)), key=lambda p: p.name)
    for block in blocks:
        view = SupervisorView(block, library(block))
        output.add(BACKEND, f"supervisor/{python_name(block.name)}.py", render("supervisor/library.py.j2", view=view))
    if blocks:
        output.add(BACKEND, "supervisor/__init__.py", render(
            "supervisor/__init__.py.j2", names=[python_name(b.name) for b in blocks],
            header=HEADER.format(sources="the procedures blocks")))
