"""Plan-space search over partial plans, as IxTeT does (seed 004 §3.2.1.2, Fig 3.6).

A partial plan holds task instances, their assertions, causal links, variable bindings and a
temporal network. Its flaws are open conditions (a hold, or the value an event changes, with
nothing yet giving it), threats (an event that may change a value while a link protects it)
and resource conflicts. Resolvers link an existing event, insert a task, order two timepoints
or keep two arguments apart; the flaw with the fewest resolvers is solved first, and a flaw
with a single resolver is solved at once.

How a timepoint nature decides (a contingent task end, a visibility window's instant) enters the
temporal network depends on the controllability the planner asks of its plans:

- strong (the default): the network is kept in its strongly controllable form. Such a point is
  never scheduled itself; every constraint on it is rewritten on the timepoint it hangs from, for
  its worst offset (Vidal & Fargier). So the network is consistent exactly when one schedule of the
  plan's own timepoints works for every duration nature may pick.
- pseudo: the problem's contingent instants (nature's events: a window opens, closes) are
  timepoints of the network like any other, each bound to the origin by a contingent link that
  the network must not narrow (pseudo-controllability, as IxTeT checks it: seed 004 §4.1.3, a
  contingent interval "must not be reduced" by the plan). Each instant alone may then fall anywhere
  in its bounds, but not every combination of them: a plan may need a window to close late when it
  opens late. Contingent durations stay strong: the executive dispatches what follows an action
  for its longest duration, as it must when it judges an action late from its plan alone.

Either way each resolver is checked against it at once.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import NamedTuple

from specc.runtime.planner import model as pm
from specc.runtime.planner.model import EPS, differences
from specc.runtime.planner.numeric import (
    IDENTITY_CACHE_LIMIT,
    DurationSpec,
    Empty,
    domain_of,
    duration_of,
    is_duration,
    is_number,
)
from specc.runtime.stn import STN, Inconsistent, for_every_offset

INF = math.inf
STRONG, PSEUDO = "strong", "pseudo"  # the controllability a plan is searched for (see above)
CONTROLLABILITIES = (STRONG, PSEUDO)
TOLERANCE = 1e-6
SURELY = 10 * TOLERANCE  # a bound this close counts as met: the network loosens each constraint by TOLERANCE
Term = float | str  # a value, or a variable when the string holds a '?'


class DeadEnd(Exception):
    """This partial plan has no completion."""


def as_term(e: pm.Expr, variable: Callable[[str], str] = str) -> Term:
    """An assertion's argument or value as the plan holds it: a number, a symbol, or the plan's
    name of a variable."""
    if isinstance(e, pm.Num):
        return e.value
    if isinstance(e, pm.Sym):
        return e.name
    if isinstance(e, pm.Var):
        return variable(e.name)
    raise DeadEnd(f"expressions are not planned in assertions: {e}")


def translate(anchors: Mapping[str, tuple[str, float, float]], a: str, b: str, low: float,
              high: float) -> tuple[str, str, float, float]:
    """`low <= t(b) - t(a) <= high` rewritten on the timepoints a and b hang from (themselves when
    the plan schedules them), for every offset nature gives them."""
    pa, la, ha = anchors.get(a, (a, 0.0, 0.0))
    pb, lb, hb = anchors.get(b, (b, 0.0, 0.0))
    return (pa, pb) + for_every_offset(low, high, (la, ha), (lb, hb))


def _seconds(value: float) -> str:
    """A date or a delay in a message, to the millisecond."""
    return f"{round(value, 3) + 0.0:g}"  # + 0.0: no "-0"


def is_var(term: Term) -> bool:
    return isinstance(term, str) and "?" in term


def same_value(a: Term, b: Term) -> bool:
    if is_number(a) and is_number(b):
        return abs(float(a) - float(b)) <= TOLERANCE
    return a == b


# ---------------------------------------------------------------- bindings


class Bindings:
    """Variables of the plan in codesignation classes, each with a domain (symbols or an
    interval); `apart` pairs must never codesignate."""

    def __init__(self) -> None:
        self.parent: dict[str, str] = {}
        self.domain: dict[str, frozenset[str] | tuple[float, float] | None] = {}
        self.apart: list[tuple[Term, Term]] = []
        # Memos, forgotten when a class or a domain changes: resolve()'s answers, and the `apart`
        # pairs resolved, as what each representative must differ from (built when first asked,
        # then only replaced, so that copies may share it).
        self.resolved: dict[str, Term] = {}
        self._apart_from: dict[str, list[Term]] | None = None

    def copy(self) -> Bindings:
        other = Bindings.__new__(Bindings)
        other.parent = dict(self.parent)
        other.domain = dict(self.domain)
        other.apart = list(self.apart)
        other.resolved = dict(self.resolved)
        other._apart_from = self._apart_from
        return other

    def _forget(self) -> None:
        self.resolved.clear()
        self._apart_from = None

    def declare(self, var: str, domain: frozenset[str] | tuple[float, float] | None) -> None:
        if var in self.parent:
            self._forget()  # a new variable changes no other's class: only a redeclared one counts
        self.parent[var] = var
        self.domain[var] = domain

    def restrict(self, var: str, domain: frozenset[str] | tuple[float, float] | None) -> None:
        """Narrow the domain of the variable's class (raises DeadEnd when nothing is left)."""
        r = self.root(var)
        self.domain[r] = self._meet(self.domain[r], domain)
        self._forget()

    def root(self, var: str) -> str:
        while self.parent[var] != var:
            self.parent[var] = self.parent[self.parent[var]]
            var = self.parent[var]
        return var

    def resolve(self, term: Term) -> Term:
        """The term's value when known, else its class's representative."""
        if not isinstance(term, str) or "?" not in term:  # is_var, inlined: the search's hottest test
            return term
        known = self.resolved.get(term)
        if known is not None:
            return known
        r = self.root(term)
        d = self.domain[r]
        result: Term = r
        if isinstance(d, frozenset) and len(d) == 1:
            result = next(iter(d))
        elif isinstance(d, tuple) and d[0] == d[1]:
            result = d[0]
        self.resolved[term] = result
        return result

    def value(self, term: Term) -> Term | None:
        resolved = self.resolve(term)
        return None if is_var(resolved) else resolved

    def possibly_equal(self, a: Term, b: Term) -> bool:
        a, b = self.resolve(a), self.resolve(b)
        a_var, b_var = isinstance(a, str) and "?" in a, isinstance(b, str) and "?" in b  # is_var, inlined
        if not a_var and not b_var:
            return same_value(a, b)
        if a_var and b_var and a == b:
            return True
        var, other = (a, b) if a_var else (b, a)
        assert isinstance(var, str)
        if any(same_value(other, x) for x in self._kept_apart(var)):
            return False
        if not (a_var and b_var):
            return self._admits(self.domain[var], other)
        da, db = self.domain[str(a)], self.domain[str(b)]
        if isinstance(da, frozenset) and isinstance(db, frozenset):
            return bool(da & db)
        if isinstance(da, tuple) and isinstance(db, tuple):
            return max(da[0], db[0]) <= min(da[1], db[1]) + TOLERANCE
        return da is None or db is None

    def _kept_apart(self, representative: str) -> list[Term]:
        """What the class must differ from (values, or other classes' representatives)."""
        if self._apart_from is None:
            apart_from: dict[str, list[Term]] = {}
            for x, y in self.apart:
                rx, ry = self.resolve(x), self.resolve(y)
                if is_var(rx):
                    apart_from.setdefault(str(rx), []).append(ry)
                if is_var(ry):
                    apart_from.setdefault(str(ry), []).append(rx)
            self._apart_from = apart_from
        return self._apart_from.get(representative, [])

    @staticmethod
    def _admits(domain: frozenset[str] | tuple[float, float] | None, value: Term) -> bool:
        if domain is None:
            return True
        if isinstance(domain, frozenset):
            return isinstance(value, str) and value in domain
        return is_number(value) and domain[0] - TOLERANCE <= float(value) <= domain[1] + TOLERANCE

    def unify(self, a: Term, b: Term) -> list[str]:
        """Make a and b codesignate; returns the variables that gained a value (raises DeadEnd)."""
        ra, rb = self.resolve(a), self.resolve(b)
        self._forget()
        if not is_var(ra) and not is_var(rb):
            if not same_value(ra, rb):
                raise DeadEnd(f"{ra} is not {rb}")
            return []
        if not is_var(ra):
            ra, rb = rb, ra
        assert isinstance(ra, str)
        if is_var(rb):
            assert isinstance(rb, str)
            if ra == rb:
                return []
            da, db = self.domain[ra], self.domain[rb]
            merged = self._meet(da, db)
            self.parent[rb] = ra
            self.domain[ra] = merged
        else:
            if not self._admits(self.domain[ra], rb):
                raise DeadEnd(f"{rb} is outside the domain of {ra}")
            self.domain[ra] = frozenset((rb,)) if isinstance(rb, str) else (float(rb), float(rb))
        for x, y in self.apart:
            rx, ry = self.resolve(x), self.resolve(y)
            if (not is_var(rx) and not is_var(ry) and same_value(rx, ry)) or (is_var(rx) and rx == ry):
                raise DeadEnd(f"{x} and {y} must differ")
        # Most variables are their own class's root: only the others need the walk up.
        return [v for v, up in self.parent.items() if v == ra or (up != v and self.root(v) == ra)]

    @staticmethod
    def _meet(da: frozenset[str] | tuple[float, float] | None,
              db: frozenset[str] | tuple[float, float] | None) -> frozenset[str] | tuple[float, float] | None:
        if da is None:
            return db
        if db is None:
            return da
        if isinstance(da, frozenset) and isinstance(db, frozenset):
            if not da & db:
                raise DeadEnd("no common value")
            return da & db
        if isinstance(da, tuple) and isinstance(db, tuple):
            low, high = max(da[0], db[0]), min(da[1], db[1])
            if low > high + TOLERANCE:
                raise DeadEnd("no common value")
            return (low, max(low, high))
        raise DeadEnd("a symbol cannot equal a number")

    def keep_apart(self, a: Term, b: Term) -> None:
        if not self.possibly_equal(a, b):
            return
        ra, rb = self.resolve(a), self.resolve(b)
        self._forget()
        if not is_var(ra) and not is_var(rb):
            raise DeadEnd(f"{ra} and {rb} must differ")
        if (is_var(ra) and ra == rb):
            raise DeadEnd(f"{a} and {b} must differ")
        # A symbol apart from a constant simply loses that value.
        for var, other in ((ra, rb), (rb, ra)):
            if is_var(var) and not is_var(other) and isinstance(self.domain[str(var)], frozenset):
                remaining = self.domain[str(var)] - {other}  # type: ignore[operator]
                if not remaining:
                    raise DeadEnd(f"{a} has no value left")
                self.domain[str(var)] = remaining
                return
        self.apart.append((a, b))


