"""The resource controller's Kheops rules, derived from the executive's conflicts.

Seed 000 §3.8.1 writes these rules by hand for the generic system of Table 3.1 and its
conclusion asks for them to be generated from the modules' and services' incompatibilities:
this module does so, following the patterns of §3.8.1 for every service and event, so that
the base is complete and consistent by construction (the compiler checks it anyway).

Inputs: `service`, `event` (START INTERM END ABORT ZOMBIE) and, for every service group, its
state in the previous cycle (`@<group>state`). Outputs: `status` (OK WAIT REFUSE ERROR) and each
group's new state. External calls: changeInterState(service) marks an activity its own module
is interrupting; sendAbortRequest(service) asks another module to interrupt one.
"""

from __future__ import annotations

from specc.analysis.incompat import Group, IncompatibilityGraph, service_groups
from specc.model import nodes as m

EVENTS = ("START", "INTERM", "END", "ABORT", "ZOMBIE")
STATUSES = ("OK", "WAIT", "REFUSE", "ERROR")
IDLE = "IDLE"


def state_attribute(group: Group) -> str:
    return "".join(c if c.isalnum() else "_" for c in group.name) + "state"


def _attr(name: str, previous: bool = False) -> m.AttrRef:
    return m.AttrRef(name=name, previous=previous)


def _is(name: str, value: str, previous: bool = False) -> m.KCompare:
    return m.KCompare(attr=_attr(name, previous), op="==", value=m.String(value=value))


def _one_of(name: str, values: tuple[str, ...], previous: bool = False, negate: bool = False) -> m.KMember:
    return m.KMember(attr=_attr(name, previous), op="noneof" if negate else "oneof",
                     items=tuple(m.String(value=v) for v in values))


def _and(*operands: m.Cond) -> m.Cond:
    return operands[0] if len(operands) == 1 else m.KAnd(operands=operands)


def _or(*operands: m.Cond) -> m.Cond:
    return operands[0] if len(operands) == 1 else m.KOr(operands=operands)


def _restrict(name: str, value: str) -> m.Restrict:
    return m.Restrict(restriction=_is(name, value))


def _call(function: str, group: Group) -> m.DoAction:
    return m.DoAction(statements=(m.DoCall(function=function, args=(_attr(state_attribute(group), True),)),))


def _rule(name: str, condition: m.Cond, *actions: m.Action) -> m.Rule:
    return m.Rule(name=name, kind="when", condition=condition, actions=actions)


def controller_rules(name: str, graph: IncompatibilityGraph, groups: list[Group] | None = None) -> m.RuleBase:
    groups = service_groups(graph) if groups is None else groups
    group_of = {s: g for g in groups for s in g.services}
    rules: list[m.Rule] = []
    for service in graph.services:
        rules += start_rules(service, graph, groups)
        rules += reply_rules(service, graph, group_of.get(service))
    for group in groups:
        rules += frame_rules(group)
    attributes = [
        m.AttrDecl(role="inputs", name="service", domain=m.SymbolDomain(values=tuple(
            m.String(value=s) for s in graph.services))),
        m.AttrDecl(role="inputs", name="event", domain=m.SymbolDomain(values=tuple(m.String(value=e) for e in EVENTS))),
        m.AttrDecl(role="outputs", name="status", domain=m.SymbolDomain(values=tuple(
            m.String(value=s) for s in STATUSES))),
    ]
    attributes += [m.AttrDecl(role="outputs", name=state_attribute(g), domain=m.SymbolDomain(
        values=tuple(m.String(value=v) for v in g.states))) for g in groups]
    inits = tuple(m.InitDecl(name=state_attribute(g), value=m.String(value=IDLE)) for g in groups)
    return m.RuleBase(name=name, attributes=tuple(attributes), inits=inits, rules=tuple(rules))


