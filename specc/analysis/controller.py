"""The resource controller's Kheops rules, derived from the executive's conflicts.

Seed 000 §3.8.1 writes these rules by hand for the generic system of Table 3.1 and its
conclusion asks for them to be generated from the modules' and services' incompatibilities:
this module does so, following the patterns of §3.8.1 for every service and event, so that
the base is complete and consistent by construction (the compiler checks it anyway).

Inputs: `service`, `event` (START INTERM END ABORT ZOMBIE) and, for every service group, its
state in the previous cycle (`@<group>state`). Outputs: `status` (OK WAIT REFUSE ERROR) and each
group's new state. External calls: changeInterState(service) marks an activity its own module
is interrupting; sendAbortRequest(service) asks another module to interrupt one.

An executive's own rule bases (`executive { rules: ...; }`, e.g. Fig 5.6) join the generated
ones (`executive_controller`): where a hand-written rule applies, it takes over the decisions it
makes (the attributes it restricts, the calls it makes on a group), and the generated rules
deciding the same thing step aside; everywhere else the generated rules decide. The declared
waits are the exception: where a service must WAIT for one it is declared to wait for, no
hand-written rule applies to its start (`take_over`). A hand-written
output whose values are a group's services plus IDLE names that group's state (Fig 5.6 calls
the pilo group ExecTrajState).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from specc.analysis import kheops as k
from specc.analysis.incompat import Group, IncompatibilityGraph, build_graph, service_groups
from specc.check.symbols import symbols_of
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import walk

EVENTS = ("START", "INTERM", "END", "ABORT", "ZOMBIE")
STATUSES = ("OK", "WAIT", "REFUSE", "ERROR")
IDLE = "IDLE"


def state_attribute(group: Group, names: Mapping[Group, str] | None = None) -> str:
    """The group's state attribute: the name a hand-written base gave it, else <group>state."""
    if names and group in names:
        return names[group]
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


def _call(function: str, group: Group, names: Mapping[Group, str] | None) -> m.DoAction:
    return m.DoAction(statements=(m.DoCall(function=function, args=(_attr(state_attribute(group, names), True),)),))


def _rule(name: str, condition: m.Cond, *actions: m.Action) -> m.Rule:
    return m.Rule(name=name, kind="when", condition=condition, actions=actions)


def controller_rules(name: str, graph: IncompatibilityGraph, groups: list[Group] | None = None,
                     names: Mapping[Group, str] | None = None) -> m.RuleBase:
    groups = service_groups(graph) if groups is None else groups
    group_of = {s: g for g in groups for s in g.services}
    rules: list[m.Rule] = []
    for service in graph.services:
        rules += start_rules(service, graph, groups, names)
        rules += reply_rules(service, graph, group_of.get(service), names)
    for group in groups:
        rules += frame_rules(group, names)
    attributes = [
        m.AttrDecl(role="inputs", name="service", domain=m.SymbolDomain(values=tuple(
            m.String(value=s) for s in graph.services))),
        m.AttrDecl(role="inputs", name="event", domain=m.SymbolDomain(values=tuple(m.String(value=e) for e in EVENTS))),
        m.AttrDecl(role="outputs", name="status", domain=m.SymbolDomain(values=tuple(
            m.String(value=s) for s in STATUSES))),
    ]
    attributes += [m.AttrDecl(role="outputs", name=state_attribute(g, names), domain=m.SymbolDomain(
        values=tuple(m.String(value=v) for v in g.states))) for g in groups]
    inits = tuple(m.InitDecl(name=state_attribute(g, names), value=m.String(value=IDLE)) for g in groups)
    return m.RuleBase(name=name, attributes=tuple(attributes), inits=inits, rules=tuple(rules))


