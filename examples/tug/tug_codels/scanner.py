"""Codels of SCANNER: the clearance ahead, from the laser scanner at the tug's front."""

from __future__ import annotations

import numpy as np

AHEAD = np.radians(60.0)  # the beams within this of the heading look where the tug goes
FAR = 30.0  # m: the clearance when no beam looks ahead


def initLaser(sdi):
    sdi.clearance = FAR


def readLaser(sdi):
    laser = sdi.hardware.laser
    ranges = laser.read()
    ahead = ranges[np.abs(laser.angles) <= AHEAD]
    sdi.clearance = float(ahead.min()) if ahead.size else FAR