# ---------------------------------------------------------------- partial plans


@dataclass(frozen=True)
class Assertion:
    """An assertion of a partial plan: an event, hold or resource use, with its timepoints."""

    id: int
    kind: str  # event | hold | use
    attribute: str
    args: tuple[Term, ...]
    value: Term  # after (event), value (hold), amount (use)
    before: Term | None  # event only
    start: str  # timepoints (an event: start == end)
    end: str
    owner: str  # task instance id, or "problem"
    given: bool  # explained or contingent: needs no support
    line: int
    goal: pm.GoalMark | None = None

    @property
    def wanted(self) -> Term:
        """The value a need reads: an event's value before it, a hold's value."""
        wanted = self.before if self.kind == "event" else self.value
        assert wanted is not None
        return wanted

    def text(self, bindings: Bindings | None = None) -> str:
        show = (lambda t: t) if bindings is None else bindings.resolve

        def fmt(t: Term) -> str:
            value = show(t)
            return f"{value:g}" if isinstance(value, float) else str(value)
        args = f"({', '.join(fmt(a) for a in self.args)})"
        if self.kind == "event":
            assert self.before is not None
            return f"event({self.attribute}{args}: ({fmt(self.before)}, {fmt(self.value)}))"
        if self.kind == "hold":
            return f"hold({self.attribute}{args}: {fmt(self.value)})"
        return f"use({self.attribute}{args}: {fmt(self.value)})"


