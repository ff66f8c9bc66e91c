"""The pictures of a run drawn from its event log alone (specc.run.render, issue #9's run folder and
`specc replay`): what the pure readers extract from real logs agrees with what the runners kept
(actions, activities, objects, path, model), logs cut short still draw, logs that cannot be drawn
say why in one line, and `render_run` writes exactly the PNGs it returns."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest

from specc.run import RunError
from specc.run.mission import MissionRun, check_mission, load_robot, run_mission
from specc.run.render import (
    MAP,
    STATE,
    TIMELINE,
    action_bars,
    draw_map,
    ftplan_marks,
    last_model,
    logged_objects,
    motion_stretches,
    path_of,
    plan_starts,
    render_run,
    reply_outcome,
    run_info,
    run_world,
    scene_of,
    service_bars,
    trajectories,
)
from tests.conftest import EXAMPLES, ROOT, is_png

POSE_TOLERANCE = 0.03  # m between a pose event and the simulator's trace at the same instant


@pytest.fixture
def hunt(hunt_run: tuple[MissionRun, Path, list]) -> MissionRun:
    return hunt_run[0]


@pytest.fixture(scope="module")
def robot() -> Any:
    return load_robot(ROOT / "generated", EXAMPLES / "atrv", "atrv")


@pytest.fixture(scope="module")
def rover(robot: Any) -> MissionRun:
    """A mission with failures and replanning: three moves overrun their bound in W3's clutter."""
    return run_mission(robot, robot.mission("M3"), 0, world="W3", configuration="Robot1/2c")



def cut(events: Sequence[Mapping[str, Any]], keep: Any) -> list[Mapping[str, Any]]:
    """The log up to (not including) the first event for which `keep` is false."""
    kept = []
    for event in events:
        if not keep(event):
            break
        kept.append(event)
    return kept


# ---------------------------------------------------------------- the rover


def test_the_gantt_bars_are_the_actions_ftplan_heard_of(rover: MissionRun) -> None:
    """The executor's `action` events and FTplan's own journal (its reports) are two records of
    the same actions: the bars drawn from the first agree with the second."""
    bars = action_bars(rover.events)
    assert {b.outcome for b in bars} >= {"ended", "failed"}  # the log exercises both
    heard = [(e["t"], e["text"]) for e in rover.events if e["kind"] == "ftplan" and e["event"] == "report"
             and e["text"].split()[0] in ("started", "ended", "failed")]
    for bar in bars:
        assert (pytest.approx(bar.start, abs=1e-6), f"started {bar.text()}") in heard
        if bar.outcome in ("ended", "failed"):
            said = next(text for t, text in heard if t == pytest.approx(bar.end, abs=1e-6)
                        and text.startswith(f"{bar.outcome} {bar.text()}"))
            assert said
        assert bar.latest_end is not None and bar.latest_end >= bar.start
    # A move failed by overrunning its planned bound: its bar reaches that bound.
    overran = [b for b in bars if b.outcome == "failed" and "overran" in b.why]
    assert overran and all(b.end >= b.latest_end - 0.5 for b in overran if b.latest_end is not None)
    # The timeline's rows are what carried the actions out: the procedures' goals.
    assert {b.kind for b in bars} >= {"MOVE-TO", "PHOTOGRAPH", "TRANSMIT"}


def test_each_plan_and_ftplan_event_is_on_the_timeline(rover: MissionRun) -> None:
    bars = action_bars(rover.events)
    starts = plan_starts(rover.events)
    assert [s.number for s in starts] == sorted({b.plan for b in bars})
    for start in starts:
        first = min(b.start for b in bars if b.plan == start.number)
        assert start.time <= first + 1e-6
    marks = ftplan_marks(rover.events)
    failed = [b for b in bars if b.outcome == "failed"]
    assert [m.time for m in marks if m.event == "action-failed"] == pytest.approx([b.end for b in failed])
    assert not {"report", "execute"} & {m.event for m in marks}  # the actions and plan lines say those


def test_a_planner_switch_is_where_another_planner_s_plan_starts() -> None:
    events = [{"t": t, "kind": "ftplan", "event": "execute", "planner": p, "text": ""}
              for t, p in ((1.0, "p1"), (50.0, "p1"), (80.0, "p2"), (90.0, "p2"))]
    starts = plan_starts(events)
    assert [(s.number, s.planner, s.switched_from) for s in starts] == \
        [(1, "p1", ""), (2, "p1", ""), (3, "p2", "p1"), (4, "p2", "")]


