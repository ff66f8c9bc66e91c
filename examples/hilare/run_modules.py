"""Start Hilare's eight generated modules with their codels and exercise LOCO for a few seconds.

Run from the repository root after `specc compile examples/hilare -o generated`:
    python examples/hilare/run_modules.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent.parent / "generated"), str(HERE)]

from hilare import modules  # noqa: E402
from hilare.modules.loco import LocoClient, Ref  # noqa: E402

from specc.runtime import functional as rt  # noqa: E402


def main() -> None:
    registry = rt.Registry()
    started = time.perf_counter()
    made = modules.create_all(registry)
    loco = LocoClient(made["loco"])
    registry.kernel.run_for(0.05)  # let CmdTask initialise the odometry first
    goto = loco.final(loco.GoTo(Ref(x=1.0, y=0.5, v=0.2)))
    print(f"loco.GoTo -> {goto.status} {goto.report.code}")
    registry.kernel.run_for(10.0)
    robot = loco.poster_Robot()
    assert robot is not None
    print(f"after {registry.kernel.now:.2f} s: loco.Robot = ({robot.data.robot.x:.2f}, {robot.data.robot.y:.2f}) "
          f"dated {robot.date:.3f} s")
    track = loco.final(loco.Track("avoid.Setpoint"))
    print(f"loco.Track on a poster nobody writes -> {track.status} {track.report.code}")
    cycles = sum(runner.cycles for module in made.values() for runner in module.tasks.values())
    print(f"{len(made)} modules, {cycles} exec-task cycles, {registry.kernel.now:.1f} s simulated in "
          f"{time.perf_counter() - started:.2f} s; incidents: {registry.incidents or 'none'}")


if __name__ == "__main__":
    main()
