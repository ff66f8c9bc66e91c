"""Codels of LOCO (seed 000 §2.4.1): setpoint tracking, odometry and position servo."""

from __future__ import annotations

import math

PERIOD = 0.025  # s, CmdTask period (5 ticks)
MAX_V = 0.5  # m/s, invented limits of Hilare 2
MAX_W = 1.0  # rad/s
GAIN_D, GAIN_A = 1.0, 2.0  # servo gains (invented)


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
    return "exec"


def pumpReference(sdi, request):
    """Exec phase of Track: copy the tracked poster's setpoint into the SDI each period."""
    ref = sdi.read_poster(sdi.trackedPoster)
    if ref is None:
        return "POSTER_NOT_FOUND"
    if not all(math.isfinite(v) for v in (ref.x, ref.y, ref.theta)):
        return "INVALID_REFERENCE"
    sdi.ref = ref
    return "exec"


def smoothStopTrack(sdi, request):
    """End and inter phases of Track: stabilise the robot on its current position."""
    _hold_position(sdi)
    return "ether"


def stopRobot(sdi, request):
    """Stop (control): freeze the setpoint on the current position, stopping the robot at once."""
    _hold_position(sdi)
    return "end"


def initOdoAndAsser(sdi):
    """CmdTask init: start at the origin with a zero setpoint and a small uncertainty."""
    sdi.robot.x = sdi.robot.y = sdi.robot.theta = 0.0
    sdi.odoError.cov = [1e-4 if i in (0, 4, 8) else 0.0 for i in range(9)]
    _hold_position(sdi)
    return "exec"


def odoAndAsserv(sdi):
    """CmdTask permanent codel: odometry then position servo (placeholder unicycle model)."""
    r, ref = sdi.robot, sdi.ref
    dx, dy = ref.x - r.x, ref.y - r.y
    dist = math.hypot(dx, dy)
    bearing = math.atan2(dy, dx) if dist > 1e-3 else ref.theta
    heading_error = _wrap(bearing - r.theta)
    v = max(-MAX_V, min(MAX_V, ref.v + GAIN_D * dist * math.cos(heading_error)))
    w = max(-MAX_W, min(MAX_W, ref.w + GAIN_A * heading_error))
    r.x += v * math.cos(r.theta) * PERIOD
    r.y += v * math.sin(r.theta) * PERIOD
    r.theta = _wrap(r.theta + w * PERIOD)
    for i in (0, 4, 8):  # odometric drift grows with the distance travelled
        sdi.odoError.cov[i] += 1e-5 * abs(v) * PERIOD
    return "exec"


def _hold_position(sdi):
    sdi.ref.x, sdi.ref.y, sdi.ref.theta = sdi.robot.x, sdi.robot.y, sdi.robot.theta
    sdi.ref.v = sdi.ref.w = 0.0


def _wrap(angle):
    return math.atan2(math.sin(angle), math.cos(angle))
