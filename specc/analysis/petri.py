"""Coloured Petri nets (seed 000 §4.3) and their full state-space analysis.

A net is built through a small API: places typed by a finite colour set, transitions whose arcs
carry colours computed from a binding of the transition's variables (each ranging over a finite
set), and an optional guard. Colour sets are finite, so the net unfolds into elementary
transitions (one per binding that passes the guard) over slots (one per place and colour); a
marking is then a tuple of token counts, hashed as it is. The reachability graph is explored
breadth-first, so every reported sequence is a shortest one.

Reports: deadlocks (told apart from the terminal markings the caller expects), place bounds,
unbounded places (a reachable marking covering one of its ancestors with more tokens: the
sequence between them repeats forever), dead transitions, terminal strongly connected
components (an eternal cycle when one holds more than one marking) and home markings (the
markings of the only terminal component, when there is one). Every finding carries the firing
sequence that reaches it, each step naming where in the spec its transition comes from.
"""

from __future__ import annotations

import gc
import itertools
import re
import xml.etree.ElementTree as ET
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

BLACK = "*"  # the colour of an uncoloured token
# A marking is a byte string, one byte per (place, colour): nets translated from procedures have
# thousands of such slots, mostly empty, and bytes keep a million markings in memory.
MAX_TOKENS = 255
NONZERO = re.compile(b"[^\x00]")  # finds a marking's marked slots
Binding = Mapping[str, Any]
Colour = Any


@dataclass(frozen=True)
class Arc:
    """`weight` tokens of the colour `colour` gives for a binding (a constant, or a function)."""

    place: str
    colour: Any = BLACK
    weight: int = 1

    def colour_for(self, binding: Binding) -> Colour:
        return self.colour(binding) if callable(self.colour) else self.colour


@dataclass(frozen=True)
class Place:
    name: str
    colours: tuple[Colour, ...] = (BLACK,)
    initial: Mapping[Colour, int] = field(default_factory=dict)
    origin: str = ""  # where in the spec it comes from


@dataclass(frozen=True)
class Transition:
    name: str
    inputs: tuple[Arc, ...] = ()
    outputs: tuple[Arc, ...] = ()
    variables: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    guard: Callable[[Binding], bool] | None = None
    origin: str = ""
    # When the variables' values depend on each other, the caller may list the bindings
    # outright instead of letting every combination of `variables` through `guard`.
    bindings: tuple[Binding, ...] | None = None

    def each_binding(self) -> Iterable[Binding]:
        if self.bindings is not None:
            yield from self.bindings
            return
        names = list(self.variables)
        for values in itertools.product(*(self.variables[n] for n in names)):
            binding = dict(zip(names, values, strict=True))
            if self.guard is None or self.guard(binding):
                yield binding


@dataclass(frozen=True)
class Step:
    """One elementary transition: a transition under one binding."""

    transition: str
    binding: tuple[tuple[str, Any], ...]
    pre: tuple[tuple[int, int], ...]  # (slot, tokens taken)
    post: tuple[tuple[int, int], ...]  # (slot, tokens put)
    origin: str
    # A step standing for several (see `Unfolded.reduced`): the elementary steps, in firing
    # order, whose pre and post count slots of the unreduced net.
    parts: tuple[Step, ...] = ()

    @property
    def elementary(self) -> tuple[Step, ...]:
        return self.parts or (self,)

    def __str__(self) -> str:
        shown = ", ".join(f"{k}={v}" for k, v in self.binding)
        return f"{self.transition}({shown})" if shown else self.transition


class NetError(ValueError):
    pass


