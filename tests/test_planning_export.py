"""Export of the rover's planning models (seed 004, annex A) to unified_planning and PDDL 2.1:
durative actions over user types, goals, timed initial literals for the contingent windows,
duration tables computed from the tasks' constraints, and a note for every approximation. The
Aries run that solves M1 is a benchmark (`make bench`)."""

from __future__ import annotations

import time
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import pytest
from typer.testing import CliRunner, Result
from unified_planning.io import PDDLReader
from unified_planning.model import DurativeAction

from specc.analysis.planning import domain_model, problem_model
from specc.analysis.planning_export import (
    Exported,
    bounds,
    constant_set_names,
    export,
    in_progress_values,
    write_pddl,
)
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime.planner import model as pm
from tests.atrv import atrv_models

ATRV = Path(__file__).resolve().parent.parent / "examples" / "atrv"


@pytest.fixture(scope="module")
def program() -> m.Program:
    loaded = load([ATRV])
    assert loaded.program is not None and not loaded.errors
    return loaded.program


def exported(program: m.Program, domain_name: str, problem_name: str) -> Exported:
    domain = next(i for i in program.items if isinstance(i, m.Domain) and i.name == domain_name)
    problem = next(i for i in program.items if isinstance(i, m.Problem) and i.name == problem_name)
    return export(domain_model(program, domain), problem_model(program, problem), constant_set_names(program, domain))


@pytest.fixture(scope="module")
def modele1(program: m.Program) -> Exported:
    return exported(program, "model1", "M1_model1")


@pytest.fixture(scope="module")
def modele2(program: m.Program) -> Exported:
    return exported(program, "model2_M1", "M1_model2")


def signatures(result: Exported) -> dict[str, list[str]]:
    actions = result.problem.actions
    assert all(isinstance(a, DurativeAction) for a in actions)
    return {a.name: [p.type.name for p in a.parameters] for a in actions}


def static_value(result: Exported, function: str, *objects: str) -> object:
    problem = result.problem
    fluent = problem.fluent(function)
    return problem.initial_value(fluent(*(problem.object(o) for o in objects))).constant_value()


def timed_literals(result: Exported) -> set[tuple[Fraction, str, bool]]:
    return {(timing.delay, str(e.fluent), e.value.bool_constant_value())
            for timing, effects in result.problem.timed_effects.items() for e in effects}


def mentions(result: Exported, *words: str) -> bool:
    return any(all(w in note for w in words) for note in result.unsupported)


def test_modele1_m1_exports_its_six_tasks_over_typed_parameters(modele1: Exported) -> None:
    assert signatures(modele1) == {
        "MOVE": ["AT_ROBOT_X_value", "AT_ROBOT_Y_value", "AT_ROBOT_X_value", "AT_ROBOT_Y_value"],
        "MOVE_PAN_TILT_UNIT": ["PANTILT_POSITIONS", "PANTILT_POSITIONS"],
        "TAKE_PICTURE": ["OBJECTS", "AT_ROBOT_X_value", "AT_ROBOT_Y_value"],
        "COMMUNICATE": ["VISIBILITY_WINDOWS"],
        "INIT_PTU_DRIVER": [],
        "INIT_MVT_GENERATION": [],
    }
    assert {str(g) for g in modele1.problem.goals} == {
        "AT_ROBOT_X(AT_ROBOT_X_0)", "AT_ROBOT_Y(AT_ROBOT_Y_0)",
        "COMMUNICATION_DONE(W1)", "COMMUNICATION_DONE(W2)",
        "PICTURE_DONE(OBJ1, AT_ROBOT_X_0, AT_ROBOT_Y_0)", "PICTURE_DONE(OBJ2, AT_ROBOT_X_4, AT_ROBOT_Y_0)",
        "PICTURE_DONE(OBJ3, AT_ROBOT_X_3, AT_ROBOT_Y_m3)",
    }