def test_the_path_from_pose_events_passes_where_the_robot_stopped_and_started(rover: MissionRun) -> None:
    """`pose` events sample the simulator's true pose every 0.5 s; `robot-motion` events note it
    where the robot starts or stops: between them the sampled path is still."""
    poses = path_of(rover.events)
    assert len(poses) > 100 and poses[0, 0] == 0.0 and poses[-1, 0] <= rover.simulated_time
    stops = [e for e in rover.events if e["kind"] == "robot-motion" and not e["moving"]]
    assert stops
    for stop in stops:
        after = [row for row in poses if stop["t"] <= row[0] <= stop["t"] + 1.0]
        for _, x, y, _ in after:
            assert math.dist((x, y), (stop["x"], stop["y"])) < POSE_TOLERANCE, stop


def test_the_rover_run_folder_holds_its_map_and_timeline(robot: Any, rover: MissionRun, tmp_path: Path) -> None:
    folder = tmp_path / "run"
    written = render_run(rover.events, folder)
    assert written == [folder / MAP, folder / TIMELINE]
    assert sorted(folder.iterdir()) == sorted(written) and all(is_png(p) for p in written)
    world = run_world(rover.events)
    # The windows drawn are those the rover's extension draws for M3 with seed 0.
    check = check_mission(robot, robot.mission("M3"), "W3", 0, None, "Robot1/2c")
    windows = robot.extension.mission_windows(check.planning.problem, 0)
    assert world.name == "W3" and world.windows == windows and len(windows) == 3
    info = run_info(rover.events)
    assert (info.configuration, info.mission, info.world, info.seed, info.outcome) == \
        ("Robot1/2c", "M3", "W3", 0, "succeeded")
    with pytest.raises(RunError, match="must end in .png"):
        draw_map(rover.events, tmp_path / "m3w3.jpg")


def test_a_failure_reason_of_a_page_keeps_the_pictures_title_to_three_lines() -> None:
    from specc.run.render import RunInfo

    why = "; ".join(f"goal {k} given up: no plan within 300 partial plans (a larger search budget may find one)"
                    for k in range(20))
    title = RunInfo("scout", "Robot1/2", "morning", "orchard", 0, "failed", why, 500.0).title()
    lines = title.splitlines()
    assert len(lines) == 3 and lines[0].startswith("scout Robot1/2, mission morning")
    assert lines[-1].endswith("(the whole of it: report.json)")
    short = RunInfo("scout", "", "morning", "orchard", 0, "succeeded", "every goal met", 500.0).title()
    assert short == "scout, mission morning, world orchard, seed 0 — succeeded: every goal met"


def test_a_rover_log_cut_inside_an_action_still_draws(rover: MissionRun, tmp_path: Path) -> None:
    failing = next(b for b in action_bars(rover.events) if b.outcome == "failed")
    middle = (failing.start + failing.end) / 2
    events = cut(rover.events, lambda e: e["t"] <= middle)
    bars = action_bars(events)
    assert bars[-1].outcome == "running" and bars[-1].id == failing.id and bars[-1].end == events[-1]["t"]
    assert all(b.outcome != "running" for b in bars[:-1])
    assert "no mission-end" in run_info(events).title()
    written = render_run(events, tmp_path / "cut")
    assert [p.name for p in written] == [MAP, TIMELINE] and all(is_png(p) for p in written)


# ---------------------------------------------------------------- the hunt


def test_the_objects_states_from_the_log_are_the_hunt_s(hunt: MissionRun) -> None:
    objects = logged_objects(hunt.events)
    start = hunt.events[0]
    assert [(o.x, o.y) for o in objects] == [tuple(xy) for xy in start["objects"]]
    taken = [e["object"] for e in hunt.events if e["kind"] == "object-taken"]
    assert sorted(o.index for o in objects if o.state == "taken") == sorted(taken)
    assert {o.state for o in objects} >= {"taken", "undetected"}