class Net:
    def __init__(self, name: str):
        self.name = name
        self.places: dict[str, Place] = {}
        self.transitions: dict[str, Transition] = {}

    def place(self, name: str, colours: Iterable[Colour] = (BLACK,), initial: Mapping[Colour, int] | int = 0,
              origin: str = "") -> str:
        if name in self.places:
            raise NetError(f"place '{name}' is defined twice")
        colours = tuple(colours)
        if isinstance(initial, int):
            if initial and colours != (BLACK,):
                raise NetError(f"place '{name}' is coloured: give its initial marking by colour")
            marking = {BLACK: initial} if initial else {}
        else:
            marking = dict(initial)
        unknown = [c for c in marking if c not in colours]
        if unknown:
            raise NetError(f"place '{name}': initial colours {unknown} are not in its colour set")
        self.places[name] = Place(name, colours, {c: n for c, n in marking.items() if n}, origin)
        return name

    def transition(self, name: str, inputs: Iterable[Arc] = (), outputs: Iterable[Arc] = (),
                   variables: Mapping[str, Iterable[Any]] | None = None,
                   guard: Callable[[Binding], bool] | None = None, origin: str = "",
                   bindings: Iterable[Binding] | None = None) -> str:
        if name in self.transitions:
            raise NetError(f"transition '{name}' is defined twice")
        arcs = (*inputs, *outputs)
        for arc in arcs:
            if arc.place not in self.places:
                raise NetError(f"transition '{name}': no place '{arc.place}'")
        self.transitions[name] = Transition(name, tuple(inputs), tuple(outputs),
                                            {k: tuple(v) for k, v in (variables or {}).items()}, guard, origin,
                                            None if bindings is None else tuple(bindings))
        return name

    # ------------------------------------------------------------ unfolding
    def unfold(self) -> Unfolded:
        slots: dict[tuple[str, Colour], int] = {}
        for place in self.places.values():
            for colour in place.colours:
                slots[(place.name, colour)] = len(slots)
        steps: list[Step] = []
        for transition in self.transitions.values():
            for binding in transition.each_binding():
                pre = self._vector(transition, transition.inputs, binding, slots)
                post = self._vector(transition, transition.outputs, binding, slots)
                steps.append(Step(transition.name, tuple(binding.items()), pre, post, transition.origin))
        initial = [0] * len(slots)
        for place in self.places.values():
            for colour, count in place.initial.items():
                initial[slots[(place.name, colour)]] = count
        if any(count > MAX_TOKENS for count in initial):
            raise NetError(f"an initial marking puts more than {MAX_TOKENS} tokens in one place")
        return Unfolded(self, list(slots), steps, bytes(initial))

    def _vector(self, transition: Transition, arcs: Iterable[Arc], binding: Binding,
                slots: Mapping[tuple[str, Colour], int]) -> tuple[tuple[int, int], ...]:
        counts: dict[int, int] = {}
        for arc in arcs:
            colour = arc.colour_for(binding)
            slot = slots.get((arc.place, colour))
            if slot is None:
                raise NetError(f"transition '{transition.name}' with {dict(binding)}: colour {colour!r} is not "
                               f"in the colour set of place '{arc.place}'")
            counts[slot] = counts.get(slot, 0) + arc.weight
        return tuple(sorted(counts.items()))