def move(function: str, x1: str, y1: str, x2: str, y2: str) -> tuple[str, ...]:
    return (function, f"AT_ROBOT_X_{x1}", f"AT_ROBOT_Y_{y1}", f"AT_ROBOT_X_{x2}", f"AT_ROBOT_Y_{y2}")


def test_modele1_move_durations_come_from_the_distance(modele1: Exported) -> None:
    # d = |dx| + |dy|; the longest move lasts d * 1 / 0.17 s, rounded up to a whole second.
    assert static_value(modele1, *move("MOVE_duration", "0", "0", "4", "0")) == 24
    assert static_value(modele1, *move("MOVE_duration", "3", "m3", "0", "0")) == 36
    # A move shorter than 0.5 m (here: staying put) is not allowed.
    assert static_value(modele1, *move("MOVE_allowed", "4", "0", "4", "0")) is False
    assert static_value(modele1, *move("MOVE_allowed", "0", "0", "3", "m3")) is True
    communicate = modele1.problem.action("COMMUNICATE")
    assert communicate.duration.lower.constant_value() == communicate.duration.upper.constant_value() == 25


def test_modele1_windows_are_timed_literals_at_their_pessimistic_dates(modele1: Exported) -> None:
    literals = timed_literals(modele1)
    # W1 opens in [125, 127] and closes in [154, 156]: usable from 127 to 154 only.
    assert {(125, "VISIBILITY_WINDOW_OUT(W1)", False), (127, "VISIBILITY_WINDOW_IN(W1)", True),
            (154, "VISIBILITY_WINDOW_IN(W1)", False), (156, "VISIBILITY_WINDOW_OUT(W1)", True)} <= literals
    assert (800, "within_horizon", False) in literals  # the horizon's latest end is a deadline


def test_modele1_notes_say_what_is_approximated(modele1: Exported) -> None:
    assert mentions(modele1, "MOVE", "contingent duration", "upper bound")
    assert mentions(modele1, "COMMUNICATE", "contingent duration [18, 25]")
    assert mentions(modele1, "priorities", "oversubscription")
    assert mentions(modele1, "MOVE", "real-valued", "?x1 in {0, 3, 4}")
    assert mentions(modele1, "timed initial literals", "latest opening", "earliest closing")
    assert mentions(modele1, "?x1, ?y1", "unification")


def test_modele2_m1_exports_its_seven_tasks(modele2: Exported) -> None:
    assert signatures(modele2) == {
        "MOVE_NOMINAL": ["OBJECTS", "OBJECTS"],
        "MOVE_RECOV": ["LOCALISATION", "OBJECTS"],
        "MOVE_PTU": ["PTU_PAN_value", "PTU_TILT_value", "PTU_PAN_value", "PTU_TILT_value"],
        "TAKE_SHOT": ["OBJECTS", "IDLE_INITED"],  # the task's ?state becomes a parameter
        "COMMUNICATE_ANTENNA": ["WINDOWS", "IDLE_INITED"],
        "INIT_PTU": ["IDLE_INITED"],
        "INIT_FRAME": [],
    }
    assert {str(g) for g in modele2.problem.goals} == {
        "FRAME_POS(O1)", "COMMUNICATION_TRUE(W1)", "COMMUNICATION_TRUE(W2)",
        "SHOT_TRUE(O1)", "SHOT_TRUE(O2)", "SHOT_TRUE(O3)",
    }
    # The distance table: O1 -> O2 is 6 m, at 0.17 m/s at worst; a move from O1 to O1 has no distance.
    assert static_value(modele2, "MOVE_NOMINAL_duration", "O1", "O2") == 36
    assert static_value(modele2, "MOVE_NOMINAL_allowed", "O1", "O1") is False
    assert mentions(modele2, "MOVE_NOMINAL", "contingent duration", "MOVE_NOMINAL_duration")
    assert mentions(modele2, "priorities", "oversubscription")


