"""Codels of SICK (seed 004 §4.1.1, note 3): the laser scanner's periodic acquisition.

With a simulator the scan is the simulated laser's; without one, every beam sees the far walls
the worlds put at 20 m (seed 004 note 3), so that navigation still has a scan to read.
"""

from __future__ import annotations

import math

import numpy as np

from atrv_codels import LENGTH


BEAMS = 181
FIELD = math.pi  # rad, centred on the heading
MAX_RANGE = 30.0  # m (SICK LMS)
MOUNT = LENGTH / 2.0  # m from the centre to the front edge, where ranges start
FALLBACK_RANGE = 20.0  # m: the far walls of note 3, when no simulator gives a scan


def initLaser(sdi):
    """ScanTask init: the scanner's geometry (the simulated robot's when one is attached)."""
    scan = sdi.scan
    scan.firstAngle, scan.step = -FIELD / 2.0, FIELD / (BEAMS - 1)
    scan.mount, scan.maxRange = MOUNT, MAX_RANGE
    hardware = sdi.hardware
    if hardware is not None:
        laser = hardware.laser
        angles = laser.angles
        if len(angles) != BEAMS:
            raise ValueError(f"the simulated laser has {len(angles)} beams, SICK expects {BEAMS}")
        scan.firstAngle, scan.step = float(angles[0]), float(angles[1] - angles[0])
        scan.maxRange = float(laser.max_range)
        scan.mount = float(laser.offset)  # ranges are read from there along each beam
    scan.ranges = [scan.maxRange] * BEAMS
    scan.number = 0
    scan.echo = False
    return "exec"


def readLaser(sdi):
    """ScanTask permanent codel: one scan; `echo` is false when no beam came back (note 3)."""
    scan = sdi.scan
    hardware = sdi.hardware
    if hardware is not None:
        ranges = np.minimum(hardware.laser.read(), scan.maxRange).tolist()
    else:
        ranges = [min(FALLBACK_RANGE, scan.maxRange)] * BEAMS
    scan.ranges = ranges
    scan.echo = min(ranges) < scan.maxRange
    scan.number += 1
    return "exec"


def configureLaser(sdi, request):
    """Configure (control): bound the useful range (beams beyond it read as no echo)."""
    if not (math.isfinite(request.maxRange) and 0.0 < request.maxRange <= MAX_RANGE):
        return "BAD_RANGE"
    sdi.scan.maxRange = request.maxRange
    return "end"
