"""Back end `supervisor`: each `procedures` block becomes a module holding its KA library, its
predicate declarations and the bindings of primitive actions and evaluable predicates, ready for
the PRS interpreter of `specc.runtime.supervisor` (seed 000 ch. 4)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from specc.analysis.procedures import library
from specc.backends.env import render
from specc.backends.manifest import Output, header
from specc.backends.records import literal
from specc.backends.rules import python_name
from specc.model import nodes as m
from specc.runtime import procedures as rp

BACKEND = "supervisor"


# Records short enough to read positionally: Var('$X'), Compound('EXECUTION', ('GO',)), Step(Goal(...)).
POSITIONAL = (rp.Var, rp.Compound, rp.Goal, rp.Step)


@dataclass
class SupervisorView:
    procedures: m.Procedures
    library: rp.Library

    @property
    def header(self) -> str:
        return header(self.procedures.span.file)

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
        return [literal(v, POSITIONAL, 4) for v in values]

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
            header=header("the procedures blocks")))
