"""Drive the simulated ATRV rover of seed 004 through its real functional modules.

The six generated modules (RFLEX, SICK, NDD, PLATINE, CAMERA, ANTENNA) run with their codels on
one simulated clock with the rover of `specc.runtime.sim` in a world W1..W4 (§4.1.2.1); for each
goal in turn, NDD's GotoTarget drives it there among the obstacles (optionally followed by a
photograph at the robot's feet), then the run is drawn.

Run from the repository root after `specc compile examples/atrv -o generated`:
    python examples/atrv/run_sim.py --world W2 --goal 4,0 --goal 5,5 --photos -o build/w2.png
    python examples/atrv/run_sim.py --world W4 --goal 5,5          # trapped in the pocket
Negative coordinates may be written `--goal -5,3` or `--goal=-5,3`.
Exit status: 0 when every request succeeded, 1 when one failed, 2 for a usage error.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path
from typing import Any, NamedTuple

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
WORLDS = HERE / "worlds"
TOLERANCE = 0.3  # m: how close to a goal counts as there (INVENTED)
# Without --goal: mission M2's three targets (far apart, around W2's and W3's obstacles) and
# home; in W4 the way to M2's (5, 5), across the pocket.
TOUR = [(-5.0, 3.0), (5.0, 5.0), (4.0, -5.0), (0.0, 0.0)]
TRAP = [(5.0, 5.0)]


class UsageError(Exception):
    """A bad command line: reported in one line, exit status 2."""


class Package(NamedTuple):
    """The compiled atrv package: its modules, and the body its system block gives the rover."""

    modules: Any  # atrv.modules
    body: Any  # specc.runtime.body.RobotConfig


class Rover(NamedTuple):
    """The six modules on one registry with the simulated rover, a client per module."""

    registry: Any
    sim: Any
    clients: Any  # .rflex, .ndd, ... : each module's client
    modules: dict[str, Any]  # the module instances, by name (their SDI)

    @property
    def kernel(self) -> Any:
        return self.registry.kernel


def import_generated() -> Package:
    """The generated package (`specc compile examples/atrv -o generated`), with the codels of
    this folder on the import path."""
    from specc.run import RunError
    from specc.run.mission import load_robot

    try:
        robot = load_robot(ROOT / "generated", HERE, "atrv")
    except RunError as exc:
        raise UsageError(str(exc)) from None
    return Package(robot.part("modules"), robot.system.body)


def build(world: Any, seed: int = 0) -> Rover:
    """The ATRV's six modules and the simulated rover in `world`."""
    from types import SimpleNamespace

    from specc.runtime import functional as rt
    from specc.runtime.sim import Simulation, WorldError

    package = import_generated()
    registry = rt.Registry()
    try:
        sim = Simulation(world, package.body, seed=seed, kernel=registry.kernel).attach(registry)
    except WorldError as exc:  # what the world asks cannot be built (objects without room)
        raise UsageError(str(exc)) from None
    made = package.modules.create_all(registry)
    clients = SimpleNamespace(**{name: package.modules.MODULES[name].client(module) for name, module in made.items()})
    return Rover(registry, sim, clients, dict(made))


def resolve_world(name: str) -> Any:
    """W1..W4 (this folder's worlds) or a world file."""
    from specc.runtime.sim import WorldError, load_world

    named = {p.stem.upper(): p for p in sorted(WORLDS.glob("*.toml"))}
    path = named.get(name.upper(), Path(name))
    if name.upper() not in named and path.suffix != ".toml":
        raise UsageError(f"unknown world '{name}': give {', '.join(p.stem for p in named.values())} or a world "
                         "file (.toml)")
    try:
        return load_world(path)
    except WorldError as exc:
        raise UsageError(str(exc)) from None


