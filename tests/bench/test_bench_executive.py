"""`make bench`: the executive's whole cycle (one event: a task request, an interruption, a
module reply or a timeout, then a new start authorisation for every WAIT activity) under
100,000 random events, on Hilare's executive (21 services, 432 controller states) driving its
real modules on the simulated clock; the time modules spend on what the executive sends them
(other processes on the robot) is left out. Baseline, measured in the same run: one call of the
controller's decision function, the least a cycle can cost."""

from __future__ import annotations

import gc
import random
import statistics
import sys
import time

import pytest

from specc.runtime import executive as rx
from specc.runtime import functional as rt
from tests.conftest import EXAMPLES, ROOT

pytestmark = pytest.mark.bench

EVENTS = 100_000


def test_executive_cycle_under_random_events() -> None:
    sys.path[:0] = [str(ROOT / "generated"), str(EXAMPLES / "hilare")]
    from hilare import modules  # type: ignore[import-not-found]
    from hilare.executive import hilare, hilare_resource_controller  # type: ignore[import-not-found]

    registry = rt.Registry()
    modules.create_all(registry)
    executive = hilare.create(registry, world=str(EXAMPLES / "hilare" / "worlds" / "room.toml"), measure=True)
    services = list(hilare.SERVICES)
    replies = 0

    def count(message: rx.Message) -> None:
        nonlocal replies
        replies += message.kind == "REPLY"

    executive.listeners.append(count)
    gc.collect()
    gc.freeze()  # what start-up built lives for the whole run: collections need not walk it again
    rng = random.Random(11)
    next_id = 1
    started = time.perf_counter()
    while len(executive.cycle_durations) < EVENTS:
        roll = rng.random()
        if roll < 0.45 and len(executive.activities) < 6:
            executive.request(rng.choice(services), next_id)
            next_id += 1
        elif roll < 0.6 and executive.activities:
            executive.interrupt(rng.choice(list(executive.activities)))
        else:
            registry.kernel.run_for(rng.choice([0.001, 0.01, 0.1, 1.0]))
        for activity in list(executive.activities.values()):  # the task level acknowledges ZOMBIEs
            if activity.state is rx.Phase.ZOMBIE:
                executive.interrupt(activity.id)
    wall = time.perf_counter() - started
    cycles = sorted(executive.cycle_durations)

    inputs = {"service": "CALC-TRAJ-OBJ", "event": "START"} | {f"@{g}": "IDLE" for g in hilare.GROUPS}
    best = float("inf")
    for _ in range(5):
        begin = time.perf_counter()
        for _ in range(20_000):
            hilare_resource_controller.decide(inputs)
        best = min(best, (time.perf_counter() - begin) / 20_000)

    def us(fraction: float) -> float:
        return cycles[min(len(cycles) - 1, int(fraction * len(cycles)))] * 1e6

    print(f"\nHilare executive, {len(cycles):,} cycles from random requests, interruptions, replies and timeouts"
          f"\n  ({next_id - 1:,} requests, {replies:,} final replies, {registry.kernel.now:,.0f} s simulated "
          f"in {wall:.1f} s; error state: {executive.error or 'never'})"
          f"\n  baseline: one controller decision   {best * 1e6:8.2f} us"
          f"\n  cycle p50                           {us(0.50):8.2f} us  ({us(0.50) / (best * 1e6):.1f}x baseline)"
          f"\n  cycle p99                           {us(0.99):8.2f} us  ({us(0.99) / (best * 1e6):.1f}x baseline)"
          f"\n  cycle max                           {cycles[-1] * 1e6:8.2f} us"
          f"\n  cycle mean                          {statistics.fmean(cycles) * 1e6:8.2f} us")
    gc.unfreeze()
    assert executive.error is None
