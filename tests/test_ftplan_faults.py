"""FTplan with planners made faulty on purpose, each in its own process (`ProcessPool`): one that
hangs, one that crashes, one whose plans break an analyzer constraint (the seed's mutation
1-592), one whose plans fail in execution (a model ten times too fast), one that silently leaves
goals aside. Each fault is caught by its own mechanism and the recovery goes on with the next
planner, a correct one; with every planner faulty the mission exception is raised and reported."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import pytest

from specc.runtime.ftplan import FtPlan, MissionResult, Outcome, ProcessPool, ScriptedExecutor
from specc.runtime.ftplan.component import MISSION_FAILED_IN_TIME
from specc.runtime.ftplan.config import PlannerConfig
from specc.runtime.planner.plan import Action
from tests.atrv import atrv_models

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generated"))
from atrv.ftplan import rover  # noqa: E402  (the generated package of examples/atrv)

WALL_LIMIT = 5.0  # wall seconds before a silent planner is killed: a hung one costs this much
TRUE_SPEED = 0.25  # m/s along the Manhattan path: within Modele1's [0.17, 0.35], ten times below the fast model's


def faulty(name: str, factory: str) -> PlannerConfig:
    return PlannerConfig(name, "model1", factory=f"tests.ftplan_faulty:{factory}")


CORRECT = PlannerConfig("correct", "model1")


def rover_world(action: Action, now: float) -> Outcome:
    """The rover as it is: a move takes its Manhattan length at TRUE_SPEED, and reports where
    the robot stands when it ends; the rest takes what was planned."""
    if action.task == "MOVE":
        x1, y1, x2, y2 = (float(a) for a in action.args)
        return Outcome(duration=(abs(x2 - x1) + abs(y2 - y1)) / TRUE_SPEED, reports=(("ROBOT_POSITION", (x2, y2)),))
    return Outcome()


pytestmark = pytest.mark.usefixtures("no_planner_left_behind")


def run(*planners: PlannerConfig, policy: str = "successive") -> tuple[MissionResult, list[str]]:
    domain, problem = atrv_models("M1_model1")
    config = replace(rover.CONFIG, planners=planners, policy=policy)
    messages: list[str] = []
    with ProcessPool(planners, {"model1": domain}) as pool:
        result = FtPlan(config, problem, pool, ScriptedExecutor(rover_world), wall_limit=WALL_LIMIT,
                        operator=messages.append).run()
    return result, messages


def chosen(result: MissionResult) -> list[str]:
    return [text.removeprefix("choose ") for line, text in result.trace if line == 6]


def kinds(result: MissionResult, planner: str) -> set[str]:
    return {e.kind for e in result.events if e.planner == planner}


def test_a_hanging_planner_is_killed_by_the_watchdog_and_the_next_one_plans() -> None:
    result, _ = run(faulty("hangs", "hanging_planner"), CORRECT)
    assert chosen(result) == ["hangs", "correct"]
    assert "watchdog" in kinds(result, "hangs") and "did not answer" in result.events[1].text
    assert result.success, result.missed


def test_a_crashing_planner_is_detected_and_the_next_one_plans() -> None:
    result, _ = run(faulty("crashes", "crashing_planner"), CORRECT)
    assert chosen(result) == ["crashes", "correct"]
    crash = next(e.text for e in result.events if e.kind == "watchdog")
    assert "crashed" in crash and "exited with code 3" in crash
    assert result.success, result.missed


def test_a_plan_breaking_an_analyzer_constraint_is_refused_before_execution() -> None:
    result, messages = run(faulty("mutant", "mutation_1_592_planner"), CORRECT)
    assert chosen(result) == ["mutant", "correct"]
    assert "invalid-plan" in kinds(result, "mutant") and "execute" not in kinds(result, "mutant")
    assert any("PTU_POSITION" in m and "TAKE_PICTURE" in m for m in messages)
    assert result.success, result.missed


def test_a_plan_failing_in_execution_is_detected_and_the_next_planner_replans() -> None:
    result, _ = run(faulty("fast", "optimistic_planner"), CORRECT)
    assert chosen(result) == ["fast", "correct"]
    failure = next(e for e in result.events if e.kind == "action-failed")
    assert failure.planner == "fast" and "overran its planned duration" in failure.text
    assert any(e.kind == "safe-state" for e in result.events)
    # The correct planner starts from FTplan's state: the motion generator to re-initialise.
    assert any(e.kind == "report" and e.planner == "correct" and "INIT_MVT_GENERATION" in e.text
               for e in result.events)
    assert result.replannings == 1 and result.success, result.missed


def test_goals_silently_left_aside_are_found_open_and_planned_by_the_next_planner() -> None:
    result, _ = run(faulty("silent", "silently_dropping_planner"), CORRECT)
    assert chosen(result) == ["silent", "correct"]
    left = next(e.text for e in result.events if e.kind == "goals-open")
    assert "COMMUNICATION(W1)" in left and "COMMUNICATION(W2)" in left
    # By then W1 has closed (its goal is missed, and said why); W2 is still ahead: recovered.
    assert list(result.missed) == ["COMMUNICATION(W1) = DONE (line 33, priority 3)"]
    assert "deadline" in result.missed["COMMUNICATION(W1) = DONE (line 33, priority 3)"]
    assert "COMMUNICATION(W2) = DONE (line 34, priority 3)" in result.met


def test_with_every_planner_faulty_the_mission_exception_is_raised_and_reported() -> None:
    result, messages = run(faulty("hangs", "hanging_planner"), faulty("crashes", "crashing_planner"),
                           faulty("mutant", "mutation_1_592_planner"))
    assert chosen(result) == ["hangs", "crashes", "mutant"]
    assert result.failure == MISSION_FAILED_IN_TIME and not result.success
    assert messages[-1] == MISSION_FAILED_IN_TIME
    assert [line for line, _ in result.trace][-2:] == [23, 24]


def test_concurrent_planning_takes_the_first_valid_plan_among_faulty_planners() -> None:
    result, _ = run(faulty("crashes", "crashing_planner"), faulty("mutant", "mutation_1_592_planner"), CORRECT,
                    policy="concurrent")
    assert [text for line, text in result.trace if line == 15] == ["correct executes its plan"]
    assert result.success, result.missed