def test_the_service_bars_pair_each_request_with_its_reply(hunt: MissionRun) -> None:
    bars = service_bars(hunt.events)
    requests = [e for e in hunt.events if e["kind"] == "request"]
    replies = {e["id"]: e for e in hunt.events if e["kind"] == "reply"}
    assert [(b.service, b.id, b.requested) for b in bars] == [(e["service"], e["id"], e["t"]) for e in requests]
    for bar in bars:
        reply = replies[bar.id]
        assert bar.ended == reply["t"] and bar.result == reply["result"]
        assert bar.outcome == reply_outcome(reply) and (bar.outcome == "ok") == reply["ok"]
        assert bar.started is None or bar.requested <= bar.started <= bar.ended
    outcomes = {(b.service, b.outcome) for b in bars}
    assert ("SEARCH-OBJ", "ok") in outcomes  # a count of objects seen is a success
    assert ("EXEC-TRAJ-GOAL", "interrupted") in outcomes  # §5.5: a detection stops the exploration move


def reply(result: Any, **ok: bool) -> dict[str, Any]:
    return {"t": 3.0, "kind": "reply", "service": "PROBE", "id": 1, "result": result, "detail": "", **ok}


def test_a_service_whose_output_function_returns_a_word_succeeded() -> None:
    """The executive's `ok` tells a success from a failure, not the result's word: an output
    function may return HEAVY, or even TIMEOUT, for a service that ended well."""
    events = [{"t": 1.0, "kind": "request", "service": "PROBE", "id": 1, "request": "probe.Weigh"},
              {"t": 1.0, "kind": "activity", "service": "PROBE", "id": 1, "from": "WAIT", "to": "INIT"},
              {"t": 2.0, "kind": "activity", "service": "PROBE", "id": 1, "from": "INIT", "to": "EXEC"},
              reply("HEAVY", ok=True),
              {"t": 3.0, "kind": "activity", "service": "PROBE", "id": 1, "from": "EXEC", "to": "ETHER"}]
    [bar] = service_bars(events)
    assert (bar.result, bar.outcome) == ("HEAVY", "ok")
    assert reply_outcome(reply("TIMEOUT", ok=True)) == "ok"
    assert reply_outcome(reply("OK", ok=False)) == reply_outcome(reply("BLOCKED", ok=False)) == "failed"
    assert reply_outcome(reply("INT", ok=False)) == "interrupted"
    # A log written before replies said `ok`: OK or a count is all there is to go by.
    assert reply_outcome(reply("OK")) == reply_outcome(reply(2)) == "ok"
    assert reply_outcome(reply("INT")) == "interrupted" and reply_outcome(reply("TIMEOUT")) == "failed"


def test_motions_alternate_and_the_arm_moves_for_its_services(hunt: MissionRun) -> None:
    robot = motion_stretches(hunt.events, "robot-motion")
    assert robot and all(a.end <= b.start for a, b in zip(robot, robot[1:], strict=False))
    arm = motion_stretches(hunt.events, "arm-motion")
    assert {s.label for s in arm} == {"ARM-OBJ", "ARM-BACK"}


def test_the_map_shows_the_model_and_trajectories_the_hunt_ended_with(hunt: MissionRun) -> None:
    certainty, goal = last_model(hunt.events)
    model = [e for e in hunt.events if e["kind"] == "model"][-1]
    assert certainty is not None and (certainty.cell, certainty.nx, certainty.ny) == (
        model["certainty"]["cell"], model["certainty"]["nx"], model["certainty"]["ny"])
    assert certainty.grid().shape == (certainty.ny, certainty.nx) and 0.0 <= certainty.grid().min()
    assert goal == tuple(model["goal"])
    planned = [e["points"] for e in hunt.events if e["kind"] == "trajectory"]
    assert trajectories(hunt.events) == tuple(tuple(tuple(p) for p in points) for points in planned) and planned
    scene = scene_of(hunt.events)
    objects = logged_objects(hunt.events)
    assert scene.object_states == tuple(o.state for o in objects)
    assert scene.taken_order == tuple(sorted((o.index for o in objects if o.taken_at is not None),
                                             key=lambda k: objects[k].taken_at or 0.0))
    assert scene.robot.radius == 0.35 and scene.robot.sonars == 32  # the body the log carries
    assert any(mark.points for mark in scene.marks if "interrupted" in mark.label)


