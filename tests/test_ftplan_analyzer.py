"""FTplan's plan analyzer (seed 004 §3.1.1) on the rover's real plans: no false alarm on the
plans of both models, the seed's mutation 1-592 caught before execution, and one hand-broken
plan per kind of rule."""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import pytest

from specc.analysis.ftplan import ftplan_config
from specc.model import nodes as m
from specc.runtime.ftplan.analyzer import Violation, analyse
from specc.runtime.ftplan.config import FtPlanConfig, Requirement, Var
from specc.runtime.ftplan.state import SystemState
from specc.runtime.ftplan.view import View
from specc.runtime.planner import Planner
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Action, Plan
from specc.runtime.planner.validate import validate
from tests.atrv import ATRV, atrv_models, mutation_1_592, program

MISSIONS = [f"M{k}_{model}" for model in ("model1", "model2") for k in (1, 2, 3, 4)]


@cache
def config() -> FtPlanConfig:
    return ftplan_config(next(item for item in program().items if isinstance(item, m.FtPlan)), program())


def plan_of(domain: pm.PlanningDomain, problem: pm.Problem) -> Plan:
    result = Planner(domain).plan(problem)
    assert result.plan is not None, result.reason
    return result.plan


@cache
def planned(name: str) -> Plan:
    return plan_of(*atrv_models(name))


def check(plan: Plan, name: str, rules: FtPlanConfig | None = None) -> list[Violation]:
    """The analyzer's verdict on a plan for problem `name` ("M1_model2"), as FTplan judges it: on
    its own state (the mission's Modele1 problem), through p2's view for a Modele2 plan."""
    mission, model = name.split("_")
    problem = atrv_models(f"{mission}_model1")[1]
    view = None
    if model == "model2":
        view = View(next(p for p in config().for_mission(mission).planners if p.name == "p2").view)
    return analyse(plan, rules or config(), SystemState.from_problem(problem), problem, view)


def rule_line(text: str) -> int:
    """The line of ftplan.spec that holds `text`: found in the file, not taken from the config."""
    lines = (ATRV / "ftplan.spec").read_text().splitlines()
    return next(number for number, line in enumerate(lines, 1) if text in line)


def action(plan: Plan, text: str) -> Action:
    return next(a for a in plan.actions if a.text() == text)


def with_action(plan: Plan, changed: Action) -> Plan:
    return replace(plan, actions=tuple(changed if a.id == changed.id else a for a in plan.actions))


def shifted(plan: Plan, moved: Action, seconds: float) -> Plan:
    """The plan with `moved` dispatched `seconds` later (earlier when negative), its end with it."""
    low, high = plan.uncontrolled[moved.end]
    changed = with_action(plan, replace(moved, dispatch=moved.dispatch + seconds))
    return replace(changed, schedule=plan.schedule | {moved.start: moved.dispatch + seconds},
                   uncontrolled=plan.uncontrolled | {moved.end: (low + seconds, high + seconds)})


def found(violations: list[Violation], line: int, action_id: str) -> Violation:
    hits = [v for v in violations if v.line == line and v.action == action_id]
    assert hits, f"no violation of line {line} by {action_id} in {[v.message for v in violations]}"
    return hits[0]


# ---------------------------------------------------------------- no false alarms


@pytest.mark.parametrize("name", MISSIONS)
def test_the_planners_plans_pass(name: str) -> None:
    assert check(planned(name), name) == []


def test_the_windows_fall_back_on_the_problems_bounds() -> None:
    """Without the windows' dates in the plan, the problem's constraints give them."""
    plan = planned("M1_model1")
    windows = {point: dates for point, dates in plan.uncontrolled.items() if point.startswith("t_")}
    assert windows  # the plan carries the problem's window instants
    unwindowed = replace(plan, uncontrolled={p: d for p, d in plan.uncontrolled.items() if p not in windows})
    assert check(unwindowed, "M1_model1") == []
    early = action(plan, "COMMUNICATE(W1)")
    found(check(shifted(unwindowed, early, -30.0), "M1_model1"),
          rule_line("requires VISIBILITY_WINDOW(?w): IN"), early.id)