def start_rules(service: str, graph: IncompatibilityGraph, groups: list[Group],
                names: Mapping[Group, str] | None = None) -> list[m.Rule]:
    """START: wait while a service it waits for runs; otherwise interrupt what it conflicts with
    (its own module by marking the activity, another module by an abort request, then WAIT)."""
    start = (_is("event", "START"), _is("service", service))
    waits = {a.target for a in graph.arcs if a.source == service and a.policy == "wait"}
    interrupts = {a.target for a in graph.arcs if a.source == service and a.policy == "interrupt"}
    waited = [(g, tuple(s for s in g.services if s in waits)) for g in groups]
    waited = [(g, members) for g, members in waited if members]
    rules: list[m.Rule] = []
    for group, members in waited:
        rules.append(_rule(declared_wait(service, group),
                           _and(*start, _one_of(state_attribute(group, names), members, previous=True)),
                           _restrict("status", "WAIT")))
    none_waited = tuple(_one_of(state_attribute(g, names), members, previous=True, negate=True)
                        for g, members in waited)
    must_wait_for_abort: list[m.Cond] = []
    for group in groups:
        targets = tuple(s for s in group.services if s in interrupts)
        if not targets:
            continue
        running = _one_of(state_attribute(group, names), targets, previous=True)
        # The module interrupts an activity by itself only when its requests are incompatible
        # (a physical arc); a logical conflict needs an explicit abort, even in the same module.
        local = all(graph.modules.get(t) == graph.modules.get(service) and physical(graph, service, t)
                    for t in targets)
        actions: list[m.Action] = [_call("changeInterState", group, names)]
        if not local:
            actions.append(_call("sendAbortRequest", group, names))
            must_wait_for_abort.append(running)
        # Interrupt only along with the answer that goes with it (OK once the module interrupts by
        # itself, WAIT while an abort is under way): a hand-written rule answering otherwise where
        # it applies (REFUSE, WAIT) leaves running services alone.
        answer = _is("status", "WAIT" if not local else "OK")
        rules.append(_rule(f"{service}_interrupts_{group.name}", _and(*start, *none_waited, running, answer),
                           *actions))
    if must_wait_for_abort:
        rules.append(_rule(f"{service}_waits_for_abort", _and(*start, *none_waited, _or(*must_wait_for_abort)),
                           _restrict("status", "WAIT")))
    free = tuple(m.KNot(operand=c) for c in must_wait_for_abort)
    rules.append(_rule(f"{service}_starts", _and(*start, *none_waited, *free), _restrict("status", "OK")))
    return rules


def declared_wait(service: str, group: Group) -> str:
    """The name of the generated rule making `service` WAIT while a member of `group` it is declared
    to wait for runs: no hand-written rule takes that decision over."""
    return f"{service}_waits_{group.name}"


def wait_rules(graph: IncompatibilityGraph, groups: list[Group]) -> dict[str, tuple[str, str]]:
    """The generated wait rules by name, each with the service it makes WAIT and the group it waits on."""
    return {declared_wait(a.source, g): (a.source, g.name) for a in graph.arcs if a.policy == "wait"
            for g in groups if a.target in g.services}


def declared_waits(graph: IncompatibilityGraph, groups: list[Group]) -> frozenset[str]:
    return frozenset(wait_rules(graph, groups))


def physical(graph: IncompatibilityGraph, source: str, target: str) -> bool:
    return any(a.physical for a in graph.arcs if a.source == source and a.target == target)


def reply_rules(service: str, graph: IncompatibilityGraph, group: Group | None,
                names: Mapping[Group, str] | None = None) -> list[m.Rule]:
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
    state = state_attribute(group, names)
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


def frame_rules(group: Group, names: Mapping[Group, str] | None = None) -> list[m.Rule]:
    """A group keeps its state unless an intermediate reply starts one of its services in it,
    or the end of its running service empties it."""
    state = state_attribute(group, names)
    changes = _or(
        _and(_is("event", "INTERM"), _one_of("service", group.services), _is(state, IDLE, previous=True)),
        _and(_is("event", "END"), _or(*(_and(_is("service", s), _is(state, s, previous=True))
                                        for s in group.services))))
    return [_rule(f"keep_{state}_{value}", _and(_is(state, value, previous=True), m.KNot(operand=changes)),
                  _restrict(state, value)) for value in group.states]