@dataclass
class Unfolded:
    net: Net
    slots: list[tuple[str, Colour]]
    steps: list[Step]
    initial: bytes
    # The slots the parts of reduced steps count (the unreduced net's); `slots` when unreduced.
    original_slots: list[tuple[str, Colour]] | None = None

    def reduced(self, protected: Callable[[str], bool] = lambda place: False) -> Unfolded:
        """The same behaviour over fewer slots and markings.

        First, the slots no firing sequence can ever mark, and the steps needing them, go.
        Then each slot whose only consumer is a step taking that one token and nothing else is
        merged away (Berthelot's pre-agglomeration): once the slot is marked that step is
        enabled and nothing can disable it, so firing it straight after whichever step marked
        the slot loses no deadlock, no end marking and no cycle; only the marking in between.
        Places for which `protected` holds keep their slots."""
        markable = {s for s, n in enumerate(self.initial) if n}
        steps = list(self.steps)
        usable: list[Step] = []
        while True:
            waiting = []
            for step in steps:
                if all(s in markable for s, _ in step.pre):
                    usable.append(step)
                    markable.update(s for s, _ in step.post)
                else:
                    waiting.append(step)
            if len(waiting) == len(steps):
                break
            steps = waiting
        alive: dict[int, Step] = dict(enumerate(usable))
        consumers: dict[int, set[int]] = {}
        producers: dict[int, set[int]] = {}
        for i, step in alive.items():
            for s, _ in step.pre:
                consumers.setdefault(s, set()).add(i)
            for s, _ in step.post:
                producers.setdefault(s, set()).add(i)
        removed: set[int] = set()
        for slot in sorted(markable):
            if self.initial[slot] or protected(self.slots[slot][0]) or len(consumers.get(slot, ())) != 1:
                continue
            (t,) = consumers[slot]
            taker = alive[t]
            makers = producers.get(slot, set())
            if taker.pre != ((slot, 1),) or t in makers or not makers:
                continue
            if any(dict(alive[h].post).get(slot) != 1 for h in makers):
                continue
            for h in makers:
                maker = alive[h]
                post = dict(maker.post)
                del post[slot]
                for s, n in taker.post:
                    post[s] = post.get(s, 0) + n
                fused = Step(maker.transition, maker.binding, maker.pre, tuple(sorted(post.items())), maker.origin,
                             maker.elementary + taker.elementary)
                alive[h] = fused
                for s, _ in taker.post:
                    producers.setdefault(s, set()).add(h)
            for s, _ in taker.post:
                producers[s].discard(t)
            del alive[t]
            del consumers[slot]
            producers.pop(slot, None)
            removed.add(slot)
        kept = [s for s in sorted(markable) if s not in removed]
        renumber = {old: new for new, old in enumerate(kept)}
        new_steps = [Step(st.transition, st.binding, tuple((renumber[s], n) for s, n in st.pre),
                          tuple((renumber[s], n) for s, n in st.post), st.origin, st.elementary)
                     for _, st in sorted(alive.items())]
        return Unfolded(self.net, [self.slots[s] for s in kept], new_steps, bytes(self.initial[s] for s in kept),
                        self.original_slots or self.slots)

    def describe(self, marking: bytes) -> str:
        parts = []
        for (place, colour), count in zip(self.slots, marking, strict=True):
            if count:
                token = place if colour == BLACK else f"{place}({colour})"
                parts.append(token if count == 1 else f"{count}*{token}")
        return " + ".join(parts) or "empty"


# ---------------------------------------------------------------- the state space


@dataclass
class Finding:
    kind: str  # deadlock | unbounded | dead-transition | eternal-cycle
    message: str
    trace: list[Step]
    marking: str = ""
    places: list[str] = field(default_factory=list)  # unbounded: the places that grow
    loop: list[Step] = field(default_factory=list)  # unbounded: the steps that repeat


@dataclass
class StateSpace:
    unfolded: Unfolded
    markings: list[bytes]
    edges: list[list[tuple[int, int]]]  # state -> [(step index, next state)]
    parents: list[tuple[int, int] | None]  # state -> (previous state, step index)
    complete: bool
    unbounded: list[Finding]
    limit_reached: bool = False  # incomplete because of the state limit (else: growing places cut)

    @property
    def states(self) -> int:
        return len(self.markings)

    def trace(self, state: int) -> list[Step]:
        steps: list[Step] = []
        link = self.parents[state]
        while link is not None:
            steps.append(self.unfolded.steps[link[1]])
            link = self.parents[link[0]]
        return steps[::-1]

    def deadlocks(self) -> list[int]:
        return [i for i, out in enumerate(self.edges) if not out]

    def bounds(self) -> dict[str, int]:
        """The most tokens each place ever holds (all colours together)."""
        places = list(self.unfolded.net.places)
        index = {p: i for i, p in enumerate(places)}
        owner = [index[place] for place, _ in self.unfolded.slots]
        best = [0] * len(places)
        for marking in self.markings:
            totals: dict[int, int] = {}
            for match in NONZERO.finditer(marking):
                place = owner[match.start()]
                totals[place] = totals.get(place, 0) + marking[match.start()]
            for place, count in totals.items():
                if count > best[place]:
                    best[place] = count
        return dict(zip(places, best, strict=True))

    def fired(self) -> set[int]:
        return {step for out in self.edges for step, _ in out}

    def dead_transitions(self) -> list[str]:
        alive = {part.transition for i in self.fired() for part in self.unfolded.steps[i].elementary}
        return [name for name in self.unfolded.net.transitions if name not in alive]

    def components(self) -> list[list[int]]:
        """Strongly connected components of the whole state space."""
        return strongly_connected(range(len(self.markings)), lambda state: [t for _, t in self.edges[state]])

    def terminal_components(self) -> list[list[int]]:
        components = self.components()
        owner = {state: n for n, component in enumerate(components) for state in component}
        return [c for n, c in enumerate(components)
                if all(owner[target] == n for state in c for _, target in self.edges[state])]

    def home_markings(self) -> list[int]:
        """Markings reachable from every reachable marking: those of the only terminal component."""
        terminal = self.terminal_components()
        return sorted(terminal[0]) if len(terminal) == 1 else []


