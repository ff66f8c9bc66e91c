"""Codels of PLAN (seed 000 §5.2.2, Table 5.2): non-holonomic path planning (placeholder)."""

from __future__ import annotations

import math
import pathlib
import tomllib

MAX_POINTS = 64


def setAutoBox(sdi, request):
    """autoBox: choose automatic or manual environment bounds."""
    sdi.autoBox = bool(request.auto)
    return "end"


def checkBox(sdi, request):
    """setPlannerEnv: accept a non-empty bounding box."""
    b = request.box
    if b.xmin >= b.xmax or b.ymin >= b.ymax:
        return "BAD_BOX"
    sdi.box = b
    return "end"


def openModelFile(sdi, request):
    """readModelFile start: check that the obstacle file exists."""
    if not pathlib.Path(request.file).is_file():
        return "FILE_NOT_FOUND"
    sdi.modelFile = request.file
    return "exec"


def readPolygons(sdi, request):
    """readModelFile exec: load the polygonal obstacles ([[obstacles]] polygon = [[x, y], ...])."""
    try:
        world = tomllib.loads(pathlib.Path(sdi.modelFile).read_text())
    except (OSError, tomllib.TOMLDecodeError):
        return "BAD_MODEL"
    polygons = [o["polygon"] for o in world.get("obstacles", [])][: len(sdi.obstacles)]
    for slot, polygon in zip(sdi.obstacles, polygons, strict=False):
        slot.n = min(len(polygon), len(slot.x))
        for k, (x, y) in enumerate(polygon[: slot.n]):
            slot.x[k], slot.y[k] = x, y
    sdi.nbObstacles = len(polygons)
    return "ether"


def startPlan(sdi, request):
    """plan start: full planning, geometric phase included."""
    return _start(sdi, request)


def startReplan(sdi, request):
    """replan start: same model as the previous planning, initial phase skipped."""
    return _start(sdi, request)


def computePlan(sdi, request):
    """plan/replan exec: placeholder straight-line path, sampled for PILO."""
    s, g, t = sdi.start, sdi.goal, sdi.traj
    n = min(MAX_POINTS, max(2, int(math.hypot(g.x - s.x, g.y - s.y) / 0.25) + 1))
    for k in range(n):
        a = k / (n - 1)
        t.x[k], t.y[k] = s.x + a * (g.x - s.x), s.y + a * (g.y - s.y)
        t.theta[k] = math.atan2(g.y - s.y, g.x - s.x)
    t.theta[n - 1] = g.theta
    t.nbPoints, t.kind, t.tolerance = n, "BROKEN_LINE", 0.1
    return "ether"


def abortPlanning(sdi, request):
    """Inter phase of the three exec requests: drop the current computation."""
    return "ether"


def _start(sdi, request):
    if not sdi.modelFile:
        return "NO_MODEL"
    sdi.start, sdi.goal = request.start, request.goal
    return "exec"
