"""Diversified heuristics (#25 item 5, seed 004 §3.1 and §3.2.2.2: planners of one model made
diverse by their heuristics): a planner block names its resolver order (`heuristic:`) and its
flaw order (`flaws:`). With the oldest task's open conditions first, the search proves a broken
task's goals impossible where the default runs out of its budget: two planners of one model, one
with each order, tolerate a fault that stops the default."""

from __future__ import annotations

import sys
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest

from specc.mutation.mutants import enumerate_mutants, mutant_domain, mutation_target
from specc.runtime.ftplan import FtPlan, LocalPool, ScriptedExecutor
from specc.runtime.ftplan.config import PlannerConfig
from specc.runtime.planner import Planner
from specc.runtime.planner import model as pm
from specc.runtime.planner.heuristics import OLDEST_TASK_FIRST
from specc.runtime.planner.validate import validate
from tests.atrv import ATRV, atrv_models
from tests.conftest import tug_with

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generated"))
from atrv.ftplan import rover  # noqa: E402  (the generated package of examples/atrv)

LIMIT = 800  # partial plans: what FTplan's 10 s watchdog pays for under its cost model
# A fault of Modele1 (seed 004 §4.1.3's value class): TAKE_PICTURE expects the photo DONE where it
# should be PICTURE_IDLE, so no photo can ever be taken.
BROKEN_PHOTO = "value PICTURE_IDLE -> DONE of PICTURE (before) in TAKE_PICTURE"


@cache
def broken_model() -> pm.PlanningDomain:
    (mutant,) = [m for m in enumerate_mutants(mutation_target(ATRV, "model1"), classes=["value"])
                 if BROKEN_PHOTO in m.description]
    return mutant_domain(mutant)


@pytest.mark.parametrize("mission", ["M1", "M2", "M3"])
def test_both_flaw_orders_plan_the_missions_validly_with_the_same_goals(mission: str) -> None:
    domain, problem = atrv_models(f"{mission}_model1")
    default = Planner(domain).plan(problem)
    oldest = Planner(domain, flaws=OLDEST_TASK_FIRST).plan(problem)
    for result in (default, oldest):
        assert result.plan is not None
        assert validate(domain, problem, result.plan, dropped_lines={g.line for g in result.dropped}) == []
    assert [g.kept for g in oldest.goals] == [g.kept for g in default.goals]
    assert oldest.nodes != default.nodes  # another search, not the same one renamed


def test_the_oldest_task_first_proves_broken_photos_impossible_where_the_default_runs_out() -> None:
    domain, problem = broken_model(), atrv_models("M1_model1")[1]
    default = Planner(domain, node_limit=LIMIT).plan(problem)
    assert default.plan is None and f"limit of {LIMIT} partial plans" in default.reason
    oldest = Planner(domain, node_limit=LIMIT, flaws=OLDEST_TASK_FIRST).plan(problem)
    assert oldest.plan is not None and oldest.nodes < LIMIT
    kept = {g.description.split("(")[0] for g in oldest.goals if g.kept}
    dropped = [g for g in oldest.goals if not g.kept]
    assert kept == {"COMMUNICATION", "AT_ROBOT_X", "AT_ROBOT_Y"}
    assert dropped and all(g.description.startswith("PICTURE") and "impossible even alone" in g.reason
                           for g in dropped)


def test_two_planners_of_one_model_with_diverse_flaw_orders_tolerate_the_fault() -> None:
    domain, problem = broken_model(), atrv_models("M1_model1")[1]

    def mission(second_order: str | None) -> tuple[bool, int]:
        planners = (PlannerConfig("p1", "model1"), PlannerConfig("p2", "model1", flaws=second_order))
        config = replace(rover.CONFIG, planners=planners, policy="successive")
        pool = LocalPool({p.name: Planner(domain, node_limit=LIMIT, flaws=p.flaws or "newest-task-first")
                          for p in planners})
        result = FtPlan(config, problem, pool, ScriptedExecutor()).run()
        return bool(result.failure), sum(goal.startswith("COMMUNICATION") for goal in result.met)

    # The same heuristics twice (the seed's Robot1/1): both run out, the mission exception, no
    # communication made.
    assert mission(None) == (True, 0)
    # p2 with the other flaw order plans the two communications (and the return home).
    assert mission(OLDEST_TASK_FIRST) == (False, 2)


def test_a_planner_block_names_its_flaw_order(tmp_path: Path) -> None:
    from specc.runtime.ftplan.planners import standard_planner

    _, config, domains = tug_with(tmp_path, "careful", "flaws: oldest-task-first;")
    quick, slow = config.planners
    assert (quick.flaws, slow.flaws) == (None, OLDEST_TASK_FIRST)
    assert standard_planner(slow, domains).flaws == OLDEST_TASK_FIRST
    assert standard_planner(quick, domains).flaws == "newest-task-first"
