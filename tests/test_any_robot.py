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
  internal_data { x: double; y: double; }  // where the codels keep the pose they last read
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
    sdi.x, sdi.y = x, y  # the Pose poster
    dx, dy = request.x - x, request.y - y
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


# The same cart with a planner: FTplan plans a round (go to A, drop there, come back to the dock)
# and the bindings carry each action out, GOTO as a PRS goal whose KA requests the GOTO service,
# DROP as the module request itself.
PLANNING = """
domain carting {
  attribute AT() { ?value in {DOCK, A, B}; }
  attribute DELIVERED(?p) { ?p in {A, B}; ?value in {NO, YES}; }
  attribute POS_X() { ?value in [-100, 100]; }
  attribute POS_Y() { ?value in [-100, 100]; }
  task GOTO(?from, ?to) (t_start, t_end) {
    ?from in {DOCK, A, B};
    ?to in {DOCK, A, B};
    event(AT(): (?from, ?to), t_end);
    contingent (t_end - t_start) in [2, 40];
  } nonPreemptive
  task DROP(?p) (t_start, t_end) {
    ?p in {A, B};
    hold(AT(): ?p, (t_start, t_end));
    event(DELIVERED(?p): (NO, YES), t_end);
    contingent (t_end - t_start) in [1, 3];
  } nonPreemptive
}
problem round_a for carting {
  timepoint t1, t2;
  explained event(AT(): (A, DOCK), t_start);
  explained event(DELIVERED(A): (YES, NO), t_start);
  explained event(DELIVERED(B): (YES, NO), t_start);
  hold(DELIVERED(A): YES, (t1, t_end)) goal(2, 0);
  hold(AT(): DOCK, (t2, t_end)) goal(1, 0);
  t1 < t2;
  (t_end - t_start) in [0, 200];
}
ftplan rounds {
  planners: p1;
  policy: successive;
  watchdog: 10 s;
  planner p1 { domain: carting; }
  state {
    on ended GOTO(?from, ?to) => AT() := ?to;
    on ended DROP(?p) => DELIVERED(?p) := YES;
    on report WHERE(?x, ?y) => POS_X() := ?x, POS_Y() := ?y;
  }
  mission round_a { p1: round_a; }
}
"""
PLANNED_SPEC = SPEC.replace("""  mission deliver { world: shop; horizon: 120 s; goal: !(GO 3 4); }
}""", """  mission deliver { world: shop; horizon: 120 s; goal: !(GO 3 4); }
  planning: rounds;
  mission round { world: shop; plan: round_a; horizon: 300 s; }
  bindings {
    GOTO(?from, ?to) => goal GO-PLACE(AT()) report WHERE(drive.Pose.x, drive.Pose.y);
    DROP(?p) => request drive.Drop(?p);
  }
}""").replace("""  exec_task Motion""", """  request Drop {
    type: exec;
    input: place: string;
    task: Motion;
    codel start: start_drop;
    codel exec: drop;
  }
  exec_task Motion""").replace("""  internal_data { x: double; y: double; }""", """\
  internal_data { dropCycles: int; x: double; y: double; }
  poster Pose { update: auto; data: x, y; activity: step; }""").replace("""  ka Goto {""", """\
  ka GoDock { invocation: !(GO-PLACE DOCK); body { !(GO 1 1); } }
  ka GoA { invocation: !(GO-PLACE A); body { !(GO 4 4); } }
  ka GoB { invocation: !(GO-PLACE B); body { !(GO 2 5); } }
  ka Goto {""") + PLANNING
DROP_CODELS = '''

DROP_CYCLES = 20  # of the 50 ms task: 1 s


def start_drop(sdi, request):
    sdi.dropCycles = 0
    return "exec"


def drop(sdi, request):
    sdi.dropCycles += 1
    return "end" if sdi.dropCycles >= DROP_CYCLES else "exec"
'''


