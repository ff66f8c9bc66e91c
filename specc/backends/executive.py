"""Back end `executive`: each executive's service list, groups, reflexes and parameters, and its
resource controller (generated rules + the executive's own, compiled to a decision function)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from specc.analysis import kheops as k
from specc.analysis.controller import Controller, executive_controller
from specc.backends.env import render
from specc.backends.manifest import HEADER, Output
from specc.backends.rules import DecisionView, python_name
from specc.model import nodes as m

BACKEND = "executive"


def value_literal(value: Any) -> str:
    """A spec value (service argument, reflex constant) as Python source."""
    if isinstance(value, (m.String, m.Number)):
        return repr(value.value)
    if isinstance(value, m.Duration):
        return repr(value.seconds)
    if isinstance(value, m.Ref):
        return repr({"true": True, "false": False}.get(value.text, value.text))
    return repr(str(value))


def seconds(duration: m.Duration | None) -> str:
    return "None" if duration is None else repr(duration.seconds)


@dataclass
class ServiceView:
    service: m.Service
    controller: Controller
    requests: dict[str, m.Request]

    @property
    def name(self) -> str:
        return self.service.name

    @property
    def fields(self) -> list[str]:
        service, graph = self.service, self.controller.graph
        module, request = service.request.parts[0], service.request.parts[1]  # type: ignore[union-attr]
        kind = self.requests[self.name].kind
        timeout = service.timeout or m.Timeouts()
        linked = sorted({a.target for a in graph.arcs if a.source == self.name}
                        | {a.source for a in graph.arcs if a.target == self.name})
        args = "{" + ", ".join(f"{a.name!r}: {value_literal(a.value)}" for a in service.args) + "}"
        return [f"name={self.name!r}", f"module={module!r}", f"request={request!r}", f"kind={kind!r}",
                f"args={args}", f"input={service.input.text if service.input else None!r}",
                f"output={service.output.text if service.output else None!r}",
                f"start_timeout={seconds(timeout.start)}", f"interm_timeout={seconds(timeout.interm)}",
                f"final_timeout={seconds(timeout.final)}", f"conflicts=frozenset({linked!r})"]


@dataclass
class ExecutiveView:
    executive: m.Executive
    controller: Controller
    compiled: k.Compiled
    requests: dict[str, m.Request]

    @property
    def header(self) -> str:
        return HEADER.format(sources=self.executive.span.file)

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
    def group_summary(self) -> str:
        return "; ".join(f"{self.controller.state_attribute(g)} = {' | '.join(g.states)}"
                         for g in self.controller.groups) or "none"

    @property
    def services(self) -> list[ServiceView]:
        return [ServiceView(s, self.controller, self.requests) for s in self.executive.services]

    @property
    def groups(self) -> list[tuple[str, str]]:
        return [(self.controller.state_attribute(g), repr(g.services)) for g in self.controller.groups]

    @property
    def reflexes(self) -> list[str]:
        lines = []
        for number, reflex in enumerate(self.executive.reflexes):
            comparison = reflex.comparison
            op = repr(comparison.op) if comparison else "None"
            value = value_literal(comparison.value) if comparison else "None"
            actions = tuple((a.verb, a.target.text) for a in reflex.actions)
            lines.append(f"rt.ReflexSpec({reflex.name or f'reflex{number + 1}'!r}, {reflex.trigger!r}, "
                         f"{reflex.source.text!r}, {op}, {value}, {actions!r})")
        return lines

    @property
    def parameters(self) -> list[tuple[str, str]]:
        return [(p.name, f"rt.ParameterSpec({p.name!r}, {p.get.text if p.get else None!r}, "
                         f"{p.set.text if p.set else None!r})") for p in self.executive.parameters]

    @property
    def codel_module(self) -> str:
        return repr(self.executive.codel_module.value) if self.executive.codel_module else "None"


def service_requests(program: m.Program, executive: m.Executive) -> dict[str, m.Request]:
    modules = {i.name: i for i in program.items if isinstance(i, m.Module)}
    found = {}
    for service in executive.services:
        assert service.request is not None  # checked
        module, request = service.request.parts
        found[service.name] = next(r for r in modules[module].requests if r.name == request)
    return found


def generate(program: m.Program, output: Output, robot: str = "") -> None:
    executives = sorted((i for i in program.items if isinstance(i, m.Executive)), key=lambda e: e.name)
    for executive in executives:
        controller = executive_controller(program, executive)
        compiled = k.compile_base(controller.base)
        sources = ", ".join(sorted({executive.span.file} | {r.span.file for r in program.items
                                                              if isinstance(r, m.RuleBase)
                                                              and r.name in {x.text for x in executive.rules}}))
        output.add(BACKEND, f"executive/{python_name(controller.name)}.py",
                   render("rules/decision.py.j2", view=DecisionView(compiled, sources)))
        view = ExecutiveView(executive, controller, compiled, service_requests(program, executive))
        output.add(BACKEND, f"executive/{python_name(executive.name)}.py",
                   render("executive/executive.py.j2", view=view))
    if executives:
        output.add(BACKEND, "executive/__init__.py", render(
            "executive/__init__.py.j2", names=[python_name(e.name) for e in executives],
            header=HEADER.format(sources="the executive blocks")))