@dataclass(frozen=True)
class Instance:
    """A task put in the partial plan, with its arguments."""

    id: str
    task: pm.Task
    variables: tuple[str, ...]  # plan variables, in the order params + task.variables

    def var(self, local: str) -> str:
        return f"{self.id}{local}"

    def point(self, local: str) -> str:
        return f"{self.id}.{local}"

    @property
    def start(self) -> str:
        return self.point(self.task.start)

    @property
    def end(self) -> str:
        return self.point(self.task.end)


@dataclass(frozen=True)
class Link:
    """A causal link: the producer assertion gives the consumer the value it needs."""

    producer: int
    consumer: int


class Threat(NamedTuple):
    """An event that may change a linked value while the link needs it."""

    link: Link
    event: Assertion
    before: bool  # may the event still come before the producer
    after: bool  # may it still come after the consumer


@dataclass
class Limits:
    """How large a partial plan may grow."""

    instances: int = 60
    per_task: int = 20


@dataclass(frozen=True)
class Context:
    """What every node of the searches for one problem shares."""

    horizon_end: str
    origin: str
    now: float
    limits: Limits
    capacity: Mapping[str, float]
    producers: Mapping[str, list[tuple[pm.Task, int]]]  # attribute -> (task, event index), see producers_of
    # Orders nature promises between its own instants (`t_evisi1 < t_svisi2`): (earlier, later).
    nature_before: set[tuple[str, str]] = field(default_factory=set)
    controllability: str = STRONG
    oldest_task_first: bool = False  # the flaw order (specc.runtime.planner.heuristics.FLAW_ORDERS)
    # The order the goals are taken up in, by source line (an improvement's trial); absent: the
    # goal that may come earliest first.
    goal_order: Mapping[int, int] = field(default_factory=dict)
    # The events that give back a value their task changed (task name, event index), see restoring_events.
    restoring: frozenset[tuple[str, int]] = frozenset()


