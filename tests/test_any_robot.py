"""A robot of one's own runs from its specs alone: a minimal robot written into a temporary
folder (one module, one service that takes arguments, one procedure, a body, a world, a
mission) goes through `specc check` and `specc run`, with nothing of it in examples/ or specc/."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from specc.run.events import read_events

SPEC = """\
module drive {
  codels: "cart_codels.drive";
  request Goto {
    type: exec;
    input: x: float, y: float;
    task: Motion;
    codel start: start;
    codel exec: step;
    codel inter: halt;
    fail: BLOCKED;
    incompatible_with: Goto;
  }
  exec_task Motion { period: 50 ms; priority: 10; }
}

executive cart {
  service GOTO {
    request: drive.Goto;
    takes: x, y;  // given by the task level with each request
    timeout { final: 60 s; }
    conflicts { GOTO: interrupt; }
  }
}

procedures tasks {
  predicate event REPLY(id: int, result: {OK, ERROR, BLOCKED, INT, TIMEOUT});
  action GOTO(x: float, y: float) -> int = service GOTO;
  ka SendGoto { invocation: !(SEND-GOTO $X $Y $ID); action: (GOTO $X $Y) -> $ID; }
  ka Goto {
    invocation: !(GO $X $Y);
    body { !(SEND-GOTO $X $Y $ID); ^(REPLY $ID $RESULT); ?(= $RESULT OK); }
  }
}

system cart {
  modules: drive;
  executive: cart;
  supervisor: tasks;
  body { radius: 0.25; mass: 30; wheel_base: 0.4; max_wheel_speed: 0.6; }
  worlds { shop: "worlds/shop.toml"; }
  mission deliver { world: shop; horizon: 120 s; goal: !(GO 3 4); }
}
"""

WORLD = """\
[room]
width = 6.0
height = 6.0

[start]
x = 1.0
y = 1.0