# ---------------------------------------------------------------- the executive's whole controller


@dataclass(frozen=True)
class Problem:
    """Why a hand-written base cannot join the controller (reported by the executive check)."""

    code: str
    message: str
    node: m.Node


@dataclass
class Controller:
    """An executive's resource controller: the groups and the merged, normalised rule base."""

    executive: m.Executive
    graph: IncompatibilityGraph
    groups: list[Group]
    names: dict[Group, str]
    base: k.Base
    problems: list[Problem] = field(default_factory=list)
    # The generated frame rules (a group keeps its state), as objects of `base`: a rule a
    # hand-written one took over is another object, and no longer a plain frame.
    frames: tuple[k.Rule, ...] = ()

    @property
    def name(self) -> str:
        return self.base.name

    def state_attribute(self, group: Group) -> str:
        return state_attribute(group, self.names)

    def parts(self) -> dict[str, tuple[k.Base, tuple[str, ...]]]:
        """One decision per service, deciding only the group states its events may change: a group
        the service is not in, whose state no rule that can apply to the service reads as it is
        decided or restricts, keeps its previous state without a test (its frame rules are left
        out). A decision then tests the groups its service is in conflict with (seed 000 §3.8.1's
        rules for it), not the product of every group's states: the controller grows with the
        conflicts (issue #24)."""
        framed = {id(rule): output for rule in self.frames for output in k.targets(rule)}
        framed_states = set(framed.values())
        member_states = {service: {self.state_attribute(g) for g in self.groups if service in g.services}
                         for service in self.graph.services}
        service_attribute = self.base.attributes["service"]
        memory = k.initial_memory(self.base)
        mentions = {id(rule): mentioned(rule) for rule in self.base.rules if id(rule) not in framed}
        parts: dict[str, tuple[k.Base, tuple[str, ...]]] = {}
        for service in service_attribute.values:
            memory["service"] = frozenset({service})
            applicable = [rule for rule in self.base.rules
                          if rule.condition is None or k.truth(rule.condition, memory) != k.FALSE]
            read = set().union(*(mentions[id(rule)] for rule in applicable if id(rule) in mentions))
            kept = tuple(output for output in self.base.outputs if output in framed_states
                         and output not in read and output not in member_states.get(service, ()))
            rules = tuple(rule for rule in applicable if framed.get(id(rule)) not in kept)
            attributes = {name: a for name, a in self.base.attributes.items() if name not in kept}
            attributes["service"] = dataclasses.replace(service_attribute, values=(service,))
            parts[service] = (k.Base(f"{self.base.name}[{service}]", attributes, rules, self.base.source), kept)
        return parts

    def compile(self) -> k.Compiled:
        """The decision graph, one decision per service; past Kheops' work limit, the reason told
        in the executive's terms."""
        parts = self.parts()
        try:
            return k.compile_parts(self.base, "service", parts)
        except k.TooLarge as exc:
            bound, largest = k.paths_bound_text(parts[exc.part][0], shown=8)
            raise k.TooLarge(
                f"the resource controller of executive '{self.executive.name}' needs more than {exc.limit:,} "
                f"decision-tree nodes to compile (the decision for service {exc.part} alone tests up to {bound:,} "
                f"combinations: {largest} values): declare fewer conflicts for that service (every group "
                "it interrupts or waits for multiplies its decision), or give each independent part of the robot "
                f"its own executive; {k.WORK_LIMIT_VARIABLE}=N raises the limit", self.executive, exc.limit,
                exc.part) from None


def mentioned(rule: k.Rule) -> set[str]:
    """Every attribute a rule tests, restricts, assigns or passes to a call."""
    return {atom.attribute for atom in k.atoms(rule.condition)} | _acted_on(rule)