def start_rules(service: str, graph: IncompatibilityGraph, groups: list[Group]) -> list[m.Rule]:
    """START: wait while a service it waits for runs; otherwise interrupt what it conflicts with
    (its own module by marking the activity, another module by an abort request, then WAIT)."""
    start = (_is("event", "START"), _is("service", service))
    waits = {a.target for a in graph.arcs if a.source == service and a.policy == "wait"}
    interrupts = {a.target for a in graph.arcs if a.source == service and a.policy == "interrupt"}
    waited = [(g, tuple(s for s in g.services if s in waits)) for g in groups]
    waited = [(g, members) for g, members in waited if members]
    rules: list[m.Rule] = []
    for group, members in waited:
        rules.append(_rule(f"{service}_waits_{group.name}",
                           _and(*start, _one_of(state_attribute(group), members, previous=True)),
                           _restrict("status", "WAIT")))
    none_waited = tuple(_one_of(state_attribute(g), members, previous=True, negate=True) for g, members in waited)
    must_wait_for_abort: list[m.Cond] = []
    for group in groups:
        targets = tuple(s for s in group.services if s in interrupts)
        if not targets:
            continue
        running = _one_of(state_attribute(group), targets, previous=True)
        local = all(graph.modules.get(t) == graph.modules.get(service) for t in targets)
        actions: list[m.Action] = [_call("changeInterState", group)]
        if not local:
            actions.append(_call("sendAbortRequest", group))
            must_wait_for_abort.append(running)
        rules.append(_rule(f"{service}_interrupts_{group.name}", _and(*start, *none_waited, running), *actions))
    if must_wait_for_abort:
        rules.append(_rule(f"{service}_waits_for_abort", _and(*start, *none_waited, _or(*must_wait_for_abort)),
                           _restrict("status", "WAIT")))
    free = tuple(m.KNot(operand=c) for c in must_wait_for_abort)
    rules.append(_rule(f"{service}_starts", _and(*start, *none_waited, *free), _restrict("status", "OK")))
    return rules


def reply_rules(service: str, graph: IncompatibilityGraph, group: Group | None) -> list[m.Rule]:
    """INTERM, END, ABORT, ZOMBIE: a group records its running service from the intermediate
    reply to the end; anything that cannot happen in the current state is an ERROR (§3.4.2)."""
    me = _is("service", service)
    if service in graph.control:
        return [_rule(f"{service}_end", _and(_is("event", "END"), me), _restrict("status", "OK")),
                _rule(f"{service}_impossible", _and(_one_of("event", ("INTERM", "ABORT", "ZOMBIE")), me),
                      _restrict("status", "ERROR"))]
    if group is None:
        return [_rule(f"{service}_replies", _and(_one_of("event", ("INTERM", "END", "ABORT", "ZOMBIE")), me),
                      _restrict("status", "OK"))]
    state = state_attribute(group)
    return [
        _rule(f"{service}_interm", _and(_is("event", "INTERM"), me, _is(state, IDLE, previous=True)),
              _restrict("status", "OK"), _restrict(state, service)),
        _rule(f"{service}_interm_not_idle", _and(_is("event", "INTERM"), me,
                                                 _one_of(state, (IDLE,), previous=True, negate=True)),
              _restrict("status", "ERROR")),
        _rule(f"{service}_end", _and(_is("event", "END"), me, _is(state, service, previous=True)),
              _restrict("status", "OK"), _restrict(state, IDLE)),
        _rule(f"{service}_still_running", _and(_one_of("event", ("ABORT", "ZOMBIE")), me,
                                               _is(state, service, previous=True)),
              _restrict("status", "OK")),
        _rule(f"{service}_not_running", _and(_one_of("event", ("END", "ABORT", "ZOMBIE")), me,
                                             _one_of(state, (service,), previous=True, negate=True)),
              _restrict("status", "ERROR")),
    ]


def frame_rules(group: Group) -> list[m.Rule]:
    """A group keeps its state unless an intermediate reply starts one of its services in it,
    or the end of its running service empties it."""
    state = state_attribute(group)
    changes = _or(
        _and(_is("event", "INTERM"), _one_of("service", group.services), _is(state, IDLE, previous=True)),
        _and(_is("event", "END"), _or(*(_and(_is("service", s), _is(state, s, previous=True))
                                        for s in group.services))))
    return [_rule(f"keep_{state}_{value}", _and(_is(state, value, previous=True), m.KNot(operand=changes)),
                  _restrict(state, value)) for value in group.states]