def write_robot(folder: Path, spec: str = SPEC, codels: str = CODELS) -> Path:
    robot = folder / "cart"
    (robot / "worlds").mkdir(parents=True)
    (robot / "cart_codels").mkdir()
    (robot / "cart.spec").write_text(spec)
    (robot / "worlds" / "shop.toml").write_text(WORLD)
    (robot / "cart_codels" / "__init__.py").write_text("")
    (robot / "cart_codels" / "drive.py").write_text(codels)
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
    # A world file named from the robot's folder, as its system block names them, from another folder.
    relative = specc(work, "run", cart, "--goal", "!(GO 2 5)", "--world", "worlds/shop.toml", "--folder",
                     work / "relative", "-q")
    assert relative.returncode == 0, relative.stderr
    # Without --folder, runs of other goals go to folders of their own: none overwrites another.
    for goal in ("!(GO 2 5)", "!(GO 3 4)"):
        assert specc(work, "run", cart, "--goal", goal, "--runs", work / "goals", "-q").returncode == 0
    folders = sorted(p.name for p in (work / "goals").iterdir())
    assert [f[:-7] for f in folders] == ["cart-goal-shop-s0-GO-2-5", "cart-goal-shop-s0-GO-3-4"]  # and a digest
    # The same text once cleaned, another goal: a folder of its own.
    test = specc(work, "run", cart, "--goal", "?(GO 2 5)", "--runs", work / "goals", "-q")
    assert len(list((work / "goals").iterdir())) == 3, test.stderr


def test_a_goal_the_robot_cannot_reach_fails_with_the_modules_reason(cart: Path) -> None:
    work = cart.parent
    result = specc(work, "run", cart, "--goal", "!(GO 4.5 1.5)", "--folder", work / "blocked", "-q")
    assert result.returncode == 1, result.stderr
    report = json.loads((work / "blocked" / "report.json").read_text())
    assert report["outcome"] == "failed"
    assert "GOTO answered BLOCKED" in report["why"], report["why"]



def test_a_test_goal_is_posted_and_the_first_goal_failing_ends_the_mission(tmp_path: Path) -> None:
    """A mission (or --goal) may test the database, `?(P ...)` of a declared predicate; the
    mission fails as soon as one of its goals fails (docs/language.md), with that goal's reason,
    not at the horizon for the goals still running."""
    spec = SPEC.replace("goal: !(GO 3 4); }", "goal: ?(REPLY 1 OK); goal: !(GO 3 4); }")
    robot = write_robot(tmp_path, spec)
    assert specc(tmp_path, "check", robot).returncode == 0
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "-q")
    assert result.returncode == 1, result.stderr
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "failed" and report["why"].startswith("?(REPLY 1 OK) failed"), report["why"]
    assert report["simulated_time"] < 1.0
    tested = specc(tmp_path, "run", robot, "--goal", "?(REPLY 1 OK)", "--folder", tmp_path / "tested", "-q")
    assert tested.returncode == 1, tested.stderr  # posted and run: the fact is not there
    unknown = specc(tmp_path, "run", robot, "--goal", "?(REPLI 1 OK)", "--folder", tmp_path / "unknown", "-q")
    assert unknown.returncode == 2 and "declare no predicate REPLI (did you mean 'REPLY'?)" in unknown.stderr


def test_a_mission_states_what_its_supervisor_knows_from_the_start(tmp_path: Path) -> None:
    """`goal: =>(FACT ...);` in a mission is concluded before its goals are posted (a robot that
    knows where the objects lie): the test goal that failed without it succeeds, and the fact is
    no goal of the run. A fact of an undeclared predicate, of another arity or outside its
    predicate's domain is refused by check."""
    spec = SPEC.replace("goal: !(GO 3 4); }", "goal: =>(REPLY 1 OK); goal: ?(REPLY 1 OK); }")
    robot = write_robot(tmp_path, spec)
    assert specc(tmp_path, "check", robot).returncode == 0
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "-q")
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "succeeded", report["why"]
    start = read_events(tmp_path / "run" / "events.jsonl")[0]
    assert start["goals"] == ["?(REPLY 1 OK)"] and start["facts"] == ["=>(REPLY 1 OK)"]
    for wrong, code in (("=>(REPLI 1 OK)", "undefined-predicate"), ("=>(REPLY 1)", "arity-mismatch")):
        bad = write_robot(tmp_path / code, SPEC.replace("goal: !(GO 3 4); }", f"goal: {wrong}; }}"))
        checked = specc(tmp_path, "check", bad)
        assert checked.returncode == 1 and f"[{code}]" in checked.stdout + checked.stderr, checked.stdout