def strongly_connected(nodes: Iterable[int], successors: Callable[[int], Iterable[int]]) -> list[list[int]]:
    """Strongly connected components of the graph `nodes` induce (Tarjan, without recursion);
    successors outside `nodes` are ignored."""
    members = set(nodes)
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    on_stack: set[int] = set()
    stack: list[int] = []
    found: list[list[int]] = []
    counter = 0
    for root in sorted(members):
        if root in index:
            continue
        work: list[tuple[int, list[int], int]] = [(root, [t for t in successors(root) if t in members], 0)]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children, position = work.pop()
            for k in range(position, len(children)):
                child = children[k]
                if child not in index:
                    work.append((node, children, k + 1))
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, [t for t in successors(child) if t in members], 0))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    found.append(component)
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
    return found


def explore(net: Net | Unfolded, limit: int = 2_000_000, progress: Callable[[int], None] | None = None
            ) -> StateSpace:
    # The state space only grows while it is built and holds no reference cycles: the cyclic
    # garbage collector would only walk it again and again.
    enabled = gc.isenabled()
    gc.disable()
    try:
        return _explore(net, limit, progress)
    finally:
        if enabled:
            gc.enable()


def _explore(net: Net | Unfolded, limit: int, progress: Callable[[int], None] | None) -> StateSpace:
    unfolded = net.unfold() if isinstance(net, Net) else net
    steps = unfolded.steps
    delta = []
    for step in steps:
        change: dict[int, int] = {}
        for slot, weight in step.pre:
            change[slot] = change.get(slot, 0) - weight
        for slot, weight in step.post:
            change[slot] = change.get(slot, 0) + weight
        delta.append(tuple((s, d) for s, d in change.items() if d))
    # A net whose every step keeps the token count is bounded; any other may grow forever.
    conservative = all(sum(d for _, d in change) == 0 for change in delta)
    seen = {unfolded.initial: 0}
    markings = [unfolded.initial]
    totals = [sum(unfolded.initial)]  # tokens per marking: only a smaller ancestor can be covered
    # The most tokens on the path to each marking. An unbounded net has a path whose token count
    # keeps setting new records (König), and among those record markings one covers an earlier
    # one (Dickson): checking record markings only is enough, and they are rare in bounded nets.
    records = [totals[0]]
    gain = [sum(d for _, d in change) for change in delta]
    parents: list[tuple[int, int] | None] = [None]
    edges: list[list[tuple[int, int]]] = []
    unbounded: list[Finding] = []
    complete, limit_reached = True, False
    queue = deque([0])
    # Index the steps by their first input slot: a marking only ever enables steps whose first
    # input slot holds tokens, and markings are sparse.
    by_slot: list[list[int]] = [[] for _ in unfolded.slots]
    free: list[int] = []
    for i, step in enumerate(steps):
        (by_slot[step.pre[0][0]] if step.pre else free).append(i)
    rest = [step.pre[1:] for step in steps]
    first = [step.pre[0][1] if step.pre else 0 for step in steps]
    seen_get, pop, nonzero = seen.get, queue.popleft, NONZERO.finditer
    while queue:
        state = pop()
        marking = markings[state]
        out: list[tuple[int, int]] = []
        candidates = list(free)
        for match in nonzero(marking):
            slot = match.start()
            tokens = marking[slot]
            for i in by_slot[slot]:
                if tokens >= first[i]:
                    candidates.append(i)
        for i in candidates:
            for slot, weight in rest[i]:
                if marking[slot] < weight:
                    break
            else:
                after = bytearray(marking)
                try:
                    for slot, d in delta[i]:
                        after[slot] += d
                except ValueError:  # a place would hold more tokens than a byte counts
                    if not unbounded:
                        unbounded.append(_overflowing(unfolded, markings, parents, state, i))
                    complete = False
                    continue
                successor = bytes(after)
                target = seen_get(successor)
                if target is None:
                    total = totals[state] + gain[i]
                    if not conservative and not unbounded and total > records[state]:
                        covered = _covered_ancestor(markings, totals, parents, state, successor, total)
                        if covered is not None:
                            unbounded.append(_unbounded(unfolded, markings, parents, covered, state, i, successor))
                            complete = False
                            continue
                    if len(markings) >= limit:
                        complete, limit_reached = False, True
                        continue
                    target = len(markings)
                    seen[successor] = target
                    markings.append(successor)
                    totals.append(total)
                    records.append(max(records[state], total))
                    parents.append((state, i))
                    queue.append(target)
                out.append((i, target))
        edges.append(out)
        if progress is not None and state % 10_000 == 0:
            progress(len(markings))
    while len(edges) < len(markings):  # states left unexplored when the limit was reached
        edges.append([])
    return StateSpace(unfolded, markings, edges, parents, complete, unbounded, limit_reached)


