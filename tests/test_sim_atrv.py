"""The ATRV rover of seed 004 in the simulator, driven through its generated modules (RFLEX, SICK,
NDD, PLATINE, CAMERA, ANTENNA; examples/atrv/modules) in the worlds W1-W4 of §4.1.2.1."""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import subprocess
import sys
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import pytest

from specc.run.mission import load_robot
from specc.runtime import functional as rt
from specc.runtime.sim import Window, load_world, parse_world
from specc.runtime.sim.world import Circle, Polygon
from tests.conftest import EXAMPLES, ROOT

ATRV = EXAMPLES / "atrv"
WORLDS = ATRV / "worlds"
# m, the simulated ATRV's (1.05 m x 0.65 m, system.spec)
HALF_WIDTH = load_robot(ROOT / "generated", ATRV, "atrv").system.body.width / 2.0
TOLERANCE = 0.3


@pytest.fixture(scope="module")
def run_sim() -> Iterator[ModuleType]:
    """examples/atrv/run_sim.py, whose `build` puts the generated modules and the codels on
    sys.path (restored afterwards)."""
    saved = list(sys.path)
    spec = importlib.util.spec_from_file_location("atrv_run_sim", ATRV / "run_sim.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.import_generated()
    yield module
    sys.path[:] = saved


def rover(run_sim: ModuleType, name: str = "W1", seed: int = 0, **changes: Any) -> Any:
    world = load_world(WORLDS / f"{name}.toml")
    return run_sim.build(dataclasses.replace(world, **changes) if changes else world, seed)


def goto(r: Any, x: float, y: float, timeout: float = 200.0) -> rt.Reply:
    return r.clients.ndd.final(r.clients.ndd.GotoTarget(x, y, TOLERANCE), timeout=timeout)


def clearance(obstacle: Circle | Polygon, pose: tuple[float, float, float]) -> float:
    return obstacle.distance(pose[0], pose[1])


# ---------------------------------------------------------------- worlds


@pytest.mark.parametrize("name", ["W1", "W2", "W3", "W4"])
def test_worlds_hold_every_mission_target_reachable_within_the_12_m_square(name: str) -> None:
    world = load_world(WORLDS / f"{name}.toml")
    assert world.bounds == (-20.0, 20.0, -20.0, 20.0) and world.start == (0.0, 0.0, 0.0)
    assert len(world.targets) == 15 and {t.name for t in world.targets} >= {"M1_OBJ1", "M4_OBJ5"}
    for target in world.targets:
        assert world.clearance(target.x, target.y) > 0.75, target  # the rover's circle fits there
    for obstacle in world.obstacles:
        corners = obstacle.points if isinstance(obstacle, Polygon) else [
            (obstacle.x + dx, obstacle.y + dy) for dx in (-obstacle.radius, obstacle.radius)
            for dy in (-obstacle.radius, obstacle.radius)]
        assert all(abs(x) <= 6.0 and abs(y) <= 6.0 for x, y in corners), obstacle
    kinds = {type(o) for o in world.obstacles}
    assert kinds == {"W1": set(), "W2": {Circle}, "W3": {Circle, Polygon}, "W4": {Polygon}}[name]


# ---------------------------------------------------------------- navigation (RFLEX, SICK, NDD)


def test_rover_reaches_a_goal_in_the_empty_world(run_sim: ModuleType) -> None:
    r = rover(run_sim, "W1")
    reply = goto(r, 3.0, -3.0)
    assert reply.ok, reply
    x, y, _ = r.sim.pose
    assert math.hypot(x - 3.0, y + 3.0) < TOLERANCE + 0.1
    odometry = r.clients.rflex.poster_Robot().data.pose
    assert math.hypot(odometry.x - x, odometry.y - y) < 0.1  # odometry from the encoders, not the truth
    assert reply.output.arrival.distance <= TOLERANCE
    assert r.sim.trace.blocked_at is None


@pytest.mark.parametrize("goal", [(5.0, 5.0), (4.0, 0.0)])
def test_rover_goes_round_the_cylinders_of_w2(run_sim: ModuleType, goal: tuple[float, float]) -> None:
    r = rover(run_sim, "W2")
    cylinders = [o for o in r.sim.world.obstacles if isinstance(o, Circle)]
    # A cylinder stands across the straight way: going round it is the navigator's doing.
    assert any(abs(c.x * goal[1] - c.y * goal[0]) / math.hypot(*goal) < c.radius + HALF_WIDTH for c in cylinders)
    reply = goto(r, *goal)
    assert reply.ok, reply
    x, y, _ = r.sim.pose
    assert math.hypot(x - goal[0], y - goal[1]) < TOLERANCE + 0.1
    nearest = min(clearance(c, pose) for c in cylinders for pose in r.sim.trace.poses)
    assert nearest > HALF_WIDTH
    assert r.sim.trace.blocked_at is None


def test_rover_tours_mission_m3_in_w3_among_obstacles_near_its_targets(run_sim: ModuleType) -> None:
    r = rover(run_sim, "W3")
    for goal in [(2.0, 1.0), (-1.0, 2.0), (-2.0, -2.0), (1.0, -3.0), (0.0, 0.0)]:
        reply = goto(r, *goal)
        assert reply.ok, (goal, reply)
        x, y, _ = r.sim.pose
        assert math.hypot(x - goal[0], y - goal[1]) < TOLERANCE + 0.1
    nearest = min(clearance(o, pose) for o in r.sim.world.obstacles for pose in r.sim.trace.poses)
    assert nearest > HALF_WIDTH and r.sim.trace.blocked_at is None


def test_w4_pocket_traps_the_rover_for_good(run_sim: ModuleType) -> None:
    r = rover(run_sim, "W4")
    reply = goto(r, 5.0, 5.0)
    assert reply.status is rt.Status.END
    assert reply.report.code in ("NO_PROGRESS", "BLOCKED")
    assert reply.report.code == "BLOCKED" or r.sim.now >= r.modules["ndd"].sdi.params.progressTime
    x, y, _ = r.sim.pose
    assert math.hypot(x - 5.0, y - 5.0) > 2.0
    u, v = (x + y) / math.sqrt(2), (y - x) / math.sqrt(2)  # along the pocket's axis, across it
    assert 2.4 < u < 6.0 and abs(v) < 1.6, (x, y)  # still inside the pocket
    # The wheels are stopped once the navigation gave up.
    assert r.clients.rflex.poster_Robot().data.speed.v == 0.0


def test_blocked_wheels_end_the_speed_tracking(run_sim: ModuleType) -> None:
    wall = parse_world({"bounds": {"xmin": -3.0, "xmax": 1.5, "ymin": -3.0, "ymax": 3.0}}, "wall.toml")
    r = run_sim.build(wall)
    ndd = r.modules["ndd"]
    ndd.sdi.speed.v = 0.3  # what NDD would export, written by hand: RFLEX alone drives into the wall
    ndd.update_poster("Speed")
    reply = r.clients.rflex.final(r.clients.rflex.TrackSpeed("ndd.Speed"), timeout=30.0)
    assert (reply.status, reply.report.code) == (rt.Status.END, "BLOCKED")
    assert r.sim.trace.blocked_at is not None and r.sim.trace.blocked_at <= reply.time
    assert r.sim.pose[0] < 1.5 - 0.5  # the wall held


def test_laser_without_echo_stops_the_navigation(run_sim: ModuleType) -> None:
    r = rover(run_sim, "W1")
    assert r.modules["sick"].sdi.scan.echo is False  # no scan yet
    r.kernel.run_for(0.2)
    assert r.modules["sick"].sdi.scan.echo is True  # the far walls at 20 m (note 3)
    assert r.clients.sick.final(r.clients.sick.Configure(1.0)).ok  # nothing within 1 m: no beam comes back
    r.kernel.run_for(0.2)
    reply = goto(r, 3.0, 0.0)
    assert (reply.status, reply.report.code) == (rt.Status.END, "LASER_FAILURE")


# ---------------------------------------------------------------- PLATINE, CAMERA, ANTENNA


def test_pan_tilt_reaches_its_target(run_sim: ModuleType) -> None:
    r = rover(run_sim)
    started = r.kernel.now
    reply = r.clients.platine.final(r.clients.platine.MoveTo(1.0, -0.4))
    assert reply.ok, reply
    unit = r.sim.pan_tilt
    assert unit.pan.position == pytest.approx(1.0) and unit.tilt.position == pytest.approx(-0.4)
    assert not unit.moving
    assert reply.time - started >= 1.0 / unit.pan.speed - 1e-6  # it waited for the unit
    assert r.clients.platine.poster_Position().data.position.pan == pytest.approx(1.0)
    refused = r.clients.platine.final(r.clients.platine.MoveTo(0.0, 3.0))
    assert (refused.status, refused.report.code) == (rt.Status.FINAL_ERROR, "BAD_POSITION")


def test_photo_of_a_target_in_view_succeeds_and_out_of_view_fails(run_sim: ModuleType) -> None:
    r = rover(run_sim)  # at the start (0, 0) facing +x: M1_OBJ2 (4, 0) straight ahead
    ok = r.clients.camera.final(r.clients.camera.TakePicture("M1_OBJ2"))
    assert ok.ok, ok
    assert "M1_OBJ2" in ok.output.photo.targets.split(",")
    assert (ok.time, "M1_OBJ2", True) in r.sim.trace.photos
    assert r.clients.platine.final(r.clients.platine.MoveTo(math.pi, 0.0)).ok  # looking back: nothing in view
    failed = r.clients.camera.final(r.clients.camera.TakePicture("M1_OBJ2"))
    assert (failed.status, failed.report.code) == (rt.Status.END, "NO_TARGET_IN_VIEW")
    assert r.sim.trace.photos[-1] == (failed.time, "M1_OBJ2", False)
    from atrv_codels.platine import AT_MY_FEET

    assert r.clients.platine.final(r.clients.platine.MoveTo(*AT_MY_FEET)).ok  # annex A's AT_MY_FEET
    feet = r.clients.camera.final(r.clients.camera.TakePicture("M1_OBJ1"))  # the target under the robot
    assert feet.ok and feet.output.photo.targets == "M1_OBJ1"


def test_photo_while_the_pan_tilt_unit_moves_fails(run_sim: ModuleType) -> None:
    r = rover(run_sim)
    r.clients.platine.MoveTo(2.0, 0.0)
    r.kernel.run_for(0.2)
    reply = r.clients.camera.final(r.clients.camera.TakePicture(""))
    assert reply.report.code == "PTU_MOVING"


def test_communication_inside_a_window_succeeds_and_outside_fails(run_sim: ModuleType) -> None:
    r = rover(run_sim)
    r.sim.antenna.windows = (Window("W1", 5.0, 30.0),)
    early = r.clients.antenna.final(r.clients.antenna.Communicate(5.0))
    assert (early.status, early.report.code) == (rt.Status.END, "NO_VISIBILITY")
    r.kernel.run_until(6.0)
    inside = r.clients.antenna.final(r.clients.antenna.Communicate(10.0))
    assert inside.ok and inside.output.window == "W1"
    assert len(r.sim.antenna.sent) == 1
    start, end, name = r.sim.antenna.sent[0]
    assert name == "W1" and 5.0 <= start and end <= 30.0 and end - start == pytest.approx(10.0)
    r.kernel.run_until(25.0)
    cut = r.clients.antenna.final(r.clients.antenna.Communicate(10.0))  # the window closes at 30 s
    assert (cut.status, cut.report.code) == (rt.Status.END, "LINK_LOST")
    assert 30.0 <= cut.time < 31.0
    assert len(r.sim.antenna.sent) == 1


# ---------------------------------------------------------------- determinism, fallback, script


def test_same_seed_same_trace_and_another_seed_another(run_sim: ModuleType) -> None:
    def path(seed: int) -> list[tuple[float, float, float]]:
        r = rover(run_sim, "W2", seed)
        r.clients.ndd.GotoTarget(4.0, 0.0, TOLERANCE)
        r.kernel.run_for(12.0)
        return r.sim.trace.poses

    first = path(3)
    assert len(first) > 100
    assert path(3) == first
    assert path(4) != first


def test_modules_work_without_a_simulator(run_sim: ModuleType) -> None:
    modules = run_sim.import_generated().modules
    registry = rt.Registry()
    made = modules.create_all(registry)
    client = {name: modules.MODULES[name].client(module) for name, module in made.items()}
    reply = client["ndd"].final(client["ndd"].GotoTarget(2.0, 1.0, 0.2), timeout=60.0)
    assert reply.ok, reply
    pose = client["rflex"].poster_Robot().data.pose
    assert math.hypot(pose.x - 2.0, pose.y - 1.0) <= 0.2
    assert client["platine"].final(client["platine"].MoveTo(0.5, -0.5)).ok
    assert client["camera"].final(client["camera"].TakePicture("OBJ1")).ok
    assert client["antenna"].final(client["antenna"].Communicate(2.0)).ok
    assert registry.incidents == []


def run_script(*args: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(ATRV / "run_sim.py"), *args], capture_output=True, text=True,
                          timeout=timeout)


def test_run_sim_drives_the_rover_and_draws_the_run(tmp_path: Any) -> None:
    picture = tmp_path / "w2.png"
    result = run_script("--world", "W2", "--goal", "4,0", "--goal", "-1,2", "--photos", "--seed", "1",
                        "-o", str(picture))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "ndd.GotoTarget(4, 0, 0.3) -> END OK" in result.stdout
    assert "camera.TakePicture('M3_OBJ2') -> END OK" in result.stdout
    assert "blocked: no" in result.stdout and "real time" in result.stdout
    assert picture.stat().st_size > 10_000


@pytest.mark.parametrize("args, message", [
    (["--world", "nowhere.toml"], "nowhere.toml: cannot read the world file"),
    (["--world", "W9"], "unknown world 'W9': give W1, W2, W3, W4"),
    (["--world", "W2", "--goal", "4;0"], "--goal '4;0': expected x,y"),
    (["--world", "W2", "--goal", "2.6,2.8"], "inside an obstacle"),
    (["--world", "W1", "--goal", "-30,0"], "outside the walls"),
])
def test_run_sim_reports_bad_arguments_in_one_line(args: list[str], message: str) -> None:
    result = run_script(*args, timeout=60.0)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.stderr
