"""The rover missions of seed 004 end to end (issue #9): FTplan's planners in their processes, their
plans carried out by the ATRV's generated modules on the simulated rover (`specc.run.rover`), and
the measures of §4.1.4 (`specc.run.measures`). Real runs, no mocks; the campaign-sized ones are
marked slow. Wall times are printed (`pytest -s`)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest

from specc.run import RunError
from specc.run.events import EventLog, read_events
from specc.run.measures import (
    GoalCount,
    Measures,
    aggregate,
    markdown_table,
    measure,
    measure_table,
    rich_table,
)
from specc.run.rover import (
    WORLDS,
    PreparedMission,
    RoverProgress,
    RoverRun,
    SimExecutor,
    prepare_mission,
    run_rover_mission,
)
from specc.runtime import functional as rt
from specc.runtime.ftplan import Report
from specc.runtime.planner.plan import Action, Plan
from specc.runtime.sim import Polygon, World, load_world


def timed(run: RoverRun) -> RoverRun:
    print(f"\n{run.configuration} on {run.mission} in {run.world} (seed {run.seed}): "
          f"{run.simulated_time:.0f} s of mission in {run.wall_time:.2f} s of wall time")
    return run


def assert_position_reported_before(events: Sequence[Mapping[str, Any]], prefix: str) -> None:
    """Each FTplan report starting with `prefix` (a move's end) comes right after the report of
    where the robot stands."""
    reports = [e["text"] for e in events if e["kind"] == "ftplan" and e["event"] == "report"]
    for k, text in enumerate(reports):
        if text.startswith(prefix):
            assert reports[k - 1].startswith("report ROBOT_POSITION("), (reports[k - 1], text)


@pytest.fixture(scope="module")
def robot1_m1_w1(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[RoverRun, Path, list[RoverProgress]]]:
    log_path = tmp_path_factory.mktemp("rover") / "m1w1.jsonl"
    progress: list[RoverProgress] = []
    with EventLog(log_path) as log:
        run = timed(run_rover_mission("Robot1", "M1", "W1", seed=0, log=log, progress=progress.append))
    yield run, log_path, progress


# ---------------------------------------------------------------- whole missions


def test_robot1_meets_every_goal_of_m1_in_the_empty_world(robot1_m1_w1: tuple[RoverRun, Path, list]) -> None:
    run, _, _ = robot1_m1_w1
    assert run.result.success and not run.result.failure, run.result.missed
    measures = measure(run)
    assert (measures.photos, measures.communications, measures.home) == (GoalCount(3, 3), GoalCount(2, 2),
                                                                         GoalCount(1, 1))
    assert measures.success and measures.nu == 1 and measures.kappa == 0 and measures.replannings == 0
    assert measures.believed == GoalCount(7, 7)
    # Photos of the mission's targets, at the robot's feet, where the robot really stood.
    taken = {photo.target: photo for photo in run.photos if photo.ok}
    assert set(taken) == {"M1_OBJ1", "M1_OBJ2", "M1_OBJ3"}
    for goal in run.goals:
        if goal.kind == "photo":
            photo = taken[goal.name]
            assert goal.name in photo.seen and photo.tilt < -1.0
            assert goal.point is not None and math.hypot(photo.x - goal.point[0], photo.y - goal.point[1]) < 0.5
    # Each communication inside the window it was meant for, as nature opened it.
    windows = {w.name: w for w in run.windows}
    assert [c.window for c in run.communications if c.ok] == ["W1", "W2"]
    for link in run.communications:
        assert link.link == link.window and windows[link.window].start <= link.start < link.end <= windows[
            link.window].end
    assert math.hypot(*run.final_position) < 0.5
    # The robot moved only during moves: T counts the actions, D the true path.
    assert 0 < measures.activity_time < run.simulated_time and 9.0 < measures.distance < 13.0
    assert all(a.outcome == "ended" for a in run.actions) and len(run.actions) == len(run.planned) == 14


def test_every_action_is_logged_with_its_simulated_time(robot1_m1_w1: tuple[RoverRun, Path, list]) -> None:
    run, log_path, progress = robot1_m1_w1
    events = read_events(log_path)
    assert events == list(run.events)
    assert events[0]["kind"] == "mission-start" and events[-1]["kind"] == "mission-end"
    assert events[-1]["outcome"] == "succeeded"
    times = [e["t"] for e in events]
    assert times == sorted(times)
    actions = [e for e in events if e["kind"] == "action"]
    assert {e["status"] for e in actions} == {"started", "ended"}
    for executed in run.actions:
        mine = [e for e in actions if e["id"] == executed.id and e["plan"] == executed.plan]
        assert [(e["status"], e["t"]) for e in mine] == [("started", round(executed.start, 6)),
                                                        ("ended", round(executed.end, 6))]
    # FTplan's own events, every one, at their mission time.
    forwarded = [(e["t"], e["event"], e["text"]) for e in events if e["kind"] == "ftplan"]
    assert forwarded == [(round(e.time, 6), e.kind, e.text) for e in run.result.events]
    # Every move's end reports where the robot stands, before its end.
    assert_position_reported_before(events, "ended MOVE(")
    assert len([e for e in events if e["kind"] == "photo"]) == 3
    assert progress[-1].what == "mission succeeded" and progress[-1].goals_met == progress[-1].goals == 7


def test_same_seed_gives_the_same_mission(robot1_m1_w1: tuple[RoverRun, Path, list]) -> None:
    first, _, _ = robot1_m1_w1
    again = timed(run_rover_mission("Robot1", "M1", "W1", seed=0))
    assert [(e.time, e.kind, e.text, e.planner) for e in again.result.events] == \
        [(e.time, e.kind, e.text, e.planner) for e in first.result.events]
    assert again.events == first.events
    assert again.path == first.path
    assert measure(again).to_json() == measure(first).to_json()


def test_robot1_2_succeeds_m1_among_the_cylinders_of_w2() -> None:
    run = timed(run_rover_mission("Robot1/2", "M1", "W2", seed=0))
    measures = measure(run)
    assert run.result.success and measures.success, measures.summary()
    cylinders = run.simulation.world.obstacles
    assert cylinders and min(o.distance(x, y) for o in cylinders for _, x, y, _ in run.path) > 0.3


def test_concurrent_planning_is_one_round_of_requests() -> None:
    """Robot1/2c asks both planners at once (Fig 3.2): two requests, one planning, no replanning."""
    run = timed(run_rover_mission("Robot1/2c", "M1", "W1", seed=0))
    assert run.policy == "concurrent" and run.result.plannings == 2
    assert measure(run).replannings == 0 and measure(run).success


def test_robot2_photographs_with_modele2s_own_angles() -> None:
    """Modele2 points the camera 45 degrees down for a photo (annex A.2), and its places are the
    mission's view: M1's first photo is of the lander, under the robot."""
    run = timed(run_rover_mission("Robot2", "M1", "W1", seed=0))
    assert run.result.success and measure(run).success, run.result.missed
    shots = [p for p in run.photos if p.ok]
    assert {p.target for p in shots} == {"M1_OBJ1", "M1_OBJ2", "M1_OBJ3"}
    assert all(p.tilt == pytest.approx(math.radians(-45.0), abs=1e-3) for p in shots)
    assert {a.task for a in run.actions} >= {"MOVE_NOMINAL", "MOVE_PTU", "TAKE_SHOT", "COMMUNICATE_ANTENNA"}
    # Its plan photographs O3 while the antenna transmits in W1: both ran at once.
    link = next(a for a in run.actions if a.text() == "COMMUNICATE_ANTENNA(W1)")
    shot = next(a for a in run.actions if a.text() == "TAKE_SHOT(O3)")
    assert link.start < shot.start < shot.end < link.end


@pytest.mark.parametrize("configuration, mission, world, message", [
    ("Robot3", "M1", "W1", "no robot configuration 'Robot3' (known: Robot1, Robot2, Robot1/2, Robot1/2c; add"),
    ("Robot1", "M9", "W1", "has no mission 'M9' (it has: M1, M2, M3, M4)"),
    ("Robot1", "M1", "W9", "unknown world 'W9': give W1, W2, W3, W4"),
    ("Robot1", "M1", "nowhere.toml", "nowhere.toml: cannot read the world file"),
])
def test_unknown_names_raise_a_one_line_error(configuration: str, mission: str, world: str, message: str) -> None:
    with pytest.raises(RunError) as caught:
        run_rover_mission(configuration, mission, world)
    assert message in str(caught.value) and "\n" not in str(caught.value)


@pytest.mark.parametrize("arguments, message", [
    ({"seed": -1}, "seed -1: give a whole number >= 0"),
    ({"timing": "fast"}, "timing 'fast': give model or wall"),
])
def test_bad_seed_or_timing_raises_a_one_line_error(arguments: dict, message: str) -> None:
    with pytest.raises(RunError, match=message):
        run_rover_mission("Robot1", "M1", "W1", **arguments)


def test_a_world_without_the_missions_targets_is_refused() -> None:
    bare = dataclasses.replace(load_world(WORLDS / "W1.toml"), targets=())
    with pytest.raises(RunError, match="has no photo target M2_OBJ1 at \\(-5, 3\\), which mission M2 photographs"):
        run_rover_mission("Robot1", "M2", bare)


def pocket_facing(target: tuple[float, float], origin: tuple[float, float]) -> World:
    """W4 with its pocket turned to open towards `origin` on the way to `target` (behind its back
    wall, as (5, 5) is in W4): a robot driving from there to there goes in and is trapped."""
    w4 = load_world(WORLDS / "W4.toml")
    turn = math.atan2(target[1] - origin[1], target[0] - origin[0]) - math.atan2(5.0, 5.0)
    c, s = math.cos(turn), math.sin(turn)

    def turned(x: float, y: float) -> tuple[float, float]:
        return target[0] + c * (x - 5.0) - s * (y - 5.0), target[1] + s * (x - 5.0) + c * (y - 5.0)

    pocket = tuple(Polygon(tuple(turned(*p) for p in o.points)) for o in w4.obstacles[:3] if isinstance(o, Polygon))
    return dataclasses.replace(w4, name="W4-trap", obstacles=pocket, source="")


def test_a_trapped_robot_fails_its_moves_cleanly_and_the_mission_ends() -> None:
    """Modele1 plans M2 as start -> (-5, 3) -> (5, 5): with W4's pocket opening towards (-5, 3),
    NDD drives into it and cannot reach (5, 5). Each move fails with why; FTplan replans from
    where the robot stands, and the mission ends, with the goals it could not reach missed."""
    run = timed(run_rover_mission("Robot1", "M2", pocket_facing((5.0, 5.0), (-5.0, 3.0)), seed=0))
    failed = [a for a in run.actions if a.outcome == "failed"]
    assert failed and all(a.task == "MOVE" and a.args[2:] == (5.0, 5.0) for a in failed)
    assert "NO_PROGRESS" in failed[0].why and "trapped" in failed[0].why
    assert all("trapped" in a.why or "overran its planned duration" in a.why for a in failed)
    # Replanning starts where the robot stood, which it reported before each failure.
    assert len(failed) > 1 and all(a.args[:2] != (-5.0, 3.0) for a in failed[1:])
    assert_position_reported_before(run.events, "failed MOVE(")
    measures = measure(run)
    assert not run.result.success and not measures.success
    assert measures.photos.met < measures.photos.asked
    assert not any(goal.startswith("PICTURE(OBJ2, 5, 5)") for goal in run.result.met)
    assert run.events[-1]["kind"] == "mission-end" and run.events[-1]["outcome"] == "failed"
    assert math.hypot(run.final_position[0] - 5.0, run.final_position[1] - 5.0) > 2.0
    print(measures.summary())


# ---------------------------------------------------------------- the executor on hand-made plans


def action(ident: str, task: str, args: tuple, dispatch: float, duration: tuple[float, float]) -> Action:
    return Action(ident, task, args, f"{ident}.start", f"{ident}.end", dispatch, duration, True, True)


def plan_of(*actions: Action, orderings: tuple = ()) -> Plan:
    return Plan("model1", "hand-made", actions, orderings, (), {}, {}, {})


@pytest.fixture
def m1_in_w4() -> PreparedMission:
    return prepare_mission("Robot1", "M1", "W4", seed=0)


def test_concurrent_actions_run_together_and_orderings_are_kept(m1_in_w4: PreparedMission) -> None:
    executor = SimExecutor(m1_in_w4.rover, m1_in_w4.tasks)
    window = m1_in_w4.world.windows[0]
    start = math.ceil(window.start)
    link = action("COMMUNICATE#1", "COMMUNICATE", ("W1",), start, (18.0, 25.0))
    unit = action("MOVE_PAN_TILT_UNIT#2", "MOVE_PAN_TILT_UNIT", ("STRAIGHT", "AT_MY_FEET"), start + 1.0, (2.0, 10.0))
    photo = action("TAKE_PICTURE#3", "TAKE_PICTURE", ("OBJ1", 0.0, 0.0), start + 1.0, (2.0, 6.0))
    reports: list[Report] = []
    outcome = executor.execute(plan_of(link, unit, photo, orderings=(("MOVE_PAN_TILT_UNIT#2.end",
                                                                      "TAKE_PICTURE#3.start", 0.0),)), 0.0,
                               reports.append)
    assert outcome.completed, outcome
    ran = {a.id: a for a in executor.actions}
    assert ran["COMMUNICATE#1"].start == start and ran["MOVE_PAN_TILT_UNIT#2"].start == start + 1.0
    # The photo waited for the pan-tilt unit, not for its own dispatch date ...
    assert ran["TAKE_PICTURE#3"].start == ran["MOVE_PAN_TILT_UNIT#2"].end > start + 1.0
    # ... and the three ran while the antenna transmitted.
    assert ran["TAKE_PICTURE#3"].end < ran["COMMUNICATE#1"].end
    assert [p.target for p in executor.photos if p.ok] == ["M1_OBJ1"]
    assert [(c.window, c.ok, c.link) for c in executor.communications] == [("W1", True, "W1")]
    kinds = [(r.kind, r.name) for r in reports]
    assert kinds.index(("ended", "MOVE_PAN_TILT_UNIT")) < kinds.index(("started", "TAKE_PICTURE"))


def test_an_action_past_its_latest_end_fails_and_is_stopped(m1_in_w4: PreparedMission) -> None:
    executor = SimExecutor(m1_in_w4.rover, m1_in_w4.tasks)
    rushed = action("TAKE_PICTURE#1", "TAKE_PICTURE", ("OBJ1", 0.0, 0.0), 1.0, (0.5, 1.0))  # CAMERA exposes 2 s
    reports: list[Report] = []
    outcome = executor.execute(plan_of(rushed), 0.0, reports.append)
    assert not outcome.completed and outcome.failed_action == "TAKE_PICTURE#1"
    assert "overran its planned duration [0.5, 1] s" in outcome.why
    assert outcome.now == pytest.approx(2.0)
    assert [r.kind for r in reports] == ["started", "failed"] and reports[-1].why == outcome.why
    assert executor.safe_state(outcome.now) >= outcome.now
    camera = m1_in_w4.rover.clients.camera.module
    assert not camera.activities and executor.photos == []  # the exposure was interrupted


def test_a_move_into_w4s_pocket_ends_in_a_failure_not_a_hang(m1_in_w4: PreparedMission) -> None:
    rover = m1_in_w4.rover
    executor = SimExecutor(rover, m1_in_w4.tasks)
    move = action("MOVE#1", "MOVE", (0.0, 0.0, 5.0, 5.0), 0.0, (1.5, 300.0))
    reports: list[Report] = []
    outcome = executor.execute(plan_of(move), 0.0, reports.append)
    assert not outcome.completed
    assert "ndd.GotoTarget(5, 5, 0.3) -> END NO_PROGRESS" in outcome.why and "trapped" in outcome.why
    position, failure = reports[-2], reports[-1]
    assert (position.kind, position.name, failure.kind) == ("report", "ROBOT_POSITION", "failed")
    x, y, _ = rover.sim.pose
    assert math.hypot(x - float(position.args[0]), y - float(position.args[1])) < 0.2  # odometry
    assert 2.4 < (x + y) / math.sqrt(2) < 6.0 and abs(y - x) / math.sqrt(2) < 1.6  # in the pocket
    now = executor.safe_state(outcome.now)
    assert now >= outcome.now and rover.sim.rover.left_speed == rover.sim.rover.right_speed == 0.0
    assert not any(a.state is rt.State.EXEC for a in rover.clients.ndd.module.activities.values())


# ---------------------------------------------------------------- measures


def test_goals_are_judged_on_what_happened_not_on_what_ftplan_believes(
        robot1_m1_w1: tuple[RoverRun, Path, list]) -> None:
    run, _, _ = robot1_m1_w1
    blurred = dataclasses.replace(run, photos=tuple(dataclasses.replace(p, seen=()) for p in run.photos),
                                  path=run.path[:-1] + ((run.path[-1][0], 2.0, 0.0, 0.0),))
    measures = measure(blurred)
    assert measures.photos == GoalCount(3, 0) and measures.home == GoalCount(1, 0)
    assert measures.believed == GoalCount(7, 7) and measures.mu == 1


def sample(configuration: str, mission: str, world: str, photos: int, replannings: int, activity: float) -> Measures:
    return Measures(configuration, mission, world, 0, GoalCount(3, photos), GoalCount(2, 2), GoalCount(1, 1), 0,
                    replannings, activity, 10.0, 300.0, 0, GoalCount(7, 7))


def test_means_and_tables_follow_the_thesis_notation() -> None:
    runs = [sample("Robot1", "M1", "W1", 3, 0, 100.0), sample("Robot1", "M1", "W1", 0, 2, 200.0),
            sample("Robot1", "M2", "W1", 3, 0, 300.0)]
    rows = measure_table(runs)
    assert [(r.configuration, r.mission, r.world, r.runs) for r in rows] == [("Robot1", "M1", "W1", 2),
                                                                            ("Robot1", "M2", "W1", 1)]
    first = rows[0]
    assert first.sigma_p == pytest.approx(0.5) and first.phi_p == pytest.approx(0.5)
    assert first.nu == pytest.approx(0.5) and first.replannings == 1.0 and first.activity_time == 150.0
    overall = aggregate(runs)
    assert (overall.mission, overall.world) == ("*", "W1") and overall.runs == 3
    assert overall.sigma_p == pytest.approx(2 / 3)
    assert measure_table(runs, by=("world",))[0].mission == "*"
    text = markdown_table(rows)
    assert text.splitlines()[0].startswith("| configuration | mission | world | runs | ν |")
    assert "| Robot1 | M1 | W1 | 2 | 50 % | 50 % | 0 % | 0 % | 0 % | 1.00 | 150 | 10.0 |" in text
    assert rich_table(rows).row_count == 2
    assert runs[1].to_json()["sigma_p"] == 0.0 and runs[1].to_json()["mu"] == 1
    with pytest.raises(RunError, match="cannot group runs by seed"):
        measure_table(runs, by=("seed",))


# ---------------------------------------------------------------- the campaign (slow)


@pytest.mark.slow
def test_campaign_m1_m4_in_w1_w3_with_robot1_and_robot1_2() -> None:
    """Seed 004 §4.2.1.1 without faults: Robot1 and Robot1/2 meet every goal in W1-W3, M4's
    second communication included: W2 may close 24 s after it opens (missions.md: [150..152,
    176..178]) and a communication may need 25 s, which Modele1's pseudo-controllable plan risks."""
    measured = []
    for configuration in ("Robot1", "Robot1/2"):
        for mission in ("M1", "M2", "M3", "M4"):
            for world in ("W1", "W2", "W3"):
                run = timed(run_rover_mission(configuration, mission, world, seed=0))
                measures = measure(run)
                measured.append(measures)
                assert measures.photos.sigma == measures.home.sigma == 1.0, measures.summary()
                assert measures.communications == GoalCount(len(run.windows), len(run.windows)), measures.summary()
                assert measures.kappa == 0
    print()
    print(markdown_table(measure_table(measured)))
    print(markdown_table(measure_table(measured, by=("configuration",))))