# ---------------------------------------------------------------- seed mutation 1-592


@pytest.mark.parametrize("name", ["M1_model1", "M3_model1"])
def test_mutation_1_592_is_caught_before_execution(name: str) -> None:
    domain, problem = atrv_models(name)
    mutated = mutation_1_592(domain)
    plan = plan_of(mutated, problem)
    photos = [a for a in plan.actions if a.task == "TAKE_PICTURE"]
    # The mutated model still plans its photos, and the plan is right by that model: only
    # constraints written apart from it can tell.
    assert photos and validate(mutated, problem, plan) == []
    violations = check(plan, name)
    line = rule_line("during TAKE_PICTURE(?o, ?x, ?y) requires PTU_POSITION(): AT_MY_FEET")
    for photo in photos:
        assert "PTU_POSITION() is STRAIGHT" in found(violations, line, photo.id).message


# ---------------------------------------------------------------- hand-broken plans


def test_two_overlapping_moves() -> None:
    plan = planned("M1_model1")
    first, second = action(plan, "MOVE(0, 0, 4, 0)"), action(plan, "MOVE(4, 0, 3, -3)")
    broken = shifted(plan, second, first.dispatch + 5.0 - second.dispatch)
    violation = found(check(broken, "M1_model1"), rule_line("no_overlap MOVE, MOVE;"), second.id)
    assert first.id in violation.message


def test_touching_actions_do_not_overlap() -> None:
    plan = planned("M1_model1")
    first, second = action(plan, "MOVE(0, 0, 4, 0)"), action(plan, "MOVE(4, 0, 3, -3)")
    # The second move right at the first's latest end: touching; its start is sure of its place.
    touching = shifted(plan, second, plan.uncontrolled[first.end][1] - second.dispatch)
    assert [v for v in check(touching, "M1_model1") if v.line == rule_line("no_overlap MOVE, MOVE;")] == []


def test_a_photo_away_from_its_target() -> None:
    plan = planned("M1_model1")
    photo = action(plan, "TAKE_PICTURE(OBJ2, 4, 0)")
    broken = with_action(plan, replace(photo, args=("OBJ2", 5.0, 0.0)))
    violation = found(check(broken, "M1_model1"), rule_line("requires AT_ROBOT_X(): ?x;"), photo.id)
    assert "AT_ROBOT_X() is 4 " in violation.message and "not 5" in violation.message


def test_a_move_longer_than_any_path() -> None:
    plan = planned("M1_model1")
    move = action(plan, "MOVE(0, 0, 4, 0)")
    broken = with_action(plan, replace(move, duration=(8.0, 250.0)))
    violation = found(check(broken, "M1_model1"), rule_line("max_duration MOVE 190 s;"), move.id)
    assert "250.00 s" in violation.message


def test_a_communication_before_its_window_opens() -> None:
    plan = planned("M1_model1")
    talk = action(plan, "COMMUNICATE(W1)")
    broken = shifted(plan, talk, -30.0)  # the window opens at 125..127 s, it starts at 97 s
    violation = found(check(broken, "M1_model1"), rule_line("requires VISIBILITY_WINDOW(?w): IN"), talk.id)
    assert "VISIBILITY_WINDOW(W1) is OUT" in violation.message


def test_a_communication_that_may_outlast_its_window() -> None:
    plan = planned("M1_model1")
    talk = action(plan, "COMMUNICATE(W1)")
    # Starts when the window surely is open (127 s) but may end after its earliest close (154 s).
    broken = replace(plan, uncontrolled=plan.uncontrolled | {talk.end: (145.0, 160.0)})
    violation = found(check(broken, "M1_model1"), rule_line("requires VISIBILITY_WINDOW(?w): IN"), talk.id)
    assert "uncertain" in violation.message and "t_evisi1" in violation.message