def test_modele2_communicates_in_each_window(modele2: Exported) -> None:
    # Modele2 has one WINDOW() for every window, so the time constraints of the problem decide which
    # communication happens in which window.
    communicate = modele2.problem.action("COMMUNICATE_ANTENNA")
    guards = {str(c) for conditions in communicate.conditions.values() for c in conditions}
    literals = timed_literals(modele2)
    # hold(COMMUNICATION(W2): FALSE, (t_start, t_evisi1)): W2's communication ends after W1's latest closing.
    assert "(past_t_evisi1 or (not (w == W2)))" in guards
    assert (156, "past_t_evisi1", True) in literals
    assert mentions(modele2, "COMMUNICATION(W2): FALSE", "kept until t_evisi1")
    # COMMUNICATION(W1) is a goal by t_goal3e, 2 to 4 s after W1 closes in [154, 156]: done by 154 + 4 s.
    assert "(before_t_goal3e or (not (w == W1)))" in guards
    assert (158, "before_t_goal3e", False) in literals
    assert mentions(modele2, "COMMUNICATION(W1): TRUE", "reached by 158 s")


@pytest.mark.parametrize("model", ["modele1", "modele2"])
def test_write_pddl_is_read_back(model: str, request: pytest.FixtureRequest, tmp_path: Path) -> None:
    result: Exported = request.getfixturevalue(model)
    domain, problem = write_pddl(result, tmp_path)
    assert (domain, problem) == (tmp_path / "domain.pddl", tmp_path / "problem.pddl")
    text = domain.read_text()
    assert "(:durative-action" in text and ":timed-initial-literals" in text and ":numeric-fluents" in text
    parsed = PDDLReader().parse_problem(str(domain), str(problem))
    assert {a.name for a in parsed.actions} == {a.name.lower() for a in result.problem.actions}
    assert len(parsed.timed_effects) == len(result.problem.timed_effects)


def test_bounds_propagate_through_the_tasks_arithmetic() -> None:
    d, s, duration = pm.Var("?d"), pm.Var("?s"), pm.Var("?duration")
    constraints: list[pm.Constraint] = [
        pm.Relation("=", d, pm.Op("max", (pm.Op("-", (pm.Num(4.0), pm.Num(1.0))), pm.Num(0.0)))),
        pm.Member(s, pm.Interval(0.17, 0.35)),
        pm.Relation("=", d, pm.Op("*", (s, duration))),
        pm.Relation("=", duration, pm.Op("-", (pm.Time("t_end"), pm.Time("t_start"))), contingent=True),
    ]
    found = bounds(constraints, {("time", "t_start"): (0.0, 0.0)}, [("time", "t_end")])
    assert found is not None
    low, high = found[("time", "t_end")]  # type: ignore[misc]
    assert low == pytest.approx(3 / 0.35) and high == pytest.approx(3 / 0.17)
    assert bounds([*constraints, pm.Relation("<=", duration, pm.Num(5.0))], {("time", "t_start"): (0.0, 0.0)},
                  []) is None


@pytest.mark.bench
def test_aries_solves_m1_modele2(modele2: Exported) -> None:
    pytest.importorskip("up_aries")
    from unified_planning.engines import PlanGenerationResultStatus
    from unified_planning.shortcuts import OneshotPlanner, get_environment

    get_environment().credits_stream = None
    started = time.perf_counter()
    with OneshotPlanner(name="aries") as planner:
        result = planner.solve(modele2.problem, timeout=600)
    elapsed = time.perf_counter() - started
    print(f"\nAries on M1 (Modele2): {result.status.name} in {elapsed:.1f} s")
    assert result.status in (PlanGenerationResultStatus.SOLVED_SATISFICING, PlanGenerationResultStatus.SOLVED_OPTIMALLY)
    print(result.plan)
    names = {a.action.name for _, a, _ in result.plan.timed_actions}
    assert {"TAKE_SHOT", "COMMUNICATE_ANTENNA", "MOVE_NOMINAL"} <= names


