"""Run FTplan (seed 004 ch. 3) on one of the rover's missions, its planners in their own processes,
its plans carried out by the scripted executor (every action taking the longest its plan allows),
and print what happened: the log, the line-by-line trace of Fig 3.1/3.2, the goals met and missed.

Run from the repository root after `specc compile examples/atrv -o generated`:
    python examples/atrv/run_ftplan.py [--config Robot1/2] [--mission M1] [--trace]
The configurations are those of seed 004 §4.2.1.1: Robot1 (Modele1), Robot2 (Modele2), Robot1/2
(successive), Robot1/2c (concurrent). Exit status: 0 when every goal was met, 1 otherwise, 2 for a
usage error. (`specc run` runs whole missions on the simulated rover.)
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent / "generated"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default="Robot1/2", help="robot configuration (default Robot1/2)")
    parser.add_argument("--mission", default="M1", help="mission M1..M4 (default M1)")
    parser.add_argument("--trace", action="store_true", help="also print the trace of Fig 3.1/3.2")
    args = parser.parse_args(argv)
    try:
        from atrv import planner  # type: ignore[import-not-found]
        from atrv.ftplan import rover  # type: ignore[import-not-found]
    except ImportError as exc:
        print(f"error: cannot import the generated package ({exc}); run `specc compile examples/atrv -o generated`",
              file=sys.stderr)
        return 2
    from specc.runtime.ftplan import FtPlan, ProcessPool, ScriptedExecutor, UnknownName, mission_setup

    try:
        setup = mission_setup(rover.CONFIGURATIONS, args.config, args.mission, planner)
    except UnknownName as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    names = ", ".join(f"{p.name} ({p.domain})" for p in setup.config.planners)
    print(f"FTplan {args.config} on {args.mission}: {setup.config.policy} planning with {names}")
    with ProcessPool(setup.config.planners, setup.domains) as pool:
        result = FtPlan(setup.config, setup.problem, pool, ScriptedExecutor(), problems=setup.problems).run()
    for event in result.events:
        if event.kind != "report" or not event.text.startswith("started"):
            who = f"[{event.planner}] " if event.planner else ""
            print(f"{event.time:8.1f} s  {event.kind:<15} {who}{event.text}")
    if args.trace:
        for line, text in result.trace:
            print(f"  Fig {'3.1' if setup.config.policy == 'successive' else '3.2'} line {line:>2}: {text}")
    print(f"{len(result.met)} goal(s) met, {len(result.missed)} missed; {result.plannings} planning(s), "
          f"{result.planner_failures} planner failure(s); mission over at {result.now:.1f} s"
          + (f"; {result.failure}" if result.failure else ""))
    return 0 if result.success else 1


if __name__ == "__main__":
    sys.exit(main())
