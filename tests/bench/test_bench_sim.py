"""`make bench`: simulated seconds per wall-clock second of the pymunk rover (Hilare 2 in its
room, 32 sonars), next to a baseline measured in the same run: a plain pymunk loop stepping the
same robot and world at the same rate with 32 `Space.segment_query_first` calls per step.

Three configurations of ours:
- sensing at the baseline's pace: physics + the 32 sonars read at every step (40 Hz);
- sensing as the modules use it: physics + the ring read by US's scan period (10 Hz);
- the full module stack: LOCO, PILO, AVOID, US (and the idle others) driving PLAN's paths.
Goal: at least 500x real time with the 32 sonars, read as the modules read them. The full stack
runs about 130 codel cycles per simulated second (LOCO's two 25 ms tasks of seed 000 alone make
80), each a Python call doing real work, so it is reported next to the baseline, not held to 500x."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
import pymunk
import pytest

from specc.runtime import functional as rt
from specc.runtime.sim import Simulation, load_world
from tests.conftest import hilare

HILARE = hilare().system.body  # examples/hilare/system.spec's body block

pytestmark = pytest.mark.bench

ROOT = Path(__file__).resolve().parents[2]
ROOM = ROOT / "examples" / "hilare" / "worlds" / "room.toml"
SECONDS = 300.0  # simulated per measurement
PERIOD = 0.025  # the physics period of Simulation, LOCO's period


def baseline_speed() -> float:
    """A plain pymunk loop: the rover's body pushed by a velocity-controlled pivot, 32 per-ray
    queries each step."""
    room = load_world(ROOM)
    space = pymunk.Space()
    space.add(*[pymunk.Segment(space.static_body, (a, b), (c, d), 0.0) for a, b, c, d in room.segments()])
    body = pymunk.Body(HILARE.mass, pymunk.moment_for_circle(HILARE.mass, 0.0, HILARE.radius))
    body.position = room.start[:2]
    shape = pymunk.Circle(body, HILARE.radius)
    control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    pivot = pymunk.PivotJoint(control, body, (0, 0), (0, 0))
    pivot.max_bias, pivot.max_force = 0.0, 600.0
    space.add(body, shape, control, pivot)
    query = pymunk.ShapeFilter(mask=pymunk.ShapeFilter.ALL_MASKS() ^ 1)
    shape.filter = pymunk.ShapeFilter(categories=1)
    angles = np.linspace(0.0, math.tau, 32, endpoint=False)
    steps = int(SECONDS / PERIOD)
    started = time.perf_counter()
    for k in range(steps):
        control.velocity = (0.3 * math.cos(k * 0.001), 0.3 * math.sin(k * 0.001))
        space.step(PERIOD)
        x, y = body.position
        ranges = []
        for a in angles:
            hit = space.segment_query_first((x, y), (x + 5.0 * math.cos(a), y + 5.0 * math.sin(a)), 0.0, query)
            ranges.append(5.0 if hit is None else hit.alpha * 5.0)
    return SECONDS / (time.perf_counter() - started)


def sensing_speed(sonar_period: float) -> float:
    sim = Simulation(load_world(ROOM), HILARE, seed=1)
    sim.wheels.drive(0.3, 0.05)
    assert sim.sonars is not None
    sonars = sim.sonars

    def scan() -> None:
        sonars.read()
        sim.kernel.call_later(sonar_period, scan, priority=10)

    sim.kernel.call_at(sonar_period, scan, priority=10)
    started = time.perf_counter()
    sim.run_for(SECONDS)
    return SECONDS / (time.perf_counter() - started)


def full_stack_speed() -> tuple[float, str]:
    sys.path[:0] = [str(ROOT / "generated"), str(ROOT / "examples" / "hilare")]
    from hilare import modules
    from hilare.modules.pilo import PiloClient
    from hilare.modules.plan import Box, PlanClient, Posit

    registry = rt.Registry()
    sim = Simulation(load_world(ROOM), HILARE, seed=1, kernel=registry.kernel).attach(registry)
    made = modules.create_all(registry)
    plan, pilo = PlanClient(made["plan"]), PiloClient(made["pilo"])
    xmin, xmax, ymin, ymax = sim.world.bounds
    assert plan.final(plan.setPlannerEnv(Box(xmin, ymin, xmax, ymax))).ok
    assert plan.final(plan.readModelFile(str(ROOM))).ok and pilo.final(pilo.avoidOnOff(True)).ok
    goals = [(9.0, 7.0), (2.0, 7.0), (10.0, 2.0), (1.0, 1.0)]
    started, origin, legs = time.perf_counter(), sim.now, 0
    while sim.now - origin < SECONDS:
        gx, gy = goals[legs % len(goals)]
        r = made["loco"].sdi.robot
        assert plan.final(plan.plan(Posit(x=r.x, y=r.y, theta=r.theta), Posit(x=gx, y=gy))).ok
        assert pilo.final(pilo.execPosterTraj("plan.Traj")).ok
        legs += 1
    elapsed = time.perf_counter() - started
    return (sim.now - origin) / elapsed, f"{legs} paths planned and driven, avoidance on"


def test_simulation_speed():
    baseline = baseline_speed()
    at_every_step = sensing_speed(PERIOD)
    at_scan_rate = sensing_speed(0.1)
    stack, what = full_stack_speed()
    rows = [("sensing, 32 sonars every step (as the baseline)", at_every_step),
            ("sensing, 32 sonars at US's 10 Hz scan", at_scan_rate),
            (f"full module stack ({what})", stack)]
    width = max(len(label) for label, _ in rows) + 2
    print("\nsimulated seconds per wall second (Hilare 2, its room, 32 sonars, physics at 40 Hz)")
    print(f"  {'baseline: pymunk loop, 32 segment queries per step':<{width}s}{baseline:8.0f}x")
    for label, speed in rows:
        verdict = "" if label.startswith("full") else \
            f"   {'meets' if speed >= 500 else 'misses'} the 500x goal"
        print(f"  {label:<{width}s}{speed:8.0f}x   {speed / baseline:5.2f} x baseline{verdict}")
    assert min(at_every_step, at_scan_rate, stack) > 0
