"""Fault-injection campaigns (seed 004 ch. 4): real experiments on the simulated rover, a real
kill and resume, the seed's filters, the report."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import pytest

from specc.campaign.campaign import EQUIVALENT, KEPT, NEVER_PLANS, UNJUDGED, judge
from specc.campaign.engines import DaskEngine, ExperimentProcess, LocalEngine
from specc.campaign.experiments import ORIGINAL, Experiment, Outcome, Setting
from specc.campaign.report import Coverage, build_report, coverage, markdown, write_report
from specc.campaign.store import MutantRecord, ResultStore
from specc.run import RunError
from tests.conftest import is_png

ROOT = Path(__file__).resolve().parents[1]
ATRV = ROOT / "examples" / "atrv"
SETTING = Setting(ROOT / "generated", ATRV, "atrv")
ONE = Experiment("Robot1", ORIGINAL, "M1", "W1", 0)
# A small real campaign: three mutants drawn, one activity, one run, Robot1 then Robot1/2.
SMALL = ["--mutants", "3", "--missions", "M1", "--worlds", "W1", "--runs", "1", "--configs", "Robot1,Robot1/2",
         "--workers", "2", "--seed", "0"]


def specc(*args: str | Path, **kwargs: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, timeout=600, **kwargs)  # type: ignore[call-overload]


def rows(store: Path) -> list[tuple[str, float]]:
    """The store's results as (key, when recorded); none while the campaign is creating it."""
    db = sqlite3.connect(store)
    try:
        return list(db.execute("SELECT key, finished FROM results ORDER BY key"))
    except sqlite3.OperationalError:
        return []
    finally:
        db.close()


