"""Replanning from the current state (seed 004 §3.2.2.3: FTplan sends IxTeT the current state
as hold/event facts, the goals still to meet and the mission time; IxTeT builds its initial
plan from them, not from its own, possibly wrong, idea of the past).

The new problem keeps the mission's time origin (windows and goal deadlines stay where they
were), replaces the initial values of the attributes the facts mention, keeps only the goals
named as remaining, and the planner schedules nothing before `now`. Tasks still running are the
caller's business: a non-preemptive one (nonPreemptive, earlyPreemptive) is let finish and its
outcome sent as facts; a preemptible one (latePreemptive) is stopped first.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

from specc.runtime.planner import model as pm

Value = float | str


@dataclass(frozen=True)
class Fact:
    """`attribute(args) = value` now."""

    attribute: str
    args: tuple[Value, ...]
    value: Value

    @classmethod
    def parse(cls, text: str) -> Fact:
        """`AT_ROBOT_X() = 2.5`, `PICTURE(OBJ1, 0, 0) = DONE`."""
        head, sep, value = text.partition("=")
        name, paren, rest = head.strip().partition("(")
        if not sep or not paren or not rest.rstrip().endswith(")") or not name.strip():
            raise ValueError(f"'{text}' is not a fact: write ATTRIBUTE(args) = value")
        args = tuple(_value(a) for a in rest.rstrip()[:-1].split(",") if a.strip())
        return cls(name.strip(), args, _value(value))


def checked_facts(domain: pm.PlanningDomain, facts: Iterable[Fact]) -> list[Fact]:
    """`facts` as they fit `domain`, or ValueError saying which does not: an attribute it has,
    with as many arguments, each (and the value) in its domain, and one value per attribute
    instance."""
    seen: dict[tuple[str, tuple[Value, ...]], Fact] = {}
    for fact in facts:
        text = f"{fact.attribute}({', '.join(map(_text, fact.args))}) = {_text(fact.value)}"
        attribute = domain.attribute(fact.attribute)
        if attribute is None:
            known = ", ".join(sorted(a.name for a in domain.attributes))
            raise ValueError(f"fact '{text}': domain '{domain.name}' has no attribute {fact.attribute} ({known})")
        if len(fact.args) != len(attribute.params):
            raise ValueError(f"fact '{text}': {fact.attribute} takes {len(attribute.params)} argument(s), "
                             f"{len(fact.args)} given")
        slots = [*zip(fact.args, attribute.param_domains or (None,) * len(fact.args), strict=True),
                 (fact.value, attribute.values)]
        for value, allowed in slots:
            problem = _outside(value, allowed)
            if problem is not None:
                raise ValueError(f"fact '{text}': {problem}")
        key = (fact.attribute, fact.args)
        if key in seen and seen[key].value != fact.value:
            raise ValueError(f"fact '{text}': {fact.attribute}({', '.join(map(_text, fact.args))}) is already "
                             f"{_text(seen[key].value)}: give one value")
        seen[key] = fact
    return list(seen.values())


def _outside(value: Value, allowed: pm.Values | None) -> str | None:
    """Why `value` is not in `allowed` (None when it is, or when nothing is declared)."""
    if isinstance(allowed, pm.Symbols) and value not in allowed.values:
        return f"{_text(value)} is not one of {', '.join(allowed.values)}"
    if isinstance(allowed, pm.Interval):
        if not isinstance(value, float):
            bounded = math.isfinite(allowed.low) or math.isfinite(allowed.high)
            return f"{value} is not a number" + (f" (the domain is [{allowed.low:g}, {allowed.high:g}])" if bounded
                                                 else "")
        if not (allowed.low <= value <= allowed.high):
            return f"{value:g} is outside [{allowed.low:g}, {allowed.high:g}]"
    return None


def _text(value: Value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _value(text: str) -> Value:
    text = text.strip()
    try:
        number = float(text)
    except ValueError:
        return text
    return number if math.isfinite(number) else text  # `nan`, `inf`: no value a domain holds


def _expr(value: Value) -> pm.Expr:
    return pm.Num(float(value)) if isinstance(value, (int, float)) else pm.Sym(value)


def _matches(event: pm.Event, fact: Fact) -> bool:
    if event.attribute != fact.attribute or len(event.args) != len(fact.args):
        return False
    for arg, value in zip(event.args, fact.args, strict=False):
        if isinstance(arg, pm.Var):
            continue  # the problem leaves it open: the fact decides it
        if arg != _expr(value):
            return False
    return True


def replanning_problem(problem: pm.Problem, facts: Iterable[Fact], remaining_goals: Iterable[int],
                       now: float, dates: Mapping[str, tuple[float, float]] | None = None) -> pm.Problem:
    """The problem FTplan sends at `now`: `facts` as the initial values, only the goals whose
    source lines are in `remaining_goals`. With the [earliest, latest] `dates` of the problem's
    timepoints, the required holds that surely ended by `now` are left out: they speak of the past,
    which the facts now tell (Modele2's `COMMUNICATION(W2): FALSE` until W1 closes)."""
    facts = list(facts)
    remaining = set(remaining_goals)
    assertions: list[pm.Assertion] = []
    for a in problem.assertions:
        if isinstance(a, pm.Event) and a.kind == "explained" and any(_matches(a, f) for f in facts):
            continue  # the present replaces what the problem said of the start
        if a.goal is not None and a.line not in remaining:
            continue
        if (a.goal is None and isinstance(a, pm.Hold) and dates is not None
                and dates.get(a.end, (0.0, math.inf))[1] <= now):
            continue
        assertions.append(a)
    for fact in facts:
        value = _expr(fact.value)
        assertions.append(pm.Event(fact.attribute, tuple(_expr(x) for x in fact.args), value, value,
                                   problem.start, kind="explained"))
    # The timepoints of the goals left out go with them, and so do the constraints on them.
    used = {point for a in assertions for point in pm.assertion_timepoints(a)}
    gone = {point for point in problem.timepoints if point not in used}
    constraints = tuple(c for c in problem.constraints if not pm.timepoints_of(c) & gone)
    return replace(problem, name=f"{problem.name}@{now:g}", assertions=tuple(assertions), constraints=constraints,
                   timepoints=tuple(p for p in problem.timepoints if p not in gone))
