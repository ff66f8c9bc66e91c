"""Planners with another vocabulary than FTplan's state (`view` and `mission` in an ftplan block):
Modele2 reads FTplan's state (Modele1's vocabulary) through p2's correspondences, its tasks'
reports are written back through them, its goals stand for FTplan's, and its plans are judged by
the same analyzer. Robot2 (Modele2 alone) and Robot1/2 (Modele1, then Modele2 from FTplan's state)
run the rover's missions."""

from __future__ import annotations

import sys
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest

from specc.runtime.ftplan import FtPlan, LocalPool, MissionResult, Outcome, ProcessPool, ScriptedExecutor
from specc.runtime.ftplan.analyzer import analyse
from specc.runtime.ftplan.config import FtPlanConfig, PlannerConfig
from specc.runtime.ftplan.planners import standard_planner
from specc.runtime.ftplan.state import SystemState, consequences
from specc.runtime.ftplan.view import View
from specc.runtime.planner import Planner
from specc.runtime.planner.plan import Action
from specc.runtime.planner.validate import validate
from tests.atrv import atrv_models, mutation_1_592_modele2

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generated"))
from atrv.ftplan import rover  # noqa: E402  (the generated package of examples/atrv)

TRUE_SPEED = 0.25  # m/s


def on_mission(configuration: str, mission: str) -> FtPlanConfig:
    return rover.CONFIGURATIONS[configuration].for_mission(mission)


def p2_view(mission: str) -> View:
    return View(next(p for p in on_mission("Robot1/2", mission).planners if p.name == "p2").view)


def ftplan_state(mission: str) -> SystemState:
    return SystemState.from_problem(atrv_models(f"{mission}_model1")[1])


# ---------------------------------------------------------------- the correspondences


def test_modele2_reads_the_start_of_m1_from_ftplans_state() -> None:
    read = p2_view("M1").read(ftplan_state("M1").facts)
    assert read[("FRAME_POS", ())] == "O1" and read[("FRAME_MODE", ())] == "NOMINAL"
    # STRAIGHT reads as Modele2's moving angles, the first correspondence to give them
    assert (read[("PTU_PAN", ())], read[("PTU_TILT", ())]) == (0.0, -30.0)
    assert read[("PTU_STATE", ())] == "INITED" and read[("FRAME_STATE", ())] == "INITED"
    assert read[("COMMUNICATION", ("W1",))] == "FALSE" and read[("COMMUNICATION", ("W2",))] == "FALSE"


def test_away_from_the_missions_points_the_robot_is_at_the_nearest_localisation_point() -> None:
    facts = ftplan_state("M1").facts | {("AT_ROBOT_X", ()): 0.6, ("AT_ROBOT_Y", ()): -5.2}
    read = p2_view("M1").read(facts)
    assert read[("FRAME_POS", ())] == "G8" and read[("FRAME_MODE", ())] == "RECOV"  # G8 = (3, -6)
    # the same coordinates name a singular point of M3 only where M3 has one
    assert p2_view("M3").read(facts | {("AT_ROBOT_X", ()): -1.0, ("AT_ROBOT_Y", ()): 2.0})[("FRAME_POS", ())] == "O3"


def test_modele2_reports_are_written_into_ftplans_state() -> None:
    rules, view = rover.CONFIG.state_rules, p2_view("M1")
    moved = dict(consequences(rules, "ended", "MOVE_NOMINAL", ("O1", "O3"), view))
    assert moved == {("AT_ROBOT_X", ()): 3.0, ("AT_ROBOT_Y", ()): -3.0, ("MVT_GENERATION_INITIALIZED", ()): "TRUE",
                     ("ROBOT_STATUS", ()): "STILL"}
    feet = dict(consequences(rules, "ended", "MOVE_PTU", (0.0, -30.0, 0.0, -45.0), view))
    assert feet == {("PTU_POSITION", ()): "AT_MY_FEET"}
    askew = dict(consequences(rules, "ended", "MOVE_PTU", (0.0, -30.0, 10.0, 20.0), view))
    assert askew == {("PTU_POSITION", ()): "OTHER_POSITION"}
    shot = dict(consequences(rules, "ended", "TAKE_SHOT", ("O2",), view))
    assert shot == {("PICTURE", ("OBJ2", 4.0, 0.0)): "DONE"}
    # Without the view the same rule would write Modele2's attributes into FTplan's state.
    assert ("FRAME_POS", ()) in dict(consequences(rules, "ended", "MOVE_NOMINAL", ("O1", "O3")))


def test_modele2_goals_stand_for_ftplans() -> None:
    view = p2_view("M2")
    assert view.state_facts_of(("SHOT", ("O3",)), "TRUE") == [(("PICTURE", ("OBJ2", 5.0, 5.0)), "DONE")]
    assert view.state_facts_of(("FRAME_POS", ()), "O1") == [(("AT_ROBOT_X", ()), 0.0), (("AT_ROBOT_Y", ()), 0.0)]
    assert view.state_facts_of(("COMMUNICATION", ("W2",)), "TRUE") == [(("COMMUNICATION", ("W2",)), "DONE")]


