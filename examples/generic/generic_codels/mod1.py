"""Codels of mod1 (seed 000 §3.8): mod1f1, mod1f2 (single instance) and mod1f3 (several)."""

from __future__ import annotations

DURATION = 20  # periods an activity lasts (invented)


def mod1f1Start(sdi, request):
    """mod1f1 start."""
    request.cycles = 0
    return "exec"


def mod1f1Exec(sdi, request):
    """mod1f1 exec: runs DURATION periods."""
    return _count(sdi, request)


def mod1f2Start(sdi, request):
    """mod1f2 start."""
    request.cycles = 0
    return "exec"


def mod1f2Exec(sdi, request):
    """mod1f2 exec: runs DURATION periods."""
    return _count(sdi, request)


def mod1f3Start(sdi, request):
    """mod1f3 start (one call per instance; instances may run side by side)."""
    request.cycles = 0
    return "exec"


def mod1f3Exec(sdi, request):
    """mod1f3 exec: runs DURATION periods."""
    return _count(sdi, request)


def mod1Inter(sdi, request):
    """Inter phase of the three activities."""
    return "ether"


def _count(sdi, request):
    sdi.cycles += 1
    request.cycles += 1
    return "ether" if request.cycles >= DURATION else "exec"