def _acted_on(rule: k.Rule) -> set[str]:
    """Every attribute a rule's actions restrict, assign, compute from or pass to a call."""
    found = set(k.targets(rule))
    for action in rule.actions:
        if isinstance(action, k.Call):
            found |= set().union(*(arg.attributes() for arg in action.args))
        elif isinstance(action, k.Assign):
            found |= action.expr.attributes()
    return found


def mentioned_where(rule: k.Rule, memory: Mapping[str, frozenset[Any]]) -> set[str]:
    """What `mentioned` says, leaving out the tests whose truth `memory` already decides: the
    generated rules step aside where a hand-written one applies by a condition that names its
    own service, and for any other service that part is false whatever it tests."""

    def tested(cond: k.Cond | None) -> set[str]:
        if cond is None or k.truth(cond, memory) != k.UNKNOWN:
            return set()
        if isinstance(cond, k.Atom):
            return {cond.attribute}
        if isinstance(cond, k.Not):
            return tested(cond.operand)
        return set().union(*(tested(operand) for operand in cond.operands))

    return tested(rule.condition) | _acted_on(rule)


def controller_name(executive: m.Executive) -> str:
    return f"{executive.name}_resource_controller"


@dataclass
class Naming:
    """An executive's groups, the names its own rule bases give them, and what they got wrong."""

    graph: IncompatibilityGraph
    groups: list[Group]
    hand: list[m.RuleBase]
    names: dict[Group, str]
    problems: list[Problem]


def naming(program: m.Program, executive: m.Executive) -> Naming:
    """Cheap (no rules normalised or compiled): the executive check reports its problems."""
    graph = build_graph(program, executive)
    groups = service_groups(graph)
    bases = symbols_of(program).blocks[m.RuleBase]
    hand = [bases[ref.text] for ref in executive.rules if ref.text in bases]
    names: dict[Group, str] = {}
    problems: list[Problem] = []
    for base in hand:
        problems += name_groups(base, graph, groups, names)
    return Naming(graph, groups, hand, names, problems)


def executive_controller(program: m.Program, executive: m.Executive) -> Controller:
    """The generated rules of `executive`, joined by its hand-written bases."""
    named = naming(program, executive)
    graph, groups, names = named.graph, named.groups, named.names
    merged = k.normalise(controller_rules(controller_name(executive), graph, groups, names))
    frame_names = {rule.name for group in groups for rule in frame_rules(group, names)}
    frames = tuple(rule for rule in merged.rules if rule.name in frame_names)
    if not named.problems:
        for base in named.hand:
            merged = take_over(merged, k.normalise(base), groups, names, declared_waits(graph, groups))
    return Controller(executive, graph, groups, names, merged, named.problems, frames)


def name_groups(base: m.RuleBase, graph: IncompatibilityGraph, groups: list[Group],
                names: dict[Group, str]) -> list[Problem]:
    """Check a hand-written base's attributes against what the executive gives its controller,
    and learn the names it gives group states."""
    problems = []
    fixed = {"service": ("inputs", graph.services), "event": ("inputs", EVENTS), "status": ("outputs", STATUSES)}
    for decl in base.attributes:
        values = [getattr(v, "value", getattr(v, "text", None)) for v in decl.domain.values] \
            if isinstance(decl.domain, m.SymbolDomain) else None
        if decl.name in fixed:
            role, allowed = fixed[decl.name]
            unknown = [v for v in values or () if v not in allowed]
            if decl.role != role or values is None or unknown:
                problems.append(Problem("controller-attribute", (
                    f"in an executive's rules, '{decl.name}' is one of its {role} with values among "
                    f"{', '.join(allowed)}" + (f" (not: {', '.join(map(str, unknown))})" if unknown else "")), decl))
        elif decl.role == "outputs":
            group = next((g for g in groups if values is not None and set(values) == set(g.states)), None)
            taken = {name: g for g, name in names.items()}
            if group is None:
                listed = "; ".join(" ".join(g.states) for g in groups) or "none"
                problems.append(Problem("unknown-group-state", (
                    f"output '{decl.name}' must be a service group's state: its values are one group's "
                    f"services plus \"{IDLE}\" (groups of this executive: {listed})"), decl))
            elif names.get(group, decl.name) != decl.name or taken.get(decl.name, group) != group:
                problems.append(Problem("unknown-group-state", (
                    f"'{decl.name}' names group {group.name} differently from another rule base"), decl))
            else:
                names[group] = decl.name
        elif decl.role == "inputs":
            problems.append(Problem("controller-attribute", (
                f"the executive gives its controller only service, event and the groups' previous states; "
                f"it cannot supply input '{decl.name}'"), decl))
    return problems


