"""Waypoints (#25, plan quality): where a plan keeps the robot waiting (for a window to open, for
a communication to end), the improvement splits the next move so that the robot goes part of the
way during the wait. Shown on a cart of this file's own (nothing of the rover), then on the
rover's M2 with Modele1, where the planner grounding every coordinate (Aries) found shorter plans
by stopping half-way. Every plan is checked by the independent validator."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest

from specc.runtime.planner import Planner, PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner import waypoints as wp
from specc.runtime.planner.plan import Action, Plan
from specc.runtime.planner.validate import validate
from tests.atrv import ATRV, atrv_models
from tests.test_planner import from_text

# A cart on a rail: it must radio a report while still, inside a window that opens at 30-31 s and
# closes at 60-61 s (a report takes 20-25 s, so it starts by 35 s at the latest), and end at 20 m.
# Driving 20 m takes up to 40 s: the cart cannot get there before the report, so the first plan
# radios from the start and drives afterwards, idle until the window opens.
CART = """
domain cart {
  attribute POS() { ?value in [-100, 100]; }
  attribute STATUS() { ?value in {STILL, MOVING}; }
  attribute WINDOW() { ?value in {OUT, IN}; }
  attribute SENT() { ?value in {NO, YES}; }
  task DRIVE(?a, ?b) (t_start, t_end) {
    ?a in [-100, 100];
    ?b in [-100, 100];
    event(POS(): (?a, 1000), t_start);
    hold(POS(): 1000, (t_start, t_end));
    event(POS(): (1000, ?b), t_end);
    event(STATUS(): (STILL, MOVING), t_start);
    hold(STATUS(): MOVING, (t_start, t_end));
    event(STATUS(): (MOVING, STILL), t_end);
    variable ?d;
    ?d =. abs(?b - ?a);
    variable ?speed;
    ?speed in [0.5, 1];
    variable ?duration;
    ?duration in [1, +oo];
    ?d =. ?speed *. ?duration;
    contingent ?duration =. t_end - t_start;
  } latePreemptive
  task SEND() (t_start, t_end) {
    hold(WINDOW(): IN, (t_start, t_end));
    hold(STATUS(): STILL, (t_start, t_end));
    event(SENT(): (NO, YES), t_end);
    contingent (t_end - t_start) in [20, 25];
  } nonPreemptive
}
problem report for cart {
  timepoint t_open, t_close, t_sent, t_there;
  explained event(POS(): (1000, 0), t_start);
  explained event(STATUS(): (MOVING, STILL), t_start);
  explained event(SENT(): (YES, NO), t_start);
  explained event(WINDOW(): (IN, OUT), t_start);
  contingent event(WINDOW(): (OUT, IN), t_open);
  contingent event(WINDOW(): (IN, OUT), t_close);
  (t_open - t_start) in [30, 31];
  (t_close - t_start) in [60, 61];
  t_open < t_close;
  hold(SENT(): YES, (t_sent, t_end)) goal(2, 0);
  hold(POS(): 20, (t_there, t_end)) goal(1, 0);
  (t_end - t_start) in [0, 200];
}
"""


@cache
def cart() -> tuple[pm.PlanningDomain, pm.Problem]:
    return from_text(CART)


def checked(domain: pm.PlanningDomain, problem: pm.Problem, result: PlanResult) -> Plan:
    assert result.plan is not None, result.reason
    assert validate(domain, problem, result.plan, dropped_lines={g.line for g in result.dropped}) == []
    return result.plan


def test_a_mover_is_any_task_taking_an_attribute_from_a_parameter_to_another() -> None:
    domain, _ = cart()
    found = wp.movers(domain)
    assert set(found) == {"DRIVE"}
    assert found["DRIVE"].pairs == (("POS", 0, 1),)
    assert found["DRIVE"].changes == {"POS", "STATUS"}
    rover, _ = atrv_models("M1_model1")
    # Modele1's MOVE; not its pan-tilt unit's move, whose duration no position changes.
    assert {name: m.pairs for name, m in wp.movers(rover).items()} == {
        "MOVE": (("AT_ROBOT_X", 0, 2), ("AT_ROBOT_Y", 1, 3))}
    symbolic, _ = atrv_models("M1_model2")
    assert {name: m.pairs for name, m in wp.movers(symbolic).items()} == {
        "MOVE_NOMINAL": (("FRAME_POS", 0, 1),), "MOVE_RECOV": (("FRAME_POS", 0, 1),)}


def test_one_event_from_a_parameter_to_another_makes_a_mover_when_the_distance_sets_the_duration() -> None:
    def hop(duration: str) -> pm.Task:
        domain, _ = from_text(f"""
            domain hops {{
              attribute AT() {{ ?value in [0, 100]; }}
              task HOP(?from, ?to) (t_start, t_end) {{
                ?from in [0, 100];
                ?to in [0, 100];
                event(AT(): (?from, ?to), t_end);
                {duration}
              }} nonPreemptive
            }}
            problem stay for hops {{
              explained event(AT(): (1, 0), t_start);
              (t_end - t_start) in [0, 100];
            }}""")
        return domain

    assert wp.movers(hop("contingent (t_end - t_start) =. abs(?to -. ?from);"))["HOP"].pairs == (("AT", 0, 1),)
    assert wp.movers(hop("contingent (t_end - t_start) in [3, 80];")) == {}


def test_the_cart_drives_part_of_the_way_before_the_window_and_the_rest_after() -> None:
    domain, problem = cart()
    first = checked(domain, problem, Planner(domain, exact=False).plan(problem))
    (drive,) = [a for a in first.actions if a.task == "DRIVE"]
    (send,) = [a for a in first.actions if a.task == "SEND"]
    assert drive.args == (0.0, 20.0) and drive.dispatch >= first.ends_by(send) - 1e-6  # radios, then drives

    result = Planner(domain, exact=False, improve=2000).plan(problem)
    improved = checked(domain, problem, result)
    legs = sorted((a for a in improved.actions if a.task == "DRIVE"), key=lambda a: a.dispatch)
    (send,) = [a for a in improved.actions if a.task == "SEND"]
    assert [len(legs), legs[0].args[0], legs[-1].args[1]] == [2, 0.0, 20.0]
    waypoint = legs[0].args[1]
    assert isinstance(waypoint, float) and 0 < waypoint < 20 and legs[1].args[0] == waypoint
    # The first leg ends before the report starts, the second starts once it has ended.
    assert improved.ends_by(legs[0]) <= send.dispatch + 1e-6
    assert legs[1].dispatch >= improved.ends_by(send) - 1e-6
    assert improved.makespan < first.makespan - 1
    assert any("(waypoints)" in note for note in result.notes)


def test_rover_m2_stops_half_way_where_it_would_wait_and_ends_sooner() -> None:
    domain, problem = atrv_models("M2_model1")
    first = checked(domain, problem, Planner(domain, improve=0).plan(problem))
    improved = checked(domain, problem, Planner(domain, improve=3000).plan(problem))
    assert improved.makespan < first.makespan - 1
    photos = {(float(a.args[1]), float(a.args[2])) for a in improved.actions if a.task == "TAKE_PICTURE"}
    stops = {(float(a.args[2]), float(a.args[3])) for a in improved.actions if a.task == "MOVE"}
    assert stops - photos - {(0.0, 0.0)}, "no move ends at a point no goal names"


def action(name: str, task: str, start: float, end: float, *args: float | str) -> Action:
    return Action(name, task, args, f"{name}.s", f"{name}.e", start, (end - start, end - start), False, False)


def test_the_idle_time_is_the_longest_stretch_with_nothing_running_since_the_last_move() -> None:
    actions = (action("M#1", "MOVE", 0, 10), action("P#1", "LOOK", 10, 20), action("R#1", "SEND", 30, 40),
               action("M#2", "MOVE", 45, 50))
    plan = Plan("d", "p", actions, (), (), {}, {}, {})
    assert wp.idle_time(plan, actions[-1]) == pytest.approx(10.0)  # 20 to 30: 5 s from 40 to 45 is shorter
    assert wp.idle_time(plan, actions[0]) == 0.0
    # A report begun during the first move and still running after it: the robot is busy until 40.
    overlapping = (action("M#1", "MOVE", 0, 10), action("R#1", "SEND", 5, 40), action("M#2", "MOVE", 45, 50))
    assert wp.idle_time(Plan("d", "p", overlapping, (), (), {}, {}, {}), overlapping[-1]) == pytest.approx(5.0)


def test_waypoints_are_tried_farthest_first_and_never_at_either_end() -> None:
    domain, _ = cart()
    mover = wp.movers(domain)["DRIVE"]
    move = action("D#1", "DRIVE", 0, 10, 0.0, 5.0)
    points = wp.candidates(move, mover, {"POS": {0.0, 5.0, 2.5}})
    assert points == [(4.0,), (3.0,), (2.5,), (2.0,), (1.0,)]
    # A long move tries at most STEPS whole numbers (and the places the plan reaches).
    far = wp.candidates(action("D#2", "DRIVE", 0, 10, 0.0, 1000.0), mover, {"POS": {0.0, 1000.0, 333.0}})
    assert len(far) <= wp.STEPS + 1 and (333.0,) in far
    assert [p[0] for p in far] == sorted((p[0] for p in far), reverse=True)


def test_a_first_leg_longer_than_the_idle_time_is_not_searched() -> None:
    domain, _ = cart()
    mover = wp.movers(domain)["DRIVE"]
    move = action("D#1", "DRIVE", 0, 10, 0.0, 20.0)
    # 15 m take up to 30 s at 0.5 m/s: they fit in 31 s, not in 29 s.
    assert wp.first_leg_fits(move, mover, (15.0,), 31.0)
    assert not wp.first_leg_fits(move, mover, (15.0,), 29.0)


def test_a_waypoint_driven_through_without_a_stop_is_found_for_merging() -> None:
    domain, _ = cart()
    movers = wp.movers(domain)
    legs = (action("D#1", "DRIVE", 0, 10, 0.0, 5.0), action("D#2", "DRIVE", 10, 40, 5.0, 20.0))
    through = Plan("cart", "report", legs, (), (), {}, {}, {})
    assert [(a.id, b.id) for a, b, _ in wp.drive_throughs(through, movers)] == [("D#1", "D#2")]
    merged = wp.merge(through, *legs, movers["DRIVE"])
    (whole,) = merged.actions
    assert whole.args == (0.0, 20.0)
    # The report starts while the cart drives to 5 m, and the cart leaves once it is sent: a stop.
    waiting = (action("D#1", "DRIVE", 0, 10, 0.0, 5.0), action("S#1", "SEND", 8, 33),
               action("D#2", "DRIVE", 33, 63, 5.0, 20.0))
    assert wp.drive_throughs(Plan("cart", "report", waiting, (), (), {}, {}, {}), movers) == []
    # There and back is no drive-through: merged, it would be a move that goes nowhere.
    back = (action("D#1", "DRIVE", 0, 10, 0.0, 5.0), action("D#2", "DRIVE", 10, 20, 5.0, 0.0))
    assert wp.drive_throughs(Plan("cart", "report", back, (), (), {}, {}, {}), movers) == []


def test_no_improved_rover_plan_drives_through_a_waypoint() -> None:
    domain, problem = atrv_models("M1_model1")
    improved = checked(domain, problem, Planner(domain, improve=3000).plan(problem))
    assert wp.drive_throughs(improved, wp.movers(domain)) == []


def test_a_rover_planning_with_improvement_carries_out_its_waypoints_in_the_simulator(tmp_path: Path) -> None:
    # The rover's FTplan with `improve: 300;` on its first planner: M2's plan stops at (2, 5),
    # a point no goal names, to communicate during W1, and the simulated rover drives there and
    # meets every goal.
    robot = tmp_path / "atrv"
    shutil.copytree(ATRV, robot)
    spec = robot / "ftplan.spec"
    text = spec.read_text(encoding="utf-8")
    first = "  planner p1 {\n    domain: model1;\n"
    assert first in text
    spec.write_text(text.replace(first, first + "    improve: 300;\n"), encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "specc.cli", "run", str(robot), "--mission", "M2", "--world", "W1",
                           "--config", "Robot1", "-g", str(tmp_path / "generated"), "--runs", str(tmp_path / "runs"),
                           "--no-pictures", "-q"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    (log,) = (tmp_path / "runs").glob("*/events.jsonl")
    events = [json.loads(line) for line in log.read_text(encoding="utf-8").splitlines()]
    started = [e["text"] for e in events if e["kind"] == "ftplan" and e.get("text", "").startswith("started MOVE(")]
    assert "started MOVE(-5, 3, 2, 5)" in started and "started MOVE(2, 5, 5, 5)" in started
    (end,) = [e for e in events if e["kind"] == "mission-end"]
    assert end["outcome"] == "succeeded", end