def test_the_hunt_run_folder_holds_map_timeline_and_state(hunt: MissionRun, tmp_path: Path) -> None:
    folder = tmp_path / "hunt"
    written = render_run(hunt.events, folder)
    assert written == [folder / MAP, folder / TIMELINE, folder / STATE]
    assert sorted(folder.iterdir()) == sorted(written) and all(is_png(p) for p in written)


def test_a_hunt_log_cut_in_the_middle_still_draws(hunt: MissionRun, tmp_path: Path) -> None:
    events = list(hunt.events[: len(hunt.events) // 2])
    assert not any(e["kind"] in ("mission-end", "model") for e in events)
    assert last_model(events) == (None, None)
    open_bars = [b for b in service_bars(events) if b.outcome == "running"]
    assert open_bars and all(b.ended == events[-1]["t"] for b in open_bars)
    states = [o.state for o in logged_objects(events)]
    assert states.count("taken") < 5
    # No model yet, so no state of Fig 5.11 to draw.
    written = render_run(events, tmp_path / "cut")
    assert [p.name for p in written] == [MAP, TIMELINE] and all(is_png(p) for p in written)
    # Cut right after its first line: the room, the objects where they lie, empty rows.
    written = render_run(hunt.events[:1], tmp_path / "start")
    assert [p.name for p in written] == [MAP, TIMELINE] and all(is_png(p) for p in written)


# ---------------------------------------------------------------- logs that cannot be drawn


def test_a_log_without_mission_start_cannot_be_drawn(hunt: MissionRun, tmp_path: Path) -> None:
    headless = [e for e in hunt.events if e["kind"] != "mission-start"]
    with pytest.raises(RunError, match="no mission-start") as error:
        render_run(headless, tmp_path / "none")
    assert "\n" not in str(error.value)
    assert not (tmp_path / "none").exists()


def test_a_log_without_the_world_or_the_body_cannot_be_drawn(hunt: MissionRun, tmp_path: Path) -> None:
    start = {k: v for k, v in hunt.events[0].items() if k != "world_data"}
    with pytest.raises(RunError, match="no world_data"):
        render_run([start, *hunt.events[1:]], tmp_path / "old")
    bodiless = {k: v for k, v in hunt.events[0].items() if k != "body"}
    with pytest.raises(RunError, match="no body"):
        render_run([bodiless, *hunt.events[1:]], tmp_path / "bodiless")
    broken = {**hunt.events[0], "world_data": {"room": {"width": -1, "height": 2}}}
    with pytest.raises(RunError, match="positive"):
        render_run([broken, *hunt.events[1:]], tmp_path / "broken")
    assert not list(tmp_path.iterdir())
    # An event edited by hand: the message names what is wrong, in one line.
    edited = [{k: v for k, v in e.items() if k != "y"} if e["kind"] == "pose" else e for e in hunt.events]
    with pytest.raises(RunError, match="the log cannot be drawn.*KeyError.*'y'") as error:
        render_run(edited, tmp_path / "edited")
    assert "\n" not in str(error.value)


def test_the_reflexes_that_fired_have_their_row_on_the_timeline(hunt: MissionRun, tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    from specc.run import pictures
    from specc.run.render import draw_service_timeline

    rows: list[list[str]] = []
    real = pictures.save

    def save(figure: Any, path: Any) -> Path:
        rows.append([label.get_text() for label in figure.axes[0].get_yticklabels()])
        return real(figure, path)

    monkeypatch.setattr(pictures, "save", save)
    draw_service_timeline(list(hunt.events), tmp_path / "plain.png")
    fired = {"t": 5.0, "kind": "reflex", "reflex": "stop", "on": "reply us.watchObstacle", "code": "OBSTACLE",
             "actions": ["request loco.Stop"]}
    draw_service_timeline([*hunt.events, fired], tmp_path / "reflex.png")
    had_reflexes = any(e["kind"] == "reflex" for e in hunt.events)
    assert ("reflexes" in rows[0]) == had_reflexes and "reflexes" in rows[1]
    assert rows[1].index("reflexes") == rows[1].index("alarms") - 1


def test_a_box_footprint_is_drawn_to_its_whole_extent_with_its_front_marked() -> None:
    """The picture's outline reaches the box's four corners (where it hits things), turned with its
    heading; the front is marked by a notch cut inward, not by cutting the corners off."""
    from specc.runtime.body import RobotConfig
    from specc.runtime.sim.render import outline

    box = RobotConfig(length=0.9, width=0.6)
    points = outline(box, (1.0, 2.0, 0.0))
    assert points[:, 0].min() == pytest.approx(0.55) and points[:, 0].max() == pytest.approx(1.45)
    assert points[:, 1].min() == pytest.approx(1.7) and points[:, 1].max() == pytest.approx(2.3)
    front = points[points[:, 0] < 1.45 - 1e-9]  # the notch's inner point lies behind the front edge
    assert any(abs(y - 2.0) < 1e-9 and x > 1.0 for x, y in front)
    turned = outline(box, (0.0, 0.0, math.pi / 2))  # facing +y: the length lies along y
    assert turned[:, 1].max() == pytest.approx(0.45) and turned[:, 0].max() == pytest.approx(0.3)


def test_a_goal_failed_by_a_fail_statement_is_said_to_fail_there() -> None:
    """`fail;` leaves no "... failed: why" line of its own: the run's reason names the statement,
    not only the top-level "every applicable KA failed"."""
    from specc.run.mission import why_failed
    from specc.runtime.procedures import KA, Compound, Fail, Goal, If, Library, Step
    from specc.runtime.supervisor import Supervisor

    keep = KA(name="Keep", invocation=Goal("!", Compound("KEEP")), line=2,
              body=(If(Goal("?", Compound("Q"), 3), (Step(Goal("=>", Compound("P"), 4)),), (Fail(5),), 3),))
    supervisor = Supervisor(Library("tasks", kas=(keep,)))
    intention = supervisor.post("!(KEEP)")
    supervisor.run()
    assert intention.status == "failed" and why_failed(intention.trace, []) == "Keep:5: fail"


def test_a_table_lists_each_run_that_did_not_succeed_with_its_outcome(tmp_path: Path) -> None:
    """A run stopped at the horizon is not a mission that failed: the table says which it was."""
    from specc.run.session import RunOutcome
    from specc.run.sweep import SweepResult, mission_rows

    def outcome(name: str, ended: str, why: str) -> RunOutcome:
        return RunOutcome(tmp_path / name, "cart", {"outcome": ended, "why": why, "mission": "m", "world": "w",
                                                    "simulated_time": 10.0}, "")

    runs = [outcome("cart-m-w-s0", "succeeded", "every goal achieved (1)"),
            outcome("cart-m-w-s1", "horizon", "!(GO 1 2) still running at the 60 s horizon"),
            outcome("cart-m-w-s2", "failed", "!(GO 1 2) failed: Go:3: ?(= $R OK)")]
    result = SweepResult("cart", runs, missions=mission_rows(runs))
    assert [(f.name, f.outcome) for f in result.failures] == [("cart-m-w-s1", "horizon"), ("cart-m-w-s2", "failed")]
    text = result.markdown()
    assert "- cart-m-w-s1 (horizon): !(GO 1 2) still running at the 60 s horizon\n" in text
    assert "- cart-m-w-s2 (failed): !(GO 1 2) failed: Go:3: ?(= $R OK)\n" in text


def test_a_goal_still_running_at_the_horizon_says_what_it_waited_on() -> None:
    """A ZOMBIE the procedures never interrupted holds its request without a final reply: the
    horizon's reason names it, in the phase its activity last entered, and since when."""
    from specc.run.mission import waiting_on

    events = [{"kind": "request", "id": 1, "service": "GOTO", "t": 0.0},
              {"kind": "activity", "id": 1, "service": "GOTO", "from": "INIT", "to": "EXEC", "t": 0.0},
              {"kind": "reply", "id": 1, "service": "GOTO", "result": "OK", "t": 9.0},
              {"kind": "request", "id": 2, "service": "OPEN-DRAWER", "t": 9.5},
              {"kind": "activity", "id": 2, "service": "OPEN-DRAWER", "from": "EXEC", "to": "ZOMBIE", "t": 14.0}]
    assert waiting_on(events) == "; waiting on OPEN-DRAWER (id 2) in ZOMBIE since 14.0 s"
    assert waiting_on(events[:3]) == ""
    # A request the controller never let start stays in WAIT, its first phase, which only its
    # `request` event shows.
    assert waiting_on(events[:4]) == "; waiting on OPEN-DRAWER (id 2) in WAIT since 9.5 s"
