"""`specc run`, `specc replay` and `specc table` as a user meets them: real missions end to end
(compiled package, modules on the simulated robot, executive or FTplan and its planners), run
folders, exit codes, one clear line for bad input, never a traceback."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from specc.run import RunError
from specc.run.events import read_events
from specc.run.session import RunCrashed, RunRequest, run_compiled
from specc.runtime.sim import Polygon, World, load_world
from tests.conftest import EXAMPLES, PNG_MAGIC, ROOT, is_png

ATRV = EXAMPLES / "atrv"
HILARE = EXAMPLES / "hilare"


def specc(*args: str | Path, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=timeout)


def assert_clean_failure(result: subprocess.CompletedProcess[str], code: int, message: str) -> None:
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    assert message in result.stderr, result.stderr


@pytest.fixture(scope="module")
def m1_w2(tmp_path_factory: pytest.TempPathFactory) -> tuple[subprocess.CompletedProcess[str], Path]:
    runs = tmp_path_factory.mktemp("runs")
    return specc("run", ATRV, "--mission", "M1", "--world", "W2", "--config", "Robot1/2", "--runs", runs), runs


def test_a_rover_mission_leaves_a_run_folder_with_log_report_and_pictures(m1_w2: tuple) -> None:
    result, runs = m1_w2
    assert result.returncode == 0, result.stderr
    folder = runs / "atrv-M1-W2-Robot1-2-s0"
    assert f"run folder: {folder}" in result.stdout
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "succeeded" and report["configuration"] == "Robot1/2"
    measures = report["measures"]
    assert measures["nu"] == 1 and measures["kappa"] == 0
    assert measures["goals"] == [{"kind": "p", "asked": 3, "met": 3}, {"kind": "c", "asked": 2, "met": 2},
                                 {"kind": "h", "asked": 1, "met": 1}]
    events = read_events(folder / "events.jsonl")
    assert events[0]["kind"] == "mission-start" and events[-1]["kind"] == "mission-end"
    # The report agrees with the log it was measured from.
    assert report["simulated_time"] == pytest.approx(events[-1]["t"], abs=1e-3)
    assert measures["distance"] == pytest.approx(events[-1]["distance"], abs=1e-3)
    summary = (folder / "summary.txt").read_text()
    assert "mission succeeded" in summary and "p 3/3 (sigma_p 100 %)" in summary
    for picture in report["pictures"]:
        path = folder / picture
        assert is_png(path) and f"picture: {path}" in result.stdout
    assert {"map.png", "timeline.png"} <= set(report["pictures"])


def test_the_same_seed_gives_the_same_log_through_the_command_line(m1_w2: tuple, tmp_path: Path) -> None:
    _, runs = m1_w2
    (tmp_path / "again").mkdir()
    (tmp_path / "again" / "state.png").write_bytes(PNG_MAGIC)  # an earlier run's picture, not this one's
    again = specc("run", ATRV, "--mission", "M1", "--world", "W2", "--config", "Robot1/2", "--folder",
                  tmp_path / "again", "--no-pictures")
    assert again.returncode == 0, again.stderr
    assert sorted(p.name for p in (tmp_path / "again").iterdir()) == ["events.jsonl", "report.json", "summary.txt"]
    first = (runs / "atrv-M1-W2-Robot1-2-s0" / "events.jsonl").read_bytes()
    assert (tmp_path / "again" / "events.jsonl").read_bytes() == first


def test_replay_plays_the_log_back_and_draws_it_again(m1_w2: tuple, tmp_path: Path) -> None:
    _, runs = m1_w2
    folder = runs / "atrv-M1-W2-Robot1-2-s0"
    events = read_events(folder / "events.jsonl")
    result = specc("replay", folder, "--kind", "action", "--output", tmp_path)
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stdout.splitlines() if not line.startswith("picture: ")]
    actions = [e for e in events if e["kind"] == "action"]
    assert len(lines) == len(actions) and all(" action " in line for line in lines)
    assert lines[0].split()[0] == f"{actions[0]['t']:.3f}" and "started" in lines[0]
    drawn = sorted(p.name for p in tmp_path.iterdir())
    assert drawn == sorted(json.loads((folder / "report.json").read_text())["pictures"])
    window = specc("replay", folder, "--from", "100", "--to", "110", "--no-render")
    times = [float(line.split()[0]) for line in window.stdout.splitlines()]
    assert times and all(100 <= t <= 110 for t in times)


def test_the_hunt_runs_from_the_command_line(tmp_path: Path) -> None:
    result = specc("run", HILARE, "--seed", "2", "--runs", tmp_path)
    assert result.returncode == 0, result.stderr
    folder = tmp_path / "hilare-hunt-room-s2"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "succeeded" and report["measures"]["objects_taken"] == 5
    assert report["measures"]["arm_moves_while_robot_moves"] == 0
    assert report["measures"]["detections_interrupting_exploration"] >= 1
    assert {"map.png", "timeline.png", "state.png"} <= set(report["pictures"])
    assert "5 of 5 object(s) taken" in result.stdout


def test_a_table_of_the_hunt_over_seeds(tmp_path: Path) -> None:
    result = specc("table", HILARE, "--seeds", "2", "--runs", tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    # The terminal (here a pipe) gets a table, a row per mission; the figures' means are in the files.
    (line,) = [row for row in result.stdout.splitlines() if row.lstrip().startswith("hunt")]
    cells = [cell.strip() for cell in line.split("│")]
    assert cells[:6] == ["hunt", "room", "-", "2", "2", "100 %"] and len(cells) == 7, cells
    assert "success rate" in result.stdout and "objects_taken" in (tmp_path / "hilare-table.md").read_text()
    data = json.loads((tmp_path / "hilare-table.json").read_text())
    (row,) = data["missions"]
    assert (row["mission"], row["world"], row["seeds"], row["succeeded"]) == ("hunt", "room", 2, 2)
    assert row["means"]["objects_taken"] == 5 and row["means"]["arm_moves_while_robot_moves"] == 0
    table = (tmp_path / "hilare-table.md").read_text()
    assert "| hunt | room | - | 2 | 2 | 100 % |" in table and "objects_taken" in table


@pytest.mark.parametrize(("args", "message"), [
    (("--mission", "M9", "--world", "W2"), "error: robot 'atrv' has no mission 'M9' (its missions: M1, M2, M3, M4)"),
    (("--mission", "M1", "--world", "W9"), "error: robot 'atrv' has no world 'W9' (its worlds: W1, W2, W3, W4;"),
    (("--mission", "M1", "--world", "W1", "--config", "Robot3"), "error: no robot configuration 'Robot3'"),
    ((), "error: robot 'atrv' needs --mission (M1, M2, M3, M4) or --goal"),
    (("--mission", "M1", "--horizon", "-60"), "error: horizon -60.0: give a positive number of simulated seconds"),
])
def test_unknown_names_are_one_line_and_leave_no_run_folder(args: tuple[str, ...], message: str,
                                                            tmp_path: Path) -> None:
    result = specc("run", ATRV, *args, "--runs", tmp_path)
    assert_clean_failure(result, 2, message)
    assert len(result.stderr.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_the_hunt_refuses_the_rovers_options(tmp_path: Path) -> None:
    assert_clean_failure(specc("run", HILARE, "--config", "Robot1", "--runs", tmp_path), 2,
                         "error: --config: mission hunt of robot 'hilare' is not planned")
    assert_clean_failure(specc("run", HILARE, "--goal", "!(COLLECT-OBJECT 2)", "--runs", tmp_path), 2,
                         "no KA of procedures 'hilare_tasks' is invoked by COLLECT-OBJECT (did you mean "
                         "'COLLECT-OBJECTS'?)")
    assert_clean_failure(specc("run", HILARE, "--horizon", "nan", "--runs", tmp_path), 2, "error: horizon nan")
    assert not any(tmp_path.iterdir())  # checked before anything is written
    assert_clean_failure(specc("run", EXAMPLES / "generic", "--runs", tmp_path), 2,
                         "error: robot 'generic' has no system block")
    assert_clean_failure(specc("run", tmp_path / "nowhere"), 2, "is not a robot's spec folder")


def atrv_copy(tmp_path: Path) -> Path:
    copy = tmp_path / "atrv"
    shutil.copytree(ATRV, copy, ignore=shutil.ignore_patterns("__pycache__"))
    return copy


def test_a_spec_that_does_not_compile_is_reported_gcc_style(tmp_path: Path) -> None:
    robot = atrv_copy(tmp_path)
    mission = robot / "missions" / "M1_model1.spec"
    mission.write_text(mission.read_text().replace("include model1_goals_M1;", "include model1_goals_M9;"))
    result = specc("run", robot, "--mission", "M1", "--world", "W1", "-g", tmp_path / "gen")
    assert_clean_failure(result, 2, "do not compile")
    assert f"{mission}:" in result.stderr and ": error: " in result.stderr and "model1_goals_M9" in result.stderr


def test_a_planner_that_finds_nothing_ends_the_mission_with_a_report(tmp_path: Path) -> None:
    # A hold the problem requires (no goal: nothing may drop it) that the start contradicts: the
    # rover is at x = 0 at t_start, not 9. `specc check` cannot tell; the planner finds it.
    robot = atrv_copy(tmp_path)
    mission = robot / "missions" / "M1_model1.spec"
    horizon = "  (t_end - t_start) in [330, 800];\n"
    mission.write_text(mission.read_text().replace(horizon, horizon + "  hold(AT_ROBOT_X(): 9.0, (t_start, t_end));\n"))
    result = specc("run", robot, "--mission", "M1", "--world", "W1", "--config", "Robot1", "-g", tmp_path / "gen",
                   "--runs", tmp_path / "runs", "--no-pictures")
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    report = json.loads((tmp_path / "runs" / "atrv-M1-W1-Robot1-s0" / "report.json").read_text())
    assert report["outcome"] == "failed" and report["measures"]["kappa"] == 1
    # The planner's own words say what no plan can satisfy.
    assert "no valid plan" in report["why"] and "no plan satisfies the problem's required assertions" in report["why"]
    assert "mission failed" in result.stdout


def toml_world(w: World, path: Path) -> Path:
    """A world with polygon obstacles and targets, written as its TOML file."""
    xmin, xmax, ymin, ymax = w.bounds
    lines = [f'[world]\nname = "{w.name}"', f"[bounds]\nxmin = {xmin}\nxmax = {xmax}\nymin = {ymin}\nymax = {ymax}"]
    lines += [f"[[obstacles]]\npolygon = {[list(p) for p in o.points]}" for o in w.obstacles if isinstance(o, Polygon)]
    lines += [f'[[targets]]\nname = "{t.name}"\nx = {t.x}\ny = {t.y}' for t in w.targets]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_robot_stuck_in_a_pocket_fails_its_mission_with_a_report(tmp_path: Path) -> None:
    """W4's pocket turned to open towards (-5, 3) on the way to (5, 5): Modele1's M2 drives in."""
    w4 = load_world(ATRV / "worlds" / "W4.toml")
    turn = math.atan2(5.0 - 3.0, 5.0 + 5.0) - math.atan2(5.0, 5.0)
    c, s = math.cos(turn), math.sin(turn)
    pocket = tuple(Polygon(tuple((5.0 + c * (x - 5.0) - s * (y - 5.0), 5.0 + s * (x - 5.0) + c * (y - 5.0))
                                 for x, y in o.points)) for o in w4.obstacles[:3] if isinstance(o, Polygon))
    trap = toml_world(dataclasses.replace(w4, name="W4-trap", obstacles=pocket), tmp_path / "trap.toml")
    result = specc("run", ATRV, "--mission", "M2", "--world", trap, "--config", "Robot1", "--runs", tmp_path)
    assert result.returncode == 1 and "Traceback" not in result.stderr
    folder = tmp_path / "atrv-M2-trap-Robot1-s0"  # named after the world file
    report = json.loads((folder / "report.json").read_text())
    photos = next(g for g in report["measures"]["goals"] if g["kind"] == "p")
    assert report["outcome"] == "failed" and photos["met"] < 3
    failed = [e for e in read_events(folder / "events.jsonl") if e["kind"] == "action" and e["status"] == "failed"]
    assert failed and "NO_PROGRESS" in failed[0]["why"]
    assert "map.png" in report["pictures"]


def test_a_run_that_crashes_keeps_its_log_and_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A fault inside the runtime half-way through (the plans' executor breaks at its third
    action): the run folder keeps the log up to there and a report saying what broke."""
    from specc.run import plans

    started = plans.KernelExecutor._start
    calls = []

    def breaking(self: plans.KernelExecutor, *args: object) -> None:
        calls.append(args)
        if len(calls) == 3:
            raise ZeroDivisionError("injected")
        started(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(plans.KernelExecutor, "_start", breaking)
    request = RunRequest(ATRV, "M1", "W1", "Robot1", folder=tmp_path / "run", pictures=False)
    with pytest.raises(RunCrashed, match="the run crashed: ZeroDivisionError: injected") as crash:
        run_compiled("atrv", request)
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "crashed" and "injected" in report["why"]
    events = read_events(tmp_path / "run" / "events.jsonl")
    assert events[0]["kind"] == "mission-start" and sum(
        e["kind"] == "action" and e["status"] == "started" for e in events) == 2
    assert crash.value.outcome.report == report


def test_a_planned_mission_stops_at_its_horizon(tmp_path: Path) -> None:
    """A horizon shorter than the plan: the action under way is stopped there, FTplan's mission
    ends, and the run's outcome says so (not a planning failure)."""
    result = specc("run", ATRV, "--mission", "M1", "--config", "Robot1", "--horizon", "60", "--runs", tmp_path,
                   "--no-pictures")
    assert result.returncode == 1 and "Traceback" not in result.stderr
    folder = tmp_path / "atrv-M1-W1-Robot1-s0-horizon60"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "horizon" and "the run's horizon (60 s) was reached" in report["why"]
    assert report["measures"]["kappa"] == 0 and report["measures"]["nu"] == 0
    events = read_events(folder / "events.jsonl")
    stopped = [e for e in events if e["kind"] == "action" and e["status"] == "stopped"]
    assert stopped and all(e["t"] == pytest.approx(60.0, abs=0.2) for e in stopped)
    assert not [e for e in events if e["kind"] == "action" and e["status"] == "started" and e["t"] > 60.0]
    assert events[-1]["t"] < 70.0


def test_the_table_of_measures_comes_from_one_command(tmp_path: Path) -> None:
    result = specc("table", ATRV, "--mission", "M1", "--world", "W1", "--world", "W3", "--config", "Robot1",
                   "--runs", tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    table = (tmp_path / "atrv-table.md").read_text()
    rows = [line for line in table.splitlines() if line.startswith("| Robot1 ")]
    assert [row.split("|")[3].strip() for row in rows] == ["W1", "W3"]
    assert all(row.split("|")[5].strip() == "100 %" for row in rows)  # nu: every goal met
    data = json.loads((tmp_path / "atrv-table.json").read_text())
    assert [run["world"] for run in data["runs"]] == ["W1", "W3"]
    assert all((Path(run["folder"]) / "events.jsonl").is_file() for run in data["runs"])


def test_a_table_stopped_by_a_signal_keeps_the_table_of_the_runs_before(tmp_path: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C in the second of three runs: the first run's row is the table (said so), not nothing."""
    import specc.run.sweep as sweeping
    from specc.run.package import ensure_compiled

    real = sweeping.run_planned
    runs: list[object] = []

    def stopped_at_the_second(run: object) -> object:
        runs.append(run)
        if len(runs) == 2:  # as the signal handler ends a run: RunCrashed, exit code 130
            raise RunCrashed("stopped by SIGINT", real(run), 130)  # type: ignore[arg-type]
        return real(run)  # type: ignore[arg-type]

    monkeypatch.setattr(sweeping, "run_planned", stopped_at_the_second)
    tug = EXAMPLES / "tug"
    robot = ensure_compiled(tug, tmp_path / "generated").robot
    base = RunRequest(tug, generated=tmp_path / "generated", runs=tmp_path / "runs", pictures=False)
    result = sweeping.sweep(robot, base, missions=("deliver",), seeds=range(3))
    assert (result.planned, len(result.outcomes), result.interrupted) == (3, 1, True)
    assert result.missions[0].seeds == 1
    assert "Interrupted after 1 of 3 run(s): the means above are over those." in result.markdown()
    assert (result.to_json()["planned"], result.to_json()["interrupted"]) == (3, True)


def test_a_failed_mission_says_each_reason_once_and_its_summary_cuts_it_short() -> None:
    """FTplan gives every goal it abandons at once the same reason, every planner's diagnostics:
    said once for the goals it stands for, cut short in the summary's line and the table's
    failures, whole in the run's report."""
    from specc.run.mission import MissionRun, brief_why, missed_goals
    from specc.run.session import RunOutcome
    from specc.run.sweep import SweepResult

    diagnostics = ("every planner's plan left them aside (quick: CART_AT(CART1) = C (line 115, priority 2): "
                   "impossible even alone: every partial plan failed; most often: "
                   + "t_end - MOVE.t_start in [80, inf] contradicts [3, 8.7], which the plan already implies, " * 20
                   + "the goal's dates: t1 < t2 (line 117))")
    cart, dock, home = ("CART_AT(CART1) = C (line 115, priority 2)", "AT() = DOCK (line 116, priority 1)",
                        "AT() = HOME (line 118, priority 1)")
    why = missed_goals({cart: diagnostics, dock: diagnostics, home: "its deadline 300 s has passed"})
    assert why == (f"3 planned goal(s) missed: {cart}, {dock}: {diagnostics}; "
                   f"{home}: its deadline 300 s has passed")
    why += "; 51 action failure(s); the last: MOVE(AWAY, DOCK) overran its planned duration [3, 80] s"
    brief = brief_why(why)
    assert len(brief) < 600 < len(why)
    assert brief.startswith(f"3 planned goal(s) missed: {cart}, {dock}: every planner's plan left them aside "
                            "(quick: CART_AT(CART1)")
    assert brief.count("…") == 1 and "…)" in brief  # cut inside the diagnostics, their bracket closed
    # The short reasons after it, whole.
    assert brief.endswith(f"; {home}: its deadline 300 s has passed; 51 action failure(s); the last: "
                          "MOVE(AWAY, DOCK) overran its planned duration [3, 80] s")
    assert brief_why("every goal achieved (9)") == "every goal achieved (9)"
    run = MissionRun("tug", "shuttle", "blocked", 0, "failed", why, (), 893.0, 29.0, 8.6, 51, {}, (), ())
    assert run.summary().splitlines()[0] == f"tug's mission shuttle in blocked (seed 0): failed: {brief}"
    assert run.summary().splitlines()[-1] == "  893 s of mission in 29.0 s of wall time (31x real time)"
    report = {"mission": "shuttle", "world": "blocked", "outcome": "failed", "why": why, "measures": {}}
    table = SweepResult("tug", [RunOutcome(Path("runs/tug-shuttle-blocked-s0"), "tug", report, run.summary())])
    assert f"- tug-shuttle-blocked-s0 (failed): {brief}\n" in table.markdown()
    assert table.to_json()["runs"][0]["why"] == why


def test_bad_options_of_the_table_are_one_line(tmp_path: Path) -> None:
    result = specc("table", ATRV, "--mission", "M1", "--mission", "M7", "--world", "W1", "--config", "Robot1",
                   "--runs", tmp_path)
    assert_clean_failure(result, 2, "error: robot 'atrv' has no mission 'M7'")
    assert not any(tmp_path.iterdir())  # every name is checked before the first run
    assert_clean_failure(specc("table", HILARE, "--world", "W1"), 2, "robot 'hilare' has no world 'W1'")
    assert_clean_failure(specc("table", HILARE, "--config", "Robot1"), 2, "--config: no mission of robot 'hilare' "
                         "is planned (a mission with 'plan:'), and a configuration is FTplan's: run without --config")
    assert_clean_failure(specc("table", HILARE, "--mission", "hunt", "--config", "Robot1"), 2,
                         "--config: none of the missions named (hunt) is planned")
    # `--runs 3` is a count to `specc campaign`, a folder here: not a folder named 3 made silently.
    counted = specc("table", HILARE, "--seeds", "1", "--runs", "3")
    assert counted.returncode == 2 and "--runs is where the run folders go" in counted.stderr
    assert "`specc table --seeds 3`" in counted.stderr and not (ROOT / "3").exists()


def test_replay_of_a_missing_or_broken_run_is_one_line(tmp_path: Path) -> None:
    assert_clean_failure(specc("replay", tmp_path / "nothing"), 2, "no run folder or event log")
    assert_clean_failure(specc("replay", tmp_path), 2, "holds no events.jsonl")
    (tmp_path / "events.jsonl").write_text('{"t": 0, "kind": "mission-start"}\n')
    assert_clean_failure(specc("replay", tmp_path, "--kind", "actoin"), 2,
                         "no event of kind 'actoin' in this log (it has: mission-start)")
    # One kind of several absent: the others are shown, the absent one noted.
    some = specc("replay", tmp_path, "--kind", "action", "--kind", "mission-start", "--no-render")
    assert some.returncode == 0 and "mission-start" in some.stdout
    assert "note: no event of kind 'action' in this log" in some.stderr
    # On one screen (both streams into one), the note closes the listing on a line of its own.
    (tmp_path / "events.jsonl").write_text('{"t": 0, "kind": "mission-start"}\n'
                                           '{"t": 85.2, "kind": "reply", "service": "MOVE", "id": 8, "result": "OK"}\n')
    shared = subprocess.run([sys.executable, "-m", "specc.cli", "replay", str(tmp_path), "--kind", "reply",
                             "--kind", "fact", "--no-render"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, timeout=300)
    assert shared.returncode == 0, shared.stdout
    assert shared.stdout.splitlines() == ["    85.200  reply            MOVE #8 -> OK",
                                          "note: no event of kind 'fact' in this log (it has: mission-start, reply)"]
    (tmp_path / "events.jsonl").write_text('{"t": 0, "kind": "mission-start"}\nnot json\n')
    assert_clean_failure(specc("replay", tmp_path), 2, "events.jsonl")


def test_run_request_names_are_checked_before_anything_runs(tmp_path: Path) -> None:
    with pytest.raises(RunError, match="timing 'fast'"):
        run_compiled("atrv", RunRequest(ATRV, "M1", "W1", timing="fast", folder=tmp_path / "run"))
    assert not (tmp_path / "run").exists()