@pytest.mark.parametrize(("domain_name", "problem_name"), [("model1", "M4_model1"), ("model2_M4", "M4_model2")])
def test_a_goal_impossible_even_alone_is_left_out_and_said(program: m.Program, domain_name: str,
                                                           problem_name: str) -> None:
    # M4's W2 is open for sure only 24 s and a communication takes up to 25 s: `specc plan` drops
    # that goal as impossible even alone, and so does the export (PDDL 2.1 has no
    # oversubscription: keeping it, the problem has no plan at all).
    result = exported(program, domain_name, problem_name)
    problem = next(i for i in program.items if isinstance(i, m.Problem) and i.name == problem_name)
    lowered = problem_model(program, problem)
    goals = [a for a in lowered.assertions if a.goal is not None]
    w2 = [a for a in goals if "W2" in str(a.args)]
    assert len(w2) == 1
    assert len(result.problem.goals) == len(goals) - 1
    assert mentions(result, f"the goal of line {w2[0].line} is left out", "impossible even alone")
    assert result.problem.name == problem_name


def test_a_problem_whose_goals_are_all_possible_keeps_them_all(modele1: Exported, program: m.Program) -> None:
    problem = next(i for i in program.items if isinstance(i, m.Problem) and i.name == "M1_model1")
    goals = [a for a in problem_model(program, problem).assertions if a.goal is not None]
    assert len(modele1.problem.goals) == len(goals)
    assert not mentions(modele1, "is left out")


def test_values_that_only_mark_a_task_in_progress_are_found() -> None:
    modele1 = in_progress_values(*atrv_models("M1_model1"))
    assert modele1[("AT_ROBOT_X", pm.Num(1000.0))] == ["MOVE"]
    assert modele1[("ROBOT_STATUS", pm.Sym("MOVING"))] == ["MOVE"]
    assert ("ROBOT_STATUS", pm.Sym("STILL")) not in modele1  # the initial value, and COMMUNICATE's condition
    modele2 = in_progress_values(*atrv_models("M1_model2"))
    assert modele2[("FRAME_POS", pm.Sym("MOVING"))] == ["MOVE_NOMINAL", "MOVE_RECOV"]


def busy_domain(watcher: bool) -> tuple[pm.PlanningDomain, pm.Problem]:
    """WORK passes through S = BUSY; WATCH (when there) needs S = BUSY, which is then no marker."""
    idle, busy = pm.Sym("IDLE"), pm.Sym("BUSY")
    work = pm.Task("WORK", (), assertions=(
        pm.Event("S", (), idle, busy, "t_start"), pm.Hold("S", (), busy, "t_start", "t_end"),
        pm.Event("S", (), busy, idle, "t_end"), pm.Event("DONE", (), pm.Sym("NO"), pm.Sym("YES"), "t_end")),
        constraints=(pm.Member(pm.Op("-", (pm.Time("t_end"), pm.Time("t_start"))), pm.Interval(2.0, 3.0)),))
    watch = pm.Task("WATCH", (), assertions=(pm.Hold("S", (), busy, "t_start", "t_end"),),
                    constraints=(pm.Member(pm.Op("-", (pm.Time("t_end"), pm.Time("t_start"))), pm.Interval(1.0, 1.0)),))
    domain = pm.PlanningDomain("busy", tasks=(work, watch) if watcher else (work,))
    problem = pm.Problem("p", "busy", assertions=(
        pm.Event("S", (), busy, idle, "t_start", kind="explained"),
        pm.Event("DONE", (), pm.Sym("YES"), pm.Sym("NO"), "t_start", kind="explained"),
        pm.Hold("DONE", (), pm.Sym("YES"), "t_end", "t_end", goal=pm.GoalMark(1.0, 0.0))))
    return domain, problem