def test_a_goal_failed_by_a_function_that_raised_says_what_it_raised(tmp_path: Path) -> None:
    """A procedure's action bound to the user's Python (a rule base's `decide` refusing an input
    outside its domain, say) raises: the run's why is that exception, not only the KA that failed."""
    spec = SPEC.replace("  action GOTO(x: float, y: float) -> int = service GOTO;\n",
                        "  action GOTO(x: float, y: float) -> int = service GOTO;\n"
                        "  action CHECK(x: float) = \"cart_codels.checks.check\";\n"
                        "  ka InRange { invocation: !(IN-RANGE $X); action: (CHECK $X); }\n").replace(
        "body { !(SEND-GOTO $X $Y $ID);", "body { !(IN-RANGE $X); !(SEND-GOTO $X $Y $ID);")
    cart = write_robot(tmp_path, spec)
    (cart / "cart_codels" / "checks.py").write_text(
        "def check(ctx, x):\n    if x > 5:\n        raise ValueError(f'x={x} is outside its domain [0, 5]')\n")
    result = specc(tmp_path, "run", cart, "--goal", "!(GO 9 1)", "--folder", tmp_path / "far", "-q")
    assert result.returncode == 1, result.stderr
    why = json.loads((tmp_path / "far" / "report.json").read_text())["why"]
    assert "(CHECK 9) raised ValueError: x=9 is outside its domain [0, 5]" in why, why


def test_a_reflex_that_fires_is_in_the_log_before_what_it_does(tmp_path: Path) -> None:
    stop = "  request Stop { type: control; validate: stopNow; }\n"
    spec = SPEC.replace("  exec_task Motion", stop + "  exec_task Motion")
    spec = spec.replace("    conflicts { GOTO: interrupt; }\n  }\n",
                        "    conflicts { GOTO: interrupt; }\n  }\n"
                        "  reflex halt on reply drive.Goto == BLOCKED => request drive.Stop;\n")
    cart = write_robot(tmp_path, spec, CODELS + "\n\ndef stopNow(sdi, request):\n    sdi.hardware.wheels.stop()\n"
                                             "    return 'OK'\n")
    result = specc(tmp_path, "run", cart, "--goal", "!(GO 4.5 1.5)", "--folder", tmp_path / "blocked", "-q")
    assert result.returncode == 1, result.stderr
    events = read_events(tmp_path / "blocked" / "events.jsonl")
    reflex = [e for e in events if e["kind"] == "reflex"]
    assert [(e["reflex"], e["on"], e["code"], e["actions"]) for e in reflex] == [
        ("halt", "reply drive.Goto", "BLOCKED", ["request drive.Stop"])]
    blocked = next(e for e in events if e["kind"] == "reply" and e["result"] == "BLOCKED")
    assert blocked["t"] <= reflex[0]["t"]
    replay = specc(tmp_path, "replay", tmp_path / "blocked", "--kind", "reflex", "--no-render")
    assert "halt on reply drive.Goto BLOCKED: request drive.Stop" in replay.stdout, replay.stdout + replay.stderr


def test_a_world_file_broken_since_the_last_run_leaves_that_run_s_folder_whole(tmp_path: Path) -> None:
    cart = write_robot(tmp_path)
    assert specc(tmp_path, "run", cart, "-q").returncode == 0
    folder = tmp_path / "runs" / "cart-deliver-shop-s0"
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    with (cart / "worlds" / "shop.toml").open("a") as world:
        world.write("x = = 3\n")
    again = specc(tmp_path, "run", cart, "-q")
    assert again.returncode == 2 and "shop.toml: not valid TOML" in again.stderr, again.stderr
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before