def decisions(rule: k.Rule, groups: list[Group], names: Mapping[Group, str]) -> set[tuple[Any, ...]]:
    """What a rule decides: the attributes it restricts, and each call on a group (or service)."""
    group_of_service = {s: g for g in groups for s in g.services}
    group_of_attribute = {"@" + state_attribute(g, names): g for g in groups}
    found: set[tuple[Any, ...]] = set()
    for action in rule.actions:
        if isinstance(action, k.Restrict):
            found.add(("restrict", action.atom.attribute))
        elif isinstance(action, k.Assign):
            found.add(("restrict", action.target))
        else:
            targets = []
            for arg in action.args:
                if arg.op == "attr":
                    targets.append(group_of_attribute.get(arg.args[0], arg.args[0]))
                elif arg.op == "const":
                    targets.append(group_of_service.get(arg.args[0], arg.args[0]))
                else:
                    targets.append(repr(arg))
            found.add(("call", action.function, *targets))
    return found


def fixed_values(condition: k.Cond) -> dict[str, Any]:
    """The attributes a condition requires to equal one value (its top-level `a == v` tests)."""
    atoms = condition.operands if isinstance(condition, k.All) else (condition,)
    return {a.attribute: a.value for a in atoms if isinstance(a, k.Atom) and a.op == "=="}


def rules_waits_override(executive: m.Executive, named: Naming) -> list[Problem]:
    """The executive's hand-written rules that a wait always overrides: whenever one applies, so
    does the generated rule making its service WAIT (a declared `wait`, or one a `sends:` adds),
    which no hand-written rule takes over (`take_over`), so the rule never decides anything.
    `named`: the executive's `naming`, which its caller has already."""
    if named.problems or not named.hand:
        return []
    generated = k.normalise(controller_rules(controller_name(executive), named.graph, named.groups, named.names))
    waits = wait_rules(named.graph, named.groups)
    guards = [rule for rule in generated.rules if rule.name in waits and rule.condition is not None]
    found = []
    for base in named.hand:
        nodes = {rule.name: rule for rule in base.rules if isinstance(rule, m.Rule)}
        for rule in k.normalise(base).rules:
            if rule.kind != "when" or rule.condition is None or rule.name not in nodes:
                continue
            mine = fixed_values(rule.condition)
            wait = next((g for g in guards if g.condition is not None and _implies(mine, g.condition)), None)
            if wait is not None:
                service, group = waits[wait.name]
                found.append(Problem("rule-never-applies", (
                    f"rule '{rule.name}' never applies: where it does, {service} waits for what runs in group "
                    f"{group} (a declared `wait`, or one a `sends:` adds), and no hand-written rule takes a wait "
                    "over; drop the rule, or declare that conflict an interrupt"), nodes[rule.name]))
    return found