def parse_goal(text: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        x, y = (float(p) for p in parts)
    except ValueError:
        raise UsageError(f"--goal '{text}': expected x,y in metres, e.g. --goal 4,-3") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise UsageError(f"--goal '{text}': the coordinates must be finite numbers")
    return x, y


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        description="Drive the simulated ATRV rover (seed 004) to goals through its generated modules.",
        epilog="Example: python examples/atrv/run_sim.py --world W2 --goal 4,0 --goal -5,3 --photos -o w2.png")
    p.add_argument("--world", default="W2", help="W1, W2, W3, W4 (examples/atrv/worlds) or a world file (default W2)")
    p.add_argument("--goal", action="append", default=[], metavar="X,Y",
                   help="a goal in metres; repeat for several, reached in order (default: a tour of "
                        "mission M2's targets and home; in W4 the way to (5, 5))")
    p.add_argument("--tolerance", type=float, default=TOLERANCE, help=f"m around a goal (default {TOLERANCE})")
    p.add_argument("--photos", action="store_true",
                   help="at each goal, point the camera at the robot's feet and take a picture")
    p.add_argument("--seed", type=int, default=0, help="the simulation's seed (default 0)")
    p.add_argument("--duration", type=float, default=600.0, help="simulated seconds at most (default 600)")
    p.add_argument("-o", "--output", type=Path, default=None, help="the PNG to draw (default build/atrv-<world>.png)")
    p.add_argument("--gif", type=Path, default=None, help="also write an animated GIF of the run")
    return p


def _glue_negative_goals(argv: list[str]) -> list[str]:
    """`--goal -5,3` would read -5,3 as an option: glue it to its flag."""
    glued: list[str] = []
    k = 0
    while k < len(argv):
        if argv[k] == "--goal" and k + 1 < len(argv) and re.match(r"-\d|-\.\d", argv[k + 1]):
            glued.append(f"--goal={argv[k + 1]}")
            k += 2
        else:
            glued.append(argv[k])
            k += 1
    return glued


def describe(reply: Any) -> str:
    code = reply.report.code
    detail = f" ({reply.report.detail})" if reply.report.detail else ""
    return f"{reply.status.value} {code}{detail}"


class Mission:
    """Sends the requests one after the other and prints each final reply."""

    def __init__(self, rover: Any, deadline: float) -> None:
        self.rover = rover
        self.deadline = deadline
        self.failed = False

    def call(self, client: Any, label: str, rqst_id: int) -> Any:
        remaining = self.deadline - self.rover.kernel.now
        reply = client.final(rqst_id, timeout=max(remaining, 0.0))
        timed_out = reply.status.value == "TIMEOUT"
        if timed_out:
            client.abort(rqst_id)
            self.rover.kernel.run_for(0.5)  # let the interrupted activity stop the wheels
        ok = reply.ok
        self.failed |= not ok
        outcome = "interrupted: --duration is up" if timed_out else describe(reply)
        line = f"[{self.rover.kernel.now:7.1f} s] {label} -> {outcome}"
        output = reply.output
        arrival = getattr(output, "arrival", None)
        if arrival is not None:
            line += f"  (odometry ({arrival.x:.2f}, {arrival.y:.2f}), {arrival.distance:.2f} m from the goal)"
        photo = getattr(output, "photo", None)
        if photo is not None and ok:
            line += f"  (photo of {photo.targets or 'nothing'})"
        print(line)
        return reply

    def goto(self, x: float, y: float, tolerance: float) -> bool:
        ndd = self.rover.clients.ndd
        return self.call(ndd, f"ndd.GotoTarget({x:g}, {y:g}, {tolerance:g})", ndd.GotoTarget(x, y, tolerance)).ok

    def photograph(self, target: str) -> bool:
        from atrv_codels.platine import AT_MY_FEET, STRAIGHT  # importable once the rover is built

        platine, camera = self.rover.clients.platine, self.rover.clients.camera
        steps = [(platine, f"platine.MoveTo{AT_MY_FEET}", lambda: platine.MoveTo(*AT_MY_FEET)),
                 (camera, f"camera.TakePicture({target!r})", lambda: camera.TakePicture(target)),
                 (platine, f"platine.MoveTo{STRAIGHT}", lambda: platine.MoveTo(*STRAIGHT))]
        ok = True
        for client, label, send in steps:
            ok = self.call(client, label, send()).ok and ok
        return ok


