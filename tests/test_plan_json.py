"""`specc plan --json`: the plan as data another tool reads (docs/planning.md, "Plans for other
tools"). The test reads the file as such a tool would, and checks the plan against its own
partial order and windows, without specc's code."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import EXAMPLES

EPSILON = 1e-6


def planned(tmp_path: Path, robot: str, *args: str) -> dict[str, Any]:
    path = tmp_path / "plan.json"
    result = subprocess.run([sys.executable, "-m", "specc.cli", "plan", str(EXAMPLES / robot), *args,
                             "--json", str(path)], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    assert f"wrote {path}" in result.stdout
    return json.loads(path.read_text(encoding="utf-8"))  # strict JSON: no NaN or Infinity


def at_most(low: float | None, high: float | None) -> bool:
    """low <= high, where null is unbounded (below for a low, above for a high)."""
    return low is None or high is None or low <= high + EPSILON


@pytest.mark.parametrize("robot, args", [("tug", ("--problem", "shuttle")),
                                         ("atrv", ("--problem", "M1", "--domain", "model1"))])
def test_the_json_plan_holds_by_its_own_partial_order_and_windows(tmp_path: Path, robot: str,
                                                                  args: tuple[str, ...]) -> None:
    document = planned(tmp_path, robot, *args)
    assert document["format"] == "specc-plan/1" and document["validator"]["violations"] == []
    plan = document["plan"]
    assert plan is not None and plan["controllability"] == "strong"
    actions = plan["actions"]
    assert actions and [a["dispatch"] for a in actions] == sorted(a["dispatch"] for a in actions)
    for action in actions:
        low, high = action["duration"]
        assert at_most(action["window"][0], action["dispatch"]) and at_most(action["dispatch"], action["window"][1])
        assert at_most(action["dispatch"] + low, action["ends_by"])
        assert high is None or at_most(action["ends_by"], action["dispatch"] + high)
        assert plan["timepoints"][action["start"]] == action["dispatch"]
    assert plan["makespan"] == max(a["ends_by"] for a in actions)
    timepoints, uncontrolled = plan["timepoints"], plan["uncontrolled"]

    def earliest(point: str) -> float:
        return timepoints[point] if point in timepoints else uncontrolled[point][0]

    def latest(point: str) -> float | None:
        return timepoints[point] if point in timepoints else uncontrolled[point][1]

    checked = 0
    for before, after, delay in plan["orderings"]:
        if delay is None or before not in timepoints | uncontrolled or after not in timepoints | uncontrolled:
            continue
        # Strong controllability: the ordering holds for the latest `before` and the earliest `after`.
        last = latest(before)
        assert last is None or earliest(after) >= last + delay - EPSILON, (before, after, delay)
        checked += 1
    assert checked >= len(actions)  # each action is at least ordered after its start
    kept = [g for g in document["goals"] if g["kept"]]
    assert kept and all(g["reason"] == "" for g in kept)
    assert all(g["reason"] for g in document["goals"] if not g["kept"])


def test_dropped_goals_say_why_and_printing_to_stdout_prints_json_only(tmp_path: Path) -> None:
    # One second is too short to move the cart: its goal is dropped, the robot already is at DOCK.
    # A plan of no action while a goal is dropped does nothing asked of it: no plan (1), and the
    # reason names the mission's end, which a contradiction between two timepoints does not.
    result = subprocess.run([sys.executable, "-m", "specc.cli", "plan", str(EXAMPLES / "tug"), "--problem",
                             "shuttle", "--horizon", "1", "--json", "-"], capture_output=True, text=True, timeout=300)
    assert result.returncode == 1, result.stderr
    document = json.loads(result.stdout)  # nothing but the document on stdout
    dropped = [g for g in document["goals"] if not g["kept"]]
    lines = (EXAMPLES / "tug" / "planning.spec").read_text().splitlines()
    cart_goal = next(number for number, line in enumerate(lines, 1)  # the shuttle's (the first problem's)
                     if line.strip().startswith("hold(CART_AT(CART1): C"))
    assert [g["line"] for g in dropped] == [cart_goal] and "impossible even alone" in dropped[0]["reason"]
    assert "the mission ends by 1 s at the latest" in dropped[0]["reason"]
    assert document["plan"]["actions"] == [] and document["plan"]["makespan"] == 0.0


def test_the_variables_of_dropped_goals_are_said_free_not_given_a_made_up_value(tmp_path: Path) -> None:
    # M4 with Modele1 cut to 300 s drops three photos: the initial facts PICTURE(OBJk, ?xk, ?yk)
    # of those photos name variables no action of the plan binds.
    document = planned(tmp_path, "atrv", "--problem", "M4", "--domain", "model1", "--horizon", "300",
                       "--improve", "0")
    dropped = [g["description"] for g in document["goals"] if not g["kept"]]
    photos = sorted(d.split("(")[1].split(",")[0] for d in dropped if d.startswith("PICTURE"))
    assert photos == ["OBJ3", "OBJ4", "OBJ5"]
    free = document["plan"]["free"]
    assert sorted(free) == sorted(f"?{axis}{k[-1]}" for k in photos for axis in "xy")
    assert not set(free) & set(document["plan"]["bindings"]) and len(document["plan"]["bindings"]) == 4


def test_the_planner_option_plans_as_that_ftplan_planner_does_in_a_run(tmp_path: Path) -> None:
    """`--planner careful`: the tug's second planner, given a flaw order and an improvement here,
    plans with them and with the node limit FTplan's deterministic timing gives it, the plan a
    run would get; a planner no block has, or one planning another domain, is bad input."""
    import shutil

    from specc.analysis.ftplan import ftplan_config
    from specc.analysis.planning import domain_block, domain_model, problem_model
    from specc.model import nodes as m
    from specc.pipeline import load
    from specc.plan_report import choose_problem
    from specc.runtime.ftplan.component import planners_as_run
    from specc.runtime.ftplan.planners import standard_planner

    robot = tmp_path / "tug"
    shutil.copytree(EXAMPLES / "tug", robot)
    ftplan = robot / "ftplan.spec"
    ftplan.write_text(ftplan.read_text().replace("    domain: warehouse_slow;\n",
                                                 "    domain: warehouse_slow;\n    flaws: oldest-task-first;\n"
                                                 "    improve: 40;\n", 1))

    def plan(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "specc.cli", "plan", str(robot), *args],
                              capture_output=True, text=True, timeout=300)

    shown = plan("--problem", "shuttle_slow", "--planner", "careful", "--json", "-")
    assert shown.returncode == 0, shown.stderr
    document = json.loads(shown.stdout)
    program = load([robot]).program
    assert program is not None
    chosen = choose_problem(program, "shuttle_slow", None)
    model, problem = domain_model(program, domain_block(program, chosen)), problem_model(program, chosen)
    block = next(i for i in program.items if isinstance(i, m.FtPlan))
    config = next(c for c in planners_as_run(ftplan_config(block, program), "model") if c.name == "careful")
    assert config.flaws == "oldest-task-first" and config.improve == 40 and config.node_limit is not None
    expected = standard_planner(config, {model.name: model}).plan(problem)
    assert expected.plan is not None
    assert document["search"]["partial_plans"] == expected.nodes
    assert sorted((a["task"], a["args"]) for a in document["plan"]["actions"]) == sorted(
        (a.task, list(a.args)) for a in expected.plan.actions)
    default = json.loads(plan("--problem", "shuttle_slow", "--json", "-").stdout)
    # the command's own defaults search otherwise
    assert default["search"]["partial_plans"] != document["search"]["partial_plans"]

    misspelt = plan("--problem", "shuttle_slow", "--planner", "carefull")
    assert misspelt.returncode == 2 and "no FTplan planner 'carefull' (did you mean 'careful'?)" in misspelt.stderr
    elsewhere = plan("--problem", "shuttle", "--planner", "careful")
    assert elsewhere.returncode == 2 and "plans in domain 'warehouse_slow'" in elsewhere.stderr


def test_a_plan_of_no_action_that_drops_a_goal_only_for_one_it_keeps_is_a_plan(tmp_path: Path) -> None:
    """Staying HOME (true from the start, priority 2) and being at A at the end (priority 1)
    exclude each other: the best plan keeps the first with no action and drops the second, for
    the first only. That is the planner's answer (exit 0), unlike a plan of no action that drops
    a goal for itself (impossible, or not planned alone: exit 1)."""
    spec = tmp_path / "hops.spec"
    spec.write_text("""
domain hops {
  attribute AT() { ?value in {HOME, A}; }
  task HOP(?from, ?to) (t_start, t_end) {
    ?from in {HOME, A};
    ?to in {HOME, A};
    ?from != ?to;
    event(AT(): (?from, ?to), t_end);
    contingent (t_end - t_start) in [5, 10];
  } nonPreemptive
}
problem both for hops {
  timepoint th, ta;
  explained event(AT(): (A, HOME), t_start);
  hold(AT(): HOME, (th, t_end)) goal(2, 0);
  hold(AT(): A, (ta, t_end)) goal(1, 0);
  (t_end - t_start) in [0, 100];
}
""")
    result = subprocess.run([sys.executable, "-m", "specc.cli", "plan", str(spec), "--problem", "both", "--json", "-"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    document = json.loads(result.stdout)
    assert document["plan"]["actions"] == []
    assert [(g["kept"], "together with the goals kept before it" in g["reason"]) for g in document["goals"]] == [
        (True, False), (False, True)]
