"""Codels of PILO (seed 000 §5.2.1, Table 5.1): trajectory execution from a poster."""

from __future__ import annotations

import math

PERIOD = 0.05  # s, TrajTask period


def initPilo(sdi):
    """TrajTask init: avoidance off, conservative default dynamics."""
    sdi.avoidOn = False
    sdi.dynamic.vmax, sdi.dynamic.wmax = 0.3, 0.6
    sdi.dynamic.amax, sdi.dynamic.dwmax = 0.3, 0.6
    return "exec"


def setAvoidMode(sdi, request):
    """avoidOnOff: enable or disable local obstacle avoidance for the next trajectories."""
    sdi.avoidOn = bool(request.on)
    return "end"


def checkDynamic(sdi, request):
    """setDynamic: accept positive maximum speeds and accelerations."""
    d = request.dynamic
    if min(d.vmax, d.wmax, d.amax, d.dwmax) <= 0:
        return "BAD_DYNAMIC_PARAMS"
    sdi.dynamic = d
    return "end"


def readTrajPoster(sdi, request):
    """Start phase: read the trajectory and have LOCO (through AVOID if on) track the setpoint."""
    traj = sdi.read_poster(request.trajPoster)
    if traj is None:
        return "POSTER_NOT_FOUND"
    if traj.nbPoints < 1:
        return "INVALID_TRAJECTORY"
    sdi.trajPoster, sdi.traj = request.trajPoster, traj
    sdi.setpoint.x, sdi.setpoint.y, sdi.setpoint.theta = traj.x[0], traj.y[0], traj.theta[0]
    sdi.setpoint.v = sdi.setpoint.w = 0.0
    sdi.nextPoint = 1
    if sdi.avoidOn:
        sdi.send_request("avoid.Filter", setpointPoster="pilo.Setpoint")
    else:
        sdi.send_request("loco.Track", trackedPoster="pilo.Setpoint")
    return "exec"


def generateSetpoint(sdi, request):
    """Exec phase: move the setpoint along the trajectory at the maximum speed allowed."""
    i, traj, sp = sdi.nextPoint, sdi.traj, sdi.setpoint
    if i >= traj.nbPoints:
        return "end"
    dx, dy = traj.x[i] - sp.x, traj.y[i] - sp.y
    dist = math.hypot(dx, dy)
    step = sdi.dynamic.vmax * PERIOD
    if dist <= step:
        sp.x, sp.y, sp.theta = traj.x[i], traj.y[i], traj.theta[i]
        sdi.nextPoint = i + 1
    else:
        sp.x += step * dx / dist
        sp.y += step * dy / dist
        sp.theta = math.atan2(dy, dx)
    sp.v = sdi.dynamic.vmax
    return "exec"


def endTraj(sdi, request):
    """End phase: the last point is reached, the setpoint stops there."""
    sdi.setpoint.v = sdi.setpoint.w = 0.0
    return "ether"


def stopTraj(sdi, request):
    """Inter phase: interrupted, the setpoint stops where it is."""
    sdi.setpoint.v = sdi.setpoint.w = 0.0
    return "ether"
