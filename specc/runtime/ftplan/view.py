"""How a planner with its own vocabulary reads FTplan's state, and how its actions write it.

Diversified planners need not share a vocabulary: seed 004's Modele2 places the robot at
symbolic points (O1, G5) and points its pan-tilt unit by angles where Modele1 has coordinates
and named positions. FTplan keeps one state, in one vocabulary (§3.2.2.2); a planner speaking
another one declares correspondences (`view` in its `planner` block, and per mission):

    FRAME_POS(): O2, FRAME_MODE(): NOMINAL <=> AT_ROBOT_X(): 4, AT_ROBOT_Y(): 0;

- reading (`View.read`): where FTplan's state holds the right-hand facts, the planner's initial
  situation holds the left-hand ones. A right-hand value may be an interval (`[0, 4.5]`), for the
  regions a symbolic place stands for. The first correspondence to give a fact wins.
- writing (`View.write`): a state rule about one of the planner's tasks speaks the planner's
  vocabulary (`on ended MOVE_NOMINAL(?p1, ?p2) => FRAME_POS() := ?p2, ...`); where its updates set
  every left-hand fact of a correspondence, FTplan's state gets the right-hand ones. Only
  correspondences whose right-hand side is constant once matched can be written.
- goals (`View.state_facts_of`): a goal of the planner's problem stands for the FTplan facts of
  the first correspondence naming it on its left; FTplan asks for it while one of the goals of
  its own ledger on those facts is open.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence

from specc.runtime.ftplan.config import Correspondence, FactPattern, Interval, Term, Value, Var
from specc.runtime.ftplan.facts import Bindings, FactKey, match, substitute
from specc.runtime.planner.validate import normalise, same

Change = tuple[FactKey, Value]


def match_fact(pattern: FactPattern, key: FactKey, value: Value, bindings: Bindings) -> Bindings | None:
    """The bindings that make `pattern` read the fact `key = value` (extending `bindings`)."""
    attribute, args = key
    if pattern.attribute != attribute:
        return None
    found = match(pattern.args, args, bindings)
    if found is None:
        return None
    if isinstance(pattern.value, Interval):
        number = normalise(value)
        inside = isinstance(number, float) and pattern.value.low <= number <= pattern.value.high
        return found if inside else None
    return match((pattern.value,), (value,), found)


def matches(patterns: Sequence[FactPattern], facts: Mapping[FactKey, Value],
            bindings: Bindings | None = None) -> Iterator[Bindings]:
    """Every way all of `patterns` hold together in `facts`."""
    if not patterns:
        yield dict(bindings or {})
        return
    first, rest = patterns[0], patterns[1:]
    for key, value in facts.items():
        found = match_fact(first, key, value, bindings or {})
        if found is not None:
            yield from matches(rest, facts, found)


def ground(patterns: Sequence[FactPattern], bindings: Bindings) -> list[Change] | None:
    """The facts `patterns` name under `bindings`; None when one is not a single known value (an
    interval, or a ?variable the other side does not bind)."""
    facts: list[Change] = []
    for p in patterns:
        if isinstance(p.value, Interval) or not _bound(p.args, bindings) or not _bound((p.value,), bindings):
            return None
        facts.append(((p.attribute, tuple(substitute(a, bindings) for a in p.args)), substitute(p.value, bindings)))
    return facts


def _bound(terms: Sequence[Term], bindings: Bindings) -> bool:
    return all(not isinstance(t, Var) or t.name in bindings for t in terms)


class View:
    """The correspondences of one planner, in the order they are tried."""

    def __init__(self, correspondences: Sequence[Correspondence]) -> None:
        self.correspondences = tuple(correspondences)

    def read(self, state: Mapping[FactKey, Value]) -> dict[FactKey, Value]:
        """The planner's facts that FTplan's `state` gives."""
        facts: dict[FactKey, Value] = {}
        for c in self.correspondences:
            for bindings in matches(c.state_facts, state):
                for key, value in ground(c.planner_facts, bindings) or ():
                    facts.setdefault(key, value)
        return facts

    def write(self, changes: Sequence[Change]) -> list[Change]:
        """FTplan's state changes that the planner-vocabulary `changes` make."""
        updates = {key: normalise(value) for key, value in changes}
        written: dict[FactKey, Value] = {}
        for c in self.correspondences:
            for bindings in matches(c.planner_facts, updates):
                for key, value in ground(c.state_facts, bindings) or ():
                    written.setdefault(key, value)
        return list(written.items())

    def state_facts_of(self, key: FactKey, value: Value) -> list[Change]:
        """The FTplan facts the planner's fact `key = value` stands for (its goals)."""
        for c in self.correspondences:
            for pattern in c.planner_facts:
                bindings = match_fact(pattern, key, value, {})
                facts = None if bindings is None else ground(c.state_facts, bindings)
                if facts:
                    return facts
        return []


def same_fact(a: Change, b: Change) -> bool:
    return a[0][0] == b[0][0] and len(a[0][1]) == len(b[0][1]) and all(
        same(x, y) for x, y in zip(a[0][1], b[0][1], strict=True)) and same(a[1], b[1])
