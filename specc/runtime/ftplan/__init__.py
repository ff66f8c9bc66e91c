"""FTplan, the fault-tolerant planning component of seed 004 (ch. 3): diversified planners in
their own processes, a planning watchdog, a plan analyzer, action-failure detection, on-line goal
verification, successive (Fig 3.1) and concurrent (Fig 3.2) recovery.

    from specc.runtime.ftplan import FtPlan, ProcessPool, ScriptedExecutor, mission_setup
    setup = mission_setup(depot.CONFIGURATIONS, "Robot1/2", "shuttle", robot.planner)  # generated modules
    with ProcessPool(planners_as_run(setup.config, "model"), setup.domains) as pool:
        result = FtPlan(setup.config, setup.problem, pool, ScriptedExecutor(), problems=setup.problems,
                        wall_limit=HUNG_PLANNER_SECONDS).run()

A program running many missions one after another keeps the planners' processes from one to the
next inside `with planner_processes_kept():` (see `planners`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from specc.runtime.lazy import lazy_exports

if TYPE_CHECKING:
    from specc.runtime.ftplan.component import (
        HUNG_PLANNER_SECONDS,
        CostModel,
        FtPlan,
        MissionFailure,
        MissionResult,
        planners_as_run,
    )
    from specc.runtime.ftplan.config import FtPlanConfig, PlannerConfig, configurations
    from specc.runtime.ftplan.execution import Executor, Outcome, Report, ScriptedExecutor
    from specc.runtime.ftplan.missions import MissionSetup, UnknownName, mission_setup
    from specc.runtime.ftplan.planners import planner_processes_kept
    from specc.runtime.ftplan.pools import LocalPool, ProcessPool

# Each name imported where it is defined on first use (specc.runtime.lazy).
_OFFERS = {
    "component": ("HUNG_PLANNER_SECONDS", "CostModel", "FtPlan", "MissionFailure", "MissionResult", "planners_as_run"),
    "config": ("FtPlanConfig", "PlannerConfig", "configurations"),
    "execution": ("Executor", "Outcome", "Report", "ScriptedExecutor"),
    "missions": ("MissionSetup", "UnknownName", "mission_setup"),
    "planners": ("planner_processes_kept",),
    "pools": ("LocalPool", "ProcessPool"),
}

__getattr__ = lazy_exports(__name__, _OFFERS)


__all__ = ["HUNG_PLANNER_SECONDS", "CostModel", "Executor", "FtPlan", "FtPlanConfig", "LocalPool", "MissionFailure",
           "MissionResult", "MissionSetup", "Outcome", "PlannerConfig", "ProcessPool", "Report", "ScriptedExecutor",
           "UnknownName", "configurations", "mission_setup", "planner_processes_kept", "planners_as_run"]
