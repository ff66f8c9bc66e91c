"""An executive's description as the runtime uses it (seed 000 §3.3.1): the service description
list, the groups, reflexes and parameters. The executive back end prints it; `specc verify`
runs it."""

from __future__ import annotations

from typing import Any

from specc.analysis.controller import Controller
from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.runtime import executive as rx


def value_of(value: Any) -> Any:
    """A spec value (service argument, reflex constant) as plain Python data."""
    if isinstance(value, (m.String, m.Number)):
        return value.value
    if isinstance(value, m.Duration):
        return value.seconds
    if isinstance(value, m.Ref):
        return {"true": True, "false": False}.get(value.text, value.text)
    return str(value)


def seconds(duration: m.Duration | None) -> float | None:
    return None if duration is None else duration.seconds


def executive_spec(program: m.Program, controller: Controller) -> rx.ExecutiveSpec:
    executive, graph = controller.executive, controller.graph
    symbols = symbols_of(program)
    services = {}
    for service in executive.services:
        found = symbols.service_request(service)
        assert found is not None and service.request is not None  # the checks resolved it
        module, request = service.request.parts
        kind = found.kind or "exec"
        timeout = service.timeout or m.Timeouts()
        targets = {a.target for a in graph.arcs if a.source == service.name}
        linked = targets | {a.source for a in graph.arcs if a.target == service.name}
        group = next((g.services for g in controller.groups if service.name in g.services), ())
        services[service.name] = rx.ServiceSpec(
            name=service.name, module=module, request=request, kind=kind,
            args={a.name: value_of(a.value) for a in service.args}, takes=tuple(t.text for t in service.takes),
            input=service.input.text if service.input else None,
            output=service.output.text if service.output else None,
            start_timeout=seconds(timeout.start), interm_timeout=seconds(timeout.interm),
            final_timeout=seconds(timeout.final), conflicts=frozenset(linked), targets=frozenset(targets),
            group=frozenset(group))
    reflexes = tuple(rx.ReflexSpec(
        name=reflex.name or f"reflex{number + 1}", trigger=reflex.trigger, source=reflex.source.text,
        op=reflex.comparison.op if reflex.comparison else None,
        value=value_of(reflex.comparison.value) if reflex.comparison else None,
        actions=tuple((a.verb, a.target.text) for a in reflex.actions))
        for number, reflex in enumerate(executive.reflexes))
    parameters = {p.name: rx.ParameterSpec(p.name, p.get.text if p.get else None, p.set.text if p.set else None)
                  for p in executive.parameters}
    groups = {controller.state_attribute(g): g.services for g in controller.groups}
    return rx.ExecutiveSpec(executive.name, services, groups, reflexes, parameters,
                            executive.codel_module.value if executive.codel_module else None)
