"""Back end `executive`: each executive's service list, groups, reflexes and parameters, and its
resource controller (generated rules + the executive's own, compiled to a decision function)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from specc.analysis import kheops as k
from specc.analysis.controller import Controller, executive_controller
from specc.analysis.service_list import executive_spec
from specc.backends.env import Code, render
from specc.backends.manifest import Output, header
from specc.backends.rules import DecisionView, python_name
from specc.model import nodes as m
from specc.runtime import executive as rx

BACKEND = "executive"


def source(value: Any) -> str:
    """Deterministic Python source for a spec value (sets print sorted)."""
    if isinstance(value, frozenset):
        return f"frozenset({tuple(sorted(value))!r})"
    return repr(value)


def arguments(record: Any) -> list[Code]:
    """`field=value` for every field of a runtime record, each value a Python literal (`repr`)."""
    return [Code(f"{f.name}={source(getattr(record, f.name))}") for f in dataclasses.fields(record)]


@dataclass
class ExecutiveView:
    executive: m.Executive
    controller: Controller
    compiled: k.Compiled
    spec: rx.ExecutiveSpec

    @property
    def header(self) -> str:
        return header(self.executive.span.file)

    @property
    def name(self) -> str:
        return self.executive.name

    @property
    def controller_module(self) -> str:
        return python_name(self.controller.name)

    @property
    def rule_count(self) -> int:
        return len(self.compiled.base.rules)

    @property
    def hand_written(self) -> str:
        refs = [ref.text for ref in self.executive.rules]
        return "generated from the conflicts" + (f", with {', '.join(refs)}" if refs else "")

    @property
    def depth(self) -> int:
        return self.compiled.depth

    @property
    def decisions(self) -> str:
        """The bound on the reaction time, per decision (seed 000 §3.7): tests after the one on the service."""
        depths = self.compiled.part_depths()
        if not depths:
            return f"a decision graph of depth {self.depth}"
        deepest = max(depths, key=lambda service: depths[service])
        return f"at most {depths[deepest]} tests after the one on the service, for {deepest}"

    @property
    def group_summary(self) -> str:
        return "; ".join(f"{name} = {' | '.join((*services, 'IDLE'))}"
                         for name, services in self.spec.groups.items()) or "none"

    @property
    def services(self) -> list[tuple[str, list[Code]]]:
        return [(name, arguments(service)) for name, service in self.spec.services.items()]

    @property
    def groups(self) -> list[tuple[str, Code]]:
        return [(name, Code(repr(services))) for name, services in self.spec.groups.items()]

    @property
    def reflexes(self) -> list[Code]:
        return [Code(f"rt.ReflexSpec({', '.join(arguments(r))})") for r in self.spec.reflexes]

    @property
    def parameters(self) -> list[tuple[str, Code]]:
        return [(name, Code(f"rt.ParameterSpec({', '.join(arguments(p))})"))
                for name, p in self.spec.parameters.items()]

    @property
    def codel_module(self) -> Code:
        return Code(repr(self.spec.codel_module))


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    executives = sorted((i for i in program.items if isinstance(i, m.Executive)), key=lambda e: e.name)
    for executive in executives:
        controller = executive_controller(program, executive)
        compiled = controller.compile()  # what it leaves unsettled, `specc check` says (specc.pipeline)
        hand = {ref.text for ref in executive.rules}
        sources = ", ".join(sorted({executive.span.file} | {
            r.span.file for r in program.items if isinstance(r, m.RuleBase) and r.name in hand}))
        output.add(BACKEND, f"executive/{python_name(controller.name)}.py",
                   render("rules/decision.py.j2", view=DecisionView(compiled, sources)))
        view = ExecutiveView(executive, controller, compiled, executive_spec(program, controller))
        output.add(BACKEND, f"executive/{python_name(executive.name)}.py",
                   render("executive/executive.py.j2", view=view))
    if executives:
        output.add(BACKEND, "executive/__init__.py", render(
            "executive/__init__.py.j2", names=[python_name(e.name) for e in executives],
            header=header("the executive blocks")))