@pytest.mark.parametrize("hook", ["prepare", "measure"])
def test_an_extension_hook_that_raises_is_named_with_where_it_raised(tmp_path: Path, hook: str) -> None:
    spec = SPEC.replace("  supervisor: tasks;\n", '  supervisor: tasks;\n  extension: "cart_codels.ext";\n')
    cart = write_robot(tmp_path, spec)
    (cart / "cart_codels" / "ext.py").write_text(f"def {hook}(*args):\n    raise KeyError('boom')\n")
    result = specc(tmp_path, "run", cart, "--folder", tmp_path / "run", "-q")
    # The file named relative to the working folder (the test's, where cart/ is), as a user reads it.
    said = f"robot 'cart': its extension's {hook}() raised KeyError: 'boom' (cart/cart_codels/ext.py:2)"
    assert said in result.stderr and "internal error" not in result.stderr, result.stderr
    # prepare is the run's set-up: bad input, nothing run; measure comes at the end: the run crashed, its log kept.
    assert result.returncode == (2 if hook == "prepare" else 1)
    assert (tmp_path / "run" / "events.jsonl").exists() == (hook == "measure")

def test_every_run_says_what_check_warns_of(tmp_path: Path) -> None:
    """A codel reading a poster that does not exist reads None: `specc check` warns, and so does
    every `specc run`, the one that compiles and the next (which does not compile again)."""
    codels = CODELS.replace("    sdi.x, sdi.y = x, y  # the Pose poster\n",
                            "    sdi.x, sdi.y = x, y  # the Pose poster\n    sdi.read_poster('drive.Poze')\n")
    cart = write_robot(tmp_path, codels=codels)
    warned = "[undefined-poster]"
    assert warned in specc(tmp_path, "check", cart).stderr
    for folder in ("first", "second"):
        result = specc(tmp_path, "run", cart, "--folder", tmp_path / folder, "-q")
        assert result.returncode == 0 and warned in result.stderr, result.stderr
    assert "compiled" not in result.stderr  # the second run did not compile, and still said it


def test_codels_that_cannot_be_imported_are_bad_input_said_before_anything_runs(tmp_path: Path) -> None:
    """`specc check` never imports codels; `specc run` imports them before it makes the run
    folder, so a broken import is one message and exit 2, not a run that crashed at 0 s (which a
    table would count as a failed mission)."""
    cart = write_robot(tmp_path, codels="import no_such_module_anywhere\n" + CODELS)
    result = specc(tmp_path, "run", cart, "--folder", tmp_path / "run", "-q")
    assert result.returncode == 2, result.stderr
    assert "module 'drive': its codels 'cart_codels.drive' import what cannot be found: No module named " \
           "'no_such_module_anywhere' (cart_codels/drive.py:1)" in result.stderr, result.stderr
    assert "Traceback" not in result.stderr and not (tmp_path / "run").exists()


