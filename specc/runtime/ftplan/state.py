"""FTplan's own picture of the system and of the mission's goals (seed 004 §3.2.2.2).

FTplan never trusts a planner's state: it keeps the facts itself, updates them from the
execution reports through the `state` rules of its block (`on ended MOVE(...) => ...`), and sends
them, with the goals still open and the mission time, as the initial state of every planning.
The same facts let it check the goals on line, after each action and when a plan ends.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from specc.runtime.ftplan.config import FactUpdate, StateRule, Term, Value, Var
from specc.runtime.planner import model as pm
from specc.runtime.planner.replan import Fact

FactKey = tuple[str, tuple[Value, ...]]
Bindings = dict[str, Value]


def normalise(value: Value | int) -> Value:
    return float(value) if isinstance(value, (int, float)) else value


def same(a: Value, b: Value) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return math.isclose(a, b, rel_tol=0.0, abs_tol=1e-6)
    return a == b


def match(terms: tuple[Term, ...], values: tuple[Value, ...], bindings: Bindings | None = None) -> Bindings | None:
    """The bindings that make `terms` read `values` (extending `bindings`), or None."""
    if len(terms) != len(values):
        return None
    found: Bindings = dict(bindings or {})
    for term, value in zip(terms, values, strict=True):
        value = normalise(value)
        if isinstance(term, Var):
            bound = found.get(term.name)
            if bound is None:
                found[term.name] = value
            elif not same(bound, value):
                return None
        elif not same(normalise(term), value):
            return None
    return found


def substitute(term: Term, bindings: Mapping[str, Value]) -> Value:
    if isinstance(term, Var):
        if term.name not in bindings:
            raise KeyError(f"{term.name} is not bound by the rule's task or report")
        return bindings[term.name]
    return normalise(term)


def ground(updates: Iterable[FactUpdate], bindings: Mapping[str, Value]) -> list[tuple[FactKey, Value]]:
    return [((u.attribute, tuple(substitute(a, bindings) for a in u.args)), substitute(u.value, bindings))
            for u in updates]


def consequences(rules: Iterable[StateRule], report: str, name: str,
                 args: tuple[Value, ...]) -> list[tuple[FactKey, Value]]:
    """What the rules say changes when `report` (ended, failed, report) comes for name(args)."""
    changes: list[tuple[FactKey, Value]] = []
    for rule in rules:
        if rule.report == report and rule.name == name:
            bindings = match(rule.args, args)
            if bindings is not None:
                changes.extend(ground(rule.updates, bindings))
    return changes


@dataclass(frozen=True)
class Goal:
    """A goal of the mission: `attribute(args) = value`, with its priority and deadline."""

    line: int  # the goal's line in the problem: its identity in replanning requests
    attribute: str
    args: tuple[Value, ...]
    value: Value
    priority: float
    deadline: float  # latest mission time it may be met by (inf: none)
    final: bool  # holds until the mission's end (returning home): judged when the mission ends

    @property
    def key(self) -> FactKey:
        return (self.attribute, self.args)

    def text(self) -> str:
        args = ", ".join(_text(a) for a in self.args)
        return f"{self.attribute}({args}) = {_text(self.value)} (line {self.line}, priority {self.priority:g})"


def _text(value: Value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


@dataclass
class SystemState:
    """The facts FTplan believes, the goals met, failed and still open."""

    facts: dict[FactKey, Value]
    goals: tuple[Goal, ...]
    met: set[int] = field(default_factory=set)  # goal lines
    missed: dict[int, str] = field(default_factory=dict)  # goal line -> why

    # ------------------------------------------------------------ building
    @classmethod
    def from_problem(cls, problem: pm.Problem) -> SystemState:
        """The problem's initial situation (its explained events with constant arguments) and
        its goals."""
        facts: dict[FactKey, Value] = {}
        for a in problem.assertions:
            if isinstance(a, pm.Event) and a.kind == "explained" and a.goal is None and a.time == problem.start:
                key = constant_key(a.attribute, a.args)
                value = constant(a.after)
                if key is not None and value is not None:
                    facts[key] = value
        deadlines = latest_dates(problem)
        goals = []
        for a in problem.assertions:
            if a.goal is None or isinstance(a, pm.Use):
                continue
            key = constant_key(a.attribute, a.args)
            value = constant(a.value if isinstance(a, pm.Hold) else a.after)
            if key is None or value is None:
                continue  # a goal over an open argument: left to the planner
            at = a.start if isinstance(a, pm.Hold) else a.time
            final = isinstance(a, pm.Hold) and a.end == problem.end
            goals.append(Goal(a.line, key[0], key[1], value, a.goal.priority, deadlines.get(at, math.inf), final))
        return cls(facts, tuple(goals))

    # ------------------------------------------------------------ updating
    def apply(self, changes: Iterable[tuple[FactKey, Value]]) -> None:
        for key, value in changes:
            self.facts[key] = value

    def report(self, rules: Iterable[StateRule], report: str, name: str, args: tuple[Value, ...]) -> None:
        self.apply(consequences(rules, report, name, tuple(normalise(a) for a in args)))

    def check_goals(self, now: float, mission_over: bool = False) -> list[Goal]:
        """On-line goal verification: the goals newly met (a final goal only when the mission
        is over), and those whose deadline has passed are marked missed. Returns the newly met."""
        newly = []
        for goal in self.open_goals():
            if self.holds(goal) and (mission_over or not goal.final):
                self.met.add(goal.line)
                newly.append(goal)
            elif mission_over or now > goal.deadline + 1e-6:
                self.missed[goal.line] = ("not met when the mission ended" if mission_over
                                          else f"its deadline {goal.deadline:g} s has passed")
        return newly

    def pending(self) -> list[Goal]:
        """The goals that still call for action: open ones, except final goals that hold now
        (the robot is home: it only has to stay there)."""
        return [g for g in self.open_goals() if not (g.final and self.holds(g))]

    def holds(self, goal: Goal) -> bool:
        value = self.facts.get(goal.key)
        return value is not None and same(value, goal.value)

    def open_goals(self) -> list[Goal]:
        return [g for g in self.goals if g.line not in self.met and g.line not in self.missed]

    def facts_list(self) -> list[Fact]:
        return [Fact(attribute, args, value) for (attribute, args), value in sorted(self.facts.items(), key=repr)]

    def value(self, attribute: str, *args: Value) -> Value | None:
        return self.facts.get((attribute, tuple(normalise(a) for a in args)))

    def copy(self) -> SystemState:
        return SystemState(dict(self.facts), self.goals, set(self.met), dict(self.missed))


def constant(e: pm.Expr) -> Value | None:
    """The value of a constant expression of a problem (`4.0`, `W1`, `0 - 3.0`), None otherwise."""
    if isinstance(e, pm.Num):
        return float(e.value)
    if isinstance(e, pm.Sym):
        return e.name
    if isinstance(e, pm.Op) and e.op == "-" and len(e.args) == 2:  # `0 - 3.0`, as Modele1 writes -3
        left, right = constant(e.args[0]), constant(e.args[1])
        if isinstance(left, float) and isinstance(right, float):
            return left - right
    if isinstance(e, pm.Op) and e.op == "neg" and len(e.args) == 1:
        inner = constant(e.args[0])
        if isinstance(inner, float):
            return -inner
    return None


def constant_key(attribute: str, args: tuple[pm.Expr, ...]) -> FactKey | None:
    values = [constant(a) for a in args]
    if any(v is None for v in values):
        return None
    return (attribute, tuple(v for v in values if v is not None))


def latest_dates(problem: pm.Problem) -> dict[str, float]:
    """The latest date of each timepoint of the problem, measured from the mission's start."""
    return {point: dates[1] for point, dates in date_bounds(problem).items()}


