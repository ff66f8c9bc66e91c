"""The independent plan validator on hand-built plans for mission M1 (seed 004, annex A): a
strongly controllable valid plan for Modele1 and one for Modele2 pass, and each hand-broken copy
is rejected with a message naming the faulty action or goal."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import pytest

from specc.runtime.planner.model import Interval, Member, Num, Op, PlanningDomain, Problem, Resource, Task, Time, Use
from specc.runtime.planner.plan import Action, Plan, Value
from specc.runtime.planner.validate import check_task, validate
from tests.atrv import atrv_models

# Claimed duration ranges: MOVE is (|dx| + |dy|) * [0.7, 1] / [0.17, 0.35] m/s in Modele1; Modele2's
# MOVE_NOMINAL is the table distance (O1->O2 6 m, O2->O3 5.16 m, O3->O1 6.24 m) / [0.17, 0.35] m/s.
PAN_TILT = (2.0, 10.0)
PICTURE = (2.0, 6.0)
COMMUNICATION = (18.0, 25.0)
MOVE_4M = (8.0, 23.53)  # 4 * 0.7 / 0.35 .. 4 / 0.17
MOVE_6M = (12.0, 35.3)  # 6 * 0.7 / 0.35 .. 6 / 0.17

# The reference plan for M1 / Modele1: (number, task, args, dispatch, claimed duration).
# Every dispatch date comes after the previous action's latest end, so the plan holds whatever
# nature does; the communications start once their window is surely open and end before it may
# close (W1: opens by 127, closes from 154 on; 128 + 25 = 153).
M1_MODEL1_ACTIONS: list[tuple[int, str, tuple[Value, ...], float, tuple[float, float]]] = [
    (1, "MOVE_PAN_TILT_UNIT", ("STRAIGHT", "AT_MY_FEET"), 1.0, PAN_TILT),  # ends by 11
    (2, "TAKE_PICTURE", ("OBJ1", 0.0, 0.0), 12.0, PICTURE),  # by 18
    (3, "MOVE_PAN_TILT_UNIT", ("AT_MY_FEET", "STRAIGHT"), 19.0, PAN_TILT),  # by 29
    (4, "MOVE", (0.0, 0.0, 4.0, 0.0), 30.0, MOVE_4M),  # by 53.53
    (5, "MOVE_PAN_TILT_UNIT", ("STRAIGHT", "AT_MY_FEET"), 55.0, PAN_TILT),  # by 65
    (6, "TAKE_PICTURE", ("OBJ2", 4.0, 0.0), 66.0, PICTURE),  # by 72
    (7, "MOVE_PAN_TILT_UNIT", ("AT_MY_FEET", "STRAIGHT"), 73.0, PAN_TILT),  # by 83
    (8, "MOVE", (4.0, 0.0, 3.0, -3.0), 84.0, MOVE_4M),  # by 107.53
    (9, "MOVE_PAN_TILT_UNIT", ("STRAIGHT", "AT_MY_FEET"), 109.0, PAN_TILT),  # by 119
    (10, "TAKE_PICTURE", ("OBJ3", 3.0, -3.0), 120.0, PICTURE),  # by 126
    (11, "COMMUNICATE", ("W1",), 128.0, COMMUNICATION),  # in [146, 153]
    (12, "MOVE_PAN_TILT_UNIT", ("AT_MY_FEET", "STRAIGHT"), 160.0, PAN_TILT),  # by 170
    (13, "MOVE", (3.0, -3.0, 0.0, 0.0), 171.0, MOVE_6M),  # by 206.29
    (14, "COMMUNICATE", ("W2",), 241.0, COMMUNICATION),  # W2 opens by 240, closes from 267 on
]

# Goal timepoints: t_goal3e - t_evisi1 in [2, 4] for every t_evisi1 in [154, 156] forces 158
# (271 for W2); home from t_goal1 = t_end - 3; each photo's goal window after the photo.
M1_GOAL_DATES = {
    "t_end": 330.0, "t_goal1": 327.0, "t_goal3s": 155.0, "t_goal3e": 158.0, "t_goal4s": 268.0, "t_goal4e": 271.0,
    "t_goal5s": 20.0, "t_goal5e": 21.0, "t_goal6s": 74.0, "t_goal6e": 75.0, "t_goal7s": 127.0, "t_goal7e": 128.0,
}
M1_BINDINGS: dict[str, Value] = {"?x1": 0.0, "?y1": 0.0, "?x2": 4.0, "?y2": 0.0, "?x3": 3.0, "?y3": -3.0}
WINDOWS = {"t_svisi1": (125.0, 127.0), "t_evisi1": (154.0, 156.0), "t_svisi2": (238.0, 240.0),
           "t_evisi2": (267.0, 269.0)}


def build_action(number: int, task: str, args: tuple[Value, ...], dispatch: float, duration: tuple[float, float],
                 values: tuple[tuple[str, Value], ...] = ()) -> Action:
    name = f"{task}#{number}"
    return Action(name, task, args, f"{name}.start", f"{name}.end", dispatch, duration, contingent=True,
                  preemptible=task.startswith("MOVE") or task.startswith("COMMUNICATE"), window=(dispatch, dispatch),
                  values=values)


def build_plan(domain: str, problem: str, actions: list[Action], goal_dates: dict[str, float],
               bindings: dict[str, Value]) -> Plan:
    schedule = {"t_start": 0.0, **goal_dates, **{a.start: a.dispatch for a in actions}}
    uncontrolled = {**WINDOWS, **{a.end: (a.dispatch + a.duration[0], a.dispatch + a.duration[1]) for a in actions}}
    return Plan(domain, problem, tuple(actions), orderings=(), links=(), schedule=schedule, uncontrolled=uncontrolled,
                bindings=bindings)


@pytest.fixture(scope="module")
def model1() -> tuple[PlanningDomain, Problem]:
    return atrv_models("M1_model1")  # domain model1


@pytest.fixture(scope="module")
def model2() -> tuple[PlanningDomain, Problem]:
    return atrv_models("M1_model2")  # domain model2_M1


@pytest.fixture(scope="module")
def m1_plan() -> Plan:
    actions = [build_action(*row) for row in M1_MODEL1_ACTIONS]
    return build_plan("model1", "M1_model1", actions, M1_GOAL_DATES, M1_BINDINGS)


def changed(plan: Plan, action_id: str, **changes: Any) -> Plan:
    """The plan with one action changed; a new dispatch date goes to the schedule too."""
    actions = tuple(replace(a, **changes) if a.id == action_id else a for a in plan.actions)
    schedule = {**plan.schedule, **{a.start: a.dispatch for a in actions}}
    return replace(plan, actions=actions, schedule=schedule)


def without(plan: Plan, *action_ids: str) -> Plan:
    return replace(plan, actions=tuple(a for a in plan.actions if a.id not in action_ids))


def mentioning(violations: list[str], *words: str) -> list[str]:
    return [v for v in violations if all(w in v for w in words)]


# ---------------------------------------------------------------- Modele1


def test_reference_plan_is_valid(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    assert validate(*model1, m1_plan) == []


def test_nature_ranges_of_modele1_tasks(model1: tuple[PlanningDomain, Problem]) -> None:
    domain, _ = model1
    move = domain.task("MOVE")
    assert move is not None
    check = check_task(move, (0.0, 0.0, 4.0, 0.0), ())
    assert check.low == pytest.approx(8.0) and check.high == pytest.approx(4 / 0.17)
    check = check_task(move, (3.0, -3.0, 0.0, 0.0), ())
    assert check.low == pytest.approx(12.0) and check.high == pytest.approx(6 / 0.17)
    # ?mindist = min(?di, 0.5) = 0.5: a move shorter than 0.5 m (here 0.2 m) cannot be done
    assert check_task(move, (0.0, 0.0, 0.2, 0.0), ()).impossible


def test_photo_with_the_pan_tilt_unit_straight(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    violations = validate(*model1, without(m1_plan, "MOVE_PAN_TILT_UNIT#1", "MOVE_PAN_TILT_UNIT#3"))
    assert mentioning(violations, "TAKE_PICTURE#2", "PTU_POSITION()", "AT_MY_FEET", "value STRAIGHT")


def test_claimed_move_duration_too_narrow(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    violations = validate(*model1, changed(m1_plan, "MOVE#4", duration=(8.0, 10.0)))
    assert mentioning(violations, "MOVE#4: duration [8, 10] claimed, but nature may take up to 23.53 s")


def test_communication_may_end_after_its_window(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    # dispatched at 130, it ends by 155 at worst, but window W1 may close at 154
    violations = validate(*model1, changed(m1_plan, "COMMUNICATE#11", dispatch=130.0))
    found = mentioning(violations, "COMMUNICATE#11", "VISIBILITY_WINDOW(W1): IN", "broken")
    assert found and "[nature:" in found[0]  # only some realisations of nature show it


def test_arguments_breaking_the_task_constraints(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    violations = validate(*model1, changed(m1_plan, "MOVE_PAN_TILT_UNIT#1", args=("STRAIGHT", "STRAIGHT")))
    assert mentioning(violations, "MOVE_PAN_TILT_UNIT#1", "?initpos != ?finpos")


def test_move_from_the_wrong_position(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    # from (3, 0) instead of (4, 0): 3 m, [6, 17.65] s
    violations = validate(*model1, changed(m1_plan, "MOVE#8", args=(3.0, 0.0, 3.0, -3.0), duration=(6.0, 17.65)))
    assert violations == ["MOVE#8: event(AT_ROBOT_X(): (3 -> 1000)) at 84 needs AT_ROBOT_X() = 3, but it is 4 "
                          "(set by MOVE#4 at 38)"]


def test_move_during_a_communication(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    plan = changed(changed(m1_plan, "MOVE_PAN_TILT_UNIT#12", dispatch=129.0), "MOVE#13", dispatch=140.0)
    violations = validate(*model1, plan)
    assert mentioning(violations, "COMMUNICATE#11", "ROBOT_STATUS(): STILL", "broken by MOVE#13")


def test_goal_not_met_unless_dropped(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    plan = without(m1_plan, "TAKE_PICTURE#6")
    violations = validate(*model1, plan)
    assert violations == ["line 38: goal hold(PICTURE(OBJ2, 4, 0): DONE) not met: value NONE at 74"]
    assert validate(*model1, plan, dropped_lines={38}) == []


def test_action_ending_after_the_horizon(model1: tuple[PlanningDomain, Problem], m1_plan: Plan) -> None:
    plan = replace(m1_plan, schedule={**m1_plan.schedule, "t_end": 260.0, "t_goal1": 257.0})
    violations = validate(*model1, plan)
    assert mentioning(violations, "COMMUNICATE#14: may end at")
    assert mentioning(violations, "line 92:", "t_end")  # (t_end - t_start) in [330, 800]


# ---------------------------------------------------------------- Modele2

# M1 / Modele2: MOVE_NOMINAL needs the tilt at -30 degrees, TAKE_SHOT at -45.
M1_MODEL2_ACTIONS: list[tuple[int, str, tuple[Value, ...], float, tuple[float, float]]] = [
    (1, "MOVE_PTU", (0.0, 0.0, 0.0, -45.0), 1.0, PAN_TILT),  # by 11
    (2, "TAKE_SHOT", ("O1",), 12.0, PICTURE),  # by 18; ?state left to the validator
    (3, "MOVE_PTU", (0.0, -45.0, 0.0, -30.0), 19.0, PAN_TILT),  # by 29
    (4, "MOVE_NOMINAL", ("O1", "O2"), 30.0, (17.14, 35.3)),  # by 65.3
    (5, "MOVE_PTU", (0.0, -30.0, 0.0, -45.0), 66.0, PAN_TILT),  # by 76
    (6, "TAKE_SHOT", ("O2",), 77.0, PICTURE),  # by 83
    (7, "MOVE_PTU", (0.0, -45.0, 0.0, -30.0), 84.0, PAN_TILT),  # by 94
    (8, "MOVE_NOMINAL", ("O2", "O3"), 95.0, (14.74, 30.36)),  # by 125.36
    (9, "MOVE_PTU", (0.0, -30.0, 0.0, -45.0), 126.0, PAN_TILT),  # by 136
    (10, "COMMUNICATE_ANTENNA", ("W1",), 128.0, COMMUNICATION),  # in [146, 153]
    (11, "TAKE_SHOT", ("O3",), 137.0, PICTURE),  # by 143, while communicating
    (12, "MOVE_PTU", (0.0, -45.0, 0.0, -30.0), 144.0, PAN_TILT),  # by 154
    (13, "MOVE_NOMINAL", ("O3", "O1"), 155.0, (17.82, 36.71)),  # by 191.71
    (14, "COMMUNICATE_ANTENNA", ("W2",), 241.0, COMMUNICATION),
]
M1_MODEL2_GOAL_DATES = {**M1_GOAL_DATES, "t_goal6s": 84.0, "t_goal6e": 85.0, "t_goal7s": 150.0, "t_goal7e": 151.0}


@pytest.fixture(scope="module")
def m1_model2_plan() -> Plan:
    actions = []
    for number, task, args, dispatch, duration in M1_MODEL2_ACTIONS:
        values: tuple[tuple[str, Value], ...] = (("?state", "INITED"),) if task == "COMMUNICATE_ANTENNA" else ()
        actions.append(build_action(number, task, args, dispatch, duration, values))
    return build_plan("model2_M1", "M1_model2", actions, M1_MODEL2_GOAL_DATES, {})


def test_modele2_move_duration_from_the_distance_table(model2: tuple[PlanningDomain, Problem]) -> None:
    domain, _ = model2
    move = domain.task("MOVE_NOMINAL")
    assert move is not None
    check = check_task(move, ("O1", "O2"), ())  # D2 = 6 m
    assert (check.low, check.high) == pytest.approx((6 / 0.35, 6 / 0.17))
    assert check_task(move, ("O1", "O1"), ()).impossible  # no distance symbol for O1 -> O1


def test_modele2_reference_plan_is_valid(model2: tuple[PlanningDomain, Problem], m1_model2_plan: Plan) -> None:
    assert validate(*model2, m1_model2_plan) == []


def test_modele2_shot_with_the_wrong_tilt(model2: tuple[PlanningDomain, Problem], m1_model2_plan: Plan) -> None:
    violations = validate(*model2, without(m1_model2_plan, "MOVE_PTU#5", "MOVE_PTU#7"))
    assert mentioning(violations, "TAKE_SHOT#6", "PTU_TILT(): -45", "value -30")


def test_modele2_move_duration_underestimated(model2: tuple[PlanningDomain, Problem], m1_model2_plan: Plan) -> None:
    violations = validate(*model2, changed(m1_model2_plan, "MOVE_NOMINAL#4", duration=(17.14, 30.0)))
    assert mentioning(violations, "MOVE_NOMINAL#4", "up to 35.29 s")


def test_modele2_symbol_breaking_the_distance_table(model2: tuple[PlanningDomain, Problem],
                                                    m1_model2_plan: Plan) -> None:
    plan = changed(m1_model2_plan, "MOVE_NOMINAL#4", values=(("?D#1", "D3"),))  # O1 -> O2 is D2
    violations = validate(*model2, plan)
    assert mentioning(violations, "MOVE_NOMINAL#4", "?p1 in {O1} => ?D#1 in {D2, D4}")


# ---------------------------------------------------------------- resources (a made-up domain)


def test_resource_capacity() -> None:
    duration = Member(Op("-", (Time("t_end"), Time("t_start"))), Interval(1.0, 2.0), contingent=True)
    grab = Task("GRAB", (), assertions=(Use("ARM", (), Num(1.0), "t_start", "t_end", line=3),),
                constraints=(duration,))
    domain = PlanningDomain("arms", resources=(Resource("ARM", capacity=1.0),), tasks=(grab,))
    problem = Problem("two_grabs", "arms")

    def plan(second: float) -> Plan:
        actions = [build_action(1, "GRAB", (), 0.0, (1.0, 2.0)), build_action(2, "GRAB", (), second, (1.0, 2.0))]
        return replace(build_plan("arms", "two_grabs", actions, {"t_end": 10.0}, {}), uncontrolled={})

    assert validate(domain, problem, plan(2.5)) == []
    violations = validate(domain, problem, plan(1.5))  # overlaps when the first grab takes over 1.5 s
    assert mentioning(violations, "GRAB#1, GRAB#2: use 2 of ARM() at 1.5, more than its capacity 1")
