"""Plan repair (IxTeT's, seed 004 §3.2.1 and §4.2.1.2): after an action failure, a planner with
`repair: on` repairs its plan, keeping the actions still to carry out, before FTplan recovers.
The plans are the rover's (examples/atrv, Modele1); the failure is a move stopped half way, as a
blocked rover's would be; every repaired plan is checked by the independent validator."""

from __future__ import annotations

import json
import subprocess
import sys
from collections import Counter
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest

from specc.campaign.experiments import ORIGINAL, Experiment
from specc.campaign.store import ResultStore
from specc.runtime.ftplan import FtPlan, LocalPool, Outcome, ScriptedExecutor
from specc.runtime.ftplan.config import PlannerConfig, configuration_named, configurations
from specc.runtime.planner import Planner, PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Action, Plan, Repair
from specc.runtime.planner.replan import Fact, replanning_problem
from specc.runtime.planner.validate import validate
from tests.atrv import atrv_models
from tests.conftest import tug_with

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generated"))
from atrv.ftplan import rover  # noqa: E402  (the generated package of examples/atrv)


@cache
def planned(mission: str) -> tuple[pm.PlanningDomain, pm.Problem, Plan]:
    domain, problem = atrv_models(f"{mission}_model1")
    result = Planner(domain).plan(problem)
    assert result.plan is not None, result.reason
    return domain, problem, result.plan


def moves(plan: Plan) -> list[Action]:
    return [a for a in plan.ordered() if a.task == "MOVE"]


def failed_half_way(mission: str, move: int) -> tuple[pm.PlanningDomain, pm.Problem, Plan, Repair, float]:
    """The plan of `mission` whose `move`-th move stopped half way (at half its longest duration):
    the replanning problem of that moment (the robot between the two places, its motion generator
    to initialise again, the pictures and communications done) and what is to repair."""
    domain, problem, plan = planned(mission)
    order = plan.ordered()
    failed = moves(plan)[move]
    done = order[:order.index(failed)]
    x1, y1, x2, y2 = (float(v) for v in failed.args)
    now = failed.dispatch + failed.duration[1] / 2
    facts = [Fact("AT_ROBOT_X", (), (x1 + x2) / 2), Fact("AT_ROBOT_Y", (), (y1 + y2) / 2),
             Fact("MVT_GENERATION_INITIALIZED", (), "FALSE"), Fact("ROBOT_STATUS", (), "STILL"),
             Fact("PTU_POSITION", (), "STRAIGHT")]
    facts += [Fact("PICTURE", a.args, "DONE") for a in done if a.task == "TAKE_PICTURE"]
    facts += [Fact("COMMUNICATION", a.args, "DONE") for a in done if a.task == "COMMUNICATE"]
    goals = [a.line for a in problem.assertions if a.goal is not None]
    present = replanning_problem(problem, facts, goals, now)
    kept = tuple(a.id for a in order[order.index(failed) + 1:])
    return domain, present, plan, Repair(plan, kept), now


def valid(domain: pm.PlanningDomain, problem: pm.Problem, result: PlanResult) -> Plan:
    assert result.plan is not None, result.reason
    assert validate(domain, problem, result.plan, dropped_lines={g.line for g in result.dropped}) == []
    return result.plan


@pytest.mark.parametrize(("mission", "move"), [("M2", 0), ("M2", 1), ("M3", 2), ("M4", 3)])
def test_a_repair_after_a_failed_move_keeps_every_action_still_valid(mission: str, move: int) -> None:
    domain, present, plan, repair, now = failed_half_way(mission, move)
    result = Planner(domain).repair(present, now, repair)
    repaired = valid(domain, present, result)
    kept = Counter((a.task, a.args) for a in repair.actions)
    carried = Counter((a.task, a.args) for a in repaired.actions)
    # Every action still to carry out is in the repaired plan, with its arguments.
    assert kept <= carried
    # What was added: the robot's way on to where the failed move was going, and what a move
    # needs after a failure (its motion generator initialised again).
    added = carried - kept
    failed = moves(plan)[move]
    assert ("MOVE", failed.args) not in added and any(t == "MOVE" and a[2:] == failed.args[2:] for t, a in added)
    assert ("INIT_MVT_GENERATION", ()) in added
    assert sum(added.values()) <= 4
    # The goals the plan met are met again; nothing starts before the failure.
    assert set(repaired.goals) == set(plan.goals) and all(a.dispatch >= now - 1e-6 for a in repaired.actions)
    count = len(repair.kept)
    assert any(n.startswith(f"repaired: {count} of the {count} action(s)") for n in result.notes)


def test_a_plan_the_present_no_longer_fits_is_not_repaired_and_says_why() -> None:
    # M1's first move fails: the old order of things no longer reaches W1's window in time, so
    # the repair finds nothing within its budget, and a replanning from scratch does.
    domain, present, _, repair, now = failed_half_way("M1", 0)
    result = Planner(domain).repair(present, now, repair)
    assert result.plan is None and result.reason.startswith("no repair of the plan: no plan within")
    assert all(not g.kept for g in result.goals)
    valid(domain, present, Planner(domain).plan(present, now))