@pytest.mark.parametrize("watcher", [False, True])
def test_the_compact_encoding_leaves_out_only_markers(watcher: bool) -> None:
    domain, problem = busy_domain(watcher)
    assert (("S", pm.Sym("BUSY")) in in_progress_values(domain, problem)) is not watcher
    compact, full = export(domain, problem).problem, export(domain, problem, compact=False).problem
    fluents = {f.name for f in compact.fluents}
    assert "S_IDLE" in fluents and ("S_BUSY" in fluents) is watcher
    assert "S_BUSY" in {f.name for f in full.fluents}
    work = compact.action("WORK")
    # Without its marker, WORK leaves S at its start (S has no value while it runs) and sets it back at its end.
    start = {str(e) for timing, effects in work.effects.items() if timing.is_from_start() for e in effects}
    end = {str(e) for timing, effects in work.effects.items() if timing.is_from_end() for e in effects}
    assert start == ({"S_IDLE := false", "S_BUSY := true"} if watcher else {"S_IDLE := false"})
    assert {"S_IDLE := true", "DONE_YES := true"} <= end
    assert ("S_BUSY := false" in end) is watcher
    assert mentions(export(domain, problem), "in progress", "S = BUSY (WORK)") is not watcher


def test_a_value_another_task_ends_with_is_no_marker() -> None:
    # WORK passes through BUSY; FINISH passes through WRAPPING and ends with BUSY: BUSY is a value
    # like any other there, and WRAPPING alone only marks a task in progress.
    domain, problem = busy_domain(False)
    idle, busy, wrapping = pm.Sym("IDLE"), pm.Sym("BUSY"), pm.Sym("WRAPPING")
    finish = pm.Task("FINISH", (), assertions=(
        pm.Event("S", (), idle, wrapping, "t_start"), pm.Hold("S", (), wrapping, "t_start", "t_end"),
        pm.Event("S", (), wrapping, busy, "t_end")),
        constraints=(pm.Member(pm.Op("-", (pm.Time("t_end"), pm.Time("t_start"))), pm.Interval(1.0, 1.0)),))
    domain = replace(domain, tasks=(*domain.tasks, finish))
    assert in_progress_values(domain, problem) == {("S", wrapping): ["FINISH"]}
    fluents = {f.name for f in export(domain, problem).problem.fluents}
    assert "S_BUSY" in fluents and "S_WRAPPING" not in fluents


def test_numbers_a_task_computes_are_ground_too() -> None:
    # HOP's ?left =. ?b - 1: the problem writes only 3 (and the 0 it replaces at the start), and
    # HOP needs 2, 1 and 0 to be ground at all. They are reached from 3, within CHARGE's [0, 3].
    from tests.test_planner import BATTERY_SPEC, from_text

    domain, problem = from_text(BATTERY_SPEC)
    result = export(domain, problem)
    (hop,) = result.problem.actions
    assert [p.name for p in hop.parameters] == ["from", "to", "b", "left"]
    assert mentions(result, "?b in {1, 2, 3}", "?left in {0, 1, 2, 3}")
    objects = {o.name for o in result.problem.all_objects}
    assert {"CHARGE_0", "CHARGE_1", "CHARGE_2", "CHARGE_3"} <= objects and "CHARGE_4" not in objects


def test_the_numbers_reached_go_forward_only_and_a_cut_is_said() -> None:
    from tests.test_planner import BATTERY_SPEC, from_text

    text = BATTERY_SPEC.replace("[0, 3]", "[0, 100]").replace("?b in [1, 3]", "?b in [1, 100]")
    domain, problem = from_text(text.replace("(0, 3), t_start", "(0, 50), t_start"))
    result = export(domain, problem)
    objects = {o.name for o in result.problem.all_objects}
    # From 50, a hop only goes down: 49, 48, ... and never up to 51.
    assert {"CHARGE_50", "CHARGE_49", "CHARGE_0"} <= objects and "CHARGE_51" not in objects
    assert not any("cut at" in note for note in result.unsupported)
    domain, problem = from_text(text.replace("(0, 3), t_start", "(0, 100), t_start"))
    result = export(domain, problem)  # 101 numbers: more than REACHED_NUMBERS
    assert any("the numbers the tasks' events lead to are cut at 64" in note for note in result.unsupported)


