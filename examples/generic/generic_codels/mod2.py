"""Codels of mod2 (seed 000 §3.8): mod2f1, mod2f2 (exclusive) and the control request mod2f3."""

from __future__ import annotations

DURATION = 20  # periods an activity lasts (invented)


def mod2f1Start(sdi, request):
    """mod2f1 start."""
    request.cycles = 0
    return "exec"


def mod2f1Exec(sdi, request):
    """mod2f1 exec: runs DURATION periods."""
    return _count(sdi, request)


def mod2f2Start(sdi, request):
    """mod2f2 start: keep the parameter that distinguishes services F and G."""
    sdi.param = request.param
    request.cycles = 0
    return "exec"


def mod2f2Exec(sdi, request):
    """mod2f2 exec: runs DURATION periods."""
    return _count(sdi, request)


def mod2f3Control(sdi, request):
    """mod2f3 (control, zero duration): the module interrupts mod2f1/mod2f2 before it runs."""
    sdi.cycles = 0
    return "end"


def mod2Inter(sdi, request):
    """Inter phase of mod2f1 and mod2f2."""
    return "ether"


def _count(sdi, request):
    sdi.cycles += 1
    request.cycles += 1
    return "ether" if request.cycles >= DURATION else "exec"
