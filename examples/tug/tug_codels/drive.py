"""Codels of DRIVE: straight runs to a point, at the speed the speed policy allows.

The tug localises itself perfectly (a warehouse's beacons; the simulator's true pose stands for
them). The speed policy is the compiled rule base `speed_policy` (rules.spec): its `decide` is
asked at every cycle with the load pulled and the clearance SCANNER exports.
"""

from __future__ import annotations

import math

from tug.rules.speed_policy import decide  # the compiled rule base (generated/tug/rules/)

ARRIVED = 0.08  # m from the goal: there
SPEEDS = {"fast": 0.6, "slow": 0.3, "crawl": 0.1}  # m/s for the policy's words
TURN_GAIN = 2.0  # rad/s per rad of heading error
TURN_FIRST = 0.5  # rad: a larger heading error is turned on the spot first
STALL_CYCLES = 40  # 2 s of 50 ms cycles without progress: blocked


def startGoto(sdi, request):
    sdi.stalledCycles = 0
    request.travelled = 0.0
    sdi.startX, sdi.startY, _ = sdi.hardware.pose  # where it set off from, for the distance travelled
    return "exec"


def driveToGoal(sdi, request):
    sim = sdi.hardware
    x, y, theta = sim.pose
    dx, dy = request.x - x, request.y - y
    request.travelled = math.hypot(x - sdi.startX, y - sdi.startY)
    if math.hypot(dx, dy) < ARRIVED:
        sim.wheels.drive(0.0, 0.0)
        return "end"
    clearance = sdi.read_poster("scanner.Clearance")
    clearance = 30.0 if clearance is None else float(clearance)
    policy = decide({"load": sdi.load, "clearance": min(clearance, 30.0)})
    sdi.speed = SPEEDS.get(policy.outputs.get("speed"), SPEEDS["crawl"])
    error = math.remainder(math.atan2(dy, dx) - theta, math.tau)
    if abs(error) > TURN_FIRST:
        sim.wheels.drive(0.0, max(-1.0, min(1.0, TURN_GAIN * error)))
        return "exec"
    sdi.stalledCycles = sdi.stalledCycles + 1 if sim.wheels.blocked else 0
    if sdi.stalledCycles >= STALL_CYCLES:
        sim.wheels.stop()
        return "BLOCKED"
    sim.wheels.drive(min(sdi.speed, math.hypot(dx, dy)), TURN_GAIN * error)
    return "exec"


def stopWheels(sdi, request):
    sdi.hardware.wheels.stop()
    return "ether"


def stopNow(sdi, request):
    sdi.hardware.wheels.stop()
    return "end"


def setLoad(sdi, request):
    if not 0.0 <= request.load <= 1000.0:
        return "BAD_LOAD"
    sdi.load = float(request.load)
    return "end"
