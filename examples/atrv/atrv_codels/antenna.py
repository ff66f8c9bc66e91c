"""Codels of ANTENNA (seed 004 §4.1.1, §4.1.2.1): communications with the orbiter.

A communication succeeds when one visibility window holds all of it (the simulated antenna's
`record`); it fails at once when no window is open as it starts, and as soon as the window closes
before its end. Without a simulator it always succeeds, as the thesis' ANTENNA did.
"""

from __future__ import annotations

import math

PERIOD = 0.5  # s, ComTask period
MAX_DURATION = 600.0  # s (INVENTED)


def initLink(sdi):
    """ComTask init: nothing sent yet."""
    sdi.link.sent, sdi.link.window = 0, ""
    sdi.link.start = sdi.link.end = 0.0
    return "exec"


def checkDuration(sdi, request):
    """Communicate validation: a positive, bounded duration."""
    if not (math.isfinite(request.duration) and 0.0 < request.duration <= MAX_DURATION):
        return "BAD_DURATION"
    return "end"


def openLink(sdi, request):
    """Communicate start: a window must be open now."""
    hardware = sdi.hardware
    now = hardware.now if hardware is not None else sdi.link.end
    if hardware is not None and hardware.antenna.window() is None:
        return "NO_VISIBILITY"
    sdi.link.start, sdi.link.end = now, now + request.duration
    sdi.elapsed = 0.0
    return "exec"


def transmit(sdi, request):
    """Communicate exec: lost when the window closes; done when the duration has elapsed."""
    sdi.elapsed += PERIOD
    hardware = sdi.hardware
    if hardware is None:
        if sdi.elapsed < request.duration - 1e-9:
            return "exec"
        return _sent(sdi, request, "")
    if hardware.now < sdi.link.end - 1e-9:
        return "exec" if hardware.antenna.window() is not None else "LINK_LOST"
    window = hardware.antenna.record(sdi.link.start, sdi.link.end)
    if window is None:
        return "LINK_LOST"
    return _sent(sdi, request, window.name)


def closeLink(sdi, request):
    """Communicate inter: the link is closed (nothing recorded)."""
    return "ether"


def _sent(sdi, request, window):
    sdi.link.sent += 1
    sdi.link.window = window
    request.window = window
    return "ether"
