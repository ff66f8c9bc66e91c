"""Codels of EXPLOR (seed 000 §5.2.5, Table 5.5): exploration goal and grasping position."""

from __future__ import annotations

import math

R_MAX = 4.0  # m, must match VISUAL's perception range
CANDIDATES_PER_PERIOD = 64  # calcGoal spreads its search over several periods


def startCalcGoal(sdi, request):
    """calcGoal start: read VISUAL's model and reset the search over candidate cells."""
    if sdi.read_poster("visual.Model") is None:
        return "NO_MODEL"
    sdi.candidate, sdi.bestScore = 0, -1.0
    return "exec"


def scoreCandidates(sdi, request):
    """calcGoal exec: score free cells by sum((1 - c) f(r, 0)) within r_max; keep the best."""
    poster = sdi.read_poster("visual.Model")
    if poster is None:
        return "NO_MODEL"
    m = poster.model
    n = m.nx * m.ny
    reach = int(R_MAX / m.cellSize)
    stop = min(n, sdi.candidate + CANDIDATES_PER_PERIOD)
    for k in range(sdi.candidate, stop):
        if not m.free[k]:
            continue
        ci, cj = k % m.nx, k // m.nx
        score = 0.0
        for j in range(max(0, cj - reach), min(m.ny, cj + reach + 1)):
            for i in range(max(0, ci - reach), min(m.nx, ci + reach + 1)):
                r = math.hypot(i - ci, j - cj) * m.cellSize
                if r <= R_MAX:
                    score += (1.0 - m.certainty[j * m.nx + i]) * math.exp(-((r / R_MAX) ** 2))
        if score > sdi.bestScore:
            sdi.bestScore = score
            sdi.goal.x, sdi.goal.y = (ci + 0.5) * m.cellSize, (cj + 0.5) * m.cellSize
    sdi.candidate = stop
    if stop < n:
        return "exec"
    if sdi.bestScore < 0.0:
        return "NO_FREE_CELL"
    request.goal = sdi.goal
    sdi.write_poster("Goals")
    return "ether"


def startCalcObj(sdi, request):
    """calcObj start: the robot centre must be at the centre of the object's cell."""
    sdi.object = request.object
    return "exec"


def checkReachable(sdi, request):
    """calcObj exec: fail if the object's cell is not free (unreachable)."""
    model = sdi.read_poster("visual.Model")
    o = sdi.object
    if model is None or not model.model.free[o.j * model.model.nx + o.i]:
        return "UNREACHABLE_CELL"
    cell = model.model.cellSize
    sdi.graspPos.x, sdi.graspPos.y = (o.i + 0.5) * cell, (o.j + 0.5) * cell
    request.position = sdi.graspPos
    sdi.write_poster("Goals")
    return "ether"


def abortExplor(sdi, request):
    """Inter phase of calcGoal and calcObj."""
    return "ether"
