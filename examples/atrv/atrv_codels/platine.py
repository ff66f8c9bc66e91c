"""Codels of PLATINE (seed 004 §4.1.1): the pan-tilt unit carrying the cameras.

With a simulator the unit's axes move themselves (rate-limited) and the codels only command and
read them; without one, the codels move the position towards the target at the same rates, as
the thesis' PLATINE simulated its own behaviour.
"""

from __future__ import annotations

import math

from specc.runtime.sim.devices import Axis

PERIOD = 0.05  # s, PtuTask period
PAN_LIMIT = math.pi  # rad: the unit turns all round
TILT_LIMIT = math.pi / 2  # rad: from straight down to straight up
SPEED = math.radians(60)  # rad/s per axis without a simulator (the simulated unit's own rate)
TIMEOUT = 20.0  # s: a motion that lasts longer than this has failed (INVENTED)
STRAIGHT = (0.0, 0.0)  # annex A's PTU positions, in (pan, tilt)
AT_MY_FEET = (0.0, -1.2)  # INVENTED: looking down at the ground just ahead of the robot


def initPtu(sdi):
    """PtuTask init: the unit at rest, looking straight ahead."""
    sdi.position.pan, sdi.position.tilt = STRAIGHT
    sdi.target.pan, sdi.target.tilt = STRAIGHT
    sdi.moving = False
    hardware = sdi.hardware
    if hardware is not None:
        hardware.pan_tilt.point(*STRAIGHT)
    return "exec"


def readAxes(sdi):
    """PtuTask permanent codel: the axes' positions (moved here when nothing simulates them)."""
    hardware = sdi.hardware
    if hardware is not None:
        unit = hardware.pan_tilt
        sdi.position.pan, sdi.position.tilt = unit.pan.position, unit.tilt.position
        sdi.moving = bool(unit.moving)
    else:
        for axis in ("pan", "tilt"):
            moved = Axis(getattr(sdi.position, axis), getattr(sdi.target, axis), SPEED)
            moved.advance(PERIOD)
            setattr(sdi.position, axis, moved.position)
        sdi.moving = sdi.position.pan != sdi.target.pan or sdi.position.tilt != sdi.target.tilt
    return "exec"


def checkPosition(sdi, request):
    """MoveTo validation: a reachable position."""
    pan, tilt = request.pan, request.tilt
    if not (math.isfinite(pan) and math.isfinite(tilt)) or abs(pan) > PAN_LIMIT or abs(tilt) > TILT_LIMIT:
        return "BAD_POSITION"
    return "end"


def startMove(sdi, request):
    """MoveTo start: command the axes."""
    _point(sdi, request.pan, request.tilt)
    sdi.elapsed = 0.0
    return "exec"


def waitArrival(sdi, request):
    """MoveTo exec: done when both axes are at the target."""
    sdi.elapsed += PERIOD
    if not sdi.moving:  # readAxes, the task's permanent codel, ran first this cycle
        return "ether"
    if sdi.elapsed > TIMEOUT:
        return "PTU_TIMEOUT"
    return "exec"


def stopMove(sdi, request):
    """MoveTo inter: stop where the unit is."""
    _point(sdi, sdi.position.pan, sdi.position.tilt)
    return "ether"


def initDriver(sdi, request):
    """Init (control): re-initialise the driver and send the unit home (STRAIGHT)."""
    _point(sdi, *STRAIGHT)
    return "end"


def _point(sdi, pan, tilt):
    sdi.target.pan, sdi.target.tilt = pan, tilt
    hardware = sdi.hardware
    if hardware is not None:
        hardware.pan_tilt.point(pan, tilt)
        # The unit wraps the pan angle: what it will reach is its own target.
        sdi.target.pan, sdi.target.tilt = hardware.pan_tilt.pan.target, hardware.pan_tilt.tilt.target