def _covered_ancestor(markings: list[bytes], totals: list[int], parents: list[tuple[int, int] | None],
                      state: int, successor: bytes, total: int) -> int | None:
    """An ancestor of `successor` it covers with strictly more tokens (Karp-Miller)."""
    node: int | None = state
    while node is not None:
        if totals[node] < total and all(a <= b for a, b in zip(markings[node], successor, strict=True)):
            return node
        link = parents[node]
        node = link[0] if link is not None else None
    return None


def _overflowing(unfolded: Unfolded, markings: list[bytes], parents: list[tuple[int, int] | None],
                 state: int, step: int) -> Finding:
    space = StateSpace(unfolded, markings, [], parents, False, [])
    full = sorted({unfolded.slots[s][0] for s, _ in unfolded.steps[step].post})
    return Finding("unbounded", f"place(s) {', '.join(full)} would hold more than {MAX_TOKENS} tokens",
                   space.trace(state) + [unfolded.steps[step]], unfolded.describe(markings[state]))


def _unbounded(unfolded: Unfolded, markings: list[bytes], parents: list[tuple[int, int] | None],
               ancestor: int, state: int, step: int, successor: bytes) -> Finding:
    space = StateSpace(unfolded, markings, [], parents, False, [])
    before, upto = space.trace(ancestor), space.trace(state) + [unfolded.steps[step]]
    grown = sorted({unfolded.slots[s][0] for s, (a, b) in enumerate(zip(markings[ancestor], successor,
                                                                        strict=True)) if b > a})
    loop = upto[len(before):]
    shown = " ; ".join(part.transition for s in loop for part in s.elementary)
    return Finding("unbounded", f"place(s) {', '.join(grown)} grow without bound: the sequence {shown} can repeat "
                   "forever, adding tokens each time", upto, unfolded.describe(successor), grown, loop)


@dataclass
class Report:
    space: StateSpace
    findings: list[Finding]
    bounds: dict[str, int]
    home: bool


