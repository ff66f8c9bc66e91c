"""`make bench`: how long `specc check` takes on the whole Hilare example (goal: well under 1 s).

The baseline, measured in the same run, is parsing alone; the ratio shows what the checks cost.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

import pytest

from specc.pipeline import load
from specc.syntax.parser import parse_text
from tests.conftest import EXAMPLES, ROOT

HILARE = EXAMPLES / "hilare"
pytestmark = pytest.mark.bench


def median_seconds(run, repeat: int = 7) -> float:  # type: ignore[no-untyped-def]
    samples = []
    for _ in range(repeat):
        started = time.perf_counter()
        run()
        samples.append(time.perf_counter() - started)
    return statistics.median(samples)


def test_check_hilare(benchmark) -> None:  # type: ignore[no-untyped-def]
    files = sorted(HILARE.glob("*.spec"))
    texts = [(str(p), p.read_text()) for p in files]
    load([HILARE])  # builds (or loads) the parser once, as every later call in one process
    parse_only = median_seconds(lambda: [parse_text(text, path) for path, text in texts])
    full = median_seconds(lambda: load([HILARE]))
    cold = median_seconds(lambda: subprocess.run([sys.executable, "-m", "specc.cli", "check", "-q", str(HILARE)],
                                                 cwd=ROOT, check=True), repeat=3)
    lines = sum(len(text.splitlines()) for _, text in texts)
    print(f"\nspecc check examples/hilare ({len(files)} files, {lines} lines):"
          f"\n  parse only (baseline)      {parse_only * 1000:7.1f} ms"
          f"\n  parse + build + all checks {full * 1000:7.1f} ms  ratio {full / parse_only:4.2f}x baseline"
          f"\n  whole command, cold start  {cold * 1000:7.1f} ms  (goal: well under 1000 ms)")
    result = benchmark(load, [Path(HILARE)])
    assert result.program is not None and not result.errors