def restoring_events(domain: pm.PlanningDomain) -> frozenset[tuple[str, int]]:
    """The events (task name, index) that give back a value their own task changed: another event
    of the task on the same attribute instance goes from that value (a probe lowered and raised
    again, a move from STILL to STILL)."""
    found = set()
    for task in domain.tasks:
        events = [(i, a) for i, a in enumerate(task.assertions) if isinstance(a, pm.Event)]
        for i, event in events:
            if any(j != i and a.attribute == event.attribute and a.args == event.args and a.before == event.after
                   for j, a in events):
                found.add((task.name, i))
    return frozenset(found)


def producers_of(domain: pm.PlanningDomain) -> dict[str, list[tuple[pm.Task, int]]]:
    """The events of the domain's tasks by attribute: (task, index of the event in its assertions)."""
    producers: dict[str, list[tuple[pm.Task, int]]] = {}
    for task in domain.tasks:
        for i, a in enumerate(task.assertions):
            if isinstance(a, pm.Event):
                producers.setdefault(a.attribute, []).append((task, i))
    return producers


class Node:
    """One partial plan; children are copies (the search backtracks by dropping them)."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.stn = STN()
        self.anchor: dict[str, tuple[str, float, float]] = {}  # contingent point -> (point, low, high)
        self.original: list[tuple[str, str, float, float]] = []  # every requirement, as written
        self.bindings = Bindings()
        self.instances: dict[str, Instance] = {}
        self.assertions: list[Assertion] = []
        self.open: set[int] = set()
        self.links: list[Link] = []
        self.durations: dict[str, DurationSpec] = {}  # ground instances
        self.provisional: dict[str, float] = {}  # instance -> lower bound on its duration so far
        # Possible threats are tracked incrementally: a new link meets the events already there,
        # a new event the links; a pair shown harmless stays so in every descendant (constraints
        # only tighten and bindings only narrow down a branch), so it is dropped for good.
        self.pending: set[tuple[int, int]] = set()  # (link index, event id) not yet shown harmless
        # Pairs of resource uses shown apart (another resource, arguments that differ, or ordered
        # one after the other) stay so in every descendant, for the same reason: never scanned again.
        self.uses_apart: set[tuple[int, int]] = set()  # (use id, use id)
        # Indexes by attribute, so that finding producers and threats reads only the attribute's
        # own events and links, not the whole plan.
        self.events: dict[str, tuple[int, ...]] = {}  # attribute -> ids of the events on it, oldest first
        self.links_on: dict[str, tuple[int, ...]] = {}  # attribute -> indexes of the links giving it
        # Where each timepoint sits in the network: the index of the point it hangs from and its
        # offset range (0, 0 when the plan schedules it); only a point made contingent moves.
        self.places: dict[str, tuple[int, float, float]] = {}
        self.counter = 0

    def copy(self) -> Node:
        other = Node.__new__(Node)
        other.ctx = self.ctx
        other.stn = self.stn.copy()
        other.anchor = dict(self.anchor)
        other.original = list(self.original)
        other.bindings = self.bindings.copy()
        other.instances = dict(self.instances)
        other.assertions = list(self.assertions)
        other.open = set(self.open)
        other.links = list(self.links)
        other.durations = dict(self.durations)
        other.provisional = dict(self.provisional)
        other.pending = set(self.pending)
        other.uses_apart = set(self.uses_apart)
        other.events = dict(self.events)
        other.links_on = dict(self.links_on)
        other.places = dict(self.places)
        other.counter = self.counter
        return other

    # ------------------------------------------------------------ time
    def require(self, a: str, b: str, low: float = -INF, high: float = INF, record: bool = True) -> None:
        """Require `low <= t(b) - t(a) <= high` (raises DeadEnd when the network refuses)."""
        if record:
            self.original.append((a, b, low, high))
        pa, pb, new_low, new_high = translate(self.anchor, a, b, low, high)
        if pa == pb:
            if new_low > TOLERANCE or new_high < -TOLERANCE:
                raise DeadEnd(f"{b} - {a} cannot stay in [{low:g}, {high:g}] whatever nature does")
            return
        try:
            self.stn.add(pa, pb, new_low - TOLERANCE if new_low > -INF else new_low,
                         new_high + TOLERANCE if new_high < INF else new_high)
            if self.stn.contingent:
                self._keep_contingent_links()
        except Inconsistent:
            # Said without the tolerance the network adds, which would show as 29.999999 or -1e-06.
            if new_low > new_high + 2 * TOLERANCE:
                raise DeadEnd(f"{b} - {a} cannot stay in [{low:g}, {high:g}] whatever nature does") from None
            back, ahead = self._span(self.stn.index[pa], self.stn.index[pb])
            raise DeadEnd(f"{pb} - {pa} in [{_seconds(new_low)}, {_seconds(new_high)}] contradicts "
                          f"[{_seconds(-back)}, {_seconds(ahead)}], which the plan already implies") from None

    def _keep_contingent_links(self) -> None:
        """Pseudo-controllability: the network may not narrow what nature chooses."""
        d = self.stn.distances
        for link in self.stn.contingent:
            ahead, back = d.item(link.start, link.end), d.item(link.end, link.start)
            if ahead < link.high - SURELY or -back > link.low + SURELY:
                names = self.stn.names
                raise DeadEnd(f"{names[link.end]} - {names[link.start]} in [{link.low:g}, {link.high:g}] is "
                              f"nature's choice, which the plan would narrow to [{_seconds(-back)}, "
                              f"{_seconds(ahead)}]")

    def allows(self, a: str, b: str, low: float = -INF, high: float = INF) -> bool:
        """Could `require(a, b, low, high)` succeed? (The network's distances between the points a
        and b hang from, read here directly: the search asks it of every candidate producer.)"""
        i, la, ha = self._place(a)
        j, lb, hb = self._place(b)
        back, ahead = self._span(i, j)
        new_low, new_high = for_every_offset(low, high, (la, ha), (lb, hb))
        low, high = new_low - TOLERANCE, new_high + TOLERANCE  # as require() loosens them
        return low <= high and high + back >= 0 and -low + ahead >= 0

    def _place(self, point: str) -> tuple[int, float, float]:
        place = self.places.get(point)
        if place is None:
            base, low, high = self.anchor.get(point, (point, 0.0, 0.0))
            place = self.places[point] = (self.stn.index[base], low, high)
        return place

    def _span(self, i: int, j: int) -> tuple[float, float]:
        """(back, ahead): the network puts t(j) - t(i) in [-back, ahead]; a point is at 0 from
        itself (whatever rounding leaves on the network's diagonal)."""
        if i == j:
            return 0.0, 0.0
        d = self.stn.distances
        return d.item(j, i), d.item(i, j)

    def bounds(self, a: str, b: str) -> tuple[float, float]:
        """What t(b) - t(a) may be, nature's choices included."""
        if a == b:
            return 0.0, 0.0
        i, la, ha = self._place(a)
        j, lb, hb = self._place(b)
        back, ahead = self._span(i, j)
        return lb - ha - back, hb - la + ahead

    def surely_before(self, a: str, b: str, gap: float) -> bool:
        """Does b come at least `gap` after a, whatever nature does?"""
        return (a, b) in self.ctx.nature_before or self.bounds(a, b)[0] >= gap - SURELY

    def ordering(self, a: str, b: str, gap: float) -> tuple[bool, bool]:
        """(surely_before(a, b, gap), allows(a, b, gap)) from one reading of the network: the
        search asks both of every possible threat, at every node."""
        # _place() and _span(), inlined: the threats' scan calls this most of all.
        places = self.places
        i, la, ha = places.get(a) or self._place(a)
        j, lb, hb = places.get(b) or self._place(b)
        if i == j:
            back = ahead = 0.0
        else:
            d = self.stn.distances
            back, ahead = d.item(j, i), d.item(i, j)
        # The same arithmetic as bounds() and allows().
        low = 0.0 if a == b else lb - ha - back
        surely = (a, b) in self.ctx.nature_before or low >= gap - SURELY
        return surely, -(gap - (lb - ha) - TOLERANCE) + ahead >= 0

    def worst_end(self) -> float:
        """The worst-case makespan of the partial plan's earliest schedule: the latest any of its
        actions may end, whatever nature does (`Plan.makespan`'s measure, with the durations the
        search knows). No plan made from this one ends earlier: constraints only tighten and
        actions only add."""
        d = self.stn.distances
        worst = 0.0
        for instance in self.instances.values():
            spec = self.durations.get(instance.id)
            if spec is not None and not spec.contingent:  # the plan dispatches it, nature ends it by its longest
                base, _, _ = self._place(instance.start)
                worst = max(worst, -d.item(base, 0) + spec.high)
            else:
                base, _, high = self._place(instance.end)
                worst = max(worst, -d.item(base, 0) + high)
        return worst

    def make_contingent(self, point: str, start: str, low: float, high: float, instant: bool = False) -> None:
        """Nature now places `point` within [low, high] after `start`: every requirement already
        written on it is rewritten for its worst case, unless the point is one of the problem's
        `instant`s and the plan pseudo-controllable: the link then joins the network, which may
        not narrow it."""
        if instant and self.ctx.controllability == PSEUDO:
            try:
                self.stn.add_contingent(start, point, low, high)
            except Inconsistent:
                back, ahead = self.bounds(start, point)
                raise DeadEnd(f"{point} - {start} in [{low:g}, {high:g}] is nature's choice, but the plan "
                              f"already implies [{_seconds(back)}, {_seconds(ahead)}]") from None
            except ValueError as error:  # a link the network cannot take as nature's (negative bounds)
                raise DeadEnd(str(error)) from None
            self._keep_contingent_links()
            return
        self.anchor[point] = (start, low, high)
        self.places.pop(point, None)
        for a, b, lo, hi in self.original:
            if point in (a, b):
                self.require(a, b, lo, hi, record=False)

    # ------------------------------------------------------------ assertions
    def add_assertion(self, **fields: object) -> Assertion:
        assertion = Assertion(id=len(self.assertions), **fields)  # type: ignore[arg-type]
        self.assertions.append(assertion)
        if assertion.kind == "event":
            self.events[assertion.attribute] = self.events.get(assertion.attribute, ()) + (assertion.id,)
            # An event that sets the value it finds (a fact restated at a replanning) changes nothing.
            if assertion.before != assertion.value:
                for k in self.links_on.get(assertion.attribute, ()):
                    self.pending.add((k, assertion.id))
        return assertion

    def link(self, producer: Assertion, consumer: Assertion) -> None:
        """`producer` gives the value `consumer` needs, before it."""
        if producer.kind != "event" or producer.attribute != consumer.attribute:
            raise DeadEnd("not a producer")
        changed: list[str] = []
        for a, b in zip(producer.args, consumer.args, strict=False):
            changed += self.bindings.unify(a, b)
        changed += self.bindings.unify(producer.value, consumer.wanted)
        self.require(producer.start, consumer.start, EPS if consumer.kind == "event" else 0.0)
        self.links.append(Link(producer.id, consumer.id))
        k = len(self.links) - 1
        self.links_on[consumer.attribute] = self.links_on.get(consumer.attribute, ()) + (k,)
        self.pending.update((k, event_id) for event_id in self.events.get(consumer.attribute, ())
                            if event_id not in (producer.id, consumer.id)
                            and self.assertions[event_id].before != self.assertions[event_id].value)
        self.open.discard(consumer.id)
        self.bound(changed)

    def bound(self, variables: list[str]) -> None:
        """Variables gained values: ground the instances that now can be."""
        owners = {v.split("?", 1)[0] for v in variables if "#" in v.split("?", 1)[0]}
        for owner in sorted(owners):
            self.ground(owner)

    def ground(self, instance_id: str) -> None:
        instance = self.instances.get(instance_id)
        if instance is None or instance_id in self.durations:
            return
        task = instance.task
        known = {}
        for local, var in zip(task.params + task.variables, instance.variables, strict=True):
            value = self.bindings.value(var)
            if value is not None:
                known[local] = value
        try:
            spec = duration_of(task, known)
        except Empty as error:
            raise DeadEnd(f"{instance_id}: {error}") from None
        # Variables the task's constraints fix (Modele2's distance symbol) bind the plan's too.
        changed: list[str] = []
        for local, value in spec.variables.items():
            var = instance.var(local)
            if var in self.bindings.parent and self.bindings.value(var) is None:
                changed += self.bindings.unify(var, value)
        complete = all(local in known for local in task.params)
        if complete and spec.high < INF:
            self.durations[instance_id] = spec
            if spec.contingent:
                self.make_contingent(instance.end, instance.start, spec.low, spec.high)
            else:
                self.require(instance.start, instance.end, spec.low, spec.high)
        elif spec.low > self.provisional.get(instance_id, 0.0):
            self.provisional[instance_id] = spec.low
            self.require(instance.start, instance.end, spec.low, INF, record=False)
        if changed:
            self.bound(changed)

    # ------------------------------------------------------------ tasks
    def insert(self, task: pm.Task) -> Instance:
        count = sum(1 for i in self.instances.values() if i.task.name == task.name)
        if count >= self.ctx.limits.per_task or len(self.instances) >= self.ctx.limits.instances:
            raise DeadEnd("too many tasks")
        self.counter += 1
        instance = Instance(f"{task.name}#{self.counter}", task,
                            tuple(f"{task.name}#{self.counter}{v}" for v in task.params + task.variables))
        self.instances[instance.id] = instance
        for var in instance.variables:
            self.bindings.declare(var, None)
        point = instance.point
        self.stn.point(instance.start)
        self.stn.point(instance.end)
        self.require(self.ctx.origin, instance.start, self.ctx.now)
        self.require(instance.start, instance.end, 0.0)
        self.require(instance.end, self.ctx.horizon_end, 0.0)
        for name in task.timepoints:
            self.require(instance.start, point(name), 0.0)
            self.require(point(name), instance.end, 0.0)

        # Domains of the task's variables, what keeps them apart, and its temporal constraints.
        constraints = task_constraints(task)
        for local, domain in constraints.domains:
            self.bindings.restrict(instance.var(local), domain)
        for left, right in constraints.apart:
            self.bindings.keep_apart(as_term(left, instance.var), as_term(right, instance.var))
        for c in constraints.temporal:
            for first, second, low, high in differences(c, point, self.ctx.origin):
                self.require(first, second, low, high)
        own_from = len(self.assertions)  # the instance's assertions follow, together
        for a in task.assertions:
            new = self.add_written(a, instance.var, point, instance.id)
            if new.kind == "use":
                amount, capacity = self.bindings.resolve(new.value), self.ctx.capacity.get(new.attribute, 1.0)
                if is_number(amount) and float(amount) > capacity + TOLERANCE:  # alone, with no other use beside it
                    raise DeadEnd(f"{task.name} uses {float(amount):g} of {new.attribute}(), more than its capacity "
                                  f"{capacity:g}")
                self.require(new.start, new.end, 0.0)
            else:
                self._own_support(self.assertions[own_from:], instance)
        self.ground(instance.id)
        return instance

    def add_written(self, a: pm.Assertion, variable: Callable[[str], str], point: Callable[[str], str],
                    owner: str) -> Assertion:
        """A task's or the problem's assertion added to the plan, its variables and timepoints named
        by `variable` and `point`; an event or a hold needing support is an open condition (only
        the problem's explained and contingent events are given)."""
        args = tuple(as_term(x, variable) for x in a.args)
        if isinstance(a, pm.Use):
            return self.add_assertion(kind="use", attribute=a.resource, args=args, value=as_term(a.amount, variable),
                                      before=None, start=point(a.start), end=point(a.end), owner=owner, given=True,
                                      line=a.line)
        if isinstance(a, pm.Event):
            given = owner == "problem" and a.kind in ("explained", "contingent")
            new = self.add_assertion(kind="event", attribute=a.attribute, args=args, value=as_term(a.after, variable),
                                     before=as_term(a.before, variable), start=point(a.time), end=point(a.time),
                                     owner=owner, given=given, line=a.line, goal=a.goal)
        else:
            new = self.add_assertion(kind="hold", attribute=a.attribute, args=args, value=as_term(a.value, variable),
                                     before=None, start=point(a.start), end=point(a.end), owner=owner, given=False,
                                     line=a.line, goal=a.goal)
        if not new.given:
            self.open.add(new.id)
        return new

    def _own_support(self, mine: list[Assertion], instance: Instance) -> None:
        """Link the task's assertions (`mine`, so far, the newest last) the task itself explains
        (its start event sets the value a hold over the task, or its end event, needs): IxTeT
        writes tasks this way. Only pairs with the newest are tried: the others were when the
        later of them came, and nothing they depend on has changed since (a need only leaves the
        open set)."""
        new = mine[-1]
        pairs = [(producer, new) for producer in mine[:-1]] + [(new, consumer) for consumer in mine]
        for producer, consumer in pairs:
            if (consumer.id in self.open and producer.kind == "event" and producer is not consumer
                    and producer.attribute == consumer.attribute and producer.args == consumer.args
                    and producer.value == consumer.wanted
                    and producer.start == instance.start and consumer.start in (instance.start, instance.end)
                    and not (consumer.kind == "event" and consumer.start == producer.start)):
                self.link(producer, consumer)

    # ------------------------------------------------------------ flaws
    def _alike(self, need: Assertion, bindings: Bindings | None = None) -> list[Assertion]:
        """The other events on the need's attribute whose arguments may be the need's (with the
        plan's bindings, or with `bindings`)."""
        possibly_equal = (bindings or self.bindings).possibly_equal
        found = []
        for event_id in self.events.get(need.attribute, ()):
            e = self.assertions[event_id]
            if event_id != need.id and (not e.args or all(
                    possibly_equal(x, y) for x, y in zip(e.args, need.args, strict=False))):
                found.append(e)
        return found

    def producers(self, need: Assertion, bindings: Bindings | None = None) -> list[Assertion]:
        """The events that may give the need its value, oldest first (with the plan's bindings, or
        with `bindings`: those a resolver would leave)."""
        wanted, possibly_equal = need.wanted, (bindings or self.bindings).possibly_equal
        gap = EPS if need.kind == "event" else 0.0
        return [e for e in self._alike(need, bindings)
                if possibly_equal(e.value, wanted) and self.allows(e.start, need.start, gap)]

    def changers(self, need: Assertion) -> list[Assertion]:
        """The events that may change the value the need reads before it ends, oldest first."""
        gap = EPS if need.kind == "event" else 0.0
        return [e for e in self._alike(need) if not self.surely_before(need.end, e.start, gap)]

    def insertions(self, need: Assertion) -> list[tuple[pm.Task, int]]:
        wanted = need.wanted
        options = []
        for task, index in self.ctx.producers.get(need.attribute, []):
            event = task.assertions[index]
            assert isinstance(event, pm.Event)
            if not _could_be(event.after, wanted, task, self.bindings) or not all(
                    _could_be(x, y, task, self.bindings) for x, y in zip(event.args, need.args, strict=False)):
                continue
            options.append((task, index))
        return options

    def threats(self) -> Iterator[Threat]:
        """The possible threats, each read from the network as it is when it comes (a resolver
        applied meanwhile counts), with the orders that could still keep it off."""
        possibly_equal = self.bindings.possibly_equal
        for pair in sorted(self.pending):
            link = self.links[pair[0]]
            consumer, e = self.assertions[link.consumer], self.assertions[pair[1]]
            if not e.args or all(possibly_equal(x, y) for x, y in zip(e.args, consumer.args, strict=False)):
                already_before, may_be_before = self.ordering(e.start, self.assertions[link.producer].start, EPS)
                if not already_before:
                    gap = EPS if consumer.kind == "event" else 0.0
                    already_after, may_be_after = self.ordering(consumer.end, e.start, gap)
                    if not already_after:
                        yield Threat(link, e, may_be_before, may_be_after)
                        continue
            self.pending.discard(pair)  # harmless now, so for good

    def resource_conflicts(self) -> Iterator[tuple[Assertion, Assertion]]:
        uses = [a for a in self.assertions if a.kind == "use"]
        apart = self.uses_apart
        for a, b in itertools.combinations(uses, 2):
            pair = (a.id, b.id)
            if pair in apart:
                continue
            if a.attribute != b.attribute or not all(
                    self.bindings.possibly_equal(x, y) for x, y in zip(a.args, b.args, strict=False)):
                apart.add(pair)
                continue
            # Not settled for good: an amount still a variable may be bound to more.
            amount = _number(self.bindings.resolve(a.value)) + _number(self.bindings.resolve(b.value))
            if amount <= self.ctx.capacity.get(a.attribute, 1.0) + TOLERANCE:
                continue
            if self.bounds(a.end, b.start)[0] >= -SURELY or self.bounds(b.end, a.start)[0] >= -SURELY:
                apart.add(pair)
                continue
            yield a, b


@dataclass(frozen=True)
class TaskConstraints:
    """A task's constraints, sorted out once for all its instances."""

    domains: tuple[tuple[str, frozenset[str] | tuple[float, float] | None], ...]  # (variable, domain)
    apart: tuple[tuple[pm.Expr, pm.Expr], ...]  # terms that must differ
    temporal: tuple[pm.Member | pm.Relation, ...]  # between its timepoints, its duration aside


def task_constraints(task: pm.Task) -> TaskConstraints:
    """Cached by the task's identity, as numeric.duration_of is: every insertion of the task
    asks, and hashing a task (a deep frozen record) would cost more than sorting them out."""
    found = _TASK_CONSTRAINTS.get(id(task))
    if found is None:
        domains, apart, temporal = [], [], []
        for c in task.constraints:
            if isinstance(c, pm.Member) and isinstance(c.expr, pm.Var) and not c.contingent:
                domains.append((c.expr.name, domain_of(c.domain)))
            elif isinstance(c, pm.Relation) and c.op == "!=" and not is_temporal(c.left) and not is_temporal(c.right):
                apart.append((c.left, c.right))
            elif isinstance(c, (pm.Member, pm.Relation)) and is_temporal(c) and not is_duration(c, task):
                temporal.append(c)
        if len(_TASK_CONSTRAINTS) >= IDENTITY_CACHE_LIMIT:
            _TASK_CONSTRAINTS.clear()
        found = _TASK_CONSTRAINTS[id(task)] = (task, TaskConstraints(tuple(domains), tuple(apart), tuple(temporal)))
    return found[1]


_TASK_CONSTRAINTS: dict[int, tuple[pm.Task, TaskConstraints]] = {}  # the task is kept so that its id stays its own


def _number(value: Term) -> float:
    return float(value) if is_number(value) else 1.0


def is_temporal(e: pm.Expr | pm.Constraint) -> bool:
    """Does it mention a timepoint? (An implication never does: it is numeric or symbolic.)"""
    return not isinstance(e, pm.Implies) and bool(pm.timepoints_of(e))


def _could_be(e: pm.Expr, wanted: Term, task: pm.Task, bindings: Bindings) -> bool:
    """Could a new instance's `e` (a constant, or a variable of `task`) equal `wanted`?"""
    if isinstance(e, pm.Num):
        value = bindings.resolve(wanted)
        return is_var(value) or same_value(e.value, value)
    if isinstance(e, pm.Sym):
        value = bindings.resolve(wanted)
        return (bindings.possibly_equal(wanted, e.name) if is_var(value) else value == e.name)
    if isinstance(e, pm.Var):
        value = bindings.resolve(wanted)
        if is_var(value):
            return True
        for local, domain in task_constraints(task).domains:
            if local != e.name:
                continue
            if isinstance(domain, frozenset) and value not in domain:
                return False
            if isinstance(domain, tuple) and not (is_number(value) and domain[0] <= float(value) <= domain[1]):
                return False
        return True
    return True
