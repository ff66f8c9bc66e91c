"""Back end `planner`: each `domain` becomes a module holding its attributes and tasks as data
(the runtime records of `specc.runtime.planner.model`: assertions, and the numeric and temporal
constraints the planner's propagators and CasADi build from), and the problems written for it as
initial partial plans (seed 004 §3.2.1.2, annex A)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from specc.analysis.planning import domain_model, problem_model
from specc.backends.env import render
from specc.backends.manifest import Output, header
from specc.backends.records import literal
from specc.backends.rules import python_name
from specc.model import nodes as m
from specc.runtime.planner import model as pm

BACKEND = "planner"
POSITIONAL = (pm.Num, pm.Sym, pm.Var, pm.Time, pm.Op, pm.Interval, pm.Symbols, pm.GoalMark)


@dataclass
class DomainView:
    domain: m.Domain
    model: pm.PlanningDomain
    problems: list[pm.Problem]

    @property
    def header(self) -> str:
        files = sorted({self.domain.span.file} | {p.source for p in self.problems})
        return header(", ".join(files))

    @property
    def name(self) -> str:
        return self.model.name

    @property
    def summary(self) -> str:
        return (f"{len(self.model.attributes)} attributes, {len(self.model.resources)} resources, "
                f"{len(self.model.tasks)} tasks, {len(self.problems)} problems")

    def records(self, values: tuple[Any, ...] | list[Any]) -> list[str]:
        return [literal(v, POSITIONAL, 4) for v in values]


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    domains = sorted((i for i in program.items if isinstance(i, m.Domain)), key=lambda d: d.name)
    problems = sorted((i for i in program.items if isinstance(i, m.Problem)), key=lambda p: p.name)
    for domain in domains:
        mine = [problem_model(program, p) for p in problems if p.domain.text == domain.name]
        view = DomainView(domain, domain_model(program, domain), mine)
        output.add(BACKEND, f"planner/{python_name(domain.name)}.py", render("planner/domain.py.j2", view=view))
    if domains:
        output.add(BACKEND, "planner/__init__.py", render(
            "planner/__init__.py.j2", names=[python_name(d.name) for d in domains],
            header=header("the domain and problem blocks")))
