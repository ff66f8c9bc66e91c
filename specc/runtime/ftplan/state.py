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
from typing import TYPE_CHECKING

from specc.runtime.ftplan.config import FactUpdate, StateRule, Value
from specc.runtime.ftplan.facts import FactKey, match, substitute
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import format_call, format_value
from specc.runtime.planner.replan import Fact
from specc.runtime.planner.validate import normalise, same

if TYPE_CHECKING:
    from specc.runtime.ftplan.view import View

Dates = tuple[float, float]  # [earliest, latest]


def ground(updates: Iterable[FactUpdate], bindings: Mapping[str, Value]) -> list[tuple[FactKey, Value]]:
    return [((u.attribute, tuple(substitute(a, bindings) for a in u.args)), substitute(u.value, bindings))
            for u in updates]


def consequences(rules: Iterable[StateRule], report: str, name: str, args: tuple[Value, ...],
                 view: View | None = None) -> list[tuple[FactKey, Value]]:
    """What the rules say changes in FTplan's state when `report` (ended, failed, report) comes
    for name(args). The rules about a task of a planner with a `view` speak that planner's
    vocabulary: their updates are written through it. Reports from the supervisor (`report`)
    speak FTplan's."""
    changes: list[tuple[FactKey, Value]] = []
    for rule in rules:
        if rule.report == report and rule.name == name:
            bindings = match(rule.args, args)
            if bindings is not None:
                changes.extend(ground(rule.updates, bindings))
    if view is not None and report != "report":
        return view.write(changes)
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
        args = ", ".join(format_value(a) for a in self.args)
        return f"{self.attribute}({args}) = {format_value(self.value)} (line {self.line}, priority {self.priority:g})"


@dataclass(frozen=True)
class Running:
    """An action of the plan carried out, from its start to its end or failure."""

    action: str  # its id in the plan (MOVE#3)
    name: str
    args: tuple[Value, ...]

    def text(self) -> str:
        return format_call(self.name, self.args)


@dataclass
class SystemState:
    """The facts FTplan believes, the goals met, failed and still open."""

    facts: dict[FactKey, Value]
    goals: tuple[Goal, ...]
    # The [earliest, latest] date the problem's constraints allow each of its timepoints: the
    # goals' deadlines and the windows the plan analyzer falls back on. The mission's problem does
    # not change, so they are computed once, here.
    dates: dict[str, Dates]
    met: set[int] = field(default_factory=set)  # goal lines
    missed: dict[int, str] = field(default_factory=dict)  # goal line -> why
    # The facts an action that started and has not ended or failed will change as it ends (what
    # the state rules `on ended` say): their value is uncertain meanwhile, so a goal on one is not
    # met when the mission ends there (stopped at the horizon). Fact -> the action.
    changing: dict[FactKey, Running] = field(default_factory=dict)
    # The final goals that came true by their deadline and have held since: met if they still hold
    # when the mission ends, however long after their deadline that is.
    reached: set[int] = field(default_factory=set)  # goal lines

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
        dates = date_bounds(problem)
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
            deadline = dates[at][1] if at in dates else math.inf
            goals.append(Goal(a.line, key[0], key[1], value, a.goal.priority, deadline, final))
        return cls(facts, tuple(goals), dates)

    # ------------------------------------------------------------ updating
    def report(self, rules: Iterable[StateRule], report: str, name: str, args: tuple[Value, ...],
               view: View | None = None) -> None:
        self.facts.update(consequences(rules, report, name, tuple(normalise(a) for a in args), view))

    def check_goals(self, now: float, mission_over: bool = False) -> list[Goal]:
        """On-line goal verification: the goals newly met (a final goal only when the mission
        is over), and those whose deadline has passed are marked missed. Returns the newly met.

        Called after every change of the facts, so a goal found holding here for the first time
        came true `now`: after its deadline, that is too late."""
        newly = []
        for goal in self.open_goals():
            in_time = now <= goal.deadline + 1e-6
            holds = self.holds(goal)
            if goal.final and holds and in_time:
                self.reached.add(goal.line)
            elif not holds:
                self.reached.discard(goal.line)  # it must come true again, by its deadline
            running = self.changing.get(goal.key) if mission_over else None
            stopped = running.text() if running is not None else None
            late = goal.final and goal.line not in self.reached  # came true after its deadline, if at all
            if holds and stopped is None and not late and (mission_over if goal.final else in_time):
                self.met.add(goal.line)
                newly.append(goal)
            elif mission_over or (not in_time and goal.line not in self.reached):
                self.missed[goal.line] = (
                    f"not known when the mission ended: {stopped}, which changes it, was stopped on the way"
                    if stopped is not None else f"its deadline {goal.deadline:g} s had passed when it came true"
                    if holds and late else "not met when the mission ended" if mission_over
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
        return [g for g in self.goals if self.is_open(g)]

    def is_open(self, goal: Goal) -> bool:
        return goal.line not in self.met and goal.line not in self.missed


def fact_list(facts: Mapping[FactKey, Value]) -> list[Fact]:
    """Facts as a replanning problem takes them, in a fixed order."""
    return [Fact(attribute, args, value) for (attribute, args), value in sorted(facts.items(), key=repr)]


def constant(e: pm.Expr) -> Value | None:
    """The value of a constant expression of a problem (`4.0`, `W1`), None otherwise. Constant
    arithmetic (`0 - 3.0`, as Modele1 writes -3) was folded when the problem was lowered
    (`specc.analysis.planning`)."""
    if isinstance(e, pm.Num):
        return float(e.value)
    if isinstance(e, pm.Sym):
        return e.name
    return None


def constant_key(attribute: str, args: tuple[pm.Expr, ...]) -> FactKey | None:
    values = [constant(a) for a in args]
    if any(v is None for v in values):
        return None
    return (attribute, tuple(v for v in values if v is not None))


def date_bounds(problem: pm.Problem) -> dict[str, Dates]:
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
