"""The temporal planner of specc (seed 004 §3.2.1.2): IxTeT-style plan-space search over
partial plans, a strongly controllable temporal network, interval propagation and CasADi for
the exact durations the numeric constraints allow.

    from specc.runtime.planner import Planner
    result = Planner(domain).plan(problem)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from specc.runtime.lazy import lazy_exports

if TYPE_CHECKING:
    from specc.runtime.planner.plan import Action, GoalOutcome, Plan, PlanResult
    from specc.runtime.planner.planner import Planner, PlanningInputError

# Each name imported where it is defined on first use (specc.runtime.lazy).
_OFFERS = {
    "plan": ("Action", "GoalOutcome", "Plan", "PlanResult"),
    "planner": ("Planner", "PlanningInputError"),
}

__getattr__ = lazy_exports(__name__, _OFFERS)

__all__ = ["Action", "GoalOutcome", "Plan", "PlanResult", "Planner", "PlanningInputError"]
