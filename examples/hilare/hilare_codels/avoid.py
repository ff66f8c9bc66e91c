"""Codels of AVOID (seed 000 §5.2.1, §1.6.6): potential-field filtering of PILO's setpoint."""

from __future__ import annotations

import math

N_SENSORS = 32


def initAvoid(sdi):
    """AvoidTask init: default potential-field gains (invented)."""
    sdi.params.katt, sdi.params.krep, sdi.params.influence = 1.0, 0.05, 0.8
    return "exec"


def startAvoid(sdi, request):
    """Start: check the setpoint poster, start the US scan and make LOCO track our poster."""
    if sdi.read_poster(request.setpointPoster) is None:
        return "POSTER_NOT_FOUND"
    sdi.setpointPoster = request.setpointPoster
    sdi.send_request("us.scan")
    sdi.send_request("loco.Track", trackedPoster="avoid.Setpoint")
    return "exec"


def potentialField(sdi, request):
    """Exec: the setpoint attracts, close ultrasonic echoes repel; export the filtered setpoint."""
    target = sdi.read_poster(sdi.setpointPoster)
    ranges = sdi.read_poster("us.Proximity")
    robot = sdi.read_poster("loco.Robot")
    if target is None:
        return "POSTER_NOT_FOUND"
    if ranges is None or robot is None:
        return "US_FAILURE"
    p = sdi.params
    fx, fy = p.katt * (target.x - robot.robot.x), p.katt * (target.y - robot.robot.y)
    for k, r in enumerate(ranges):
        if 0.0 < r < p.influence:
            bearing = robot.robot.theta + 2 * math.pi * k / N_SENSORS
            push = p.krep * (1.0 / r - 1.0 / p.influence) / (r * r)
            fx -= push * math.cos(bearing)
            fy -= push * math.sin(bearing)
    sdi.ref.x, sdi.ref.y = robot.robot.x + fx, robot.robot.y + fy
    sdi.ref.theta, sdi.ref.v, sdi.ref.w = target.theta, target.v, target.w
    return "exec"


def stopAvoid(sdi, request):
    """End and inter: stop filtering, the last filtered setpoint stays in the poster."""
    sdi.ref.v = sdi.ref.w = 0.0
    return "ether"
