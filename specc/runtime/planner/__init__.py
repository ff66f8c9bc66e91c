"""The temporal planner of specc (seed 004 §3.2.1.2): IxTeT-style plan-space search over
partial plans, a strongly controllable temporal network, interval propagation and CasADi for
the numeric constraints and the schedule.

    from specc.runtime.planner import Planner
    result = Planner(domain).plan(problem)
"""

from __future__ import annotations

from specc.runtime.planner.plan import Action, GoalOutcome, Plan, PlanResult
from specc.runtime.planner.planner import Planner, PlanningInputError

__all__ = ["Action", "GoalOutcome", "Plan", "PlanResult", "Planner", "PlanningInputError"]
