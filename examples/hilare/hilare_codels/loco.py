"""Codels of LOCO (seed 000 §2.4.1, §5.2.1): setpoint tracking, odometry and position servo.

With a simulator or a driver attached (`sdi.hardware`), odometry integrates the wheel encoders
and the servo commands the wheels; without one (unit tests of the executive, the verifier), a
unicycle model moves the robot exactly as commanded.
"""

from __future__ import annotations

import math

PERIOD = 0.025  # s, CmdTask period (5 ticks)
MAX_V = 0.5  # m/s, invented limits of Hilare 2
MAX_W = 1.0  # rad/s
GAIN_D, GAIN_A = 1.0, 2.0  # servo gains (invented)
MOVING = 0.02  # m/s: a setpoint slower than this is a still one
K_AHEAD, K_ASIDE, K_HEADING = 1.5, 6.0, 3.0  # Kanayama's gains (tuned in simulation)
ARRIVED = 0.01  # m: closer than this, the servo only turns to the setpoint's heading
BACK_UP = 0.3  # m: a still setpoint nearer than this behind the robot is reached backwards
DRIFT = 1e-3  # m² of variance per metre travelled on x and y, rad² per radian turned (invented)
HALF_TRACK = 0.3  # m, half the distance between the drive wheels (invented, as the simulator's)
STILL = 0.005  # m/s at the wheel rims: slower than this, the robot stands still
STILL_CYCLES = 4  # still for 4 cycles (0.1 s) on end: at rest, not at the turning point of a last swing
STOP_LIMIT = 80  # cycles (2 s): a smooth stop that has not brought the robot to rest by then ends anyway


def controlRef(sdi, request):
    """Validate a GoTo setpoint and write it into the SDI, so the servo follows it."""
    ref = request.ref
    values = (ref.x, ref.y, ref.theta, ref.v, ref.w)
    if not all(math.isfinite(v) for v in values) or abs(ref.v) > MAX_V or abs(ref.w) > MAX_W:
        return "BAD_REF_DATA"
    sdi.ref = ref
    return "end"


def findTrackedPoster(sdi, request):
    """Start phase of Track: check that the poster to track exists."""
    if sdi.read_poster(request.trackedPoster) is None:
        return "POSTER_NOT_FOUND"
    sdi.trackedPoster = request.trackedPoster
    sdi.stopCycles = sdi.stillCycles = 0
    return "exec"


def pumpReference(sdi, request):
    """Exec phase of Track: copy the tracked poster's setpoint into the SDI each period; a robot
    the wheels cannot move any more ends the tracking with SHOCK."""
    ref = sdi.read_poster(sdi.trackedPoster)
    if ref is None:
        return "POSTER_NOT_FOUND"
    if not all(math.isfinite(v) for v in (ref.x, ref.y, ref.theta)):
        return "INVALID_REFERENCE"
    hardware = sdi.hardware
    if hardware is not None and hardware.wheels.blocked:
        _hold_position(sdi)
        hardware.wheels.stop()  # and forget the motion asked so far: a new Track may try again
        return "SHOCK"
    sdi.ref = ref
    return "exec"


def smoothStopTrack(sdi, request):
    """End and inter phases of Track: stabilise the robot on its current position. The setpoint
    follows the robot until the wheels have stopped, and only then does Track end: whoever asked
    for the motion (PILO, and the executive above it) hears of its end once the robot stands
    still, as taking an object requires (§5.1: "la prise d'un objet [...] exige l'immobilité du
    robot"; Fig 5.6: ARM-OBJ waits for "l'interruption effective du mouvement"). `inter` runs
    this codel again next cycle (in the end phase too: the inter codel is this one)."""
    _hold_position(sdi)
    sdi.stopCycles += 1
    still = abs(sdi.speed.v) + abs(sdi.speed.w) * HALF_TRACK < STILL
    sdi.stillCycles = sdi.stillCycles + 1 if still else 0
    return "ether" if sdi.stillCycles >= STILL_CYCLES or sdi.stopCycles >= STOP_LIMIT else "inter"


