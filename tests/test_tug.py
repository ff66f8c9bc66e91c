"""The third robot, not from the seeds (examples/tug): a warehouse tug written with specc alone,
its codels its only Python. Its missions run from its system block: one its procedures carry out
alone, and planned ones where FTplan's plans are carried out by PRS procedures, which ask the
executive for services, which run module requests."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from specc.run.events import read_events
from tests.conftest import EXAMPLES, ROOT

TUG = EXAMPLES / "tug"


def specc(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)


def test_the_tug_delivers_a_cart_with_its_procedures_alone(tmp_path: Path) -> None:
    result = specc("run", TUG, "--mission", "deliver", "--runs", tmp_path, "-q")
    assert result.returncode == 0, result.stderr
    folder = tmp_path / "tug-deliver-hall-s0"
    events = read_events(folder / "events.jsonl")
    services = [e["service"] for e in events if e["kind"] == "request"]
    # FETCH A C: to A, hitch (and the load told), to C, unhitch, back to the dock.
    assert services == ["GOTO", "HITCH", "SET-LOAD", "GOTO", "UNHITCH", "SET-LOAD", "GOTO"]
    facts = [e["fact"] for e in events if e["kind"] == "fact" and e["change"] == "concluded"]
    assert facts == ["(HOOK BUSY)", "(HOOK FREE)"]
    assert {p.name for p in folder.iterdir()} >= {"map.png", "timeline.png", "report.json"}


def test_a_planned_mission_shows_each_action_s_goal_service_and_module_request(tmp_path: Path) -> None:
    result = specc("run", TUG, "--mission", "shuttle", "--world", "crowded", "--runs", tmp_path, "-q")
    assert result.returncode == 0, result.stderr
    folder = tmp_path / "tug-shuttle-crowded-Robot1-2-s0"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "succeeded" and report["measures"]["planned_goals_met"] == 2
    # The summary says FTplan's figures as seed 004 does (σ, κ, R), and whose judgement the goals are.
    summary = (folder / "summary.txt").read_text()
    assert "goals met: CART_AT 1/1 (sigma_CART_AT 100 %), AT 1/1 (sigma_AT 100 %)" in summary
    assert "(each goal as FTplan's ledger counted it" in summary and "planned_goals_met:" not in summary
    events = read_events(folder / "events.jsonl")
    chains = []
    for start in (e for e in events if e["kind"] == "action" and e["status"] == "started"):
        end = next(e for e in events if e["kind"] == "action" and e["status"] != "started"
                   and e["id"] == start["id"] and e["plan"] == start["plan"])
        requests = [e for e in events if e["kind"] == "request" and start["t"] <= e["t"] <= end["t"]]
        chains.append((start["task"], start["goal"], [(r["service"], r["request"]) for r in requests]))
    assert chains == [
        ("MOVE", "!(GO-PLACE A)", [("GOTO", "drive.Goto")]),
        ("HITCH", "!(HITCH-CART)", [("HITCH", "lift.Hitch"), ("SET-LOAD", "drive.SetLoad")]),
        ("MOVE", "!(GO-PLACE C)", [("GOTO", "drive.Goto")]),
        ("UNHITCH", "!(HITCH-OFF)", [("UNHITCH", "lift.Unhitch"), ("SET-LOAD", "drive.SetLoad")]),
        ("MOVE", "!(GO-PLACE DOCK)", [("GOTO", "drive.Goto")]),
    ]
    # What a procedure concludes last (the hook's state) is logged before the action it carries
    # out ends, at its own time: not when the next action's request is logged.
    ends = {e["task"]: e for e in events if e["kind"] == "action" and e["status"] == "ended"}
    hooked = [e for e in events if e["kind"] == "fact" and e["fact"] == "(HOOK BUSY)" and e["change"] == "concluded"]
    assert hooked and hooked[0]["t"] <= ends["HITCH"]["t"] and events.index(hooked[0]) < events.index(ends["HITCH"])



def test_when_the_first_planner_plans_nothing_the_second_plans_the_goals_of_its_own_problem(tmp_path: Path) -> None:
    # The quick planner's model made wrong (a hitched cart stays where it was): it finds no plan, and
    # FTplan asks the careful one, whose problem states the same mission on other lines. It must be
    # asked for those goals (by what they say, not by the first problem's lines) and deliver.
    import shutil

    tug = tmp_path / "tug"
    shutil.copytree(TUG, tug)
    planning = (tug / "planning.spec").read_text()
    wrong = planning.replace("event(CART_AT(?c): (?p, TUG), t_end);", "event(CART_AT(?c): (?p, ?p), t_end);", 1)
    assert wrong != planning
    (tug / "planning.spec").write_text(wrong)
    # From its own folder: the copy compiles into tmp_path/generated, not over the project's generated/.
    result = subprocess.run([sys.executable, "-m", "specc.cli", "run", "tug", "--mission", "shuttle", "--runs", "runs",
                             "-q"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    folder = tmp_path / "runs" / "tug-shuttle-hall-Robot1-2-s0"
    assert json.loads((folder / "report.json").read_text())["measures"]["planned_goals_met"] == 2
    plans = [e["text"] for e in read_events(folder / "events.jsonl") if e["kind"] == "ftplan" and e["event"] == "plan"]
    assert plans[0].startswith("quick: 0 actions") and plans[1].startswith("careful: 5 actions"), plans


def test_a_table_of_the_tug(tmp_path: Path) -> None:
    # hall given twice: run once, counted once.
    result = specc("table", TUG, "--mission", "deliver", "--world", "hall", "--world", "crowded", "--world", "hall",
                   "--runs", tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "tug-table.json").read_text())
    assert [(row["mission"], row["world"], row["succeeded"]) for row in data["missions"]] == [
        ("deliver", "hall", 1), ("deliver", "crowded", 1)]
    # The pallets of the crowded hall slow the tug down (its speed policy).
    hall, crowded = (row["simulated_time"] for row in data["missions"])
    assert crowded > hall


@pytest.mark.parametrize("args, message", [
    (("--mission", "shuttle", "--config", "Robot3"), "no robot configuration 'Robot3'"),
    (("--mission", "shuttle", "--config", "robot1"), "no robot configuration 'robot1' (did you mean 'Robot1'?)"),
    (("--mission", "shuttle", "--config", "Robot1,Robot2"), "one configuration each time: repeat the option"),
    (("--mission", "fetch", "--world", "hall"), "robot 'tug' has no mission 'fetch'"),
    (("--goal", "!(GO-PLACE E)"), "no KA of procedures 'tug_tasks' is invoked by it (they are invoked by "
                                  "!(GO-PLACE DOCK), !(GO-PLACE A)"),  # E is no station: no run, no folder
])
def test_bad_options_for_the_tug_are_one_line(tmp_path: Path, args: tuple[str, ...], message: str) -> None:
    result = specc("run", TUG, *args, "--runs", tmp_path, "-q")
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("output, message", [
    ("afile/table.md", "the table's folder '{tmp}/afile' is a file, not a folder"),
    ("afolder", "--output '{tmp}/afolder' is a folder: give the table's file"),
])
def test_a_table_that_could_not_be_written_is_refused_before_any_run(tmp_path: Path, output: str,
                                                                      message: str) -> None:
    (tmp_path / "afile").write_text("")
    (tmp_path / "afolder").mkdir()
    result = specc("table", TUG, "--mission", "deliver", "--runs", tmp_path / "runs", "-o", tmp_path / output, "-q")
    assert result.returncode == 2 and message.format(tmp=tmp_path) in result.stderr, result.stderr
    assert not (tmp_path / "runs").exists()


def test_a_planned_mission_whose_problem_has_no_goal_is_refused_not_reported_a_success(tmp_path: Path) -> None:
    import shutil

    tug = tmp_path / "tug"
    shutil.copytree(TUG, tug)
    planning = (tug / "planning.spec").read_text()
    shuttle = planning.index("problem shuttle ")
    end = planning.index("\n}", shuttle)
    goalless = planning[:shuttle] + planning[shuttle:end].replace(" goal(2, 0)", "").replace(" goal(1, 0)", "") \
        + planning[end:]
    (tug / "planning.spec").write_text(goalless)
    result = subprocess.run([sys.executable, "-m", "specc.cli", "run", "tug", "--mission", "shuttle", "--runs", "runs",
                             "-q"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert result.returncode == 2, result.stdout + result.stderr
    assert "plans problem 'shuttle', which has no goal" in result.stderr
    assert not (tmp_path / "runs").exists()


def test_a_mission_stopped_at_its_horizon_counts_no_goal_a_stopped_action_was_changing(tmp_path: Path) -> None:
    # 20 s: the first move (DOCK to A) is on its way. FTplan's facts still say the tug is at the
    # dock, but the move was changing that: the return home is not met, and FTplan's end of
    # mission is dated at the horizon, not at its own last date (8.25 s, its planning).
    result = specc("run", TUG, "--mission", "shuttle", "--horizon", "20", "--runs", tmp_path, "-q")
    folder = tmp_path / "tug-shuttle-hall-Robot1-2-s0-horizon20"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "horizon" and report["measures"]["planned_goals_met"] == 0, result.stderr
    events = read_events(folder / "events.jsonl")
    missed = [e["text"] for e in events if e["kind"] == "ftplan" and e["event"] == "goal-missed"]
    assert any(text.startswith("AT() = DOCK") and "MOVE(DOCK, A), which changes it, was stopped" in text
               for text in missed)
    times = [e["t"] for e in events]
    assert times == sorted(times)


def test_a_mission_no_seed_of_which_succeeded_has_no_mean_time() -> None:
    from specc.run.session import RunOutcome
    from specc.run.sweep import SweepResult, mission_rows

    failed = [RunOutcome(Path(f"run{seed}"), "tug", {"mission": "deliver", "world": "hall", "outcome": "failed",
                                                     "simulated_time": 31.0 + seed, "measures": {"distance": 2.0}}, "")
              for seed in range(2)]
    (row,) = mission_rows(failed)
    assert (row.succeeded, row.simulated_time, row.means) == (0, None, {"distance": 2.0})  # not "0 s per run"
    assert "| 0 | 0 % | - |" in SweepResult("tug", failed, [], mission_rows(failed)).markdown()


def test_a_move_that_fails_leaves_the_tug_away_from_every_station(tmp_path: Path) -> None:
    # A crate across the way to A: the move is BLOCKED. FTplan's state rule puts the tug AWAY (not
    # back at the dock, as it did), so the return home is not counted met, the next plan moves
    # from AWAY, and the run's why names the failures the goals' reasons would hide.
    world = tmp_path / "blocked.toml"
    world.write_text((TUG / "worlds" / "hall.toml").read_text().replace('name = "hall"', 'name = "blocked"')
                     + "\n[[obstacles]]\npolygon = [[10.6, 6.6], [11.4, 6.6], [11.4, 9.2], [10.6, 9.2]]\n")
    result = specc("run", TUG, "--mission", "shuttle", "--world", world, "--horizon", "60", "--runs", tmp_path,
                   "-q", "--no-pictures")
    folder = tmp_path / "tug-shuttle-blocked-Robot1-2-s0-horizon60"
    report = json.loads((folder / "report.json").read_text())
    assert report["measures"]["planned_goals_met"] == 0, result.stderr
    assert "action failure(s); the last: MOVE(" in report["why"] and "GOTO answered BLOCKED" in report["why"]
    events = read_events(folder / "events.jsonl")
    started = [e["text"] for e in events if e["kind"] == "ftplan" and e["event"] == "report"
               and e["text"].startswith("started MOVE")]
    assert started[0] == "started MOVE(DOCK, A)" and "started MOVE(AWAY, A)" in started[1:]


def test_codels_beside_the_module_specs_instead_of_the_robot_s_folder_are_found_and_named(tmp_path: Path) -> None:
    # `specc check` finds codels from a spec's folder upwards; `specc run` imports them from the
    # robot's folder: codels put in modules/ pass the one and fail the other, which says where they are.
    import shutil

    tug = tmp_path / "tug"
    shutil.copytree(TUG, tug, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.move(tug / "tug_codels", tug / "modules" / "tug_codels")
    result = specc("run", tug, "--mission", "deliver", "-g", tmp_path / "gen", "--runs", tmp_path / "runs", "-q")
    assert result.returncode == 2, result.stdout + result.stderr
    assert "no tug_codels/ with the codels robot 'tug' names here" in result.stderr
    assert "it is in modules/tug_codels: move tug_codels/ up into the robot's folder" in result.stderr


def test_a_table_naming_a_goal_mission_beside_a_configuration_runs_it_once_without(tmp_path: Path) -> None:
    # `deliver` posts a goal (no FTplan): named with --config it runs once, without any, instead
    # of stopping the table; the planned `shuttle` runs with each configuration.
    result = specc("table", TUG, "--mission", "deliver", "--mission", "shuttle", "--config", "Robot1",
                   "--config", "Robot2", "--runs", tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "tug-table.json").read_text())
    assert sorted((row["mission"], row["configuration"] or "") for row in data["missions"]) == [
        ("deliver", ""), ("shuttle", "Robot1"), ("shuttle", "Robot2")]


def test_a_table_for_one_configuration_runs_the_planned_missions_alone(tmp_path: Path) -> None:
    # --config is FTplan's: without --mission, the missions it plans (not `deliver`, which only
    # posts a goal and used to stop the table with "mission deliver is not planned").
    result = specc("table", TUG, "--config", "Robot1", "--runs", tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "tug-table.json").read_text())
    assert [(row["mission"], row["configuration"]) for row in data["missions"]] == [
        ("shuttle", "Robot1"), ("fetch_b", "Robot1")]
    table = (tmp_path / "tug-table.md").read_text()
    assert all(not line.endswith(" ") for line in table.splitlines())
    # Planned missions post no goal to the supervisor: no columns of posted goals (zeros, which
    # read as goals failed), FTplan's own counted instead.
    heading = table.splitlines()[0]
    assert "planned_goals_met" in heading and "| goals |" not in heading and "goals_succeeded" not in heading


def test_a_request_no_executive_ka_serves_is_said_by_check_and_fails_in_verify(tmp_path: Path) -> None:
    """The guide's request protocol has a KA per service (`!(EXEC HITCH $R)`): a goal asking it
    for a service none of them names has no applicable KA and fails when it runs. `specc check`
    says so, and `specc verify` no longer answers it as the executive would (it said "the goal
    achieved" of a delivery that fails at run time)."""
    guide = (ROOT / "docs" / "your-robot.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```[a-z]*\n(.*?)^```$", guide, flags=re.S | re.M)
    (block,) = [b for b in blocks if "property: executive" in b]
    assert "!(EXEC UNHITCH $R);" in block
    robot = tmp_path / "tug"
    shutil.copytree(TUG, robot)
    (robot / "procedures.spec").write_text(block.replace("!(EXEC UNHITCH $R);", "!(EXEC GOTO $R);"),
                                           encoding="utf-8")
    checked = specc("check", robot)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert "asks for service 'GOTO', but no executive KA serves it (those of EXEC serve HITCH, UNHITCH)" in \
        checked.stdout + checked.stderr and "[no-applicable-ka]" in checked.stdout + checked.stderr
    proven = specc("verify", robot, "--goal", "!(FETCH A C)")
    assert "ends: 0 with the goal achieved, 1 with it failed" in proven.stdout, proven.stdout + proven.stderr


def test_a_request_id_outside_the_request_protocol_is_said_with_the_protocol_to_use(tmp_path: Path) -> None:
    # The guide's procedures with every `property: executive` taken out: the requests' ids are
    # ints the net cannot enumerate, and the message points to the protocol rather than to a
    # domain no id has.
    guide = (ROOT / "docs" / "your-robot.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```[a-z]*\n(.*?)^```$", guide, flags=re.S | re.M)
    (block,) = [b for b in blocks if "property: executive" in b]
    robot = tmp_path / "tug"
    shutil.copytree(TUG, robot)
    (robot / "procedures.spec").write_text(block.replace("property: executive;", ""), encoding="utf-8")
    refused = specc("verify", robot, "--goal", "!(FETCH A C)")
    said = refused.stdout + refused.stderr
    assert refused.returncode != 0 and "variable $ID of KA 'ExecHitch' ranges over an unbounded domain" in said
    assert said.count("a request's id: send the request and wait for its reply in a KA with `property: executive`") \
        >= 4  # ExecXY, ExecHitch, ExecUnhitch, ExecLoad


def test_the_guide_s_verifiable_procedures_verify_and_run_the_delivery(tmp_path: Path) -> None:
    """docs/your-robot.md's procedures written for `specc verify` (the request protocol in
    `property: executive` KAs, goals of finite domains), in place of the tug's own: the delivery
    is proven free of deadlocks (one end with the goal achieved) and still runs to success."""
    guide = (ROOT / "docs" / "your-robot.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```[a-z]*\n(.*?)^```$", guide, flags=re.S | re.M)  # each fenced block's text
    (block,) = [b for b in blocks if "property: executive" in b]
    robot = tmp_path / "tug"
    shutil.copytree(TUG, robot)
    (robot / "procedures.spec").write_text(block, encoding="utf-8")
    proven = specc("verify", robot, "--goal", "!(FETCH A C)")
    assert proven.returncode == 0, proven.stdout + proven.stderr
    assert "ends: 1 with the goal achieved, 0 with it failed" in proven.stdout and "\ndeadlock:" not in proven.stdout
    ran = specc("run", robot, "--mission", "deliver", "--world", "crowded", "--runs", tmp_path / "runs", "-q",
                "--no-pictures", "-g", tmp_path / "generated")  # not the repository's generated/: a copy's
    assert ran.returncode == 0, ran.stderr


def test_the_task_level_s_inputs_of_the_wrong_count_or_type_are_answered_bad_input(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """GOTO takes x and y, doubles: one input, or a word for x, is the task level's mistake
    (BAD-INPUT, saying which), not an input function that failed (ERROR)."""
    import importlib

    from specc.runtime import functional as rt

    monkeypatch.syspath_prepend(str(ROOT / "generated"))
    monkeypatch.syspath_prepend(str(TUG))  # the codels
    registry = rt.Registry()
    importlib.import_module("tug.modules").create_all(registry)
    executive = importlib.import_module("tug.executive.tug").create(registry)
    executive.request("GOTO", 1, inputs=(2.0,))
    executive.request("GOTO", 2, inputs=("far", 1.0))
    replies = [m for m in executive.messages if m.kind == "REPLY"]
    assert [(m.id, m.result) for m in replies] == [(1, "BAD-INPUT"), (2, "BAD-INPUT")]
    assert replies[0].detail == "GOTO takes x, y from the task level; 1 given"
    assert replies[1].detail == "GOTO's input x: expected float, got str"
    # A bare value, not a tuple: the caller's mistake, said with the service's inputs.
    with pytest.raises(TypeError, match=r"inputs of SET-LOAD: give a tuple of values in the order the service takes "
                                        r"them \(load\), e.g. \(1,\), not int 1"):
        executive.request("SET-LOAD", 3, inputs=1)  # type: ignore[arg-type]


def test_a_run_with_a_mutant_of_the_planning_model_says_which(tmp_path: Path) -> None:
    """`specc run --mutant ID` reruns one experiment of a campaign: FTplan plans in the mutant,
    the report and the summary name it, and a wrong id or an unplanned mission is one line."""
    result = specc("run", TUG, "--mission", "shuttle", "--config", "Robot1", "--mutant", "warehouse-0124",
                   "--runs", tmp_path, "-q", "--no-pictures")
    folder = tmp_path / "tug-shuttle-hall-Robot1-s0-warehouse-0124"
    report = json.loads((folder / "report.json").read_text())
    assert report["mutant"] == {"id": "warehouse-0124",
                                "description": "planning.spec:38:29: value TUG -> DOCK of CART_AT (after) in HITCH"}
    assert (folder / "summary.txt").read_text().startswith("with mutant warehouse-0124: planning.spec:38:29: ")
    # The mutant is what FTplan plans in: HITCH no longer puts the cart on the tug, and the cart's
    # goal is left aside (the original model meets it: tests above).
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert report["outcome"] == "failed" and "CART_AT(CART1) = C" in report["why"]
    wrong = specc("run", TUG, "--mission", "shuttle", "--mutant", "warehouse-9999", "--runs", tmp_path)
    assert wrong.returncode == 2 and "--mutant warehouse-9999: no such mutant (the mutants of 'warehouse' are " \
        "warehouse-0001 to warehouse-" in wrong.stderr
    unplanned = specc("run", TUG, "--mission", "deliver", "--mutant", "warehouse-0001", "--runs", tmp_path)
    assert unplanned.returncode == 2 and "mission deliver of robot 'tug' is not planned" in unplanned.stderr