@pytest.mark.parametrize(("args", "message"), [
    (("--mission", "collect"), "has no mission 'collect' (its missions: deliver)"),
    (("--world", "yard"), "has no world 'yard' (its worlds: shop"),
    (("--world", "worlds/yard.toml"), "no world file 'worlds/yard.toml' (looked from the current folder and from "
                                      "the robot's"),
    (("--goal", "!(GOO 1 2)"), "no KA of procedures 'tasks' is invoked by GOO (did you mean 'GO'?)"),
    (("--goal", "!(GO 1)"), "GO takes 2 argument(s), 1 given"),
    (("--goal", "!(GO $X 1)"), "goal of constants"),
    (("--goal", "!(GO 1e999 1)"), "not a PRS goal (number 1e999 is too large)"),
    (("--goal", "!(GO A 1)"), "A is not a number: argument 1 of GO reaches 'x' (float) of action GOTO"),
    (("--goal", "!(GO 1 2)", "--mission", "deliver"), "give --mission or --goal, not both"),
    (("--config", "Robot1"), "--config: mission deliver of robot 'cart' is not planned"),
    (("--wall-limit", "1e308"), "--wall-limit 1e+308: give a positive number of seconds, at most 3.1536e+07"),
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


@pytest.fixture(scope="module")
def planned_cart(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_robot(tmp_path_factory.mktemp("planned"), PLANNED_SPEC, CODELS + DROP_CODELS)


def test_ftplan_plans_and_the_bindings_carry_each_action_out(planned_cart: Path) -> None:
    work = planned_cart.parent
    result = specc(work, "run", planned_cart, "--mission", "round", "-q")
    assert result.returncode == 0, result.stderr
    folder = work / "runs" / "cart-round-shop-Robot1-s0"
    report = json.loads((folder / "report.json").read_text())
    assert report["outcome"] == "succeeded" and report["configuration"] == "Robot1"
    assert report["measures"]["planned_goals_met"] == report["measures"]["planned_goals"] == 2
    events = read_events(folder / "events.jsonl")
    started = [e for e in events if e["kind"] == "action" and e["status"] == "started"]
    # Each action of the plan, and how it was carried out: the goal, or the module request.
    assert [(e["task"], e.get("goal"), e.get("request")) for e in started] == [
        ("GOTO", "!(GO-PLACE A)", None), ("DROP", None, "drive.Drop(A)"), ("GOTO", "!(GO-PLACE DOCK)", None)]
    # The goal's procedure asked the executive for its service, with the place's coordinates.
    requests = [e for e in events if e["kind"] == "request"]
    assert [r["service"] for r in requests] == ["GOTO", "GOTO"]
    assert all(e["status"] == "ended" for e in events if e["kind"] == "action" and e["status"] != "started")
    last = [e for e in events if e["kind"] == "pose"][-1]
    assert math.hypot(last["x"] - 1, last["y"] - 1) < 0.2  # back at the dock
    assert (folder / "timeline.png").is_file()
    # After each move, where DRIVE's Pose poster says the cart stands, reported to FTplan.
    reports = [e["text"] for e in events if e["kind"] == "ftplan" and e["event"] == "report"
               and e["text"].startswith("report WHERE")]
    assert len(reports) == 2, reports


def test_an_action_past_its_planned_duration_is_stopped_and_fails(tmp_path: Path) -> None:
    """Temporal execution control: DROP may take 3 s; a drop of 5 s is stopped at 3 s, fails,
    and FTplan replans from the state the reports left."""
    slow = DROP_CODELS.replace("DROP_CYCLES = 20", "DROP_CYCLES = 100")
    robot = write_robot(tmp_path, PLANNED_SPEC, CODELS + slow)
    result = specc(tmp_path, "run", robot, "--mission", "round", "--folder", tmp_path / "run", "-q")
    assert result.returncode == 1, result.stderr
    events = read_events(tmp_path / "run" / "events.jsonl")
    failed = [e for e in events if e["kind"] == "action" and e["status"] == "failed"]
    assert failed and failed[0]["task"] == "DROP" and "overran its planned duration" in failed[0]["why"]
    drop = next(e for e in events if e["kind"] == "action" and e["status"] == "started" and e["task"] == "DROP")
    assert "still running 3 s after it started" in failed[0]["why"]
    assert failed[0]["t"] - drop["t"] == pytest.approx(3.0, abs=0.06)  # the drop ends as it is interrupted
    assert any(e["kind"] == "ftplan" and e["event"] == "action-failed" for e in events)
    assert sum(1 for e in events if e["kind"] == "ftplan" and e["event"] == "plan-request") >= 2  # it replanned
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "failed" and report["why"]


@pytest.mark.parametrize(("change", "code"), [
    (("    DROP(?p) => request drive.Drop(?p);\n", ""), "missing-binding"),
    (("request drive.Drop(?p)", "request drive.Drop(?p, 2)"), "arity-mismatch"),
    (("goal GO-PLACE(AT())", "goal GO-PLAZA(AT())"), "undefined-goal"),
    (("goal GO-PLACE(AT())", "goal GO-PLACE(?where)"), "unbound-variable"),
    (("DROP(?p) => request", "DROOP(?p) => request"), "undefined-task"),
    (("plan: round_a;", "plan: round_b;"), "undefined-mission"),
    (("goal GO-PLACE(AT())", "goal GO-PLACE(AT_PLACE())"), "undefined-attribute"),
    (("report WHERE(drive.Pose.x, drive.Pose.y)", "report THERE(drive.Pose.x, drive.Pose.y)"), "undefined-report"),
    (("report WHERE(drive.Pose.x, drive.Pose.y)", "report WHERE(drive.Pose.x)"), "arity-mismatch"),
    (("report WHERE(drive.Pose.x, drive.Pose.y)", "report WHERE(drive.Place.x, drive.Pose.y)"), "undefined-poster"),
    # `where ATTR(?v) := VALUE`: an attribute of FTplan's state, its arity, the value's variables bound
    (("request drive.Drop(?p)", "request drive.Drop(?q) where DELIVERD(?q) := YES"), "undefined-attribute"),
    (("request drive.Drop(?p)", "request drive.Drop(?q) where DELIVERED(?q, ?r) := YES"), "arity-mismatch"),
    (("request drive.Drop(?p)", "request drive.Drop(?q) where DELIVERED(?q) := ?z"), "unbound-variable"),
    (("request drive.Drop(?p)", "request drive.Drop(?q) where DELIVERED(?p) := YES"), "unbound-variable"),
])
def test_bindings_that_cannot_run_are_refused_by_check(tmp_path: Path, change: tuple[str, str], code: str) -> None:
    old, new = change
    assert old in PLANNED_SPEC
    robot = write_robot(tmp_path, PLANNED_SPEC.replace(old, new), CODELS + DROP_CODELS)
    result = specc(tmp_path, "check", robot)
    assert result.returncode == 1 and f"[{code}]" in result.stdout + result.stderr, result.stdout + result.stderr


def test_a_binding_s_where_takes_its_variables_from_ftplan_s_state(tmp_path: Path) -> None:
    """`DROP(?p) => request drive.Drop(?q) where DELIVERED(?q) := YES`: the place the drop makes
    DELIVERED, read from FTplan's state rules, is what the request is given."""
    spec = PLANNED_SPEC.replace("request drive.Drop(?p)", "request drive.Drop(?q) where DELIVERED(?q) := YES")
    robot = write_robot(tmp_path, spec, CODELS + DROP_CODELS)
    result = specc(tmp_path, "run", robot, "--mission", "round", "--folder", tmp_path / "run", "-q")
    assert result.returncode == 0, result.stderr
    events = read_events(tmp_path / "run" / "events.jsonl")
    drops = [e for e in events if e["kind"] == "action" and e["status"] == "started" and e["task"] == "DROP"]
    assert drops and all(e["request"] == f"drive.Drop({e['args'][0]})" for e in drops)


def test_a_module_drives_only_the_devices_the_system_gives_it(tmp_path: Path) -> None:
    """`devices { drive: pose; }`: DRIVE's codels may read the pose, not drive the wheels."""
    spec = SPEC.replace("  worlds { shop:", "  devices { drive: pose; }\n  worlds { shop:")
    robot = write_robot(tmp_path, spec)
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "-q")
    assert result.returncode == 1, result.stderr
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "failed"
    assert "module 'drive' has no device 'wheels': the system gives it pose" in report["why"], report["why"]


def test_the_minimal_robot_formats_to_itself() -> None:
    from specc.syntax.parser import parse_text
    from specc.syntax.printer import print_source

    parsed = parse_text(SPEC, "cart.spec")
    assert parsed.source is not None and not parsed.diagnostics
    again = parse_text(print_source(parsed.source), "cart.spec")
    assert again.source is not None
    assert print_source(again.source) == print_source(parsed.source)
    assert textwrap.dedent(print_source(parsed.source)).count("mission deliver") == 1


# A second exec task whose permanent codel raises now and then (every 20th period).
FAULTY_TASK = ("  exec_task Motion { period: 50 ms; priority: 10; }\n",
               "  exec_task Motion { period: 50 ms; priority: 10; }\n"
               "  exec_task Watch { period: 100 ms; codel permanent: watch; }\n")
FAULTY_CODEL = '''

WATCHED = [0]


def watch(sdi):
    WATCHED[0] += 1
    if WATCHED[0] % 20 == 0:
        raise ZeroDivisionError("the watch codel divided by zero")
'''


# A permanent codel that, once, sends the module's own Goto behind the executive's back: the module
# interrupts the GOTO the executive runs, which the executive never asked for (its ERROR state).
MEDDLING_TASK = (FAULTY_TASK[0], FAULTY_TASK[0] + "  exec_task Watch { period: 100 ms; codel permanent: meddle; }\n")
MEDDLING_CODEL = '''

MEDDLED = [0]


def meddle(sdi):
    MEDDLED[0] += 1
    if MEDDLED[0] == 20:
        sdi.send_request("drive.Goto", x=1.0, y=1.0)
'''


def test_the_executive_s_error_state_is_an_incident_of_the_run(tmp_path: Path) -> None:
    """The ERROR state is trouble the robot lives on with, as a codel that raised: an alarm in
    the log, and an incident of the report (it was an alarm only, and the run said "0 incidents")."""
    robot = write_robot(tmp_path, SPEC.replace(*MEDDLING_TASK), CODELS + MEDDLING_CODEL)
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "--no-pictures")
    events = read_events(tmp_path / "run" / "events.jsonl")
    assert [e for e in events if e["kind"] == "alarm" and e["what"] == "executive-error"], result.stdout
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert any("the executive entered its ERROR state" in text for text in report["incidents"])
    assert report["measures"]["incidents"] == len(report["incidents"]) >= 1


def test_a_permanent_codel_that_raises_is_in_the_log_the_report_and_the_summary(tmp_path: Path) -> None:
    """The robot goes on (a permanent codel is retried every period); the run says which module
    and codel raised, where a person and a program look."""
    robot = write_robot(tmp_path, SPEC.replace(*FAULTY_TASK), CODELS + FAULTY_CODEL)
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "--no-pictures")
    assert result.returncode == 0, result.stderr  # the mission itself succeeds
    events = read_events(tmp_path / "run" / "events.jsonl")
    alarms = [e for e in events if e["kind"] == "alarm" and e["what"] == "incident"]
    assert alarms and all("drive: permanent codel 'watch'" in e["detail"] and "ZeroDivisionError" in e["detail"]
                          for e in alarms)
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["measures"]["incidents"] == len(alarms) == len(report["incidents"])
    assert "permanent codel 'watch'" in (tmp_path / "run" / "summary.txt").read_text()
    assert "incident: " in result.stdout
    # A success, but not a clean one: the why says so, with the first incident.
    assert report["outcome"] == "succeeded" and f"; {len(alarms)} incident(s), the first: " in report["why"]
    assert "permanent codel 'watch' raised ZeroDivisionError" in report["why"]


