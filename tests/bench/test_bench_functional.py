"""`make bench`: request round trips through the generated LOCO client.

Baseline, measured in the same run: the irreducible work of one control request (calling its
validate codel and building the reply) with no controller, client or checks around it.
Goal: at least 50,000 control round trips per second on one core.
"""

from __future__ import annotations

import sys
import time

import pytest

from specc.runtime import functional as rt
from tests.conftest import EXAMPLES, ROOT

pytestmark = pytest.mark.bench


def rate(run, count: int) -> float:  # type: ignore[no-untyped-def]
    best = 0.0
    for _ in range(3):
        started = time.perf_counter()
        run(count)
        best = max(best, count / (time.perf_counter() - started))
    return best


def test_round_trips_through_the_generated_client() -> None:
    sys.path[:0] = [str(ROOT / "generated"), str(EXAMPLES / "hilare")]
    from hilare.modules import loco  # type: ignore[import-not-found]
    from hilare_codels import loco as codels  # type: ignore[import-not-found]

    registry = rt.Registry()
    client = loco.client(loco.create(registry))
    ref = loco.Ref(x=0.5, v=0.1)

    def baseline(count: int) -> None:
        sdi, record = loco.LocoData(), loco.GoToInput(ref=ref)
        for i in range(count):
            codels.controlRef(sdi, record)
            rt.Reply(i, "loco", "GoTo", rt.Status.END, rt.Report("OK"))

    def control(count: int) -> None:
        for _ in range(count):
            client.final(client.GoTo(ref))

    def lifecycle(count: int) -> None:
        for _ in range(count):
            client.final(client.Track("nowhere.Poster"))

    base, trips, lives = rate(baseline, 50_000), rate(control, 50_000), rate(lifecycle, 2_000)
    print(f"\nLOCO through the generated client (one core, in-process, simulated clock):"
          f"\n  baseline: validate codel + reply      {base:10,.0f} /s"
          f"\n  control round trips (GoTo)          {trips:10,.0f} /s  ({trips / base:.2f}x baseline; goal 50,000)"
          f"\n  exec lifecycles (Track)            {lives:10,.0f} /s  (INIT, EXEC, end codel, ETHER)")
    assert client.final(client.GoTo(ref)).status is rt.Status.END