@pytest.mark.parametrize("mission", ["M1", "M3"])
def test_modele2_with_mutation_1_592_is_caught_through_the_view(mission: str) -> None:
    domain, problem = atrv_models(f"{mission}_model2")
    mutated = mutation_1_592_modele2(domain)
    result = Planner(mutated).plan(problem)
    assert result.plan is not None and validate(mutated, problem, result.plan) == []
    shots = [a for a in result.plan.actions if a.task == "TAKE_SHOT"]
    state_problem = atrv_models(f"{mission}_model1")[1]
    violations = analyse(result.plan, rover.CONFIG, ftplan_state(mission), state_problem, p2_view(mission))
    caught = {v.action for v in violations if "PTU_POSITION() is STRAIGHT" in v.message}
    assert shots and caught >= {a.id for a in shots}


# ---------------------------------------------------------------- Robot2 and Robot1/2


def mission_problems(mission: str) -> dict[str, object]:
    return {"p1": atrv_models(f"{mission}_model1")[1], "p2": atrv_models(f"{mission}_model2")[1]}


@cache
def domains(mission: str) -> dict[str, object]:
    return {"model1": atrv_models(f"{mission}_model1")[0], f"model2_{mission}": atrv_models(f"{mission}_model2")[0]}


def rover_world(action: Action, now: float) -> Outcome:
    """Modele1's moves at TRUE_SPEED along the Manhattan path; a move that would overrun stops
    at its planned latest end, wherever the robot is then, and says so."""
    if action.task != "MOVE":
        return Outcome()
    x1, y1, x2, y2 = (float(a) for a in action.args)
    length = abs(x2 - x1) + abs(y2 - y1)
    needed, allowed = length / TRUE_SPEED, action.duration[1]
    if needed <= allowed:
        return Outcome(duration=needed, reports=(("ROBOT_POSITION", (x2, y2)),))
    along = allowed * TRUE_SPEED  # first along x, then along y
    dx = max(-along, min(along, x2 - x1))
    dy = max(-(along - abs(dx)), min(along - abs(dx), y2 - y1))
    return Outcome(ended=False, duration=allowed, reports=(("ROBOT_POSITION", (x1 + dx, y1 + dy)),),
                   why=f"{action.text()} stopped at its planned latest end, short of its goal")


@pytest.mark.parametrize("mission", ["M1", "M2", "M3", "M4"])
def test_robot2_plans_and_meets_the_mission_in_modele2_with_ftplans_state(mission: str) -> None:
    config = on_mission("Robot2", mission)
    (p2,) = config.planners
    assert p2.domain == f"model2_{mission}" and p2.view
    problems = mission_problems(mission)
    pool = LocalPool({"p2": Planner(domains(mission)[p2.domain])})  # type: ignore[arg-type]
    result = FtPlan(config, problems["p1"], pool, ScriptedExecutor(), problems=problems).run()  # type: ignore[arg-type]
    assert result.plannings == 1 and not result.failure
    if mission == "M4":
        # Modele2 has one WINDOW() attribute for every window: M4's W2 cannot be planned with
        # it (the planner says so and drops that goal), which FTplan's ledger records as missed.
        assert "dropped COMMUNICATION(W2)" in next(e.text for e in result.events if e.kind == "plan")
        assert list(result.missed) == ["COMMUNICATION(W2) = DONE (line 44, priority 3)"]
    else:
        assert result.success, result.missed
    # The goals are FTplan's own (Modele1's vocabulary), met by Modele2's reports through the view.
    assert any(goal.startswith("PICTURE(OBJ1") for goal in result.met)
    assert any(goal.startswith("AT_ROBOT_X() = 0") for goal in result.met)


def test_robot1_plans_m4s_second_window_as_its_spec_asks_pseudo_controllability() -> None:
    """`controllability: pseudo;` in ftplan.spec reaches p1's planner: M4's W2 (open 24 s at
    worst) is planned, and the whole mission is met; Modele2's p2 keeps the default (strong)."""
    config = on_mission("Robot1", "M4")
    (p1,) = config.planners
    assert p1.controllability == "pseudo"
    assert [p.controllability for p in on_mission("Robot2", "M4").planners] == ["strong"]
    problems = mission_problems("M4")
    pool = LocalPool({"p1": standard_planner(p1, domains("M4"))})  # type: ignore[arg-type]
    result = FtPlan(config, problems["p1"], pool, ScriptedExecutor(), problems=problems).run()  # type: ignore[arg-type]
    assert result.success, result.missed
    assert "COMMUNICATION(W2) = DONE (line 44, priority 3)" in result.met