LOOPING_CODEL = CODELS.replace('def step(sdi, request):\n', 'def step(sdi, request):\n    while True:\n'
                               '        pass\n')


def test_a_codel_stuck_in_a_loop_is_stopped_by_the_wall_clock_limit(tmp_path: Path) -> None:
    robot = write_robot(tmp_path, SPEC, LOOPING_CODEL)
    result = specc(tmp_path, "run", robot, "--folder", tmp_path / "run", "--wall-limit", "3", "--no-pictures")
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert "wall-clock limit of 3 s" in result.stderr
    # ... and where it stood: the codel stuck in its loop, by its file and line.
    assert "(--wall-limit) (in step, cart_codels/drive.py:" in result.stderr, result.stderr
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "interrupted" and "wall-clock limit" in report["why"]
    assert "wall-clock limit" in (tmp_path / "run" / "summary.txt").read_text()
    assert read_events(tmp_path / "run" / "events.jsonl")[0]["kind"] == "mission-start"


def test_a_run_stopped_by_sigterm_leaves_its_report(tmp_path: Path) -> None:
    import signal
    import time

    robot = write_robot(tmp_path, SPEC, LOOPING_CODEL)
    run = subprocess.Popen([sys.executable, "-m", "specc.cli", "run", str(robot), "--folder", str(tmp_path / "run"),
                            "--no-pictures"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True)
    deadline = time.monotonic() + 120
    while not (tmp_path / "run" / "events.jsonl").is_file() and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)  # into the loop
    run.send_signal(signal.SIGTERM)
    _, stderr = run.communicate(timeout=60)
    assert run.returncode == 130 and "Traceback" not in stderr, stderr
    report = json.loads((tmp_path / "run" / "report.json").read_text())
    assert report["outcome"] == "interrupted" and report["why"].startswith("stopped by SIGTERM (in step, ")