[[obstacles]]
circle = [4.5, 1.5, 0.3]
"""

# Drives straight at the goal with the true pose (a minimal robot: no odometry of its own).
CODELS = '''\
import math

ARRIVED = 0.1  # m


def start(sdi, request):
    return "exec"


def step(sdi, request):
    sim = sdi.hardware
    x, y, theta = sim.pose
    dx, dy = request.input.x - x, request.input.y - y
    if math.hypot(dx, dy) < ARRIVED:
        sim.wheels.drive(0.0, 0.0)
        return "end"
    if sim.wheels.blocked:
        sim.wheels.stop()
        return "BLOCKED"
    turn = math.remainder(math.atan2(dy, dx) - theta, math.tau)
    sim.wheels.drive(0.4 if abs(turn) < 0.5 else 0.0, 2.0 * turn)
    return "exec"


def halt(sdi, request):
    sdi.hardware.wheels.stop()
    return "ether"
'''


def write_robot(folder: Path, spec: str = SPEC) -> Path:
    robot = folder / "cart"
    (robot / "worlds").mkdir(parents=True)
    (robot / "cart_codels").mkdir()
    (robot / "cart.spec").write_text(spec)
    (robot / "worlds" / "shop.toml").write_text(WORLD)
    (robot / "cart_codels" / "__init__.py").write_text("")
    (robot / "cart_codels" / "drive.py").write_text(CODELS)
    return robot


def specc(cwd: Path, *args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


@pytest.fixture(scope="module")
def cart(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_robot(tmp_path_factory.mktemp("robot"))


def test_a_minimal_robot_of_ones_own_runs_its_mission_to_success(cart: Path) -> None:
    work = cart.parent
    assert specc(work, "check", cart).returncode == 0
    result = specc(work, "run", cart, "-q")
    assert result.returncode == 0, result.stderr
    folder = work / "runs" / "cart-deliver-shop-s0"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "succeeded" and report["robot"] == "cart" and report["mission"] == "deliver"
    events = read_events(folder / "events.jsonl")
    start = events[0]
    assert start["kind"] == "mission-start" and start["goals"] == ["!(GO 3 4)"]
    assert start["body"]["radius"] == 0.25 and start["world"] == "shop"
    # The procedure's arguments reached the module request through the executive's service.
    requests = [e for e in events if e["kind"] == "request"]
    assert [r["service"] for r in requests] == ["GOTO"]
    reply = next(e for e in events if e["kind"] == "reply")
    assert reply["result"] == "OK"
    last = [e for e in events if e["kind"] == "pose"][-1]
    assert math.hypot(last["x"] - 3, last["y"] - 4) < 0.2
    assert [e["status"] for e in events if e["kind"] == "goal"] == ["posted", "succeeded"]
    assert events[-1]["kind"] == "mission-end" and events[-1]["outcome"] == "succeeded"


def test_a_goal_from_the_command_line_is_posted_in_the_named_world(cart: Path) -> None:
    work = cart.parent
    result = specc(work, "run", cart, "--goal", "!(GO 2 5)", "--world", "shop", "--folder", work / "goal", "-q")
    assert result.returncode == 0, result.stderr
    events = read_events(work / "goal" / "events.jsonl")
    assert events[0]["goals"] == ["!(GO 2 5)"]
    last = [e for e in events if e["kind"] == "pose"][-1]
    assert math.hypot(last["x"] - 2, last["y"] - 5) < 0.2


def test_a_goal_the_robot_cannot_reach_fails_with_the_modules_reason(cart: Path) -> None:
    work = cart.parent
    result = specc(work, "run", cart, "--goal", "!(GO 4.5 1.5)", "--folder", work / "blocked", "-q")
    assert result.returncode == 1, result.stderr
    report = json.loads((work / "blocked" / "report.json").read_text())
    assert report["outcome"] == "failed"
    assert "GOTO answered BLOCKED" in report["why"], report["why"]


@pytest.mark.parametrize(("args", "message"), [
    (("--mission", "collect"), "has no mission 'collect' (its missions: deliver)"),
    (("--world", "yard"), "has no world 'yard' (its worlds: shop"),
    (("--goal", "!(GOO 1 2)"), "no KA of procedures 'tasks' is invoked by GOO (did you mean 'GO'?)"),
    (("--goal", "!(GO 1)"), "GO takes 2 argument(s), 1 given"),
    (("--goal", "!(GO $X 1)"), "goal of constants"),
    (("--goal", "!(GO 1 2)", "--mission", "deliver"), "give --mission or --goal, not both"),
    (("--config", "Robot1"), "--config: robot 'cart' has no such option"),
])
def test_bad_run_options_are_one_clear_message_and_leave_no_run_folder(cart: Path, args: tuple[str, ...],
                                                                        message: str) -> None:
    work = cart.parent
    folder = work / "never"
    result = specc(work, "run", cart, *args, "--folder", folder, "-q")
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not folder.exists()


@pytest.mark.parametrize(("change", "code"), [
    (("world: shop; horizon", "world: yard; horizon"), "undefined-world"),
    (("goal: !(GO 3 4)", "goal: !(GOTO-PLACE 3 4)"), "undefined-goal"),
    (("  supervisor: tasks;\n", ""), "goal-without-supervisor"),
    (("action GOTO(x: float, y: float)", "action GOTO(x: {A, B}, y: float)"), "bad-argument-type"),
    (("takes: x, y;", "takes: x;"), "arity-mismatch"),
])
def test_a_spec_that_cannot_run_is_refused_with_a_code_and_a_caret(tmp_path: Path, change: tuple[str, str],
                                                                    code: str) -> None:
    old, new = change
    assert old in SPEC
    robot = write_robot(tmp_path, SPEC.replace(old, new))
    result = specc(tmp_path, "run", robot, "-q")
    assert result.returncode == 2, result.stderr
    assert f"[{code}]" in result.stderr and "^" in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "runs").exists()


def test_the_minimal_robot_formats_to_itself() -> None:
    from specc.syntax.parser import parse_text
    from specc.syntax.printer import print_source

    parsed = parse_text(SPEC, "cart.spec")
    assert parsed.source is not None and not parsed.diagnostics
    again = parse_text(print_source(parsed.source), "cart.spec")
    assert again.source is not None
    assert print_source(again.source) == print_source(parsed.source)
    assert textwrap.dedent(print_source(parsed.source)).count("mission deliver") == 1
