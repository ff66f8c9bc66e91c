"""How FTplan's plans are carried out, as FTplan sees it: actions started, their reports, and
a way to bring the system to a safe state (seed 004 §3.1.2: running activities are stopped
before any recovery).

`Executor` is what the rest of the architecture provides (in a whole run, the supervisor and
executive driving the simulated robot). `ScriptedExecutor` carries a plan out in mission time
against a `world` function that decides each action's outcome: it is the executor of the
FTplan tests and of runs without a robot.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

from specc.runtime.planner.plan import Action, Plan, Value


@dataclass(frozen=True)
class Report:
    """What the execution layer tells FTplan: `started`, `ended` or `failed` for an action of
    the plan, or `report` for a measurement (ROBOT_POSITION(x, y))."""

    kind: str  # started | ended | failed | report
    name: str  # the task, or the report's name
    args: tuple[Value, ...]
    time: float
    action: str = ""  # the plan's action id
    why: str = ""  # for a failure


@dataclass(frozen=True)
class Execution:
    completed: bool  # every action of the plan ended
    now: float  # mission time when the execution stopped
    failed_action: str = ""
    why: str = ""


class Executor(Protocol):
    def execute(self, plan: Plan, now: float, report: Callable[[Report], None]) -> Execution:
        """Carry `plan` out from mission time `now`, calling `report` for every report; stop at
        the first failed action. Blocking, as in Fig 3.1 line 15."""
        ...

    def safe_state(self, now: float) -> float:
        """Stop every running activity; the mission time when the system is safe."""
        ...


@dataclass(frozen=True)
class Outcome:
    """What the world does with one action: how long it really takes, whether it ends, and the
    measurements reported with it."""

    ended: bool = True
    duration: float | None = None  # None: the planned duration's upper bound; beyond it, a failure
    reports: tuple[tuple[str, tuple[Value, ...]], ...] = ()  # measurements sent when it ends or fails
    why: str = ""


World = Callable[[Action, float], Outcome]


class Precedences:
    """The plan's orderings between actions, as every executor reads them: an action starts at
    its dispatch date, or later when an action ordered before it ends late (plus the delay)."""

    def __init__(self, plan: Plan) -> None:
        by_end = {a.end: a for a in plan.actions}
        by_start = {a.start: a for a in plan.actions}
        self.after: dict[str, list[tuple[str, float]]] = {a.id: [] for a in plan.actions}  # -> (predecessor, delay)
        for first, second, delay in plan.orderings:
            before, action = by_end.get(first), by_start.get(second)
            if before is not None and action is not None and before is not action:
                self.after[action.id].append((before.id, delay))

    def start_date(self, action: Action, ended_at: Mapping[str, float], now: float) -> float | None:
        """When the action may start, None while an action before it has not ended."""
        if not all(p in ended_at for p, _ in self.after[action.id]):
            return None
        return max(now, action.dispatch, *(ended_at[p] + d for p, d in self.after[action.id]))


OVERRUN_TOLERANCE = 1e-6  # seconds


def nominal(action: Action, now: float) -> Outcome:
    """Every action ends, taking the longest its planned duration allows."""
    return Outcome()


@dataclass
class ScriptedExecutor:
    """Carries a plan out in mission time: each action starts at its dispatch date, or later
    when an action the plan orders before it ends late; actions overlap as the plan lets them;
    `world` decides each outcome. Reports come in the order of their dates."""

    world: World = nominal

    def execute(self, plan: Plan, now: float, report: Callable[[Report], None]) -> Execution:
        waiting = plan.ordered()
        precedences = Precedences(plan)
        ended_at: dict[str, float] = {}
        running: list[tuple[float, int, Action, Outcome]] = []  # (end date, order, action, outcome)
        clock, order = now, 0
        while waiting or running:
            starts = [(date, a) for a in waiting if (date := precedences.start_date(a, ended_at, clock)) is not None]
            next_start = min(starts, key=lambda s: (s[0], s[1].dispatch, s[1].id), default=None)
            if running and (next_start is None or running[0][0] <= next_start[0]):
                end, _, action, outcome = heapq.heappop(running)
                clock = end
                # The measurements first: where a failed move left the robot matters to recovery.
                for name, args in outcome.reports:
                    report(Report("report", name, args, end, action.id))
                if not outcome.ended:
                    report(Report("failed", action.task, action.args, end, action.id, outcome.why))
                    return Execution(False, end, action.id, outcome.why or f"{action.text()} failed")
                ended_at[action.id] = end
                report(Report("ended", action.task, action.args, end, action.id))
                continue
            if next_start is None:  # an ordering no action ends: the plan is malformed
                stuck = ", ".join(a.text() for a in waiting)
                return Execution(False, clock, waiting[0].id, f"{stuck} wait for actions that never end")
            start, action = next_start
            waiting.remove(action)
            clock = start
            report(Report("started", action.task, action.args, start, action.id))
            outcome = self.world(action, start)
            planned = action.duration[1]
            duration = planned if outcome.duration is None else outcome.duration
            if duration > planned + OVERRUN_TOLERANCE:
                # Temporal execution control (seed 004 §3.2.2.2, IxTeT's): an action still running
                # past its planned latest end has failed; the executive stops it then.
                outcome = Outcome(False, planned, why=f"{action.text()} overran its planned duration "
                                  f"[{action.duration[0]:.3g}, {planned:.3g}] s (it needed {duration:.3g} s)")
                duration = planned
            end = start + (duration if math.isfinite(duration) else 0.0)
            order += 1
            heapq.heappush(running, (end, order, action, outcome))
        return Execution(True, clock)

    def safe_state(self, now: float) -> float:
        return now  # nothing of the plan runs past a failure here: the system is safe at once
