"""The event kernel: ordering, cancellation, waiting, and the two clocks."""

from __future__ import annotations

import subprocess
import sys
import time

from specc.runtime.kernel import Kernel, WallClock


def test_events_run_by_time_then_priority_then_order() -> None:
    kernel = Kernel()
    seen: list[str] = []
    kernel.call_at(0.2, lambda: seen.append("late"))
    kernel.call_at(0.1, lambda: seen.append("second"), priority=5)
    kernel.call_at(0.1, lambda: seen.append("first"), priority=1)
    kernel.call_at(0.1, lambda: seen.append("third"), priority=5)
    cancelled = kernel.call_at(0.15, lambda: seen.append("never"))
    cancelled.cancel()
    kernel.run_until(1.0)
    assert seen == ["first", "second", "third", "late"] and kernel.now == 1.0


def test_run_while_stops_when_the_awaited_thing_happens_or_at_the_deadline() -> None:
    kernel = Kernel()
    box: list[int] = []
    kernel.call_later(0.3, lambda: box.append(1))
    assert kernel.run_while(lambda: not box, deadline=1.0) and kernel.now == 0.3
    assert not kernel.run_while(lambda: True, deadline=2.0) and kernel.now == 2.0


def test_simulated_time_costs_nothing_and_wall_clock_paces_it() -> None:
    fast = Kernel()
    started = time.perf_counter()
    fast.run_until(3600.0)
    assert time.perf_counter() - started < 0.5
    paced = Kernel(WallClock(speed=10.0))
    paced.call_at(0.5, lambda: None)
    started = time.perf_counter()
    paced.run_until(0.5)
    assert time.perf_counter() - started >= 0.04  # 0.5 s of robot time at 10x real time


def test_the_runtime_never_imports_the_compiler() -> None:
    probe = ("import sys, specc.runtime.functional, specc.runtime.kernel\n"
             "bad = [m for m in sys.modules if m.startswith(('specc.syntax', 'specc.check', 'specc.backends',"
             " 'specc.pipeline', 'lark', 'jinja2'))]\nprint(bad)")
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60)
    assert result.stdout.strip() == "[]", result.stdout + result.stderr