def stopRobot(sdi, request):
    """Stop (control): freeze the setpoint on the current position, stopping the robot at once."""
    _hold_position(sdi)
    return "end"


def initOdoAndAsser(sdi):
    """CmdTask init: start where the robot stands (the world's start pose when simulated, else
    the origin) with a zero setpoint and a small uncertainty."""
    hardware = sdi.hardware
    if hardware is not None:
        sdi.robot.x, sdi.robot.y, sdi.robot.theta = hardware.world.start
        sdi.encoders.left, sdi.encoders.right = hardware.encoders.read()
    else:
        sdi.robot.x = sdi.robot.y = sdi.robot.theta = 0.0
    sdi.odoError.cov = [1e-4 if i in (0, 4, 8) else 0.0 for i in range(9)]
    _hold_position(sdi)
    return "exec"


def odoAndAsserv(sdi):
    """CmdTask permanent codel: odometry, then the position servo towards the setpoint."""
    hardware = sdi.hardware
    r = sdi.robot
    if hardware is not None:
        left, right = hardware.encoders.read()
        dl, dr = left - sdi.encoders.left, right - sdi.encoders.right
        sdi.encoders.left, sdi.encoders.right = left, right
        ds, dtheta = (dl + dr) / 2.0, (dr - dl) / hardware.encoders.wheel_base
        _integrate(sdi, ds, dtheta)
        sdi.speed.v, sdi.speed.w = ds / PERIOD, dtheta / PERIOD
    v, w = servo(r.x, r.y, r.theta, sdi.ref)
    if hardware is not None:
        hardware.wheels.drive(v, w)
        hardware.trace.estimated.append((hardware.now, r.x, r.y, r.theta))
    else:
        _integrate(sdi, v * PERIOD, w * PERIOD)
        sdi.speed.v, sdi.speed.w = v, w
    return "exec"


def servo(x, y, theta, ref):
    """Forward speed and turn rate bringing the robot at (x, y, theta) onto the setpoint.

    A moving setpoint (PILO's, AVOID's) is tracked with Kanayama's law, which converges
    without weaving; a still one is reached point to point: drive towards its position
    (backwards when it is just behind), then turn to its heading."""
    dx, dy = ref.x - x, ref.y - y
    if abs(ref.v) > MOVING:
        c, s = math.cos(theta), math.sin(theta)
        ahead, aside = c * dx + s * dy, -s * dx + c * dy  # the error in the robot's frame
        heading_error = _wrap(ref.theta - theta)
        v = ref.v * math.cos(heading_error) + K_AHEAD * ahead
        w = ref.w + ref.v * (K_ASIDE * aside + K_HEADING * math.sin(heading_error))
        return max(-MAX_V, min(MAX_V, v)), max(-MAX_W, min(MAX_W, w))
    dist = math.hypot(dx, dy)
    if dist > ARRIVED:
        bearing = math.atan2(dy, dx)
        heading_error = _wrap(bearing - theta)
        if abs(heading_error) > math.pi / 2 and dist < BACK_UP:  # just behind: reverse
            heading_error = _wrap(heading_error + math.pi)
            dist = -dist
        v = GAIN_D * dist * math.cos(heading_error)
    else:
        heading_error = _wrap(ref.theta - theta)
        v = 0.0
    w = GAIN_A * heading_error
    return max(-MAX_V, min(MAX_V, v)), max(-MAX_W, min(MAX_W, w))


def _integrate(sdi, ds, dtheta):
    """Dead reckoning over one cycle (mid-point heading); the variance grows with the motion."""
    r = sdi.robot
    heading = r.theta + dtheta / 2.0
    r.x += ds * math.cos(heading)
    r.y += ds * math.sin(heading)
    r.theta = _wrap(r.theta + dtheta)
    cov = sdi.odoError.cov
    cov[0] += DRIFT * abs(ds)
    cov[4] += DRIFT * abs(ds)
    cov[8] += DRIFT * abs(dtheta)


def _hold_position(sdi):
    sdi.ref.x, sdi.ref.y, sdi.ref.theta = sdi.robot.x, sdi.robot.y, sdi.robot.theta
    sdi.ref.v = sdi.ref.w = 0.0


def _wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))
