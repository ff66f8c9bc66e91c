"""Codels of graph35, the invented module behind the abstract services of Figs 3.5/3.6."""

from __future__ import annotations

DURATION = 20  # periods an activity lasts (invented)


def startActivity(sdi, request):
    """Start any of the ten abstract activities."""
    sdi.running += 1
    request.periods = 0
    return "exec"


def runActivity(sdi, request):
    """Run for DURATION periods of the module's task."""
    request.periods += 1
    if request.periods >= DURATION:
        sdi.running -= 1
        return "ether"
    return "exec"


def stopActivity(sdi, request):
    """Inter phase: the executive interrupted the activity."""
    sdi.running -= 1
    return "ether"
