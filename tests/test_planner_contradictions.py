"""Problems whose own constraints cannot all hold, and values of the wrong kind: the planner
gives no plan and says why (never a plan its validator rejects), and `specc plan` stops at the
check's diagnostic before planning."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from dataclasses import replace
from pathlib import Path

import pytest

from specc.analysis.planning import domain_model, problem_model
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime.planner import Planner
from specc.runtime.planner import model as pm
from specc.runtime.planner.search import CONTROLLABILITIES
from specc.runtime.planner.validate import validate

WINDOW_SPEC = """
domain door {
  attribute OPEN() { ?value in {YES, NO}; }
  attribute DONE() { ?value in {YES, NO}; }
  attribute LEVEL() { ?value in [0, 100]; }
  task WORK() (t_start, t_end) {
    hold(OPEN(): YES, (t_start, t_end));
    event(DONE(): (NO, YES), t_end);
    contingent (t_end - t_start) in [2, 5];
  } nonPreemptive
}
problem p for door {
  timepoint t_o, t_c, t_g;
  explained event(DONE(): (YES, NO), t_start);
  explained event(LEVEL(): (0, 40), t_start);
  contingent event(OPEN(): (YES, NO), t_start);
  contingent event(OPEN(): (NO, YES), t_o);
  contingent event(OPEN(): (YES, NO), t_c);
  (t_o - t_start) in [10, 20];
  (t_c - t_start) in [50, 60];
  t_o < t_c;
  hold(DONE(): YES, (t_g, t_end)) goal(1, 0);
  (t_end - t_start) in [0, 100];
}
"""


def from_text(text: str, folder: Path) -> tuple[pm.PlanningDomain, pm.Problem]:
    spec = folder / "door.spec"
    spec.write_text(textwrap.dedent(text))
    loaded = load([spec])
    assert not loaded.errors, loaded.errors
    assert loaded.program is not None
    domain = domain_model(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Domain)))
    problem = problem_model(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Problem)))
    return domain, problem


def time(name: str) -> pm.Expr:
    return pm.Time(name)


def since_start(name: str) -> pm.Expr:
    return pm.Op("-", (pm.Time(name), pm.Time("t_start")))


def test_the_window_the_right_way_round_gets_a_valid_plan(tmp_path: Path) -> None:
    domain, problem = from_text(WINDOW_SPEC, tmp_path)
    result = Planner(domain, exact=False).plan(problem)
    assert result.plan is not None and not result.dropped, result.reason
    assert validate(domain, problem, result.plan) == []


@pytest.mark.parametrize("controllability", CONTROLLABILITIES)
def test_a_window_closing_before_it_opens_gives_no_plan_naming_the_constraints(
        tmp_path: Path, controllability: str) -> None:
    domain, problem = from_text(WINDOW_SPEC, tmp_path)
    # The repro: the order written the wrong way round (the check refuses it in a spec; a planner
    # is also given problems built in code, and replanning problems).
    closes_first = replace(problem, constraints=tuple(
        pm.Relation("<", time("t_c"), time("t_o"), line=c.line) if isinstance(c, pm.Relation) else c
        for c in problem.constraints))
    result = Planner(domain, exact=False, controllability=controllability).plan(closes_first)
    assert result.plan is None, "a plan for a nature that cannot be"
    assert "required assertions and constraints" in result.reason
    assert "nature's instants cannot all hold" in result.reason
    lines = sorted(c.line for c in problem.constraints if pm.timepoints_of(c) & {"t_o", "t_c"})
    assert all(f"(line {line})" in result.reason for line in lines), result.reason
    assert [g.kept for g in result.goals] == [False]


def test_two_ranges_of_one_contingent_instant_that_do_not_meet_are_a_contradiction(tmp_path: Path) -> None:
    domain, problem = from_text(WINDOW_SPEC, tmp_path)
    apart = replace(problem, constraints=problem.constraints + (
        pm.Member(since_start("t_o"), pm.Interval(30.0, 40.0), line=999),))
    result = Planner(domain, exact=False).plan(apart)
    assert result.plan is None
    assert "nature's instants cannot all hold" in result.reason and "(line 999)" in result.reason
    assert "needs bounds" not in result.reason  # it has bounds: they contradict each other


def test_an_order_nature_keeps_only_sometimes_describes_nature_and_is_planned(tmp_path: Path) -> None:
    # A lamp nature turns on, then off, each within bounds that overlap: the order is nature's
    # promise (the validator judges the plan on the realisations that keep it), not a contradiction.
    lamp = textwrap.dedent(WINDOW_SPEC).replace(
        "  attribute LEVEL()", "  attribute LAMP() { ?value in {ON, OFF}; }\n  attribute LEVEL()").replace(
        "  timepoint t_o, t_c, t_g;\n",
        "  timepoint t_o, t_c, t_g, t_on, t_off;\n"
        "  explained event(LAMP(): (ON, OFF), t_start);\n"
        "  contingent event(LAMP(): (OFF, ON), t_on);\n"
        "  contingent event(LAMP(): (ON, OFF), t_off);\n"
        "  (t_on - t_start) in [10, 30];\n"
        "  (t_off - t_start) in [20, 40];\n"
        "  t_on < t_off;\n")
    domain, problem = from_text(lamp, tmp_path)
    assert len(problem.constraints) == len(from_text(WINDOW_SPEC, tmp_path)[1].constraints) + 3
    result = Planner(domain, exact=False).plan(problem)
    assert result.plan is not None and not result.dropped, result.reason
    assert validate(domain, problem, result.plan) == []


def test_two_goals_holding_one_attribute_at_two_values_at_once_are_said_to_clash(tmp_path: Path) -> None:
    """No budget plans both: the second is dropped at once, naming the first, instead of a search
    that runs out and says "a larger search budget may find one"."""
    both = "hold(DONE(): YES, (t_g, t_end)) goal(2, 0);\n  hold(DONE(): NO, (t_g, t_end)) goal(1, 0);"
    text = WINDOW_SPEC.replace("hold(DONE(): YES, (t_g, t_end)) goal(1, 0);", both)
    domain, problem = from_text(text, tmp_path)
    result = Planner(domain).plan(problem)
    kept, dropped = result.goals
    assert kept.kept and not dropped.kept and dropped.for_others  # each alone has a plan
    assert dropped.reason.startswith("cannot be met together with DONE() = YES (line ")
    assert "both hold DONE() from t_g to t_end, with other values" in dropped.reason
    assert result.plan is not None and not validate(domain, problem, result.plan, dropped_lines={dropped.line})


def test_a_symbol_given_to_a_numeric_attribute_is_refused_with_a_reason(tmp_path: Path) -> None:
    domain, problem = from_text(WINDOW_SPEC, tmp_path)
    wrong = replace(problem, assertions=tuple(
        replace(a, after=pm.Sym("YES")) if isinstance(a, pm.Event) and a.attribute == "LEVEL" else a
        for a in problem.assertions))
    result = Planner(domain, exact=False).plan(wrong)
    assert result.plan is None
    assert "'YES' is not a value of LEVEL, whose values are numbers in [0, 100]" in result.reason


@pytest.mark.parametrize("change, code", [
    ("t_o < t_c;", "contradictory-constraints"),
    ("explained event(LEVEL(): (0, 40), t_start);", "value-outside-domain"),
])
def test_specc_plan_stops_at_the_check_and_prints_no_plan(tmp_path: Path, change: str, code: str) -> None:
    wrong = {"t_o < t_c;": "t_c < t_o;",
             "explained event(LEVEL(): (0, 40), t_start);": "explained event(LEVEL(): (0, YES), t_start);"}[change]
    (tmp_path / "door.spec").write_text(textwrap.dedent(WINDOW_SPEC).replace(change, wrong))
    shown = subprocess.run([sys.executable, "-m", "specc.cli", "plan", str(tmp_path), "--problem", "p"],
                           capture_output=True, text=True, timeout=120)
    output = shown.stdout + shown.stderr
    assert shown.returncode == 2, output  # specs with errors: bad input to plan
    assert f"[{code}]" in output and "controllable" not in output and "REJECTS" not in output
