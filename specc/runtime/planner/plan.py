"""What the planner returns: a partially ordered plan with time windows, a dispatchable
schedule, the goals kept and dropped, or no plan and why (seed 004 §3.2.1.2)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

Value = float | str


@dataclass(frozen=True)
class Action:
    """One task instance of the plan."""

    id: str  # "MOVE#3": unique in the plan
    task: str
    args: tuple[Value, ...]  # the task's parameters, all bound
    start: str  # names of its timepoints in the plan's schedule
    end: str
    dispatch: float  # when the executive starts it
    duration: tuple[float, float]  # [low, high]: nature picks the real duration in it when contingent
    contingent: bool
    preemptible: bool  # may be stopped while it runs (latePreemptive)
    window: tuple[float, float] = (0.0, 0.0)  # [earliest, latest] start the partial order allows
    values: tuple[tuple[str, Value], ...] = ()  # the other variables the planner fixed (a symbol or a number)

    def text(self) -> str:
        return format_call(self.task, self.args)


@dataclass(frozen=True)
class Link:
    """A causal link: `producer` gives the value `consumer` needs (assertion descriptions)."""

    producer: str
    consumer: str
    attribute: str
    value: Value


@dataclass(frozen=True)
class GoalOutcome:
    """A goal of the problem, and whether the plan keeps it (and why not)."""

    description: str  # "hold(COMMUNICATION(W1): DONE) at line 37"
    priority: float
    line: int
    kept: bool
    reason: str = ""  # why it was dropped
    # Dropped for the goals kept before it (not planned together with them), not for itself.
    for_others: bool = False


@dataclass(frozen=True)
class Plan:
    """A plan: its actions with their dates and durations, and the goals it meets."""

    domain: str
    problem: str
    actions: tuple[Action, ...]
    # Precedences of the partial order: (timepoint, timepoint, minimal delay).
    orderings: tuple[tuple[str, str, float], ...]
    links: tuple[Link, ...]
    # Every timepoint the plan controls, at its dispatch date; and those nature controls
    # (contingent action ends, window instants) with their [earliest, latest] dates.
    schedule: dict[str, float]
    uncontrolled: dict[str, tuple[float, float]]
    bindings: dict[str, Value]  # the problem's ?variables
    # "strong": the schedule holds for every choice of nature; "pseudo": for each choice alone
    # (the planner's search.py), and the dispatch assumes nature's timepoints at `assumed`.
    controllability: str = "strong"
    now: float = 0.0  # mission time the plan was made for (a replanning starts later)
    assumed: dict[str, float] = field(default_factory=dict)
    goals: tuple[int, ...] = ()  # source lines of the problem's goals the plan meets
    # The problem's ?variables no assertion of the plan binds (the initial facts of a dropped
    # goal): `bindings` gives each one some value of its domain, which means nothing.
    free: tuple[str, ...] = ()

    def ends_by(self, action: Action) -> float:
        """The latest date the action may end, whatever nature does."""
        return self.uncontrolled.get(action.end, (0.0, action.dispatch + action.duration[1]))[1]

    @property
    def controllability_text(self) -> str:
        """How the plan is controllable, in words (IxTeT's pseudo-controllability)."""
        return "pseudo-controllable" if self.controllability == "pseudo" else f"{self.controllability}ly controllable"

    @property
    def makespan(self) -> float:
        return max((self.ends_by(a) for a in self.actions), default=self.now)

    def ordered(self) -> list[Action]:
        return sorted(self.actions, key=lambda a: (a.dispatch, a.id))


@dataclass(frozen=True)
class Repair:
    """What a planner is asked to repair (seed 004 §3.2.1): its `plan` under way, and the ids of
    the actions `kept`, still to carry out (the failed one and those that ended are not)."""

    plan: Plan
    kept: tuple[str, ...]

    @property
    def actions(self) -> tuple[Action, ...]:
        return tuple(a for a in self.plan.ordered() if a.id in self.kept)

    @property
    def orderings(self) -> tuple[tuple[str, str, float], ...]:
        """The plan's precedences between two of the kept actions."""
        points = {p for a in self.actions for p in (a.start, a.end)}
        return tuple(o for o in self.plan.orderings if o[0] in points and o[1] in points)


@dataclass(frozen=True)
class PlanResult:
    """What a planning call gives: the plan (or none), each goal's outcome, and its cost."""

    plan: Plan | None
    goals: tuple[GoalOutcome, ...] = ()
    reason: str = ""  # why there is no plan
    nodes: int = 0  # partial plans the search expanded
    seconds: float = 0.0
    notes: tuple[str, ...] = field(default=())

    @property
    def dropped(self) -> tuple[GoalOutcome, ...]:
        return tuple(g for g in self.goals if not g.kept)

    @property
    def ok(self) -> bool:
        return self.plan is not None


def format_value(value: Value) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def format_call(name: str, args: Iterable[Value]) -> str:
    """`MOVE(DOCK, A)`: a task (or an attribute) with its arguments, as messages and logs write it."""
    return f"{name}({', '.join(format_value(a) for a in args)})"
