"""Hilare's object hunt end to end (seed 000 ch. 5) through the generic runner (specc.run.mission)
and the robot's own extension (examples/hilare/hilare_codels/hunt.py), and the event log
(specc.run.events): real runs of the compiled package on the simulated robot, the §5.5
properties read from the log, determinism, and the log's file format."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import pytest

from specc.run import RunError
from specc.run.events import EventLog, read_events
from specc.run.mission import MissionProgress, MissionRun, load_robot, run_mission
from specc.run.render import last_model, trajectories
from specc.runtime.sim import load_world
from tests.conftest import EXAMPLES, HUNT_SEED, ROOT, hilare

SEED = HUNT_SEED  # its first exploration move has run for 8 s when the camera finds an object (§5.5, t2)
HORIZON = 900.0  # the mission's (system.spec: 15 min)

ROBOT = hilare()  # puts the codels and the extension on sys.path
from hilare_codels import hunt as extension  # noqa: E402  (importable once the robot is loaded)


@pytest.fixture
def hunt(hunt_run: tuple[MissionRun, Path, list[MissionProgress]]) -> tuple[MissionRun, Path, list[MissionProgress]]:
    """One full hunt (5 objects), its log file and its progress reports (conftest's, shared)."""
    return hunt_run


def of_kind(events: Any, *kinds: str) -> list[dict[str, Any]]:
    return [e for e in events if e["kind"] in kinds]


def with_goal(goal: str) -> Any:
    return dataclasses.replace(ROBOT.mission("hunt"), goals=(goal,))


# ---------------------------------------------------------------- the hunt


def test_the_hunt_takes_the_five_objects_of_section_5_6(hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    result, _, reports = hunt
    measures = result.measures()
    assert result.outcome == "succeeded", result.why
    assert measures["objects_wanted"] == 5 and measures["objects_taken"] == 5
    objects = extension.objects(result.events)
    assert sum(1 for o in objects if o.state == "taken") == 5
    assert len(objects) == 10  # §5.6: five of the ten objects in the room
    taken = of_kind(result.events, "object-taken")
    assert [e["taken"] for e in taken] == [1, 2, 3, 4, 5]
    assert len({e["object"] for e in taken}) == 5  # five different objects
    # Each was where VISUAL had seen it: the arm reached for a real object, not a ghost.
    for retrieved in of_kind(result.events, "object-retrieved"):
        assert retrieved["object"] is not None
        assert math.hypot(retrieved["x"] - retrieved["seen_x"], retrieved["y"] - retrieved["seen_y"]) < 0.3
    # TakeObject ends the experiment once @TAKEN = N (§5.4): (EXECUTION END) after the fifth object.
    end = next(e for e in result.events if e["kind"] == "fact" and e["fact"] == "(EXECUTION END)")
    assert end["t"] >= taken[-1]["t"]
    assert of_kind(result.events, "mission-end")[-1]["outcome"] == "succeeded"
    assert 0 < result.simulated_time < 300 and result.distance > 5.0
    assert not of_kind(result.events, "alarm")  # no blocked robot, no executive ERROR, no listener that raised
    # The robot's path and the objects are where the simulator had them.
    first = of_kind(result.events, "pose")[0]
    assert (first["x"], first["y"]) == pytest.approx((1.0, 1.0), abs=1e-3)  # worlds/room.toml's start
    assert trajectories(result.events) and last_model(result.events)[0] is not None
    assert 0.3 < measures["explored_fraction"] <= 1.0
    # Progress reports: in time order, ending with the goal achieved.
    assert [r.time for r in reports] == sorted(r.time for r in reports)
    assert reports[-1] == MissionProgress(result.simulated_time, HORIZON, 1, 1)


def test_every_executive_request_and_reply_is_in_the_log(hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    result, _, _ = hunt
    requests = {e["id"]: e["service"] for e in of_kind(result.events, "request")}
    replies = {e["id"]: e["service"] for e in of_kind(result.events, "reply")}
    assert requests == replies  # every request answered once, for the service asked
    assert sum(result.replies.values()) == len(replies)
    assert {"CALC-GOAL", "TAKE-IMAGE", "SEARCH-OBJ", *extension.TAKE_CYCLE} <= set(requests.values())
    facts = {e["fact"] for e in of_kind(result.events, "fact")}
    assert {"(EXECUTION GO)", "(OBJECTS-WANTED 5)", "(OBJ-FOUND 0)", "(OBJ-FOUND 5)"} <= facts
    times = [e["t"] for e in result.events]
    assert times == sorted(times)


def test_a_detection_interrupts_the_exploration_move_as_in_section_5_5(
        hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    """§5.5 at t2, read straight from the log: SEARCH-OBJ finds an object while the robot drives
    an exploration move; (OBJ-FOUND n) is concluded; the take-object cycle asks for GET-NEAR-OBJ;
    the executive puts the move into INTER; it answers INT; the robot stops."""
    events = list(hunt[0].events)
    executing: set[int] = set()
    moving = take_waits = False
    found = None
    for k, event in enumerate(events):
        kind = event["kind"]
        if kind == "robot-motion":
            moving = event["moving"]
        elif kind == "fact" and event["fact"] == "(EXECUTION GO)":
            take_waits = event["change"] == "concluded"  # TakeObject's first wait for an object
        elif kind == "request" and event["service"] == extension.TAKE_CYCLE[0]:
            take_waits = False
        elif kind == "activity" and event["service"] == extension.EXPLORATION_MOVE:
            (executing.add if event["to"] == "EXEC" else executing.discard)(event["id"])
        elif kind == "reply" and event["service"] == extension.TAKE_CYCLE[-1]:
            take_waits = True  # the cycle is over: it waits for the next object
        elif kind == "reply" and event["service"] == "SEARCH-OBJ" and event["result"] >= 1 \
                and executing and moving and take_waits:
            found = (k, next(iter(executing)))
            break
    assert found is not None, "no object was detected while the robot drove an exploration move"
    start, move = found
    rest = events[start + 1:]

    def first(predicate: Any) -> int:
        return next(i for i, e in enumerate(rest) if predicate(e))

    concluded = first(lambda e: e["kind"] == "fact" and e["fact"].startswith("(OBJ-FOUND ")
                      and e["change"] == "concluded")
    retrieved = first(lambda e: e["kind"] == "request" and e["service"] == "GET-NEAR-OBJ")
    interrupted = first(lambda e: e["kind"] == "activity" and e["id"] == move and e["to"] == "INTER")
    answered = first(lambda e: e["kind"] == "reply" and e["id"] == move)
    stopped = first(lambda e: e["kind"] == "robot-motion" and not e["moving"])
    assert concluded < retrieved < interrupted < answered
    assert rest[answered]["result"] == "INT"
    assert interrupted < stopped <= answered  # the move's INT comes once the robot stands still
    assert rest[interrupted]["t"] - events[start]["t"] < 1.0  # "Le déplacement est interrompu"


def test_the_interruption_check_finds_every_take_and_misses_no_detection(
        hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    report = extension.detection_interruptions(hunt[0].events)
    assert report.missed == ()
    # Each of the five take cycles found the robot exploring and stopped it.
    assert len(report.interruptions) == 5
    for interruption in report.interruptions:
        assert interruption.by in extension.TAKE_CYCLE and interruption.reply == "INT"
        assert interruption.detected_at is not None and interruption.detected_at <= interruption.interrupted_at


def test_the_arm_never_takes_an_object_while_the_robot_moves(
        hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    events = hunt[0].events
    taking = [e for e in of_kind(events, "arm-motion") if e["moving"] and e["service"] == "ARM-OBJ"]
    assert len(taking) == 5  # the arm did move, once per object
    assert len([e for e in of_kind(events, "robot-motion") if e["moving"]]) > 5
    assert extension.arm_motion_overlaps(events) == []
    # Putting the object on the robot is not incompatible with moving (§5.1): §5.5's exploration
    # restarting during the deposit shows up as ARM-BACK overlapping the robot's motion.
    assert extension.arm_motion_overlaps(events, ("ARM-BACK",))


def test_the_checks_see_what_goes_wrong_in_a_log() -> None:
    """The same checks on a log where the arm takes while the robot moves and a detection
    during an exploration move lets the move run to its end."""
    log = EventLog()
    log.emit(0.0, "fact", fact="(EXECUTION GO)", change="concluded")
    move = extension.EXPLORATION_MOVE
    log.emit(1.0, "request", service=move, id=7)
    log.emit(1.0, "activity", service=move, id=7, **{"from": "WAIT"}, to="INIT")
    log.emit(1.0, "activity", service=move, id=7, **{"from": "INIT"}, to="EXEC")
    log.emit(1.1, "robot-motion", moving=True, x=1.0, y=1.0, theta=0.0)
    log.emit(2.0, "reply", service="SEARCH-OBJ", id=9, result=1, detail="")
    log.emit(3.0, "arm-motion", moving=True, service="ARM-OBJ")
    log.emit(4.0, "arm-motion", moving=False, service="ARM-OBJ")
    log.emit(5.0, "reply", service=move, id=7, result="OK", detail="")
    log.emit(5.1, "robot-motion", moving=False, x=3.0, y=1.0, theta=0.0)
    report = extension.detection_interruptions(log.events)
    assert report.interruptions == ()
    assert [(m.detected_at, m.move, m.reply) for m in report.missed] == [(2.0, 7, "OK")]
    overlaps = extension.arm_motion_overlaps(log.events)
    assert [(o.service, o.start, o.end) for o in overlaps] == [("ARM-OBJ", 3.0, 4.0)]
    assert extension.arm_motion_overlaps(log.events, ("ARM-BACK",)) == []


def test_the_same_seed_gives_the_same_event_log(hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    again = run_mission(ROBOT, ROBOT.mission("hunt"), SEED)
    assert again.events == hunt[0].events
    assert (again.simulated_time, again.distance) == (hunt[0].simulated_time, hunt[0].distance)


def test_the_log_file_round_trips(hunt: tuple[MissionRun, Path, list[MissionProgress]]) -> None:
    result, path, _ = hunt
    assert read_events(path) == list(result.events)
    lines = path.read_text(encoding="utf-8").splitlines()
    assert len(lines) == len(result.events)
    first = json.loads(lines[0])
    assert first["kind"] == "mission-start" and first["seed"] == SEED and len(first["objects"]) == 10
    assert first["goals"] == ["!(COLLECT-OBJECTS 5)"] and first["body"]["sonars"] == 32
    assert lines[0] == json.dumps(first, sort_keys=True, separators=(",", ":"))  # keys sorted, compact


def test_objects_lie_where_hilare_can_stand_and_move_with_the_seed() -> None:
    """§5.2.5: the robot's centre goes to the centre of the object's cell, which EXPLOR's calcObj
    refuses unless the robot can stand there."""
    from hilare_codels import visual

    room = load_world(EXAMPLES / "hilare" / "worlds" / "room.toml")
    placed = extension.place_objects(room, 4)
    assert placed.random_objects == 0 and len(placed.objects) == room.random_objects == 10
    standing = set(visual.standing_cells(visual.free_cells(room), room.bounds))
    cells = {int(y // visual.CELL) * visual.NX + int(x // visual.CELL) for x, y in placed.objects}
    assert len(cells) == 10 and cells <= standing
    assert min(math.dist(a, b) for a in placed.objects for b in placed.objects if a != b) >= 0.45
    assert extension.place_objects(room, 4) == placed
    assert extension.place_objects(room, 5).objects != placed.objects


def test_a_ghost_object_fails_the_hunt_although_its_goal_succeeded() -> None:
    """The procedures count objects VISUAL saw; one the gripper never held fails the hunt."""
    events = [{"t": 0.0, "kind": "mission-start", "goals": ["!(COLLECT-OBJECTS 2)"]},
              {"t": 5.0, "kind": "object-taken", "object": 3, "x": 1.0, "y": 1.0, "taken": 1},
              {"t": 6.0, "kind": "alarm", "what": "empty-take", "detail": ""}]
    measures = {"objects_wanted": 2, "objects_taken": 1, "empty_takes": 1}
    outcome, why = extension.judge(events, measures, "succeeded", "every goal achieved (1)")
    assert outcome == "failed" and "1 take cycle(s) found nothing" in why
    assert extension.judge(events, {**measures, "objects_taken": 2}, "succeeded", "")[0] == "succeeded"
    assert extension.judge(events, measures, "horizon", "still running") == ("horizon", "still running")


# ---------------------------------------------------------------- what a user can get wrong


@pytest.mark.parametrize("arguments, fragment", [
    ({"seed": -1}, "seed -1"),
    ({"seed": 1.5}, "seed 1.5"),
    ({"seed": 1, "horizon": 0.0}, "horizon 0.0"),
    ({"seed": 1, "horizon": math.inf}, "horizon inf"),
    ({"seed": 1, "world": "garden"}, "robot 'hilare' has no world 'garden' (its worlds: room"),
])
def test_bad_arguments_are_refused_with_a_reason(arguments: dict[str, Any], fragment: str) -> None:
    with pytest.raises(RunError, match="^" + fragment.replace(".", r"\.").replace("(", r"\(")):
        run_mission(ROBOT, ROBOT.mission("hunt"), **arguments)


def test_a_missing_package_or_codels_say_what_to_do(tmp_path: Path) -> None:
    with pytest.raises(RunError, match="no compiled hilare package"):
        load_robot(tmp_path, EXAMPLES / "hilare", "hilare")
    with pytest.raises(RunError, match="hilare_codels"):
        load_robot(ROOT / "generated", tmp_path, "hilare")


def test_a_short_horizon_ends_the_hunt_without_success() -> None:
    result = run_mission(ROBOT, with_goal("!(COLLECT-OBJECTS 1)"), SEED, horizon=0.5)
    assert result.outcome == "horizon" and result.measures()["objects_taken"] == 0
    assert "0.5 s horizon" in result.why
    assert result.simulated_time == pytest.approx(0.5)


# ---------------------------------------------------------------- the event log


def test_the_event_log_writes_sorted_compact_lines_stamped_with_simulated_time(tmp_path: Path) -> None:
    path = tmp_path / "log" / "events.jsonl"  # the folder is created
    with EventLog(path) as log:
        first = log.emit(1.0000004, "request", service="CALC-GOAL", id=3)
        log.emit(2.5, "reply", service="CALC-GOAL", id=3, result="OK", where=(1.5, 2))
    assert first == {"t": 1.0, "kind": "request", "service": "CALC-GOAL", "id": 3}
    assert path.read_text(encoding="utf-8") == (
        '{"id":3,"kind":"request","service":"CALC-GOAL","t":1.0}\n'
        '{"id":3,"kind":"reply","result":"OK","service":"CALC-GOAL","t":2.5,"where":[1.5,2]}\n')
    assert read_events(path) == log.events  # in memory as a reader gets it back: tuples as lists
    assert log.of_kind("reply") == [log.events[1]]


def test_the_event_log_refuses_what_json_cannot_hold(tmp_path: Path) -> None:
    log = EventLog()
    with pytest.raises(RunError, match="reserved"):
        log.emit(0.0, "request", t=1.0)
    with pytest.raises(RunError, match="cannot be written as JSON"):
        log.emit(0.0, "request", service=object())
    with pytest.raises(RunError, match="cannot be written as JSON"):
        log.emit(0.0, "request", value=math.nan)
    with pytest.raises(RunError, match="finite number"):
        log.emit(math.inf, "request")
    with pytest.raises(RunError, match="non-empty string"):
        log.emit(0.0, "")
    assert log.events == []
    log.close()
    with pytest.raises(RunError, match="closed"):
        log.emit(0.0, "request")
    blocker = tmp_path / "file.txt"
    blocker.write_text("not a folder", encoding="utf-8")
    with pytest.raises(RunError, match="cannot write the event log"):
        EventLog(blocker / "events.jsonl")


def test_reading_a_bad_log_names_the_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.jsonl"
    path.write_text('{"t": 0.0, "kind": "goal"}\n\n{"t": 1.0}\n', encoding="utf-8")
    with pytest.raises(RunError, match=r"bad\.jsonl:3: an event must be a JSON object with a time"):
        read_events(path)
    path.write_text("not json\n", encoding="utf-8")
    with pytest.raises(RunError, match=r"bad\.jsonl:1: not a JSON event"):
        read_events(path)
    with pytest.raises(RunError, match="cannot read the event log"):
        read_events(tmp_path / "missing.jsonl")
    # A last line cut off (no newline: a run killed while writing it): the events before it, and a
    # note, when asked for; a bad line elsewhere, or a cut one without notes, is refused.
    path.write_text('{"t": 0.0, "kind": "goal"}\n{"t": 1.0, "ki', encoding="utf-8")
    notes: list[str] = []
    assert read_events(path, notes) == [{"t": 0.0, "kind": "goal"}]
    assert notes == [f"{path}:2: the last line is cut off (the run was killed while writing it): the 1 event(s) "
                     "before it are kept"]
    with pytest.raises(RunError, match=r"bad\.jsonl:2: not a JSON event"):
        read_events(path)
    path.write_text('{"t": 0.0, "ki\n{"t": 1.0, "kind": "goal"}', encoding="utf-8")
    with pytest.raises(RunError, match=r"bad\.jsonl:1: not a JSON event"):
        read_events(path, [])


# ---------------------------------------------------------------- campaign scale


@pytest.mark.slow
def test_the_hunt_succeeds_over_ten_seeds() -> None:
    results = [run_mission(ROBOT, ROBOT.mission("hunt"), seed) for seed in range(10)]
    rate = sum(r.outcome == "succeeded" for r in results) / len(results)
    wall = sum(r.wall_time for r in results) / len(results)
    print(f"\nhunt success rate over seeds 0-9: {rate:.0%} ({wall:.1f} s wall per hunt); "
          + ", ".join(f"{r.seed}: {r.outcome} {r.simulated_time:.0f} s" for r in results))
    assert rate >= 0.9, [r.why for r in results if r.outcome != "succeeded"]
    for result in results:
        assert extension.arm_motion_overlaps(result.events) == [], result.seed
        assert extension.detection_interruptions(result.events).missed == (), result.seed
