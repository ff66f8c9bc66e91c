"""`make bench`: planning time per rover mission (median of 5), Modele1 (numeric positions) and
Modele2 (symbolic positions), next to the temporal planner Aries (up-aries, bench-only) solving
the same missions exported through unified-planning in the same run; the ratio is printed.
Goals: every mission within 0.5 s with Modele1, and no slower than Aries with Modele2; M4 with a
300 s horizon answered within a second."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from specc.runtime.planner import Planner
from specc.runtime.planner import model as pm
from specc.runtime.planner.validate import validate
from tests.atrv import atrv_models

pytestmark = pytest.mark.bench

ATRV = Path(__file__).resolve().parents[2] / "examples" / "atrv"
RUNS = 5
ARIES_RUNS = 3  # Aries takes tens of seconds where it plans at all (see docs/planning.md)
ARIES_TIMEOUT = 60.0


def median_seconds(run: Callable[[], object], runs: int = RUNS) -> float:
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def aries_seconds(domain: pm.PlanningDomain, problem: pm.Problem) -> tuple[float | None, str]:
    """Aries' median time on the exported mission, or None and why it could not run."""
    try:
        import unified_planning.shortcuts as up
        from unified_planning.engines import PlanGenerationResultStatus as Status

        from specc.analysis.planning_export import export
    except ImportError as error:
        return None, f"not installed ({error.name})"
    exported = export(domain, problem).problem
    up.get_environment().credits_stream = None
    outcome: list[str] = []

    def solve() -> None:
        with up.OneshotPlanner(name="aries") as planner:
            result = planner.solve(exported, timeout=ARIES_TIMEOUT)
        outcome.append(result.status.name)
        if result.status not in (Status.SOLVED_SATISFICING, Status.SOLVED_OPTIMALLY):
            raise RuntimeError(result.status.name)

    try:
        return median_seconds(solve, ARIES_RUNS), outcome[-1]
    except Exception as error:  # Aries' own failure is a result of the comparison, not of the bench
        return None, f"{type(error).__name__}: {error}"


def test_planning_time_per_mission_against_aries() -> None:
    lines = [f"{'mission':22} {'specc (s)':>10} {'Aries (s)':>10} {'ratio':>8}  goals kept"]
    for model in ("model1", "model2"):
        for k in (1, 2, 3, 4):
            name = f"M{k}_{model}"
            domain, problem = atrv_models(name)
            result = Planner(domain).plan(problem)  # warm-up: CasADi's import, the caches
            assert result.plan is not None
            assert validate(domain, problem, result.plan, dropped_lines={g.line for g in result.dropped}) == []
            ours = median_seconds(lambda: Planner(domain).plan(problem))  # noqa: B023
            theirs, status = aries_seconds(domain, problem)
            kept = f"{sum(g.kept for g in result.goals)}/{len(result.goals)}"
            if theirs is None:
                lines.append(f"{name:22} {ours:10.3f} {'-':>10} {'-':>8}  {kept}  (Aries: {status})")
            else:
                lines.append(f"{name:22} {ours:10.3f} {theirs:10.3f} {theirs / ours:7.1f}x  {kept}")
    domain, problem = atrv_models("M4_model1")
    short = pm.with_horizon(problem, 300.0)
    result = Planner(domain).plan(short)
    assert result.plan is not None and result.dropped
    cut = median_seconds(lambda: Planner(domain).plan(short))
    lines.append(f"{'M4_model1, 300 s':22} {cut:10.3f}  (drops {len(result.dropped)} goals; goal: within 1 s)")
    print(f"\nplanning time per mission, median of {RUNS} (Aries: of {ARIES_RUNS}, {ARIES_TIMEOUT:g} s limit; "
          "goals: Modele1 <= 0.5 s, Modele2 <= Aries):\n  "
          + "\n  ".join(lines))