def first_move_blocked() -> ScriptedExecutor:
    """Actions end at their shortest duration, moves report where they end; the first move stops
    half way, where the rover says it is."""
    failures = [True]

    def world(action: Action, now: float) -> Outcome:
        if action.task != "MOVE":
            return Outcome(duration=action.duration[0])
        x1, y1, x2, y2 = (float(a) for a in action.args)
        if failures:
            failures.pop()
            return Outcome(False, action.duration[1] / 2, (("ROBOT_POSITION", ((x1 + x2) / 2, (y1 + y2) / 2)),),
                           why="blocked half way")
        return Outcome(duration=action.duration[0], reports=(("ROBOT_POSITION", (x2, y2)),))

    return ScriptedExecutor(world)


def mission_with(repair: bool, planner: object | None = None) -> FtPlan:
    domain, problem = atrv_models("M2_model1")
    config = replace(rover.CONFIG, planners=(PlannerConfig("p1", "model1", repair=repair),), policy="successive")
    return FtPlan(config, problem, LocalPool({"p1": planner or Planner(domain)}), first_move_blocked())


def kinds(ftplan: FtPlan) -> list[str]:
    return [e.kind for e in ftplan.events if e.kind not in ("report", "goal-met")]


def test_ftplan_carries_the_repaired_plan_out_instead_of_replanning() -> None:
    repairing = mission_with(repair=True)
    result = repairing.run()
    assert result.success and result.repairs == result.repaired == 1
    assert result.rounds == 1 and result.replannings == 0 and result.plannings == 1
    assert kinds(repairing) == ["plan-request", "plan", "execute", "action-failed", "safe-state", "repair-request",
                                "plan", "repaired", "execute", "mission-end"]
    replanning = mission_with(repair=False)
    without = replanning.run()
    assert without.success and without.repairs == 0 and without.replannings == 1
    assert "repair-request" not in kinds(replanning)


class PlansOnly:
    """A planner of its own (a factory's) that plans but cannot repair."""

    def __init__(self) -> None:
        self.planner = Planner(atrv_models("M2_model1")[0])

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        return self.planner.plan(problem, now)


def test_a_planner_that_cannot_repair_leaves_the_recovery_to_ftplan() -> None:
    ftplan = mission_with(repair=True, planner=PlansOnly())
    result = ftplan.run()
    assert result.success and result.repairs == 1 and result.repaired == 0 and result.replannings == 1
    said = next(e.text for e in ftplan.events if e.kind == "repair-failed")
    assert "PlansOnly does not repair plans" in said
    assert result.planner_failures == 0  # a repair found wanting is no planner failure


def test_configuration_suffixes_turn_repair_on_or_off_for_every_planner() -> None:
    known = configurations(rover.CONFIG)
    assert not any(p.repair for p in configuration_named(known, "Robot1/2").planners)
    both = configuration_named(known, "Robot1/2-repair")
    assert [p.repair for p in both.planners] == [True, True] and both.policy == "successive"
    stacked = configuration_named(known, "Robot1/2c-repair-noanalyzer")
    assert all(p.repair for p in stacked.planners) and stacked.analyzer == () and stacked.policy == "concurrent"
    with pytest.raises(ValueError, match="both on .* and off"):
        configuration_named(known, "Robot1/2-repair-norepair")
    with pytest.raises(ValueError, match="-noanalyzer twice"):
        configuration_named(known, "Robot1/2-noanalyzer-noanalyzer")
    with pytest.raises(KeyError):
        configuration_named(known, "Robot9-repair")
    # A planner's name: that planner alone, as its RobotN (and with suffixes too).
    second = rover.CONFIG.planners[1].name
    assert configuration_named(known, second) == known["Robot2"]
    assert [p.repair for p in configuration_named(known, f"{second}-repair").planners] == [True]


def test_a_planner_block_turns_repair_on(tmp_path: Path) -> None:
    _, config, _ = tug_with(tmp_path, "quick", "repair: on;")
    assert [(p.name, p.repair) for p in config.planners] == [("quick", True), ("careful", False)]


def test_a_run_and_a_campaign_with_repair_on_the_rover(tmp_path: Path) -> None:
    """The whole robot, planners in their own processes: M3 in W3, where moves fail, repaired by
    Robot1-repair with no replanning; and a small real campaign of that configuration."""
    runs = tmp_path / "runs"
    done = subprocess.run([sys.executable, "-m", "specc.cli", "run", "examples/atrv", "--mission", "M3", "--world",
                           "W3", "--config", "Robot1-repair", "--runs", str(runs)], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr
    (folder,) = runs.iterdir()
    report = json.loads((folder / "report.json").read_text())
    measures = report["measures"]
    assert measures["nu"] == 1 and measures["repairs"] >= 1 and measures["repaired"] >= 1
    assert measures["replannings"] == 0
    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    said = [e["event"] for e in events if e.get("kind") == "ftplan"]
    assert said.count("repair-request") == measures["repairs"] and said.count("repaired") == measures["repaired"]
    assert "plan repairs" in (folder / "summary.txt").read_text()
    store = tmp_path / "repair.sqlite"
    campaign = subprocess.run([sys.executable, "-m", "specc.cli", "campaign", "examples/atrv", "--mutants", "1",
                               "--missions", "M3", "--worlds", "W3", "--runs", "1", "--configs", "Robot1-repair",
                               "--workers", "2", "--seed", "0", "--store", str(store), "-q"],
                              capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert campaign.returncode == 0, campaign.stderr
    with ResultStore(store) as results:
        original = next(o for o in results.outcomes()
                        if o.experiment == Experiment("Robot1-repair", ORIGINAL, "M3", "W3", 0))
    assert original.status == "done" and original.measures is not None
    assert original.measures["repairs"] == measures["repairs"] and original.measures["replannings"] == 0