def test_a_move_from_where_the_robot_is_not() -> None:
    plan = planned("M1_model1")
    move = action(plan, "MOVE(4, 0, 3, -3)")
    broken = with_action(plan, replace(move, args=(5.0, 0.0, 3.0, -3.0)))
    violation = found(check(broken, "M1_model1"), rule_line("at_start MOVE(?x1, ?y1, ?x2, ?y2) requires AT_ROBOT_X"),
                      move.id)
    assert "at its start" in violation.message and "AT_ROBOT_X() is 4 " in violation.message


def test_a_move_started_before_the_previous_surely_ended() -> None:
    plan = planned("M1_model1")
    first, second = action(plan, "MOVE(0, 0, 4, 0)"), action(plan, "MOVE(4, 0, 3, -3)")
    earliest_end, latest_end = plan.uncontrolled[first.end]
    broken = shifted(plan, second, (earliest_end + latest_end) / 2 - second.dispatch)
    violation = found(check(broken, "M1_model1"), rule_line("at_start MOVE(?x1, ?y1, ?x2, ?y2) requires AT_ROBOT_X"),
                      second.id)
    assert "uncertain" in violation.message and first.id in violation.message


def test_at_end_reads_the_value_before_the_actions_own_effects() -> None:
    plan = planned("M1_model1")
    turns = [a for a in plan.actions if a.task == "MOVE_PAN_TILT_UNIT"]

    def at_end(value: str) -> FtPlanConfig:
        rule = Requirement("at_end", "MOVE_PAN_TILT_UNIT", (Var("?from"), Var("?to")), "PTU_POSITION", (),
                           Var(value), line=1)
        return replace(config(), analyzer=(rule,))

    assert check(plan, "M1_model1", at_end("?from")) == []
    assert {v.action for v in check(plan, "M1_model1", at_end("?to"))} == {a.id for a in turns}


def test_an_attribute_nothing_sets_is_unknown() -> None:
    plan = planned("M1_model1")
    rule = Requirement("during", "TAKE_PICTURE", (Var("?o"), Var("?x"), Var("?y")), "LIGHT", (), "ON", line=1)
    violations = check(plan, "M1_model1", replace(config(), analyzer=(rule,)))
    assert violations and all("LIGHT() is unknown" in v.message for v in violations)


def test_messages_are_one_line_naming_the_rule_and_the_action() -> None:
    plan = planned("M1_model1")
    move = action(plan, "MOVE(0, 0, 4, 0)")
    broken = shifted(with_action(plan, replace(move, duration=(8.0, 250.0))), move, 50.0)
    violations = check(broken, "M1_model1")
    assert len({v.line for v in violations}) >= 3  # overlaps, duration, positions
    for v in violations:
        assert "\n" not in v.message and v.message.startswith(f"line {v.line}: ")
        assert v.action and v.action in v.message


def test_a_start_the_problem_explains_holds_until_nature_s_first_event() -> None:
    """A window written as closed at the start by the problem itself (`explained event(...: (IN,
    OUT), t_start)`) rather than by nature: before its opening, the analyzer reads it OUT, as the
    planner and the validator do, not unknown. The plan passes; a communication moved before the
    window is refused for it."""
    plan = planned("M1_model1")
    problem = atrv_models("M1_model1")[1]
    explained = replace(problem, assertions=tuple(
        replace(a, kind="explained") if isinstance(a, pm.Event) and a.kind == "contingent"
        and a.attribute == "VISIBILITY_WINDOW" and a.time == problem.start else a for a in problem.assertions))
    assert explained != problem
    assert analyse(plan, config(), SystemState.from_problem(explained), explained) == []
    talk = action(plan, "COMMUNICATE(W1)")
    early = analyse(shifted(plan, talk, -30.0), config(), SystemState.from_problem(explained), explained)
    violation = found(early, rule_line("requires VISIBILITY_WINDOW(?w): IN"), talk.id)
    assert "VISIBILITY_WINDOW(W1) is OUT" in violation.message