def test_a_start_where_the_body_overlaps_an_obstacle_is_refused_before_the_run(cart: Path) -> None:
    """The start's centre is clear (0.4 m from the crate's centre, outside its 0.3 m) but the cart's
    0.25 m body reaches into the crate: the physics would shove it out at once."""
    work = cart.parent
    tight = WORLD.replace("x = 1.0\ny = 1.0", "x = 4.5\ny = 1.1")
    (cart / "worlds" / "tight.toml").write_text(tight)
    folder = work / "never-tight"
    result = specc(work, "run", cart, "--goal", "!(GO 3 4)", "--world", cart / "worlds" / "tight.toml",
                   "--folder", folder, "-q")
    assert result.returncode == 2, result.stderr
    assert "the robot's body (its 0.25 m radius) at its start (4.5, 1.1, heading 0 rad) overlaps" in result.stderr
    assert "Traceback" not in result.stderr and not folder.exists()


def test_a_goal_from_the_command_line_is_held_to_its_predicate_s_domains(tmp_path: Path) -> None:
    """`--goal` is checked as a mission's goal is: a value outside the domain the goal's predicate
    declares is refused before anything runs (not found out 17 s into the run)."""
    declared = SPEC.replace("  action GOTO(x: float, y: float)", "  predicate GO(x: 0..5, y: 0..5);\n"
                            "  action GOTO(x: float, y: float)")
    cart = write_robot(tmp_path, declared)
    folder = tmp_path / "never"
    result = specc(tmp_path, "run", cart, "--goal", "!(GO 9 4)", "--folder", folder, "-q")
    assert result.returncode == 2, result.stderr
    assert "--goal !(GO 9 4): '9' is not in the domain of GO's 'x' (0, 1, 2, 3, 4, 5)" in result.stderr
    assert "Traceback" not in result.stderr and not folder.exists()