def analyse(net: Net, expected_end: Callable[[Callable[[str], int]], bool] | None = None,
            limit: int = 2_000_000, progress: Callable[[int], None] | None = None) -> Report:
    """Explore `net` and report what a designer must look at. `expected_end(tokens)` tells a
    terminal marking that is a normal end (tokens(place) counts a place's tokens) from a deadlock."""
    space = explore(net, limit, progress)
    unfolded = space.unfolded
    findings: list[Finding] = list(space.unbounded)

    def tokens_of(marking: bytes) -> Callable[[str], int]:
        return lambda place: sum(n for (p, _), n in zip(unfolded.slots, marking, strict=True) if p == place)

    for state in space.deadlocks() if space.complete else []:
        marking = space.markings[state]
        if expected_end is not None and expected_end(tokens_of(marking)):
            continue
        findings.append(Finding("deadlock", "no transition can fire, and this is not an expected end",
                                space.trace(state), unfolded.describe(marking)))
        break  # the shortest one; the others usually repeat it
    if space.complete:
        for name in space.dead_transitions():
            origin = unfolded.net.transitions[name].origin
            findings.append(Finding("dead-transition", f"'{name}'{f' ({origin})' if origin else ''} can never fire",
                                    []))
        for component in space.terminal_components():
            looping = len(component) > 1 or any(t == component[0] for _, t in space.edges[component[0]])
            if looping:
                entry = min(component)
                findings.append(Finding("eternal-cycle", f"{len(component)} marking(s) cycle forever with no way "
                                        "out", space.trace(entry), unfolded.describe(space.markings[entry])))
    return Report(space, findings, space.bounds(), bool(space.home_markings()))


# ---------------------------------------------------------------- PNML (ISO/IEC 15909-2)

PNML = "http://www.pnml.org/version-2009/grammar/pnml"
PTNET = "http://www.pnml.org/version-2009/grammar/ptnet"


def to_pnml(net: Net | Unfolded) -> str:
    """The unfolded net as an ISO/IEC 15909-2 place/transition net (one place per place and
    colour, one transition per binding), readable by PNML tools. Given an `Unfolded` (the reduced
    net `specc verify` explores), that one: its transitions are the fused steps."""
    unfolded = net.unfold() if isinstance(net, Net) else net
    net = unfolded.net
    ET.register_namespace("", PNML)
    root = ET.Element(f"{{{PNML}}}pnml")
    element = ET.SubElement(root, f"{{{PNML}}}net", id=_xml_id(net.name), type=PTNET)
    ET.SubElement(ET.SubElement(element, f"{{{PNML}}}name"), f"{{{PNML}}}text").text = net.name
    page = ET.SubElement(element, f"{{{PNML}}}page", id="page0")
    for slot, (place, colour) in enumerate(unfolded.slots):
        node = ET.SubElement(page, f"{{{PNML}}}place", id=f"p{slot}")
        label = place if colour == BLACK else f"{place}({colour})"
        ET.SubElement(ET.SubElement(node, f"{{{PNML}}}name"), f"{{{PNML}}}text").text = label
        if unfolded.initial[slot]:
            marking = ET.SubElement(node, f"{{{PNML}}}initialMarking")
            ET.SubElement(marking, f"{{{PNML}}}text").text = str(unfolded.initial[slot])
    arcs = 0
    for number, step in enumerate(unfolded.steps):
        node = ET.SubElement(page, f"{{{PNML}}}transition", id=f"t{number}")
        ET.SubElement(ET.SubElement(node, f"{{{PNML}}}name"), f"{{{PNML}}}text").text = str(step)
        for source, target, weight in ([(f"p{s}", f"t{number}", w) for s, w in step.pre]
                                       + [(f"t{number}", f"p{s}", w) for s, w in step.post]):
            arc = ET.SubElement(page, f"{{{PNML}}}arc", id=f"a{arcs}", source=source, target=target)
            arcs += 1
            if weight != 1:
                inscription = ET.SubElement(arc, f"{{{PNML}}}inscription")
                ET.SubElement(inscription, f"{{{PNML}}}text").text = str(weight)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _xml_id(name: str) -> str:
    cleaned = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    return cleaned if cleaned[:1].isalpha() or cleaned[:1] == "_" else f"n_{cleaned}"
