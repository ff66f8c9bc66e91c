"""Codels of RFLEX (seed 004 §4.1.1): odometry from the wheel encoders, and the wheels servoed
on a speed poster.

With a simulator (`sdi.hardware`) odometry integrates the encoders and TrackSpeed commands the
wheels; without one, the robot moves exactly as commanded (a unicycle integrated every period).
"""

from __future__ import annotations

import math

PERIOD = 0.05  # s, OdoTask period
MAX_V = 1.0  # m/s: a speed beyond these is a bad setpoint, not one to clip (INVENTED)
MAX_W = 2.0  # rad/s


def initOdometry(sdi):
    """OdoTask init: start where the robot stands (the world's start pose when simulated)."""
    hardware = sdi.hardware
    if hardware is not None:
        sdi.pose.x, sdi.pose.y, sdi.pose.theta = hardware.world.start
        sdi.encoders.left, sdi.encoders.right = hardware.encoders.read()
    else:
        sdi.pose.x = sdi.pose.y = sdi.pose.theta = 0.0
    sdi.speed.v = sdi.speed.w = 0.0
    sdi.blocked = False
    sdi.distance = 0.0
    return "exec"


def odometry(sdi):
    """OdoTask permanent codel: dead reckoning from the encoders (or from the commanded speed)."""
    hardware = sdi.hardware
    if hardware is None:
        integrate(sdi, sdi.speed.v * PERIOD, sdi.speed.w * PERIOD)
        return "exec"
    left, right = hardware.encoders.read()
    dl, dr = left - sdi.encoders.left, right - sdi.encoders.right
    sdi.encoders.left, sdi.encoders.right = left, right
    integrate(sdi, (dl + dr) / 2.0, (dr - dl) / hardware.encoders.wheel_base)
    # Kept until a new TrackSpeed starts: stopping the wheels clears the device's own flag,
    # and NDD must see it whatever its period.
    sdi.blocked = sdi.blocked or bool(hardware.wheels.blocked)
    hardware.trace.estimated.append((hardware.now, sdi.pose.x, sdi.pose.y, sdi.pose.theta))
    return "exec"


def integrate(sdi, ds, dtheta):
    """One odometry step along the mid-point heading."""
    pose = sdi.pose
    heading = pose.theta + dtheta / 2.0
    pose.x += ds * math.cos(heading)
    pose.y += ds * math.sin(heading)
    pose.theta = math.remainder(pose.theta + dtheta, math.tau)
    sdi.distance += abs(ds)


def findSpeedPoster(sdi, request):
    """TrackSpeed start: the poster to follow must exist."""
    if sdi.read_poster(request.speedPoster) is None:
        return "POSTER_NOT_FOUND"
    sdi.speedPoster = request.speedPoster
    sdi.blocked = False
    return "exec"


def followSpeed(sdi, request):
    """TrackSpeed exec: command the wheels with the poster's speed; a robot whose wheels turn
    without moving it ends the tracking with BLOCKED."""
    speed = sdi.read_poster(sdi.speedPoster)
    if speed is None:
        return "POSTER_NOT_FOUND"
    if not (math.isfinite(speed.v) and math.isfinite(speed.w)) or abs(speed.v) > MAX_V or abs(speed.w) > MAX_W:
        return "BAD_SPEED"
    if sdi.blocked:
        return "BLOCKED"
    _command(sdi, speed.v, speed.w)
    return "exec"


def stopWheels(sdi, request):
    """TrackSpeed end and inter: stop the wheels."""
    _command(sdi, 0.0, 0.0)
    return "ether"


def stopRobot(sdi, request):
    """Stop (control): the wheels stop at once (TrackSpeed, incompatible, is interrupted)."""
    _command(sdi, 0.0, 0.0)
    return "end"


def _command(sdi, v, w):
    sdi.speed.v, sdi.speed.w = v, w
    hardware = sdi.hardware
    if hardware is not None:
        if v == 0.0 and w == 0.0:
            hardware.wheels.stop()
        else:
            hardware.wheels.drive(v, w)