def start_and_stop_after(store: Path, results: int, stop: signal.Signals) -> subprocess.Popen[str]:
    """The small campaign, sent `stop` once the store holds `results` results."""
    command = [sys.executable, "-m", "specc.cli", "campaign", str(ATRV), *SMALL, "--store", str(store), "-q"]
    # Ctrl-C's default disposition, whatever this process inherited: a job started in the
    # background (`make test &`) ignores SIGINT, and so would the campaign.
    started = subprocess.Popen(command, cwd=ROOT, start_new_session=True, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and started.poll() is None and len(rows(store)) < results:
        time.sleep(0.2)
    assert started.poll() is None, started.communicate()
    if stop == signal.SIGKILL:
        os.killpg(started.pid, stop)  # the campaign and its experiment processes, mid-campaign
    else:
        started.send_signal(stop)  # Ctrl-C
    return started


def test_a_killed_campaign_resumes_without_losing_or_repeating_a_result(tmp_path: Path) -> None:
    store = tmp_path / "small.sqlite"
    interrupted = start_and_stop_after(store, 1, signal.SIGINT)
    _, stderr = interrupted.communicate(timeout=30)  # at once, not after the experiments in flight
    assert interrupted.returncode == 130 and "Traceback" not in stderr, stderr
    assert f"interrupted: {len(rows(store))} results kept in {store}; the same command resumes" in stderr
    killed = start_and_stop_after(store, len(rows(store)) + 1, signal.SIGKILL)
    killed.wait(30)
    before = rows(store)
    assert 2 <= len(before)
    # The report of a campaign stopped half-way: nothing run, and it says what is not finished.
    partial = specc("campaign", ATRV, *SMALL, "--store", store, "--report-only", "-o", tmp_path / "partial")
    assert partial.returncode == 0, partial.stderr
    assert f"{len(before)} experiments in {store}" in partial.stdout and "not finished" in partial.stdout
    assert rows(store) == before
    partial_report = (tmp_path / "partial" / "small.md").read_text()
    assert "**not finished: Robot1" in partial_report and "; not judged yet (the first configuration" in partial_report
    resumed = specc("campaign", ATRV, *SMALL, "--store", store, "-q")
    assert resumed.returncode == 0, resumed.stderr
    assert f"results in {store} ({len(before)} already there)" in resumed.stderr
    after = rows(store)
    keys = [key for key, _ in after]
    assert len(keys) == len(set(keys))
    assert set(before) <= set(after)  # each result from before the kill kept, never run again
    with ResultStore(store) as results:
        verdicts = {m.id: m.verdict for m in results.mutants()}
        kept = [m for m, v in verdicts.items() if v == KEPT]
        assert len(verdicts) == 3 and UNJUDGED not in verdicts.values()
        expected = {f"Robot1|{m}|M1|W1|0" for m in [ORIGINAL, *verdicts]}
        expected |= {f"Robot1/2|{m}|M1|W1|0" for m in [ORIGINAL, *kept]}
        assert set(keys) == expected
        assert all(o.status == "done" for o in results.outcomes())
    report = (tmp_path / "small.md").read_text()
    assert "kept (F*)" in report and "## Means over sets of activities" in report
    assert "goals counted as FTplan believed them" not in report  # the rover judges its goals in the world
    assert is_png(tmp_path / "small.png")
    # Once complete, the same command runs nothing again and rewrites the same report.
    again = specc("campaign", ATRV, *SMALL, "--store", store, "-q")
    assert again.returncode == 0 and rows(store) == after
    assert (tmp_path / "small.md").read_text() == report


def test_a_store_refuses_to_mix_two_campaigns(tmp_path: Path) -> None:
    with ResultStore(tmp_path / "c.sqlite") as store:
        first = {"robot": "atrv", "mutants": ["model1-0001"], "runs": 3, "configurations": ["Robot1"]}
        store.describe(first)
        store.describe(first)  # the same: a resume
        with pytest.raises(RunError, match="holds another campaign \\(mutants: model1-0001 stored, model1-0002 "
                                           "asked; runs: 3 stored, 1 asked\\)"):
            store.describe(first | {"mutants": ["model1-0002"], "runs": 1})
        # More configurations after those it has: the same campaign, compared further (said).
        assert store.describe(first | {"configurations": ["Robot1", "Robot1/2"]}) == [
            f"the campaign in '{tmp_path / 'c.sqlite'}' grows by 1 configurations: Robot1/2"]
        assert store.description()["configurations"] == ["Robot1", "Robot1/2"]
        # The command it was first run with still resumes it (said), and the store keeps what it grew to.
        assert store.describe(first) == [f"'{tmp_path / 'c.sqlite'}' holds 2 configurations (it grew by a later "
                                         "command), 1 of them asked: theirs are resumed, the report covers all 2"]
        assert store.description()["configurations"] == ["Robot1", "Robot1/2"]
        # Part of it asked and something else changed: refused, saying what was asked.
        with pytest.raises(RunError, match="configurations: Robot1, Robot1/2 stored, Robot1 asked; runs: 3 stored, "
                                           "1 asked"):
            store.describe(first | {"runs": 1})
        with pytest.raises(RunError, match="configurations: Robot1, Robot1/2 stored, Robot1/2 asked"):
            store.describe(first | {"configurations": ["Robot1/2"]})
        # More mutants drawn (a larger sample holds the smaller one), never fewer.
        store.describe(first | {"configurations": ["Robot1", "Robot1/2"], "mutants": ["model1-0000", "model1-0001"]})
        with pytest.raises(RunError, match="mutants: model1-0000, model1-0001 stored, model1-0009 asked"):
            store.describe(first | {"configurations": ["Robot1", "Robot1/2"], "mutants": ["model1-0009"]})
        outcome = Outcome(ONE, "done", {"kappa": 0}, 1.0)
        store.record(outcome)
        with pytest.raises(RunError, match="already in"):
            store.record(outcome)
        assert store.count() == 1 and list(store.outcomes()) == [outcome]


def measures(kappa: int = 0, distance: float = 10.0, activity_time: float = 30.0) -> dict[str, object]:
    return {"kappa": kappa, "distance": distance, "activity_time": activity_time}


def outcomes_of(mutant: str, values: list[dict[str, object]], status: str = "done") -> list[Outcome]:
    return [Outcome(Experiment("Robot1", mutant, "M1", world, 0), status, value if status == "done" else None, 1.0)
            for world, value in zip(("W1", "W2"), values, strict=True)]


def test_the_seeds_filters_set_aside_mutants_that_never_plan_or_change_nothing() -> None:
    original = [measures(), measures(distance=12.0)]
    outcomes = (outcomes_of(ORIGINAL, original) + outcomes_of("same", original)
                + outcomes_of("blind", [measures(kappa=1, activity_time=0.0), measures(kappa=1, activity_time=0.0)])
                # Planned, ran its plan, then failed to replan: it did plan (seed 004's filter is
                # for mutants that find no plan), so it is kept.
                + outcomes_of("late", [measures(kappa=1, activity_time=40.0), measures(kappa=1, activity_time=0.0)])
                + outcomes_of("changed", [measures(), measures(distance=3.0)])
                + outcomes_of("hung", original, status="timeout")
                + outcomes_of("half", original)[:1]
                + [Outcome(Experiment("Robot1/2", "same", "M1", "W1", 0), "done", measures(distance=1.0), 1.0)])
    verdicts = judge(outcomes, "Robot1", ["same", "blind", "late", "changed", "hung", "half"], expected=2)
    assert {m: v.verdict for m, v in verdicts.items()} == {
        "same": EQUIVALENT, "blind": NEVER_PLANS, "late": KEPT, "changed": KEPT, "hung": KEPT, "half": UNJUDGED}
    assert verdicts["changed"].detail == "1 of 2 experiments differ"


def test_an_experiment_past_its_hard_timeout_is_killed_and_the_next_one_runs() -> None:
    process = ExperimentProcess(SETTING, timeout=0.3)
    try:
        late = process.run(ONE, None)
        assert late.status == "timeout" and "killed" in late.why and process.process is None
        process.timeout = 120.0
        done = process.run(ONE, None)
        assert done.status == "done" and done.measures is not None and done.measures["nu"] == 1
    finally:
        process.close()


def test_an_experiment_is_a_pure_function_wherever_it_runs(tmp_path: Path) -> None:
    """The same experiment on the local pool and on a local Dask cluster gives the same measures;
    an unknown world is a crashed experiment that says why, not a crashed campaign."""
    odd = Experiment("Robot1", ORIGINAL, "M1", "W9", 0)
    local = {o.experiment: o for o in LocalEngine(SETTING, 2, 120.0).run([(ONE, None), (odd, None)])}
    assert local[odd].status == "crashed" and "W9" in local[odd].why
    (dask,) = DaskEngine(SETTING, "local", 1, 120.0).run([(ONE, None)])
    assert dask.status == local[ONE].status == "done"
    assert dask.measures == local[ONE].measures


def record_m1(store: ResultStore, configuration: str, mutant: str, world: str, success: bool | None) -> None:
    """An experiment of M1 in `world`, seed 0: every goal met or none (measures as a run gives
    them), or, for `success` None, one that crashed."""
    goals = {"asked": 1, "met": 1 if success else 0}
    measures = None if success is None else {
        "configuration": configuration, "mission": "M1", "world": world, "seed": 0,
        "goals": [{"kind": kind, **goals} for kind in "pch"], "kappa": 0, "replannings": 0,
        "activity_time": 10.0, "distance": 5.0, "mission_time": 100.0, "planner_failures": 0, "believed": goals}
    store.record(Outcome(Experiment(configuration, mutant, "M1", world, 0),
                         "done" if success is not None else "crashed", measures, 1.0))


def test_the_report_compares_the_configurations_with_and_without_faults(tmp_path: Path) -> None:
    with ResultStore(tmp_path / "r.sqlite") as store:
        store.describe({"robot": "atrv", "domain": "model1", "configurations": ["Robot1", "Robot1/2"],
                        "missions": ["M1"], "worlds": ["W1", "W4"], "runs": 1, "set_apart": ["W4"]})
        store.add_mutants([MutantRecord("model1-0001", "numeric", "model1.spec:1:1: numeric 1 -> 2 in MOVE", "")])
        store.judge([("model1-0001", KEPT, "")])

        for configuration in ("Robot1", "Robot1/2"):
            for world in ("W1", "W4"):
                record_m1(store, configuration, ORIGINAL, world, True)
        record_m1(store, "Robot1", "model1-0001", "W1", False)
        record_m1(store, "Robot1", "model1-0001", "W4", False)
        record_m1(store, "Robot1/2", "model1-0001", "W1", True)
        record_m1(store, "Robot1/2", "model1-0001", "W4", False)
        report = build_report(store)
    without_w4 = next(h for h in report.headlines if h.worlds == "W* \\ W4")
    assert (without_w4.faulty, without_w4.fault_free) == ((0.0, 1.0), (1.0, 1.0))
    every = next(h for h in report.headlines if h.worlds == "W*")
    assert every.faulty == (0.0, 0.5) and every.absolute == 0.5 and every.relative is None
    text = markdown(report)
    assert [(c.configuration, c.done, c.expected) for c in report.coverage] == [("Robot1", 4, 4), ("Robot1/2", 4, 4)]
    assert "Robot1 4 of 4; Robot1/2 4 of 4" in text and "not finished" not in text
    grown = {**report.description, "configurations": ["Robot1", "Robot1/2", "Robot1/2c"]}
    partial = replace(report, coverage=coverage(grown, report.mutants, report.outcomes))
    assert partial.coverage[-1] == Coverage("Robot1/2c", 0, 4)
    assert "**not finished: Robot1/2c.**" in markdown(partial)
    assert "Robot1/2 succeeds in 50% of missions against Robot1's 0%: +50 points" in text
    # The seed's basis (§4.2.2.3): the cut in the failure rate, next to the rise in success.
    assert "failures cut from 100% to 50%, 50% relative (the seed's basis)" in text
    assert "its Robot1 succeeded in about 54% of missions under faults, its Robot1/2 in about 73%" in text
    assert "| model1-0001 | numeric |" in text and "| 0% | 50% |" in text
    assert "| σ̄_p | σ̄_c | σ̄_h | ν̄ | κ̄ |" in text
    # One kept mutant: the report says it weighs the whole of each mean under faults.
    assert "**few mutants:** the means under faults are over 1 kept mutant(s); one mutant's runs weigh 100%" in text
    written = write_report(report, tmp_path / "out")
    assert [p.name for p in written] == ["campaign.md", "campaign.json", "campaign.png"] and is_png(written[2])


def test_the_chart_s_title_fits_one_panel_as_two(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Without a world set apart the chart has one panel, 720 pixels wide: its title was cut at
    both ends (a trial's report)."""
    import matplotlib.figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from specc.campaign.report import draw

    with ResultStore(tmp_path / "c.sqlite") as store:
        store.describe({"robot": "atrv", "domain": "model1", "configurations": ["Robot1", "Robot1/2"],
                        "mutants": ["model1-0001"], "missions": ["M1"], "worlds": ["W1"], "runs": 1})
        store.add_mutants([MutantRecord("model1-0001", "numeric", "model1.spec:1:1: numeric 1 -> 2 in MOVE", "")])
        store.judge([("model1-0001", KEPT, "")])
        for configuration in ("Robot1", "Robot1/2"):
            record_m1(store, configuration, ORIGINAL, "W1", True)
            record_m1(store, configuration, "model1-0001", "W1", configuration == "Robot1/2")
        report = build_report(store)
    for apart in ([], ["W1"]):
        drawn: list[matplotlib.figure.Figure] = []
        save = matplotlib.figure.Figure.savefig
        with monkeypatch.context() as patch:
            patch.setattr(matplotlib.figure.Figure, "savefig",
                          lambda self, *args, **kwargs: (drawn.append(self), save(self, *args, **kwargs))[1])
            draw(replace(report, description={**report.description, "set_apart": apart}), tmp_path / "chart.png")
        figure = drawn[0]
        renderer = FigureCanvasAgg(figure).get_renderer()
        title = figure._suptitle
        assert title is not None and len(figure.axes) == 1 + len(apart)
        box, whole = title.get_window_extent(renderer), figure.bbox
        assert whole.x0 <= box.x0 and box.x1 <= whole.x1, (box, whole)


def test_the_configurations_are_compared_on_the_experiments_each_finished(tmp_path: Path) -> None:
    """Robot1/2 crashed on the kept mutant in W4: that activity leaves both configurations'
    means (else Robot1's failure there would count and Robot1/2's would not, a gain from a
    crash), and the report says how many were left out. (One that timed out is run again by a
    resumed campaign, and until then the campaign is not finished.)"""
    with ResultStore(tmp_path / "r.sqlite") as store:
        store.describe({"robot": "atrv", "domain": "model1", "configurations": ["Robot1", "Robot1/2"],
                        "missions": ["M1"], "worlds": ["W1", "W4"], "runs": 1, "set_apart": []})
        store.add_mutants([MutantRecord("model1-0001", "numeric", "model1.spec:1:1: numeric 1 -> 2 in MOVE", "")])
        store.judge([("model1-0001", KEPT, "")])

        for configuration in ("Robot1", "Robot1/2"):
            for world in ("W1", "W4"):
                record_m1(store, configuration, ORIGINAL, world, True)
        record_m1(store, "Robot1", "model1-0001", "W1", True)
        record_m1(store, "Robot1", "model1-0001", "W4", False)
        record_m1(store, "Robot1/2", "model1-0001", "W1", True)
        record_m1(store, "Robot1/2", "model1-0001", "W4", None)  # crashed
        report = build_report(store)
    every = next(h for h in report.headlines if h.worlds == "W*")
    assert every.faulty == (1.0, 1.0)  # W1 alone, for both: not (0.5, 1.0)
    assert report.unpaired == 1
    assert "- 1 activity (a mutant or the original in a mission, world and seed) left out of every configuration's " \
           "means" in markdown(report)


def test_a_report_needs_a_store_that_holds_a_campaign(tmp_path: Path) -> None:
    missing = specc("campaign", ATRV, *SMALL, "--store", tmp_path / "none.sqlite", "--report-only")
    assert missing.returncode == 2 and "no results store" in missing.stderr and "Traceback" not in missing.stderr
    ResultStore(tmp_path / "empty.sqlite").close()
    empty = specc("campaign", ATRV, *SMALL, "--store", tmp_path / "empty.sqlite", "--report-only")
    assert empty.returncode == 2 and "holds no campaign" in empty.stderr
    with ResultStore(tmp_path / "two.sqlite") as store:
        store.describe({"robot": "atrv", "configurations": ["Robot1", "Robot1/2"]})
    asked = specc("campaign", ATRV, *SMALL, "--store", tmp_path / "two.sqlite", "--report-only", "--configs",
                  "Robot1,Robot1/2c")  # a configuration the store has no experiment of: said, not left out
    assert asked.returncode == 2 and "has no experiment of Robot1/2c (its configurations: Robot1, Robot1/2)" \
        in asked.stderr, asked.stderr


@pytest.mark.parametrize(("args", "message"), [
    (["--mutants", "many"], "error: --mutants many: give a number of mutants, or 'all'"),
    (["--missions", "M9"], "no mission 'M9'"),
    (["--configs", "Robot7"], "no robot configuration 'Robot7'"),
    (["--configs", "Robot2"], "configuration Robot2 does not plan in 'model1'"),
    (["--domain", "model9", "--mutants", "2"], "model9"),
    (["--scheduler", "bogus"], "--scheduler bogus: missing port number in address 'bogus'; give tcp://HOST:PORT"),
    (["-o", "{tmp}/afile"], "the report's folder '{tmp}/afile' is a file, not a folder"),
])
def test_bad_campaign_input_is_one_line_and_exit_2(tmp_path: Path, args: list[str], message: str) -> None:
    (tmp_path / "afile").write_text("")
    args = [a.format(tmp=tmp_path) for a in args]
    message = message.format(tmp=tmp_path)
    result = specc("campaign", ATRV, "--missions", "M1", "--worlds", "W1", "--runs", "1", *args,
                   "--store", tmp_path / "bad.sqlite", "-q")
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "bad.sqlite").exists()


def test_a_configuration_without_its_plan_analyzer_is_named_by_a_suffix() -> None:
    from specc.run.mission import check_mission, load_robot

    robot = load_robot(SETTING.generated, SETTING.example, SETTING.robot)
    m1 = robot.mission("M1")
    with_analyzer = check_mission(robot, m1, "W1", 0, None, "Robot1/2").planning.config
    without = check_mission(robot, m1, "W1", 0, None, "Robot1/2-noanalyzer").planning.config
    assert with_analyzer.analyzer and without.analyzer == ()
    assert without.planners == with_analyzer.planners and without.policy == with_analyzer.policy
    with pytest.raises(RunError, match="add -noanalyzer to one"):
        check_mission(robot, m1, "W1", 0, None, "Robot3-noanalyzer")


def test_a_small_campaign_on_the_tug(tmp_path: Path) -> None:
    """Any robot with an ftplan block has a campaign: the tug's (examples/tug), with its defaults
    (its planned missions, Robot1 then Robot1/2, faults in its first planner's model) on one
    mission and world; its goals are counted by FTplan's attributes, as its ledger judged them."""
    store = tmp_path / "tug.sqlite"
    result = specc("campaign", ROOT / "examples" / "tug", "--mutants", "2", "--missions", "shuttle", "--worlds",
                   "hall", "--runs", "1", "--workers", "2", "--store", store, "-q")
    assert result.returncode == 0, result.stderr
    with ResultStore(store) as results:
        description = results.description()
        assert (description["domain"], description["configurations"]) == ("warehouse", ["Robot1", "Robot1/2"])
        outcomes = list(results.outcomes())
        original = next(o for o in outcomes if o.experiment == Experiment("Robot1", ORIGINAL, "shuttle", "hall", 0))
    assert original.status == "done" and original.measures is not None and original.measures["nu"] == 1
    assert {g["kind"] for g in original.measures["goals"]} == {"CART_AT", "AT"} and original.measures["distance"] > 5.0
    report = (tmp_path / "tug.md").read_text()
    assert "faults injected into warehouse of tug" in report and "σ̄_CART_AT" in report
    assert "T̄ the physical activity time" in report  # the columns are said, for a reader of the report alone
    # The tug judges no goal in the world: the report says its goals are what FTplan believed.
    assert original.measures["judged_by_robot"] is False and "**goals counted as FTplan believed them:**" in report
    assert dict(original.measures["detected"]) == {"watchdog": 0, "analyzer": 0, "action failure": 0, "goal check": 0}
    assert "## Detections per experiment, by mechanism (FTplan's log; seed 004 §3.1.1)" in report
    assert "| configuration | faults | worlds | watchdog | analyzer | action failure | goal check |" in report


def test_a_campaign_with_experiments_timed_out_exits_1_and_says_so(tmp_path: Path) -> None:
    """A script must be able to tell a finished campaign from one whose experiments timed out
    (an experiment of the rover's takes seconds: one second is too short for most)."""
    store = tmp_path / "short.sqlite"
    result = specc("campaign", ATRV, *SMALL, "--configs", "Robot1", "--timeout", "1", "--store", store, "-q")
    with ResultStore(store) as results:
        timed_out = sum(o.status == "timeout" for o in results.outcomes())
    assert timed_out, "every experiment ended within a second: this test needs a longer one"
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert f"the campaign is not finished: {timed_out} experiment(s) timed out (--timeout 1 s)" in result.stderr


def test_a_damaged_or_foreign_store_is_one_clear_message_and_loses_no_verdict(tmp_path: Path) -> None:
    good = tmp_path / "good.sqlite"
    with ResultStore(good) as store:
        store.describe({"robot": "atrv", "configurations": ["Robot1"]})
        store.add_mutants([MutantRecord("model1-0001", "numeric", "a mutant", "")])
        store.judge([("model1-0001", KEPT, "")])
        store.record(Outcome(ONE, "done", {"kappa": 0}, 1.0))
    # Not a database at all.
    garbage = tmp_path / "garbage.sqlite"
    garbage.write_bytes(b"this is not SQLite" * 100)
    with pytest.raises(RunError, match="cannot open the results store .*is it a results store"):
        ResultStore(garbage)
    # Another program's database.
    foreign = tmp_path / "foreign.sqlite"
    db = sqlite3.connect(foreign)
    db.execute("CREATE TABLE results (id INTEGER, payload BLOB)")
    db.commit()
    db.close()
    with pytest.raises(RunError, match="is not a specc results store: its table 'results' has the columns"):
        ResultStore(foreign)
    # A row whose measures are not JSON, a row with a status no campaign writes, a verdict no filter gives.
    for column, value, message in (("measures", "{broken", "the measures of experiment .* is not JSON"),
                                   ("status", "weird", "has the status 'weird'")):
        damaged = tmp_path / f"{column}.sqlite"
        damaged.write_bytes(good.read_bytes())
        db = sqlite3.connect(damaged)
        db.execute(f"UPDATE results SET {column} = ?", (value,))
        db.commit()
        db.close()
        with ResultStore(damaged) as store, pytest.raises(RunError, match=message):
            list(store.outcomes())
        with ResultStore(damaged) as store:  # the verdicts are still there, untouched
            assert [(m.id, m.verdict) for m in store.mutants()] == [("model1-0001", KEPT)]
    # Through the command: one line, exit 2, no traceback.
    damaged = tmp_path / "status.sqlite"
    result = specc("campaign", ATRV, *SMALL, "--configs", "Robot1", "--store", damaged, "--report-only", "-o",
                   tmp_path / "out")  # the configurations the store was described with
    assert result.returncode == 2 and "has the status 'weird'" in result.stderr and "Traceback" not in result.stderr


def test_planners_sharing_the_mutated_model_are_said_to_share_its_faults(tmp_path: Path) -> None:
    """The rover's two planners plan in two models: no note. The tug's given one model, a mutant of
    it reaches both, which the campaign says before it runs (their diversity is then no defence)."""
    import shutil

    from specc.campaign.campaign import CampaignPlan, check_names
    from specc.run.session import compile_robot

    assert check_names(CampaignPlan(ATRV, SETTING, "model1", 1, 0, ("M1",), ("W1",), 1, ("Robot1", "Robot1/2"))) == []
    one_model = tmp_path / "tug"
    shutil.copytree(ROOT / "examples" / "tug", one_model)
    spec = (one_model / "ftplan.spec").read_text()
    assert "careful: shuttle_slow;" in spec
    (one_model / "ftplan.spec").write_text(spec.replace("careful: shuttle_slow;", "careful: shuttle;"))
    generated = tmp_path / "generated"
    robot = compile_robot(one_model, generated, lambda text: None)
    said = check_names(CampaignPlan(one_model, Setting(generated, one_model, robot), "warehouse", 1, 0, ("shuttle",),
                                    ("hall",), 1, ("Robot1", "Robot1/2")))
    assert len(said) == 1 and said[0].startswith("configuration Robot1/2: planners quick, careful all plan in "
                                                 "'warehouse', so each mutant reaches them all")


def test_a_store_refuses_the_results_of_a_changed_robot_and_lets_the_report_s_options_change(tmp_path: Path) -> None:
    """The robot's files (or specc) changed since the store was begun: its results would mix two
    robots in one report, so the resume is refused, saying so. Which worlds the report also
    leaves out (`--set-apart`) only shapes the report: a resume may change it."""
    from specc.run.package import robot_digest

    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "robot.spec").write_text("module m { }\n")
    first = {"robot": "robot", "runs": 1, "set_apart": ["W4"], "files": robot_digest(robot)[:16]}
    with ResultStore(tmp_path / "c.sqlite") as store:
        store.describe(first)
        store.describe({**first, "set_apart": []})  # accepted, and kept
        assert store.description()["set_apart"] == []
        (robot / "robot.spec").write_text("module m { number: 2; }\n")
        changed = {**first, "files": robot_digest(robot)[:16]}
        assert changed["files"] != first["files"]
        with pytest.raises(RunError, match=r"the robot's specs, codels and worlds, or specc itself, changed since"):
            store.describe(changed)


def test_an_experiment_that_timed_out_is_run_again_by_a_resumed_campaign(tmp_path: Path) -> None:
    """A wall-clock timeout says how busy the machine was, not what the robot did: a resumed
    campaign runs the experiment again, and its new outcome replaces the timeout."""
    experiment = Experiment("Robot1", ORIGINAL, "M1", "W1", 0)
    with ResultStore(tmp_path / "c.sqlite") as store:
        store.record(Outcome(experiment, "timeout", None, 4.0, "killed after 4 s"))
        assert experiment.key not in store.done()
        store.record(Outcome(experiment, "done", {"kappa": 0}, 30.0))
        assert experiment.key in store.done() and [o.status for o in store.outcomes()] == ["done"]
        with pytest.raises(RunError, match="already in"):
            store.record(Outcome(experiment, "done", {"kappa": 0}, 30.0))