def test_a_square_is_propagated_as_a_square_not_as_a_product_of_two_ranges() -> None:
    # A Euclidean distance written with squares: d * d = 3 * 3 + 4 * 4, so d = 5; 5 m at 0.4-0.6 m/s
    # take 8.33-12.5 s. Dividing 25 by d's own range [0.5, 50] would never tighten it (125 s).
    d, speed, duration = pm.Var("?d"), pm.Var("?speed"), pm.Var("?duration")
    constraints: list[pm.Constraint] = [
        pm.Relation(">=", d, pm.Num(0.5)),
        pm.Relation("=", pm.Op("*", (d, d)), pm.Op("+", (pm.Num(9.0), pm.Num(16.0)))),
        pm.Member(speed, pm.Interval(0.4, 0.6)),
        pm.Relation("=", d, pm.Op("*", (speed, duration))),
        pm.Relation("=", duration, pm.Op("-", (pm.Time("t_end"), pm.Time("t_start"))), contingent=True),
    ]
    found = bounds(constraints, {("time", "t_start"): (0.0, 0.0)}, [("time", "t_end"), ("var", "?d")])
    assert found is not None
    assert found[("var", "?d")] == pytest.approx((5.0, 5.0))
    assert found[("time", "t_end")] == pytest.approx((5 / 0.6, 5 / 0.4))
    # A square is never negative: d * d = -1 has no solution.
    negative = [pm.Relation("=", pm.Op("*", (d, d)), pm.Num(-1.0))]
    assert bounds(negative, {}, [("var", "?d")]) is None


def test_a_goal_held_to_the_end_keeps_the_deadline_of_its_start(tmp_path: Path) -> None:
    """`hold(CHECKED(CP1): YES, (t1, t_end))` with `(t1 - t_start) in [0, 100]`: checked by 100 s and
    so to the end. The effects achieving it are refused after 100 s; the home goal, held from 2 s
    before the end, keeps the horizon's deadline alone."""
    from tests.test_plan_anytime import PATROL, spec_models

    domain, problem = spec_models(tmp_path / "patrol", PATROL, "night")
    result = export(domain, problem)
    literals = timed_literals(result)
    assert {(Fraction(100), "before_t1", False), (Fraction(200), "before_t2", False),
            (Fraction(300), "before_t3", False)} <= literals
    assert not any(name == "before_t_home" for _, name, _ in literals)
    assert mentions(result, "CHECKED(CP1): YES", "reached by 100 s")


def test_the_files_are_the_same_from_one_process_to_the_next(tmp_path: Path) -> None:
    import os
    import subprocess
    import sys

    def written(seed: str) -> list[str]:
        folder = tmp_path / seed
        subprocess.run([sys.executable, "-m", "specc.cli", "export", str(ATRV), "--problem", "M4", "--domain",
                        "model2", "-o", str(folder)], check=True, capture_output=True,
                       env={**os.environ, "PYTHONHASHSEED": seed})
        return [(folder / name).read_text() for name in ("domain.pddl", "problem.pddl")]

    assert written("1") == written("2")


def test_the_files_read_back_for_aries_have_whole_durations(modele1: Exported, tmp_path: Path) -> None:
    """PDDL has only `number`: the reader makes Modele1's duration table real, which Aries refuses;
    `read_pddl` gives it back as whole numbers, the rest of the problem untouched."""
    from specc.analysis.planning_export import read_pddl

    domain, problem = write_pddl(modele1, tmp_path)
    plain = PDDLReader().parse_problem(str(domain), str(problem))
    ready = read_pddl(domain, problem)
    durations = {f.name for f in plain.fluents if "duration" in f.name.lower()}
    assert durations and all(plain.fluent(name).type.is_real_type() for name in durations)
    assert all(ready.fluent(name).type.is_int_type() for name in durations)
    assert {a.name for a in ready.actions} == {a.name for a in plain.actions} and ready.goals == plain.goals