def date_bounds(problem: pm.Problem) -> dict[str, tuple[float, float]]:
    """[earliest, latest] date of each timepoint of the problem its temporal constraints allow
    (holds run forwards, every timepoint lies within the mission); (-inf, inf) for all when they
    contradict each other, which the planner would have refused."""
    from specc.runtime.planner.search import differences  # the difference form of a constraint
    from specc.runtime.stn import STN, Inconsistent

    points = (problem.start, problem.end, *problem.timepoints)
    network = STN()
    for point in points:
        network.point(point)
    try:
        for c in problem.constraints:
            if isinstance(c, (pm.Member, pm.Relation)) and pm.timepoints_of(c):
                try:
                    requirements = differences(c, origin=problem.start)
                except ValueError:
                    continue  # not a difference of dates: no bound to learn from it
                for a, b, low, high in requirements:
                    network.add(a, b, low, high)
        for assertion in problem.assertions:
            if isinstance(assertion, (pm.Hold, pm.Use)):
                network.add(assertion.start, assertion.end, 0.0, math.inf)
        for point in problem.timepoints:
            network.add(problem.start, point, 0.0, math.inf)
            network.add(point, problem.end, 0.0, math.inf)
    except Inconsistent:
        return {point: (-math.inf, math.inf) for point in points}
    return {point: network.bounds(problem.start, point) for point in points}
