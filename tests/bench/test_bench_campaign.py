"""`make bench`: campaign throughput, in experiments per hour on this machine (issue #10's goal:
the seed's 3,500 experiments in under one hour, i.e. 3,500 per hour or more).

The experiments are one run of each of the 16 activities (M1-M4 x W1-W4) with Robot1 and the
original Modele1: a campaign's mix of mission lengths. They run twice, measured in the same run:
- the baseline, one after another in this process (`run_experiment` called directly: no
  process, no timeout, what a hand-written loop over missions would do);
- the campaign's local engine with one experiment process per CPU (`LocalEngine`), as
  `specc campaign` runs them, each in a killable process of its own.
Printed: both rates, the engine's speed-up over the baseline, and the hours the seed's 3,500
experiments would take at the engine's rate. Same experiments, same results: asserted."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from specc.campaign.engines import LocalEngine
from specc.campaign.experiments import ORIGINAL, Experiment, Outcome, Setting, run_experiment

pytestmark = pytest.mark.bench

ROOT = Path(__file__).resolve().parents[2]
SETTING = Setting(ROOT / "generated", ROOT / "examples" / "atrv", "atrv")
EXPERIMENTS = [Experiment("Robot1", ORIGINAL, mission, world, 0)
               for mission in ("M1", "M2", "M3", "M4") for world in ("W1", "W2", "W3", "W4")]
SEED_CAMPAIGN = 3500  # experiments (seed 004 ch. 4: "more than 3,500")


def per_hour(count: int, seconds: float) -> float:
    return count / seconds * 3600.0


def test_campaign_throughput_against_experiments_one_after_another() -> None:
    run_experiment(EXPERIMENTS[0], None, SETTING)  # imports and the planners' forkserver, warmed up
    started = time.perf_counter()
    alone = {e: run_experiment(e, None, SETTING) for e in EXPERIMENTS}
    baseline = time.perf_counter() - started
    workers = os.cpu_count() or 1
    engine = LocalEngine(SETTING, workers, timeout=300.0)
    started = time.perf_counter()
    pooled: dict[Experiment, Outcome] = {o.experiment: o for o in engine.run((e, None) for e in EXPERIMENTS)}
    wall = time.perf_counter() - started
    assert all(pooled[e].measures == alone[e].measures and alone[e].status == "done" for e in EXPERIMENTS)
    rate, base_rate = per_hour(len(EXPERIMENTS), wall), per_hour(len(EXPERIMENTS), baseline)
    print()
    print(f"campaign throughput, {len(EXPERIMENTS)} experiments (M1-M4 x W1-W4, Robot1, original Modele1):")
    print(f"  one after another, in process : {baseline:6.1f} s  {base_rate:7,.0f} experiments/h")
    print(f"  local engine, {workers} process(es)   : {wall:6.1f} s  {rate:7,.0f} experiments/h "
          f"({rate / base_rate:.2f}x the baseline, process starts included)")
    print(f"  the seed's {SEED_CAMPAIGN:,} experiments: {SEED_CAMPAIGN / rate:.2f} h at this rate "
          f"(goal: under 1 h; {rate / SEED_CAMPAIGN:.2f}x the rate it needs)")
