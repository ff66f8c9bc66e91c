"""The plan analyzer (seed 004 §3.1.1): before a plan is executed, FTplan checks it against
constraints written from the system's specification apart from the planning models, so that a
fault in a model is not repeated in the check meant to catch it (the `analyzer` block of an
`ftplan`).

Every check takes the worst case over what nature chooses: the contingent durations of the
actions and the dates of the problem's contingent events (the visibility windows), which a
pseudo-controllable plan fixes at the dates it assumes (`Plan.assumed`).

- An attribute's value along the plan is FTplan's own state (its `state` rules, not the
  planner's model) projected along the plan: the `ended` consequences of each action take
  effect at its end, at a date in [earliest, latest] end. The attributes the problem changes
  through contingent events (VISIBILITY_WINDOW) follow those events instead.
- A requirement holds when the attribute surely has the value: `at_start` at the action's
  dispatch, `during` over [dispatch, latest end], `at_end` over the dates its end may have
  (before its own effects). A change that may happen, or not, by then makes the value
  uncertain, which the analyzer rejects like a wrong value.
- An action occupies [dispatch, latest end]; touching intervals do not overlap.
- A task's longest duration is the upper bound of its instances' durations.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from specc.runtime.ftplan.config import FtPlanConfig, MaxDuration, NoOverlap, Requirement, Term, Var
from specc.runtime.ftplan.facts import FactKey, match, substitute
from specc.runtime.ftplan.state import Dates, SystemState, consequences, constant, constant_key
from specc.runtime.ftplan.view import View
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Action, Plan, Value, format_call, format_value
from specc.runtime.planner.validate import same

# Dates computed by the planner's solver differ in their last digits from the same date reached
# another way (an end's latest date and the next dispatch): closer than this is the same date.
EPSILON = 1e-6


@dataclass(frozen=True)
class Violation:
    line: int  # the analyzer rule's line in the spec
    action: str  # the offending action's id ("" when not one action)
    message: str  # one sentence: the rule, the action(s), what was found instead, when


@dataclass(frozen=True)
class Change:
    """An attribute instance takes `value` at a date nature places in `dates`."""

    value: Value
    dates: Dates
    cause: str  # what brings it, for the messages: "set when MOVE#4 ends"
    action: str = ""  # the action whose end brings it ("" for the problem's events)


@dataclass(frozen=True)
class Timeline:
    """An attribute instance along the plan: its value now (None: unknown) and its changes."""

    initial: Value | None
    origin: str  # where the value now comes from, for the messages
    changes: tuple[Change, ...]


@dataclass(frozen=True)
class Possibility:
    """A value an attribute instance may have when a requirement reads it, and why."""

    value: Value | None  # None: unknown
    source: str


def analyse(plan: Plan, config: FtPlanConfig, state: SystemState, problem: pm.Problem,
            view: View | None = None) -> list[Violation]:
    """What in `plan` breaks the rules of `config`'s analyzer, FTplan believing `state` now;
    `view` is the correspondences of the planner that made the plan, if it speaks another
    vocabulary. A rule whose task the plan does not use (another planner's) does not apply."""
    projection = Projection(plan, config, state, problem, view)
    violations: list[Violation] = []
    for rule in config.analyzer:
        if isinstance(rule, Requirement):
            violations.extend(_requirement(rule, plan, projection))
        elif isinstance(rule, NoOverlap):
            violations.extend(_no_overlap(rule, plan))
        elif isinstance(rule, MaxDuration):
            violations.extend(_max_duration(rule, plan))
    return violations


# ---------------------------------------------------------------- projection


class Projection:
    """The attribute instances along the plan: FTplan's state changed by the actions' ends, and
    the problem's contingent events for the attributes nature changes."""

    def __init__(self, plan: Plan, config: FtPlanConfig, state: SystemState, problem: pm.Problem,
                 view: View | None = None) -> None:
        self.facts = state.facts
        self.effects: dict[FactKey, list[Change]] = {}
        for action in plan.actions:
            ends = end_dates(plan, action)
            for key, value in consequences(config.state_rules, "ended", action.task, action.args, view):
                self.effects.setdefault(key, []).append(Change(value, ends, f"set when {action.id} ends", action.id))
        self.events = _contingent_events(problem, _timepoint_dates(plan, state))
        # What the problem says such an attribute starts at (`explained event(EMPTY(R104): (NO,
        # YES), t_start)`), before nature's first event on it.
        self.starts: dict[FactKey, Value] = {}
        for a in problem.assertions:
            if isinstance(a, pm.Event) and a.kind == "explained" and a.goal is None and a.time == problem.start:
                started, start = constant_key(a.attribute, a.args), constant(a.after)
                if started is not None and start is not None:
                    self.starts[started] = start

    def timeline(self, key: FactKey) -> Timeline:
        events = self.events.get(key)
        if events is not None:
            # Nature sets these, whatever FTplan believes: its state has no say on them, the
            # problem's start does.
            start = self.starts.get(key)
            return Timeline(start, "the problem's start" if start is not None
                            else "before the problem's first event on it", tuple(events))
        initial = self.facts.get(key)
        origin = "FTplan's state" if initial is not None else "not in FTplan's state"
        return Timeline(initial, origin, tuple(self.effects.get(key, ())))


def end_dates(plan: Plan, action: Action) -> Dates:
    if action.end in plan.uncontrolled:
        return plan.uncontrolled[action.end]
    if action.end in plan.schedule:
        return plan.schedule[action.end], plan.schedule[action.end]
    return action.dispatch + action.duration[0], action.dispatch + action.duration[1]


def occupancy(plan: Plan, action: Action) -> Dates:
    """The worst case of the time an action runs: from its dispatch to its latest end."""
    return action.dispatch, end_dates(plan, action)[1]


def _contingent_events(problem: pm.Problem, dates: Mapping[str, Dates]) -> dict[FactKey, list[Change]]:
    events: dict[FactKey, list[Change]] = {}
    for a in problem.assertions:
        if isinstance(a, pm.Event) and a.kind == "contingent":
            key, value = constant_key(a.attribute, a.args), constant(a.after)
            if key is not None and value is not None:
                events.setdefault(key, []).append(Change(value, dates[a.time], f"set at {a.time}"))
    return events


def _timepoint_dates(plan: Plan, state: SystemState) -> dict[str, Dates]:
    """The dates of the problem's timepoints: the plan's (its schedule, the dates nature may choose
    for the others, or those a pseudo-controllable plan assumes), else the bounds the problem's own
    constraints give."""
    return (state.dates | {name: (date, date) for name, date in plan.schedule.items()} | dict(plan.uncontrolled)
            | {name: (date, date) for name, date in plan.assumed.items()})


# ---------------------------------------------------------------- requirements


def possible_values(timeline: Timeline, span: Dates, ignore: str) -> list[Possibility]:
    """The values the attribute instance may have at some instant of `span`, the changes the
    action `ignore` brings left out. A change counts from its date on."""
    start, end = span
    changes = [c for c in timeline.changes if c.action != ignore]
    done = [c for c in changes if c.dates[1] <= start + EPSILON]
    # The last of the changes surely done by the start: none surely comes after it.
    last = [c for c in done if not any(d.dates[0] > c.dates[1] + EPSILON for d in done)]
    found = [Possibility(c.value, f"{c.cause}, in {_interval(c.dates)}") for c in last]
    if not done:
        found.append(Possibility(timeline.initial, timeline.origin))
    # The changes that may or may not be done at the start, and those that may come inside.
    found += [Possibility(c.value, f"{c.cause}, in {_interval(c.dates)}") for c in changes
              if c.dates[1] > start + EPSILON and (c.dates[0] <= start + EPSILON or c.dates[0] < end - EPSILON)]
    distinct: list[Possibility] = []
    for possibility in found:
        if not any(_same_value(possibility.value, p.value) for p in distinct):
            distinct.append(possibility)
    return distinct


def _same_value(a: Value | None, b: Value | None) -> bool:
    return a is b if a is None or b is None else same(a, b)


def _requirement(rule: Requirement, plan: Plan, projection: Projection) -> list[Violation]:
    violations = []
    for action in plan.ordered():
        if action.task != rule.task:
            continue
        bindings = match(rule.args, action.args)
        if bindings is None:
            continue
        key = (rule.attribute, tuple(substitute(a, bindings) for a in rule.attribute_args))
        required = substitute(rule.value, bindings)
        span, when = _requirement_span(rule.kind, plan, action)
        found = possible_values(projection.timeline(key), span, action.id)
        if all(_same_value(p.value, required) for p in found):
            continue
        attribute = format_call(key[0], key[1])
        if len(found) == 1:
            what = f"{attribute} is {_possibility(found[0])}, not {format_value(required)}"
        else:
            what = (f"{attribute} is uncertain, it may be "
                    f"{' or '.join(_possibility(p) for p in found)}, not surely {format_value(required)}")
        violations.append(Violation(rule.line, action.id,
                                    f"line {rule.line}: {action.id} {action.text()} breaks "
                                    f"`{_requirement_text(rule)}`: {when} {what}."))
    return violations


def _requirement_span(kind: str, plan: Plan, action: Action) -> tuple[Dates, str]:
    """The dates a requirement of `kind` speaks of, and how to say them."""
    earliest_end, latest_end = end_dates(plan, action)
    if kind == "at_start":
        return (action.dispatch, action.dispatch), f"at its start ({_date(action.dispatch)} s)"
    if kind == "at_end":
        return (earliest_end, latest_end), f"at its end (in {_interval((earliest_end, latest_end))})"
    return (action.dispatch, latest_end), f"while it runs ({_interval((action.dispatch, latest_end))})"


def _possibility(p: Possibility) -> str:
    return f"unknown ({p.source})" if p.value is None else f"{format_value(p.value)} ({p.source})"


def _requirement_text(rule: Requirement) -> str:
    return (f"{rule.kind} {rule.task}({_terms(rule.args)}) requires "
            f"{rule.attribute}({_terms(rule.attribute_args)}): {_term(rule.value)}")


def _terms(terms: Iterable[Term]) -> str:
    return ", ".join(_term(t) for t in terms)


def _term(term: Term) -> str:
    return term.name if isinstance(term, Var) else format_value(term)


# ---------------------------------------------------------------- overlaps and durations


def _no_overlap(rule: NoOverlap, plan: Plan) -> list[Violation]:
    violations = []
    actions = plan.ordered()
    for i, earlier in enumerate(actions):
        for later in actions[i + 1:]:
            # `no_overlap MOVE, MOVE` names the set {MOVE}: any two instances of MOVE.
            if {earlier.task, later.task} != {rule.first, rule.second}:
                continue
            first, second = occupancy(plan, earlier), occupancy(plan, later)
            if first[0] < second[1] - EPSILON and second[0] < first[1] - EPSILON:
                violations.append(Violation(
                    rule.line, later.id,
                    f"line {rule.line}: {later.id} {later.text()} (running {_interval(second)}) overlaps "
                    f"{earlier.id} {earlier.text()} (running {_interval(first)}), "
                    f"against `no_overlap {rule.first}, {rule.second}`."))
    return violations


def _max_duration(rule: MaxDuration, plan: Plan) -> list[Violation]:
    return [Violation(rule.line, action.id,
                      f"line {rule.line}: {action.id} {action.text()} may last {_date(action.duration[1])} s, "
                      f"longer than `max_duration {rule.task} {rule.seconds:g} s`.")
            for action in plan.ordered()
            if action.task == rule.task and action.duration[1] > rule.seconds + EPSILON]


def _date(seconds: float) -> str:
    return f"{seconds:.2f}"


def _interval(dates: Dates) -> str:
    return f"[{_date(dates[0])}, {_date(dates[1])}] s"
