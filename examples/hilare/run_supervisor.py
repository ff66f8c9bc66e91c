"""Run Hilare's task level (seed 000 ch. 4, §5.4): the PRS procedures of procedures.spec drive the
executive and the modules on the simulated robot and room until the robot has collected its
objects - the object hunt of ch. 5, through specc's generic runner (`specc.run.mission`) and this
robot's extension (hilare_codels/hunt.py).

Run from the repository root after `specc compile examples/hilare -o generated`:
    python examples/hilare/run_supervisor.py [N] [--seed S] [--log hunt.jsonl] [-o hunt.png]
It posts `!(COLLECT-OBJECTS N)` (N = 2 by default; COLLECT-OBJECTS allows 0 to 5, §5.6 asks for 5
of the room's 10 objects, which the seed scatters). The KA CollectObjects calls the
initialisation services, then runs TAKE-OBJECT, EXPLORE and MODELISE in parallel; every request
goes through ExecRequest (the EXEC-REQUEST protocol of §4.2.1). The (REPLY id result) and
(WARNING service id type) facts are printed as they reach the supervisor, except the modelling
cycle's routine ones (TAKE-IMAGE, TURN-CAMERA, SEARCH-OBJ finding nothing), which are only
counted; then the outcome, the objects taken and the §5.5 checks read from the event log.
Exit status: 0 when the goal succeeded, 1 when it failed or was still running at the horizon,
2 for a usage error.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))  # specc itself, when it is not installed

from specc.run import RunError  # noqa: E402
from specc.run.events import EventLog  # noqa: E402
from specc.run.mission import load_robot, run_mission  # noqa: E402
from specc.run.package import ensure_compiled  # noqa: E402
from specc.run.render import draw_map  # noqa: E402

WANTED = 2
SEED = 7  # the seed places the objects and draws every random event: a fixed seed, a repeatable run
ROUTINE = {("TAKE-IMAGE", "OK"), ("TURN-CAMERA", "OK"), ("SEARCH-OBJ", 0)}  # counted, not printed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("wanted", nargs="?", type=int, default=WANTED, help="objects to collect (0 to 5)")
    parser.add_argument("--seed", type=int, default=SEED, help="places the objects, draws the random events")
    parser.add_argument("--horizon", type=float, default=900.0, help="simulated seconds allowed")
    parser.add_argument("--log", type=Path, help="write the event log (JSON lines) here")
    parser.add_argument("-o", "--output", type=Path, help="PNG picture of the hunt and of its final state")
    args = parser.parse_args(argv)
    try:
        if args.output is not None and args.output.suffix.lower() != ".png":
            raise RunError(f"-o {args.output}: the file name must end in .png")
        goal = f"!(COLLECT-OBJECTS {args.wanted})"
        generated = HERE.parent.parent / "generated"
        robot = load_robot(generated, HERE, ensure_compiled(HERE, generated).robot)
        hunt = dataclasses.replace(robot.mission("hunt"), goals=(goal,))
        with EventLog(args.log) as log:
            result = run_mission(robot, hunt, args.seed, horizon=args.horizon, log=log)
    except RunError as error:
        print(f"run_supervisor.py: error: {error}", file=sys.stderr)
        return 2
    from hilare_codels.hunt import arm_motion_overlaps, detection_interruptions, objects  # on sys.path now

    seen = objects(result.events)
    print(f"posted {goal} (seed {args.seed}); the executive's replies and warnings "
          "(routine modelling replies only counted):")
    retrieved = taken = 0
    facts: dict[str, str] = {}
    for event in result.events:
        kind = event["kind"]
        if kind == "fact" and event["change"] == "concluded":
            facts[event["fact"].split()[0].lstrip("(")] = event["fact"]
        elif kind == "object-retrieved":
            retrieved += 1
            where = "nothing" if event["object"] is None else \
                f"object {event['object']} at ({event['x']:.2f}, {event['y']:.2f})"
            print(f"  {event['t']:7.2f} s  {'':<28} {'':<15}{where} retrieved")
        elif kind == "alarm":
            print(f"  {event['t']:7.2f} s  alarm: {event['what']}: {event['detail']}")
        elif kind == "object-taken":
            taken = event["taken"]
            print(f"  {event['t']:7.2f} s  {'':<28} {'':<15}object {taken} on the robot")
        elif kind in ("reply", "warning"):
            if kind == "reply" and (event["service"], event["result"]) in ROUTINE:
                continue
            fact = f"(REPLY {event['id']} {event['result']})" if kind == "reply" else \
                f"(WARNING {event['service']} {event['id']} {event['type']})"
            note = f"  ({event['detail']})" if event.get("detail") else ""
            print(f"  {event['t']:7.2f} s  {fact:<28} {event['service']:<15}{note}".rstrip())
    print(f"outcome: {goal} {result.outcome} - {result.why}")
    requests = sum(1 for e in result.events if e["kind"] == "request")
    warnings = sum(1 for e in result.events if e["kind"] == "warning")
    print(f"simulated time {result.simulated_time:.1f} s (wall {result.wall_time:.1f} s), {result.distance:.1f} m "
          f"travelled; {requests} executive requests, {sum(result.replies.values())} replies, {warnings} warnings")
    print("replies: " + ", ".join(f"{name} x{count}" for name, count in result.replies.items()))
    print(f"database: {facts.get('OBJ-FOUND', '(OBJ-FOUND -)')} {facts.get('EXECUTION', '(EXECUTION -)')}")
    print(f"objects taken: {taken} of {args.wanted} wanted ({retrieved} retrieved, "
          f"{sum(1 for o in seen if o.detected_at is not None)} of {len(seen)} seen)")
    report = detection_interruptions(result.events)
    overlaps = arm_motion_overlaps(result.events)
    print(f"§5.5: {len(report.interruptions)} exploration move(s) interrupted by the take-object cycle, "
          f"{len(report.missed)} detection(s) missed; the arm took objects while the robot moved "
          f"{len(overlaps)} time(s)")
    if args.output is not None:
        try:
            print(f"wrote {draw_map(result.events, args.output)}")
        except RunError as error:
            print(f"run_supervisor.py: error: {error}", file=sys.stderr)
            return 1
    return 0 if result.outcome == "succeeded" else 1


if __name__ == "__main__":
    sys.exit(main())
