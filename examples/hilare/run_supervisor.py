"""Run Hilare's task level (seed 000 ch. 4, §5.4): the PRS procedures of procedures.spec drive the
executive and the modules over the simulated kernel until the robot has collected its objects.

Run from the repository root after `specc compile examples/hilare -o generated`:
    python examples/hilare/run_supervisor.py [N]
It posts `!(COLLECT-OBJECTS N)` (N = 2 by default; OBJECTS-WANTED allows 0 to 3, and VISUAL scatters
10 objects in the room at random, from a fixed seed here). The KA CollectObjects calls the
initialisation services, then runs TAKE-OBJECT, EXPLORE and MODELISE in parallel; every request
goes through ExecRequest (the EXEC-REQUEST protocol of §4.2.1). The (REPLY id result) and
(WARNING service id type) facts are printed as they reach the supervisor, except the modelling
cycle's routine ones (TAKE-IMAGE, TURN-CAMERA, SEARCH-OBJ finding nothing), which are only
counted; then the outcome, the objects taken and the end of the intention's trace. The exit
status is 1 if the goal failed or was still running at the simulated-time limit.
"""

from __future__ import annotations

import os
import random
import sys
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parent.parent / "generated"), str(HERE)]

from hilare import modules  # noqa: E402
from hilare.executive import hilare  # noqa: E402
from hilare.supervisor import hilare_tasks  # noqa: E402

from specc.runtime import executive as rx  # noqa: E402
from specc.runtime import functional as rt  # noqa: E402

WANTED = 2
LIMIT = 600.0  # s of simulated time
SEED = 7  # VISUAL places the objects at random (readObstacles, §5.2.4): a fixed seed, a repeatable run
TRACE_LINES = 8
ROUTINE = {("TAKE-IMAGE", "OK"), ("TURN-CAMERA", "OK"), ("SEARCH-OBJ", 0)}  # counted, not printed


class Monitor:
    """Watches what the executive tells the task level: prints it (routine replies aside), counts
    the replies per service and result, and counts the objects put on the robot (OPEN-GRIP
    answering OK ends a take cycle, §5.4)."""

    def __init__(self, kernel, executive: rx.Executive):
        self.kernel = kernel
        self.executive = executive
        self.replies: Counter[tuple[str, object]] = Counter()
        self.warnings = 0
        self.taken = 0
        executive.listeners.append(self.receive)

    def receive(self, message: rx.Message) -> None:
        fact = "(" + " ".join(str(part) for part in message.fact) + ")"
        if message.kind == "WARNING":
            self.warnings += 1
        else:
            self.replies[message.service, message.result] += 1
            if (message.service, message.result) in ROUTINE:
                return
        note = f"  ({message.detail})" if message.detail else ""
        if message.kind == "REPLY" and message.result == "OK":
            if message.service == "GET-NEAR-OBJ":
                obj = self.executive.context.vars["object"]
                note += f"  object at ({obj['x']:.2f}, {obj['y']:.2f})"
            elif message.service.startswith("EXEC-TRAJ"):
                robot = self.executive.get_param("ROBOT-POSITION")
                note += f"  robot at ({robot.x:.2f}, {robot.y:.2f})"
            elif message.service == "OPEN-GRIP":
                self.taken += 1
                note += f"  object {self.taken} on the robot"
        print(f"  {self.kernel.now:7.2f} s  {fact:<28} {message.service:<15}{note}".rstrip())


def main() -> int:
    wanted = int(sys.argv[1]) if len(sys.argv) > 1 else WANTED
    os.chdir(HERE)  # the robot's files (worlds/room.toml) are named relative to its folder
    random.seed(SEED)
    started = time.perf_counter()
    registry = rt.Registry()
    modules.create_all(registry)
    executive = hilare.create(registry, world=str(HERE / "worlds" / "room.toml"), measure=True)
    kernel = registry.kernel
    monitor = Monitor(kernel, executive)
    supervisor = hilare_tasks.create(kernel=kernel, executive=executive)
    goal = f"!(COLLECT-OBJECTS {wanted})"
    print(f"posting {goal}; the executive's replies and warnings (routine modelling replies only counted):")
    intention = supervisor.post(goal)
    deadline = kernel.now + LIMIT
    kernel.run_while(lambda: intention.status == "running", deadline)

    lines = intention.lines()
    sent = sum(1 for line in lines if line.partition(": ")[2].startswith("(SEND-REQUEST "))
    found = [fact.args[0] for fact in supervisor.database.facts("OBJ-FOUND")]
    execution = [fact.args[0] for fact in supervisor.database.facts("EXECUTION")]
    limit = f" (still running at the {LIMIT:.0f} s limit)" if intention.status == "running" else ""
    print(f"outcome: {goal} {intention.status}{limit}")
    print(f"simulated time {kernel.now:.1f} s (wall {time.perf_counter() - started:.1f} s); "
          f"{sent} executive requests, {sum(monitor.replies.values())} replies, {monitor.warnings} warnings")
    print("replies: " + ", ".join(f"{service} {result} x{count}" for (service, result), count
                                  in sorted(monitor.replies.items(), key=lambda item: str(item[0]))))
    print(f"database: (OBJ-FOUND {found[0] if found else '-'}) (EXECUTION {execution[0] if execution else '-'})")
    print(f"objects taken: {monitor.taken} of {wanted} wanted")
    print(f"last {TRACE_LINES} of {intention.traced} trace lines:")
    for line in lines[-TRACE_LINES:]:
        print(f"  {line}")
    return 0 if intention.status == "succeeded" else 1


if __name__ == "__main__":
    sys.exit(main())
