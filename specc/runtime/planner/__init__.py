"""The temporal planner of specc (seed 004 §3.2.1.2): IxTeT-style plan-space search over
partial plans, a strongly controllable temporal network, interval propagation and CasADi for
the numeric constraints and the schedule.

    from specc.runtime.planner import Planner
    result = Planner(domain).plan(problem)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from specc.runtime.planner.plan import Action, GoalOutcome, Plan, PlanResult
    from specc.runtime.planner.planner import Planner, PlanningInputError

# What the package offers, each imported where it is defined on first use (PEP 562): a program
# that needs one module of the package (a generated configuration reads `specc.runtime.planner.model`) does
# not import the rest (the search, numpy).
_OFFERS = {
    "Action": "specc.runtime.planner.plan", "GoalOutcome": "specc.runtime.planner.plan",
    "Plan": "specc.runtime.planner.plan", "PlanResult": "specc.runtime.planner.plan",
    "Planner": "specc.runtime.planner.planner", "PlanningInputError": "specc.runtime.planner.planner",
}


def __getattr__(name: str) -> Any:
    module = _OFFERS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value

__all__ = ["Action", "GoalOutcome", "Plan", "PlanResult", "Planner", "PlanningInputError"]