def unread_deductions(named: Naming) -> list[Problem]:
    """What an executive's hand-written rules deduce that nothing reads: an attribute they restrict
    that is none of the controller's (`status`, a group's state), not declared, and that no rule of
    the base tests (`restrict statu == "WAIT"`, a typo): the rule then decides nothing."""
    if named.problems:
        return []
    known = {"status", *named.names.values(), *(state_attribute(g) for g in named.groups)}
    # The bases are joined into one: what one deduces, another may test.
    declared = {a.name for base in named.hand for a in base.attributes}
    tested = {n.name for base in named.hand for rule in walk(base) if isinstance(rule, m.Rule)
              and rule.condition is not None for n in walk(rule.condition) if isinstance(n, m.AttrRef)}
    found = []
    said: set[str] = set()
    for base in named.hand:
        for rule in (r for r in walk(base) if isinstance(r, m.Rule)):
            for action in (a for a in rule.actions if isinstance(a, m.Restrict)):
                name = action.restriction.attr.name
                if name in known | declared | tested | said:
                    continue
                said.add(name)
                outputs = sorted(known)
                problem = Problem("intermediate-never-read", (
                    f"rules deduce '{name}', which is none of the executive controller's outputs, not declared, "
                    f"and no rule tests: rule '{rule.name}' decides nothing"
                    f"{did_you_mean(name, outputs) or ' (a misspelt output?)'}"), action)
                found.append(problem)
    return found


def _implies(fixed: Mapping[str, Any], condition: k.Cond) -> bool:
    """Do the attribute values `fixed` make `condition` (tests of `==` and `in` only) true?"""
    operands = condition.operands if isinstance(condition, k.All) else (condition,)
    atoms = [a for a in operands if isinstance(a, k.Atom) and a.op in ("==", "in")]
    if len(atoms) != len(operands):
        return False
    return all(a.attribute in fixed
               and (fixed[a.attribute] == a.value if a.op == "==" else fixed[a.attribute] in a.value)
               for a in atoms)


def step_aside(rule: k.Rule, guards: list[k.Cond]) -> k.Rule:
    """`rule`, holding only where none of `guards` applies. Guards that cannot hold with it (they
    test another service or event) are left out: the decision graph stays as it was elsewhere."""
    assert rule.condition is not None
    mine = fixed_values(rule.condition)
    relevant = tuple(g for g in guards
                     if all(mine.get(attribute, value) == value for attribute, value in fixed_values(g).items()))
    if not relevant:
        return rule
    return k.Rule(rule.name, rule.kind, k.All((rule.condition, k.Not(k.Any_(relevant)))), rule.actions)


def take_over(generated: k.Base, hand: k.Base, groups: list[Group], names: Mapping[Group, str],
              waits: frozenset[str] = frozenset()) -> k.Base:
    """Hand-written rules first; a generated rule deciding something a hand-written one decides
    holds only where none of those hand-written rules applies. The generated rules named in
    `waits` (a service WAITs while one it is declared to wait for runs) are not taken over: a
    hand-written rule steps aside where one of them applies. Fig 5.6's rule starting CALC-TRAJ-OBJ
    at once tests only the pilo group; taking over the wait for READ-MODEL too would let the
    planner's module interrupt a READ-MODEL nobody decided to interrupt (§3.4.2's ERROR)."""
    guards = [rule.condition for rule in generated.rules if rule.name in waits and rule.condition is not None]
    hand_rules = [rule if rule.kind != "when" or rule.condition is None else step_aside(rule, guards)
                  for rule in hand.rules]
    rules: list[k.Rule] = list(hand_rules)
    when = [(rule, decisions(rule, groups, names)) for rule in hand_rules if rule.kind == "when"]
    for rule in generated.rules:
        mine = decisions(rule, groups, names)
        overriding = tuple(h.condition for h, theirs in when if theirs & mine and h.condition is not None)
        if overriding and rule.condition is not None and rule.name not in waits:
            rule = k.Rule(rule.name, rule.kind, k.All((rule.condition, k.Not(k.Any_(overriding)))), rule.actions)
        rules.append(rule)
    attributes = dict(generated.attributes)
    for name, attribute in hand.attributes.items():
        attributes.setdefault(name, attribute)
    return k.Base(generated.name, attributes, tuple(rules), generated.source)

