"""Drive the simulated Hilare 2 to goals through its real modules (seed 000 Fig. 5.3), draw the run.

PLAN plans a path among the room's polygons, PILO executes it with avoidance on (AVOID filters
the setpoint with US's sonars, LOCO servoes the wheels), the camera looks around at each goal;
the picture shows the room, the path, the planned trajectories and the objects.

Run from the repository root after `specc compile examples/hilare -o generated`:
    python examples/hilare/run_sim.py --goal 9,7 --goal 2,7 -o build/hilare-run.png [--gif build/hilare-run.gif]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent.parent / "generated"), str(HERE)]

from hilare import modules  # noqa: E402
from hilare.modules.pilo import PiloClient  # noqa: E402
from hilare.modules.plan import Box, PlanClient, Posit  # noqa: E402
from hilare.modules.visual import VisualClient  # noqa: E402

from specc.runtime import functional as rt  # noqa: E402
from specc.runtime.sim import HILARE, Simulation, WorldError, load_world  # noqa: E402
from specc.runtime.sim.render import animate, draw  # noqa: E402

WORLD = HERE / "worlds" / "room.toml"


def parse_goal(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"a goal is x,y in metres (e.g. 9,7), not '{text}'") from None
    return x, y


def run(world_path: Path, goals: list[tuple[float, float]], seed: int, budget: float) -> tuple[Simulation, list[str]]:
    registry = rt.Registry()
    world = load_world(world_path)
    sim = Simulation(world, HILARE, seed=seed, kernel=registry.kernel).attach(registry)
    made = modules.create_all(registry)
    plan, pilo, visual = PlanClient(made["plan"]), PiloClient(made["pilo"]), VisualClient(made["visual"])
    xmin, xmax, ymin, ymax = world.bounds
    log = []
    for name, reply in (("plan.setPlannerEnv", plan.final(plan.setPlannerEnv(Box(xmin, ymin, xmax, ymax)))),
                        ("plan.readModelFile", plan.final(plan.readModelFile(str(world_path)))),
                        ("visual.readObstacles", visual.final(visual.readObstacles(str(world_path)))),
                        ("pilo.avoidOnOff", pilo.final(pilo.avoidOnOff(True)))):
        log.append(f"{registry.kernel.now:7.2f} s  {name}: {reply.status} {reply.report.code}")
    deadline = registry.kernel.now + budget
    for gx, gy in goals:
        robot = made["loco"].sdi.robot
        start = Posit(x=robot.x, y=robot.y, theta=robot.theta)
        planned = plan.final(plan.plan(start, Posit(x=gx, y=gy, theta=0.0)))
        log.append(f"{registry.kernel.now:7.2f} s  plan.plan to ({gx:g}, {gy:g}): {planned.status} "
                   f"{planned.report.code}")
        if not planned.ok:
            break
        traj = plan.poster_Traj()
        if traj is not None:
            t = traj.data.traj
            sim.trace.paths.append(list(zip(t.x[: t.nbPoints], t.y[: t.nbPoints], strict=True)))
        went = pilo.final(pilo.execPosterTraj("plan.Traj"), timeout=max(1.0, deadline - registry.kernel.now))
        x, y, _ = sim.pose
        log.append(f"{registry.kernel.now:7.2f} s  pilo.execPosterTraj: {went.status} {went.report.code}; "
                   f"robot at ({x:.2f}, {y:.2f})")
        if not went.ok:
            break
        for pan in (-1.0, 0.0, 1.0):  # look around: three images, analysed at once
            visual.final(visual.moveCamera(pan))
            registry.kernel.run_for(2.0)  # the pan-tilt unit turns
            visual.final(visual.takeImage())
            found = visual.final(visual.searchObject())
            if found.ok and found.output is not None and found.output.nbFound:
                log.append(f"{registry.kernel.now:7.2f} s  visual.searchObject: {found.output.nbFound} found")
    return sim, log


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", type=Path, default=WORLD, help="world file (TOML)")
    parser.add_argument("--goal", type=parse_goal, action="append", help="x,y to reach (repeatable)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--duration", type=float, default=300.0, help="simulated seconds allowed")
    parser.add_argument("-o", "--output", type=Path, help="PNG picture of the run")
    parser.add_argument("--gif", type=Path, help="animated GIF of the run")
    args = parser.parse_args()
    goals = args.goal or [(9.0, 7.0), (2.0, 7.0)]
    started = time.perf_counter()
    try:
        sim, log = run(args.world, goals, args.seed, args.duration)
    except WorldError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    wall = time.perf_counter() - started
    print("\n".join(log))
    blocked = "no" if sim.trace.blocked_at is None else f"at {sim.trace.blocked_at:.1f} s"
    print(f"{sim.now:.1f} s simulated in {wall:.2f} s ({sim.now / wall:.0f}x real time); blocked: {blocked}; "
          f"objects detected: {len(sim.trace.detected)}/{len(sim.objects)}")
    if args.output:
        print(f"wrote {draw(sim, args.output, title='Hilare 2 in its room')}")
    if args.gif:
        print(f"wrote {animate(sim, args.gif, title='Hilare 2 in its room')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
