"""`make bench`: the executive's whole cycle (one event: a task request, an interruption, a
module reply or a timeout, then a new start authorisation for every WAIT activity) under
100,000 random events, on Hilare's executive (21 services, 432 controller states) driving its
real modules on the simulated clock; the time modules spend on what the executive sends them
(other processes on the robot) is left out. Baseline, measured in the same run: one call of the
controller's decision function, the least a cycle can cost."""

from __future__ import annotations

import gc
import statistics
import time

import pytest

from tests.storm import blow, hilare_executive

pytestmark = pytest.mark.bench

EVENTS = 100_000
EXPLORED_REQUESTS = 2  # what `specc verify` explores by default


def test_executive_cycle_under_random_events() -> None:
    storm = hilare_executive()
    executive, registry = storm.executive, storm.registry
    gc.collect()
    gc.freeze()  # what start-up built lives for the whole run: collections need not walk it again
    started = time.perf_counter()
    blow(storm, EVENTS)
    wall = time.perf_counter() - started
    cycles = sorted(executive.cycle_durations)
    replies = sum(storm.finals.values())
    controller = storm.controller
    groups = [name for name in controller.INPUTS if name.startswith("@")]
    inputs = {"service": "CALC-TRAJ-OBJ", "event": "START"} | {g: "IDLE" for g in groups}
    best = float("inf")
    for _ in range(5):
        begin = time.perf_counter()
        for _ in range(20_000):
            controller.decide(inputs)
        best = min(best, (time.perf_counter() - begin) / 20_000)

    def us(fraction: float) -> float:
        return cycles[min(len(cycles) - 1, int(fraction * len(cycles)))] * 1e6

    print(f"\nHilare executive, {len(cycles):,} cycles from random requests, interruptions, replies and timeouts"
          f"\n  ({storm.requests:,} requests, {replies:,} final replies, {registry.kernel.now:,.0f} s simulated "
          f"in {wall:.1f} s; error state: {executive.error or 'never'})"
          f"\n  baseline: one controller decision   {best * 1e6:8.2f} us"
          f"\n  cycle p50                           {us(0.50):8.2f} us  ({us(0.50) / (best * 1e6):.1f}x baseline)"
          f"\n  cycle p99                           {us(0.99):8.2f} us  ({us(0.99) / (best * 1e6):.1f}x baseline)"
          f"\n  cycle max                           {cycles[-1] * 1e6:8.2f} us"
          f"\n  cycle mean                          {statistics.fmean(cycles) * 1e6:8.2f} us")
    gc.unfreeze()
    assert executive.error is None


def test_executive_explorer_states_per_second_next_to_the_petri_engine() -> None:
    """`specc verify`'s explorer on Hilare's executive (two outstanding requests, `sends:`
    modelled where the executive can observe them; its controller compiled before the clock
    starts) against the Petri engine on the resource-allocation net, same run: states per second
    of each. Issue #24's goal, within 3x of the Petri engine, is printed, not yet met."""
    from specc.analysis.petri import explore
    from specc.analysis.verify import explorer_for
    from specc.model import nodes as m
    from specc.pipeline import load
    from tests.bench.test_bench_petri import specc_net
    from tests.conftest import EXAMPLES

    started = time.perf_counter()
    space = explore(specc_net())
    petri = space.states / (time.perf_counter() - started)
    program = load([EXAMPLES / "hilare"]).program
    assert program is not None
    executive = next(i for i in program.items if isinstance(i, m.Executive))
    explorer = explorer_for(program, executive, EXPLORED_REQUESTS)
    started = time.perf_counter()
    result = explorer.explore()
    seconds = time.perf_counter() - started
    rate = result.states / seconds
    print(f"\nstate-space exploration, same run:"
          f"\n  Petri engine, resource-allocation net  {space.states:9,} states  {petri:9,.0f} states/s"
          f"\n  executive explorer, Hilare, {EXPLORED_REQUESTS} requests {result.states:9,} states  "
          f"{rate:9,.0f} states/s  "
          f"({petri / rate:.0f}x slower; #24's goal: within 3x); the whole exploration {seconds:.1f} s"
          f"\n  (left out of the model: {'; '.join(result.left_out) or 'nothing'})")
    assert result.ok and space.complete