# A number only a macro's table writes (`_p in {A} => _x =. 7`): WORK must be at x = 7, which no
# assertion names. specc's planner moves there and works; the export must ground ?x over 7 too.
TABLE_SPEC = """
domain d {
  attribute X() { ?value in [-oo, +oo]; }
  attribute DONE() { ?value in {YES, NO}; }
  macro spot(_p, _x) { _p in {A} => _x =. 7; _p in {B} => _x =. 3; }
  task MOVE(?x1, ?x2) (t_start, t_end) {
    ?x1 in [0, 10];
    ?x2 in [0, 10];
    event(X(): (?x1, ?x2), t_end);
    contingent (t_end - t_start) in [5, 10];
  } nonPreemptive
  task WORK(?p, ?x) (t_start, t_end) {
    ?p in {A};
    spot(?p, ?x);
    hold(X(): ?x, (t_start, t_end));
    event(DONE(): (NO, YES), t_end);
    contingent (t_end - t_start) in [2, 5];
  } nonPreemptive
}
problem p for d {
  timepoint t_g;
  explained event(X(): (0, 2), t_start);
  explained event(DONE(): (YES, NO), t_start);
  hold(DONE(): YES, (t_g, t_end)) goal(1, 0);
  (t_end - t_start) in [0, 100];
}
"""

# A battery that a leg of a table drains (`?b2 =. ?b1 - 1.5 * ?d`, ?d from the leg's row): the
# numbers a plan reaches are not enumerated, so GOTO has no ground instance.
LEGS_SPEC = """
domain legs {
  attribute AT() { ?value in {DOCK, S1, P1}; }
  attribute BATT() { ?value in [0, 100]; }
  macro leg(_p1, _p2, _d) {
    variable ?e;
    ?e in {E_DOCK_S1, E_S1_P1};
    _p1 in {DOCK} => ?e in {E_DOCK_S1};
    _p2 in {DOCK} => ?e in {E_DOCK_S1};
    _p1 in {P1} => ?e in {E_S1_P1};
    _p2 in {P1} => ?e in {E_S1_P1};
    ?e in {E_DOCK_S1} => _d =. 10;
    ?e in {E_S1_P1} => _d =. 6;
  }
  task GOTO(?p1, ?p2, ?b1, ?b2) (t_start, t_end) {
    variable ?d;
    ?p1 in {DOCK, S1, P1};
    ?p2 in {DOCK, S1, P1};
    ?p1 != ?p2;
    leg(?p1, ?p2, ?d);
    event(AT(): (?p1, ?p2), t_end);
    event(BATT(): (?b1, ?b2), t_end);
    ?b2 =. ?b1 -. 1.5 *. ?d;
    ?b2 in [10, 100];
    contingent (t_end - t_start) in [5, 10];
  } nonPreemptive
  task WAIT() (t_start, t_end) {
    hold(AT(): DOCK, (t_start, t_end));
    contingent (t_end - t_start) in [1, 2];
  } nonPreemptive
}
problem go for legs {
  timepoint t_g;
  explained event(AT(): (P1, DOCK), t_start);
  explained event(BATT(): (0, 45), t_start);
  hold(AT(): S1, (t_g, t_end)) goal(1, 0);
  (t_end - t_start) in [0, 100];
}
"""


def export_command(tmp_path: Path, text: str, problem: str, *extra: str) -> Result:
    """`specc export` on `text`, in this process (the files go to tmp_path/pddl)."""
    from specc.cli import app

    spec = tmp_path / "spec" / "robot.spec"
    spec.parent.mkdir(exist_ok=True)
    spec.write_text(text)
    return CliRunner().invoke(app, ["export", str(spec.parent), "--problem", problem, "-o", str(tmp_path / "pddl"),
                                    *extra])


