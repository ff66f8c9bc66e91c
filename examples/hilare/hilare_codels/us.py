"""Codels of US (seed 000 §2.3): the belt of 32 ultrasonic range finders."""

from __future__ import annotations

N_SENSORS = 32
NO_ECHO = 5.0  # m, reading when nothing is seen (invented)


def initSensors(sdi):
    """ScanTask init: all sensors enabled, no echo yet."""
    sdi.config.enabled = [True] * N_SENSORS
    sdi.config.maxRange = NO_ECHO
    sdi.ranges = [NO_ECHO] * N_SENSORS
    return "exec"


def checkConfig(sdi, request):
    """configure: accept a configuration with a positive maximum range."""
    if request.config.maxRange <= 0 or len(request.config.enabled) != N_SENSORS:
        return "BAD_CONFIG"
    sdi.config = request.config
    return "end"


def startScan(sdi, request):
    """scan start: begin periodic acquisition."""
    return "exec"


def readSensors(sdi, request):
    """scan exec: read the enabled sensors (none without hardware: the ranges stay as they are)."""
    hardware = sdi.hardware
    measured = hardware.sonars.read().tolist() if hardware is not None else sdi.ranges
    if len(measured) != N_SENSORS:
        return "SENSOR_FAILURE"
    sdi.ranges = [
        min(r, sdi.config.maxRange) if on else NO_ECHO
        for r, on in zip(measured, sdi.config.enabled, strict=False)
    ]
    return "exec"


def stopScan(sdi, request):
    """scan end/inter: stop acquisition."""
    return "ether"


def startWatch(sdi, request):
    """watchObstacle start: install the monitor with its distance threshold."""
    sdi.threshold = request.threshold
    return "exec"


def checkObstacle(sdi, request):
    """watchObstacle exec: end with OBSTACLE as soon as an echo is closer than the threshold."""
    if min(sdi.ranges) < sdi.threshold:
        request.report = "OBSTACLE"
        return "ether"
    return "exec"
