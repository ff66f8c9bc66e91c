"""The service incompatibility graph and its reduction to service groups (seed 000 §3.6.1).

An arc A -> B says: to run A, B must first be interrupted (or, for a `wait` arc, have ended).
Arcs come from the executive's `conflicts` (logical conflicts), from the modules'
`incompatible_with` between the requests two services run (physical conflicts: the module
itself interrupts), and from the requests a service's codels send to other modules (`sends:`)
that are incompatible there with another service's request (logical: the executive aborts it
before the sender starts, and holds it back while the sender runs, since the module would
interrupt it without the executive's say). A control service takes no time, so nothing ever needs to interrupt it:
no arc ends at one.

Complete symmetric subgraphs (every pair both ways, every service looping on itself) are
reduced to macro-vertices; then, as §3.6.1 prescribes "dans la plupart des cas", every vertex
of the reduced graph that ends at least one arc needs a group, whose value says which of its
services runs (or IDLE). The resource controller has prod(M_i + 1) states.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from itertools import combinations

from specc.check.symbols import symbols_of
from specc.model import nodes as m


@dataclass(frozen=True)
class Arc:
    """An incompatibility between two services: the policy the source applies to the target."""

    source: str
    target: str
    policy: str  # interrupt | wait
    physical: bool  # implied by the modules' incompatible_with


@dataclass(frozen=True)
class IncompatibilityGraph:
    """The services of an executive and their incompatibilities (seed 000 §3.3)."""

    services: tuple[str, ...]
    arcs: tuple[Arc, ...]
    modules: dict[str, str]  # service -> module of its request
    control: frozenset[str]  # services running a control request

    def successors(self, service: str) -> set[str]:
        return {a.target for a in self.arcs if a.source == service}

    def has_arc(self, source: str, target: str) -> bool:
        return target in self.successors(source)


@dataclass(frozen=True)
class Group:
    """Services that share a controller state: a connected part of the graph."""

    services: tuple[str, ...]

    @property
    def name(self) -> str:
        joiner = "" if all(len(s) == 1 for s in self.services) else "_"
        return joiner.join(self.services)

    @property
    def states(self) -> tuple[str, ...]:
        return (*self.services, "IDLE")


def build_graph(program: m.Program, executive: m.Executive) -> IncompatibilityGraph:
    symbols = symbols_of(program)
    requests: dict[str, m.Request] = {}
    module_of: dict[str, str] = {}
    for service in executive.services:
        found = symbols.service_request(service)
        if found is not None and service.request is not None:
            requests[service.name] = found
            module_of[service.name] = service.request.parts[0]
    control = frozenset(name for name, request in requests.items() if request.kind == "control")
    arcs: dict[tuple[str, str], Arc] = {}
    for first, second in ((a, b) for a in requests for b in requests):
        if module_of[first] == module_of[second] and incompatible(requests[first], requests[second]):
            if second not in control:
                arcs[(first, second)] = Arc(first, second, "interrupt", True)
    # A request a service's codels send to another module (`sends:`, transitively) interrupts
    # there what it is incompatible with, without the executive's say, at any time the sender
    # runs: the controller stops that service (an abort) before the sender starts, and holds
    # it back (a wait) while the sender runs. Both arcs are logical.
    # Every interrupt arc first, then the waits where no arc is: which of two services sending to
    # each other comes first in the spec changes nothing.
    sent_over = [(first, second) for first, request in requests.items()
                 for module_name, sent in symbols.sent(request)
                 for second, target in requests.items()
                 if module_of[second] == module_name and second not in control and incompatible(sent, target)]
    for first, second in sent_over:
        arcs.setdefault((first, second), Arc(first, second, "interrupt", False))
    for first, second in sent_over:
        if first not in control and second != first:
            arcs.setdefault((second, first), Arc(second, first, "wait", False))
    declared = {s.name for s in executive.services}
    for service in executive.services:
        for conflict in service.conflicts:
            if conflict.service in control or conflict.service not in declared:  # unknown: reported by checks
                continue
            existing = arcs.get((service.name, conflict.service))
            physical = existing is not None and existing.physical  # a sent request's arc is logical
            arcs[(service.name, conflict.service)] = Arc(service.name, conflict.service, conflict.policy, physical)
    names = tuple(dict.fromkeys(s.name for s in executive.services))
    ordered = tuple(sorted(arcs.values(), key=lambda a: (names.index(a.source), names.index(a.target))))
    return IncompatibilityGraph(names, ordered, module_of, control)


def incompatible(first: m.Request, second: m.Request) -> bool:
    listed = {r.text for r in first.incompatible_with}
    other = {r.text for r in second.incompatible_with}
    return second.name in listed or "all" in listed or first.name in other or "all" in other


def complete_symmetric(graph: IncompatibilityGraph, services: Iterable[str]) -> bool:
    members = list(services)
    return all(graph.has_arc(s, s) for s in members) and all(
        graph.has_arc(a, b) and graph.has_arc(b, a) for a, b in combinations(members, 2))


def reduce(graph: IncompatibilityGraph) -> tuple[tuple[str, ...], ...]:
    """The macro-vertices: a partition of the services into complete symmetric subgraphs.

    Largest first; between equals, those whose services share one module (the common case
    the seed describes, one group per module), then the earliest declared."""
    looped = [s for s in graph.services if graph.has_arc(s, s)]
    mutual = {s: {t for t in looped if t != s and graph.has_arc(s, t) and graph.has_arc(t, s)} for s in looped}
    cliques = maximal_cliques(looped, mutual)
    order = {s: i for i, s in enumerate(graph.services)}
    taken: set[str] = set()
    macros: list[tuple[str, ...]] = []
    while True:
        # Cliques are sets: list their members in declaration order, or ties follow string hashing.
        candidates = [tuple(sorted((s for s in c if s not in taken), key=order.__getitem__)) for c in cliques]
        candidates = [c for c in candidates if c]
        if not candidates:
            break
        best = min(candidates, key=lambda c: (-len(c), len({graph.modules.get(s) for s in c}),
                                               [order[s] for s in c]))
        best = tuple(sorted(best, key=order.__getitem__))
        macros.append(best)
        taken.update(best)
    macros += [(s,) for s in graph.services if s not in taken]
    return tuple(sorted(macros, key=lambda c: order[c[0]]))


def maximal_cliques(vertices: list[str], neighbours: dict[str, set[str]]) -> list[frozenset[str]]:
    """Bron-Kerbosch with pivoting over the mutual-arc relation (graphs here are small)."""
    found: list[frozenset[str]] = []

    def expand(clique: set[str], candidates: set[str], excluded: set[str]) -> None:
        if not candidates and not excluded:
            found.append(frozenset(clique))
            return
        pivot = max(candidates | excluded, key=lambda v: len(neighbours[v] & candidates))
        for vertex in sorted(candidates - neighbours[pivot]):
            expand(clique | {vertex}, candidates & neighbours[vertex], excluded & neighbours[vertex])
            candidates = candidates - {vertex}
            excluded = excluded | {vertex}

    if vertices:
        expand(set(), set(vertices), set())
    return found


def service_groups(graph: IncompatibilityGraph) -> list[Group]:
    """One group per reduced vertex that ends at least one arc (a service someone interrupts)."""
    targets = {a.target for a in graph.arcs}
    return [Group(macro) for macro in reduce(graph) if any(s in targets for s in macro)]


def state_count(groups: Iterable[Group]) -> int:
    return math.prod(len(g.services) + 1 for g in groups)
