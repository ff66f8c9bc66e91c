"""The third robot, not from the seeds (examples/tug): a warehouse tug written with specc alone,
its codels its only Python. Its missions run from its system block: one its procedures carry out
alone, and planned ones where FTplan's plans are carried out by PRS procedures, which ask the
executive for services, which run module requests."""

from __future__ import annotations

import json
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


def test_a_table_of_the_tug(tmp_path: Path) -> None:
    result = specc("table", TUG, "--mission", "deliver", "--world", "hall", "--world", "crowded", "--runs",
                   tmp_path, "--quiet")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "tug-table.json").read_text())
    assert [(row["mission"], row["world"], row["succeeded"]) for row in data["missions"]] == [
        ("deliver", "hall", 1), ("deliver", "crowded", 1)]
    # The pallets of the crowded hall slow the tug down (its speed policy).
    hall, crowded = (row["simulated_time"] for row in data["missions"])
    assert crowded > hall


@pytest.mark.parametrize("args, message", [
    (("--mission", "shuttle", "--config", "Robot3"), "no robot configuration 'Robot3'"),
    (("--mission", "fetch", "--world", "hall"), "robot 'tug' has no mission 'fetch'"),
])
def test_bad_options_for_the_tug_are_one_line(tmp_path: Path, args: tuple[str, ...], message: str) -> None:
    result = specc("run", TUG, *args, "--runs", tmp_path, "-q")
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr
    assert not any(tmp_path.iterdir())