def run(argv: list[str] | None = None) -> int:
    args = parser().parse_args(_glue_negative_goals(list(sys.argv[1:] if argv is None else argv)))
    world = resolve_world(args.world)  # W1..W4 name the example worlds; anything else is a world file
    goals = [parse_goal(g) for g in args.goal] or (TRAP if world.name == "W4" else TOUR)
    xmin, xmax, ymin, ymax = world.bounds
    for x, y in goals:
        if not (xmin < x < xmax and ymin < y < ymax):
            raise UsageError(f"--goal {x:g},{y:g} is outside the walls of {world.name} "
                             f"([{xmin:g}, {xmax:g}] x [{ymin:g}, {ymax:g}])")
        half_width = import_generated().body.width / 2.0
        if world.clearance(x, y) < half_width:
            raise UsageError(f"--goal {x:g},{y:g} is inside an obstacle of {world.name} or too near one "
                             f"for the rover ({half_width:g} m at least)")
    for option, picture, suffix in (("-o", args.output, ".png"), ("--gif", args.gif, ".gif")):
        if picture is not None and Path(picture).suffix.lower() != suffix:
            raise UsageError(f"{option} {picture}: the file name must end in {suffix}")
    if not (math.isfinite(args.tolerance) and args.tolerance > 0):
        raise UsageError(f"--tolerance {args.tolerance:g}: must be a positive number of metres")
    if not (math.isfinite(args.duration) and args.duration > 0):
        raise UsageError(f"--duration {args.duration:g}: must be a positive number of seconds")
    output = args.output or ROOT / "build" / f"atrv-{world.name}.png"

    rover = build(world, args.seed)
    sim = rover.sim
    print(f"world {world.name} ({world.description or world.source}), seed {args.seed}, "
          f"{len(goals)} goal(s), at most {args.duration:g} s")
    started = time.perf_counter()
    mission = Mission(rover, rover.kernel.now + args.duration)
    for x, y in goals:
        if not mission.goto(x, y, args.tolerance):
            print("stopping: the rover did not reach its goal")
            break
        if args.photos:
            here = [t.name for t in world.targets if math.hypot(t.x - x, t.y - y) <= args.tolerance]
            mission.photograph(here[0] if here else "")
    wall = time.perf_counter() - started

    x, y, theta = sim.pose
    odo = rover.clients.rflex.poster_Robot()
    print(f"true pose ({x:.2f}, {y:.2f}, {math.degrees(theta):.0f} deg)", end="")
    if odo is not None:
        pose = odo.data.pose
        print(f", odometry ({pose.x:.2f}, {pose.y:.2f}, {math.degrees(pose.theta):.0f} deg)", end="")
    print(f", {sim.rover.distance:.1f} m travelled")
    blocked = sim.trace.blocked_at
    print("blocked: " + ("no" if blocked is None else f"yes, at {blocked:.1f} s"))
    photos = [name for _, name, ok in sim.trace.photos if ok]
    if args.photos:
        print(f"photos: {', '.join(photos) or 'none'}")
    simulated = rover.kernel.now
    print(f"simulated {simulated:.1f} s in {wall:.2f} s of wall time "
          f"({simulated / max(wall, 1e-9):.0f}x real time)")
    if rover.registry.incidents:
        print("incidents: " + "; ".join(rover.registry.incidents))

    from specc.runtime.sim.render import animate, draw

    title = f"{world.name}: " + " -> ".join(f"({gx:g}, {gy:g})" for gx, gy in goals)
    try:
        print(f"picture: {draw(sim, output, title=title)}")
        if args.gif is not None:
            print(f"animation: {animate(sim, args.gif, title=title)}")
    except OSError as exc:
        print(f"run_sim.py: error: cannot write the picture: {exc.strerror or exc} ({exc.filename or output})",
              file=sys.stderr)
        return 1
    return 1 if mission.failed else 0


def main() -> None:
    try:
        code = run()
    except UsageError as exc:
        print(f"run_sim.py: error: {exc}", file=sys.stderr)
        code = 2
    except KeyboardInterrupt:
        code = 130
    sys.exit(code)


if __name__ == "__main__":
    main()
