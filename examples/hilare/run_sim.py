"""Drive the simulated Hilare 2 to goals through its real modules (seed 000 Fig. 5.3), draw the run.

PLAN plans a path among the room's polygons, PILO executes it with avoidance on (AVOID filters
the setpoint with US's sonars, LOCO servoes the wheels), the camera looks around at each goal;
the picture shows the room, the path, the planned trajectories and the objects.

Run from the repository root after `specc compile examples/hilare -o generated`:
    python examples/hilare/run_sim.py --goal 9,7 --goal 2,7 -o build/hilare-run.png [--gif build/hilare-run.gif]
Exit status: 0 when every request succeeded, 1 when one failed, 2 for a usage error.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent.parent / "generated"), str(HERE)]

from hilare import modules  # noqa: E402
from hilare.systems import SYSTEMS  # noqa: E402
from hilare.modules.pilo import PiloClient  # noqa: E402
from hilare.modules.plan import Box, PlanClient, Posit  # noqa: E402
from hilare.modules.visual import VisualClient  # noqa: E402
from hilare_codels.plan import CLEARANCE  # noqa: E402

from specc.runtime import functional as rt  # noqa: E402
from specc.runtime.sim import Simulation, World, WorldError, load_world  # noqa: E402
from specc.runtime.sim.render import animate, draw  # noqa: E402

WORLD = HERE / "worlds" / "room.toml"
GOALS = [(9.0, 7.0), (2.0, 7.0)]  # without --goal: across the room, round the table and the pillar


class UsageError(Exception):
    """A bad command line: reported in one line, exit status 2."""


def parse_goal(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise UsageError(f"--goal '{text}': expected x,y in metres, e.g. --goal 9,7") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise UsageError(f"--goal '{text}': the coordinates must be finite numbers")
    return x, y


def check_goal(world: World, x: float, y: float) -> None:
    """A goal PLAN may accept: in the room, and not nearer to a wall or an obstacle than the
    clearance PLAN keeps around Hilare's centre (PLAN itself still has the last word)."""
    xmin, xmax, ymin, ymax = world.bounds
    if not (xmin < x < xmax and ymin < y < ymax):
        raise UsageError(f"--goal {x:g},{y:g} is outside the walls of {world.name} "
                         f"([{xmin:g}, {xmax:g}] x [{ymin:g}, {ymax:g}])")
    if world.clearance(x, y) < CLEARANCE:
        raise UsageError(f"--goal {x:g},{y:g} is inside an obstacle of {world.name} or too near one or a wall "
                         f"(PLAN keeps Hilare's centre {CLEARANCE:g} m away)")


def run(world: World, goals: list[tuple[float, float]], seed: int, budget: float) -> tuple[Simulation, list[str], bool]:
    """Drive to the goals in turn in `world` (loaded from its file, which PLAN and VISUAL read
    too); the log of replies, and whether every request succeeded."""
    world_file = world.source
    registry = rt.Registry()
    body = SYSTEMS["hilare"].body  # system.spec's body block
    sim = Simulation(world, body, seed=seed, kernel=registry.kernel).attach(registry)
    made = modules.create_all(registry)
    plan, pilo, visual = PlanClient(made["plan"]), PiloClient(made["pilo"]), VisualClient(made["visual"])
    xmin, xmax, ymin, ymax = world.bounds
    log = []
    ok = True
    for name, reply in (("plan.setPlannerEnv", plan.final(plan.setPlannerEnv(Box(xmin, ymin, xmax, ymax)))),
                        ("plan.readModelFile", plan.final(plan.readModelFile(world_file))),
                        ("visual.readObstacles", visual.final(visual.readObstacles(world_file))),
                        ("pilo.avoidOnOff", pilo.final(pilo.avoidOnOff(True)))):
        log.append(f"{registry.kernel.now:7.2f} s  {name}: {reply.status} {reply.report.code}")
        ok = ok and reply.ok
    deadline = registry.kernel.now + budget
    for gx, gy in goals:
        robot = made["loco"].sdi.robot
        start = Posit(x=robot.x, y=robot.y, theta=robot.theta)
        planned = plan.final(plan.plan(start, Posit(x=gx, y=gy, theta=0.0)))
        log.append(f"{registry.kernel.now:7.2f} s  plan.plan to ({gx:g}, {gy:g}): {planned.status} "
                   f"{planned.report.code}")
        if not planned.ok:
            ok = False
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
            ok = False
            break
        for pan in (-1.0, 0.0, 1.0):  # look around: three images, analysed at once
            visual.final(visual.moveCamera(pan))
            registry.kernel.run_for(2.0)  # the pan-tilt unit turns
            visual.final(visual.takeImage())
            found = visual.final(visual.searchObject())
            if found.ok and found.output is not None and found.output.nbFound:
                log.append(f"{registry.kernel.now:7.2f} s  visual.searchObject: {found.output.nbFound} found")
    return sim, log, ok


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", type=Path, default=WORLD, help="world file (TOML)")
    parser.add_argument("--goal", action="append", default=[], metavar="X,Y",
                        help="x,y to reach (repeatable; default 9,7 then 2,7)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--duration", type=float, default=300.0, help="simulated seconds allowed")
    parser.add_argument("-o", "--output", type=Path, help="PNG picture of the run")
    parser.add_argument("--gif", type=Path, help="animated GIF of the run")
    args = parser.parse_args(argv)
    try:
        try:
            world = load_world(args.world)
        except WorldError as error:
            raise UsageError(str(error)) from None
        goals = [parse_goal(g) for g in args.goal] or GOALS
        for x, y in goals:
            check_goal(world, x, y)
        for option, picture, suffix in (("-o", args.output, ".png"), ("--gif", args.gif, ".gif")):
            if picture is not None and picture.suffix.lower() != suffix:
                raise UsageError(f"{option} {picture}: the file name must end in {suffix}")
        if not (math.isfinite(args.duration) and args.duration > 0):
            raise UsageError(f"--duration {args.duration:g}: must be a positive number of seconds")
    except UsageError as error:
        print(f"run_sim.py: error: {error}", file=sys.stderr)
        return 2
    started = time.perf_counter()
    try:
        sim, log, ok = run(world, goals, args.seed, args.duration)
    except WorldError as error:  # what the world asks cannot be built (objects without room)
        print(f"run_sim.py: error: {error}", file=sys.stderr)
        return 2
    wall = time.perf_counter() - started
    print("\n".join(log))
    blocked = "no" if sim.trace.blocked_at is None else f"at {sim.trace.blocked_at:.1f} s"
    print(f"{sim.now:.1f} s simulated in {wall:.2f} s ({sim.now / wall:.0f}x real time); blocked: {blocked}; "
          f"objects detected: {len(sim.trace.detected)}/{len(sim.objects)}")
    try:
        if args.output:
            print(f"wrote {draw(sim, args.output, title='Hilare 2 in its room')}")
        if args.gif:
            print(f"wrote {animate(sim, args.gif, title='Hilare 2 in its room')}")
    except OSError as error:
        print(f"run_sim.py: error: cannot write the picture: {error.strerror or error} ({error.filename})",
              file=sys.stderr)
        return 1
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