def test_a_number_only_a_macros_table_writes_is_ground_and_the_task_kept(tmp_path: Path) -> None:
    from tests.test_planner import from_text

    result = export(*from_text(TABLE_SPEC))
    assert not result.left_out
    assert {a.name for a in result.problem.actions} == {"MOVE", "WORK"}
    objects = {o.name for o in result.problem.all_objects}
    # 7 from the table's row WORK reads; 3 is the row of ?p = B, which WORK never is.
    assert "X_7" in objects and "X_3" not in objects
    done = export_command(tmp_path, TABLE_SPEC, "p")
    assert done.exit_code == 0, done.stderr
    assert "(:durative-action work" in (tmp_path / "pddl" / "domain.pddl").read_text().lower()
    assert "left out" not in done.stderr


def test_a_number_a_constraint_sets_is_ground_too() -> None:
    from tests.test_planner import from_text

    plain = TABLE_SPEC.replace("spot(?p, ?x);", "?x =. 7;")
    result = export(*from_text(plain))
    assert not result.left_out and "X_7" in {o.name for o in result.problem.all_objects}


def test_the_problem_a_macros_table_needs_is_solved_from_the_files(tmp_path: Path) -> None:
    pytest.importorskip("up_aries")
    from unified_planning.engines import PlanGenerationResultStatus
    from unified_planning.shortcuts import OneshotPlanner, get_environment

    from specc.analysis.planning_export import read_pddl
    from tests.test_planner import from_text

    domain, problem = write_pddl(export(*from_text(TABLE_SPEC)), tmp_path)
    get_environment().credits_stream = None
    with OneshotPlanner(name="aries") as planner:
        solved = planner.solve(read_pddl(domain, problem), timeout=60)
    assert solved.status in (PlanGenerationResultStatus.SOLVED_SATISFICING,
                             PlanGenerationResultStatus.SOLVED_OPTIMALLY)
    assert [a.action.name for _, a, _ in solved.plan.timed_actions] == ["move", "work"]


def test_a_task_short_of_numbers_is_left_out_with_why() -> None:
    from tests.test_planner import from_text

    result = export(*from_text(LEGS_SPEC))
    assert {a.name for a in result.problem.actions} == {"WAIT"}
    assert list(result.left_out) == ["GOTO"]
    why = result.left_out["GOTO"]
    # Which parameter lacks numbers, one it would take, and why the export did not reach it.
    assert "?b2 would need another number, e.g. ?b2 = 30 with ?p1 = DOCK, ?p2 = S1, ?b1 = 45" in why
    assert "leads ?b2 anywhere in [" in why and "not enumerated" in why
    assert not mentions(result, "GOTO is dropped")


def test_export_fails_when_a_task_is_left_out_unless_partial_is_allowed(tmp_path: Path) -> None:
    refused = export_command(tmp_path, LEGS_SPEC, "go")
    assert refused.exit_code == 1
    assert "error: task GOTO of domain 'legs' is left out of the export: " in refused.stderr
    assert "--allow-partial" in refused.stderr and not (tmp_path / "pddl").exists()
    allowed = export_command(tmp_path, LEGS_SPEC, "go", "--allow-partial")
    assert allowed.exit_code == 0, allowed.stderr
    assert "warning: task GOTO of domain 'legs' is left out of the export: " in allowed.stderr
    assert "error" not in allowed.stderr
    assert "(:durative-action goto" not in (tmp_path / "pddl" / "domain.pddl").read_text().lower()


def test_a_task_no_values_can_meet_is_a_note_not_a_loss() -> None:
    from tests.test_planner import from_text

    never = TABLE_SPEC.replace("?p in {A};", "?p in {A};\n    ?x =. 7;\n    ?x > 8;")
    result = export(*from_text(never))
    assert not result.left_out and {a.name for a in result.problem.actions} == {"MOVE"}
    assert mentions(result, "WORK is left out: no values at all meet its constraints")