def run_in_processes(config: FtPlanConfig, mission: str) -> MissionResult:
    problems = mission_problems(mission)
    with ProcessPool(config.planners, domains(mission)) as pool:  # type: ignore[arg-type]
        return FtPlan(config, problems["p1"], pool, ScriptedExecutor(rover_world),  # type: ignore[arg-type]
                      wall_limit=5.0, problems=problems).run()  # type: ignore[arg-type]


def with_factory(config: FtPlanConfig, planner: str, factory: str) -> FtPlanConfig:
    return replace(config, planners=tuple(replace(p, factory=f"tests.ftplan_faulty:{factory}")
                                          if p.name == planner else p for p in config.planners))


@pytest.mark.usefixtures("no_planner_left_behind")
def test_robot1_2_recovers_a_failed_modele1_move_with_modele2_from_where_the_robot_stopped() -> None:
    # Modele2's replanning from a localisation point expands ~1100 partial plans (it weighs
    # dropping a photo): 13 s by the cost model, beyond the block's 10 s watchdog; a 30 s one
    # lets this test see the recovery itself.
    config = replace(with_factory(on_mission("Robot1/2", "M1"), "p1", "optimistic_planner"), watchdog=30.0)
    result = run_in_processes(config, "M1")
    chosen = [text.removeprefix("choose ") for line, text in result.trace if line == 6]
    assert chosen[:2] == ["p1", "p2"]
    assert next(e for e in result.events if e.kind == "action-failed").planner == "p1"
    # p2 planned from FTplan's state read in its vocabulary: the robot stopped short of (4, 0),
    # inside localisation region G6, with the motion generator to re-initialise.
    p2_actions = [e.text for e in result.events if e.kind == "report" and e.planner == "p2"]
    assert any(text.startswith("ended INIT_FRAME") for text in p2_actions)
    assert any(text.startswith("ended MOVE_RECOV(G6, ") for text in p2_actions)
    # Modele2's plans end the mission (p1 fails again when asked for the photo p2 dropped); their
    # reports met FTplan's goals, in FTplan's vocabulary.
    assert not result.failure and next(e for e in reversed(result.events) if e.kind == "execute").planner == "p2"
    assert {"PICTURE(OBJ2, 4, 0) = DONE (line 38, priority 2)", "PICTURE(OBJ3, 3, -3) = DONE (line 39, priority 2)",
            "AT_ROBOT_X() = 0 (line 29, priority 4)", "AT_ROBOT_Y() = 0 (line 30, priority 4)"} <= set(result.met)


@pytest.mark.usefixtures("no_planner_left_behind")
def test_robot1_2c_takes_modele2s_plan_when_modele1_crashes() -> None:
    config = with_factory(on_mission("Robot1/2c", "M2"), "p1", "crashing_planner")
    assert config.policy == "concurrent"
    result = run_in_processes(config, "M2")
    assert [text for line, text in result.trace if line == 15] == ["p2 executes its plan"]
    assert result.success, (result.missed, result.failure)


def test_a_planner_with_a_view_needs_its_own_problem() -> None:
    config = on_mission("Robot2", "M1")
    with pytest.raises(ValueError, match="give their own problems"):
        FtPlan(config, atrv_models("M1_model1")[1], LocalPool({}), ScriptedExecutor())


def test_an_unknown_mission_is_named_with_the_known_ones() -> None:
    with pytest.raises(KeyError, match="no mission 'M9'.*M1, M2, M3, M4"):
        rover.CONFIG.for_mission("M9")
    assert isinstance(rover.CONFIG.planners[0], PlannerConfig)


def test_modele2_replans_from_a_localisation_point_with_every_action_bounded() -> None:
    """From G6 the M1 distance table says nothing of places O4-O6 (Modele2's OBJECTS has six): a
    move there left its distance symbol open, and its duration unbounded. The planner now gives
    such a symbol a value, or refuses the plan."""
    from specc.runtime.planner.replan import Fact, replanning_problem

    domain, problem = atrv_models("M1_model2")
    facts = [Fact("FRAME_POS", (), "G6"), Fact("FRAME_MODE", (), "RECOV"), Fact("FRAME_STATE", (), "IDLE"),
             Fact("PTU_PAN", (), 0.0), Fact("PTU_TILT", (), -30.0), Fact("SHOT", ("O1",), "TRUE")]
    goals = [g.line for g in SystemState.from_problem(problem).goals if g.attribute != "SHOT" or g.args != ("O1",)]
    replan = replanning_problem(problem, facts, goals, 31.1)
    result = Planner(domain).plan(replan, 31.1)
    assert result.plan is not None, result.reason
    assert validate(domain, replan, result.plan, dropped_lines={g.line for g in result.dropped}) == []
    assert all(a.duration[1] < float("inf") for a in result.plan.actions)
    assert result.plan.actions[0].args[:1] != ("O4",) and any(a.task == "MOVE_RECOV" for a in result.plan.actions)