def test_check_refuses_a_world_whose_start_the_body_overlaps(tmp_path: Path) -> None:
    """`specc check` holds the system's worlds to its body, as the run does: the cart's 0.25 m disc
    at (4.5, 1.1) reaches into the crate centred 0.4 m away."""
    cart = write_robot(tmp_path)
    (cart / "worlds" / "shop.toml").write_text(WORLD.replace("x = 1.0\ny = 1.0", "x = 4.5\ny = 1.1"))
    result = specc(tmp_path, "check", cart)
    assert result.returncode == 1, result.stderr
    assert "worlds/shop.toml: the robot's body (its 0.25 m radius) at its start (4.5, 1.1, heading 0 rad) " \
           "overlaps obstacles[0]: move [start]" in result.stderr and "[bad-world]" in result.stderr


def test_a_misspelt_device_is_named_with_a_hint_at_the_codel_s_line(tmp_path: Path) -> None:
    """`sim.wheelz` in a codel: the run's why names the device it meant and the codel's own line,
    not the simulator's line that refused the name."""
    cart = write_robot(tmp_path, codels=CODELS.replace("    if sim.wheels.blocked:", "    if sim.wheelz.blocked:"))
    result = specc(tmp_path, "run", cart, "--goal", "!(GO 3 4)", "--folder", tmp_path / "run", "-q")
    assert result.returncode == 1, result.stderr
    why = json.loads((tmp_path / "run" / "report.json").read_text())["why"]
    line = CODELS.splitlines().index("    if sim.wheels.blocked:") + 1
    assert "has no device 'wheelz' (did you mean 'wheels'?)" in why, why
    assert f"cart_codels/drive.py:{line})" in why and "simulation.py" not in why, why
