"""Codels of EXPLOR (seed 000 §5.2.5, Table 5.5): exploration goal and grasping position.

calcGoal, the algorithm of §5.2.5 on VISUAL's grid (cells of side ``cell``; grids are numpy
arrays indexed [j, i], j the row along y):

1. Grow the obstacles by the robot's size (``candidate_cells``): a cell may hold the robot's
   centre if it is free and its centre is farther than ``GROW`` from every cell that is not. The
   growth is PLAN's outer one (``plan.GROWN_EXTENT``), so PLAN accepts every goal chosen here.
   Cells outside the room (PLAN's Env poster, set by SET-BOX) and beyond the grid count as not free.
2. Every such cell is a candidate. Around it, within r_max, each cell (i, j) that is free and not
   hidden adds (1 - c(i,j)) f(r, 0), f being VISUAL's detection reliability (§5.2.4) and r the
   distance between the cell centres. A cell is hidden when the segment between the two centres
   touches (corners included) a cell that is not free, other than the two cells themselves.
   Cells that are not free are not evaluated: no object lies in an obstacle.
3. The candidate with the largest sum wins (the first one in row order on a tie).

``VARIANT = "full"`` is that algorithm ("garantit que la cellule choisie est optimale"), in numpy.
``VARIANT = "sampled"`` is the cheaper one the thesis proposes, the default: candidates only every
r_max/2 (``sampled_candidates``), and around each only the cells met along radial axes every
θ_open/2, each axis stopping at the first cell that is not free (``radial_scores``; each sample
weighted by the area it stands for, so that the sum estimates the full one).
Either way the codel scores a few candidates per period, so a call stays short.

calcObj: the robot's centre goes to the centre of the object's cell (objects are not obstacles);
UNREACHABLE_CELL if that cell may not hold the robot (step 1) or is not connected to the robot's
position through such cells (4-neighbours: the straight moves between them are free for PLAN).
"""

from __future__ import annotations

import functools
import math
from collections import deque

import numpy as np

from hilare_codels.plan import GROWN_EXTENT
from hilare_codels.visual import R_MAX, THETA_OPEN, reliability

GROW = GROWN_EXTENT  # m: candidate centres are farther than this from cells that are not free
VARIANT = "sampled"  # "full": the optimal algorithm of §5.2.5; "sampled": its cheaper variant
CANDIDATES_PER_PERIOD = {"full": 48, "sampled": 8}  # calcGoal spreads its search over several periods
AXES = round(math.tau / (THETA_OPEN / 2))  # radial axes, one every θ_open/2
RAY_STEP = 0.25  # along an axis, samples every quarter of a cell


# ---------------------------------------------------------------- the algorithm


def candidate_cells(free: np.ndarray, cell: float, grow: float = GROW) -> np.ndarray:
    """Step 1: the cells that may hold the robot's centre (a boolean grid)."""
    ny, nx = free.shape
    g = math.ceil(grow / cell + 0.5)
    padded = np.zeros((ny + 2 * g, nx + 2 * g), dtype=bool)
    padded[g:g + ny, g:g + nx] = free
    valid = free.copy()
    for dj in range(-g, g + 1):
        for di in range(-g, g + 1):
            # distance from a cell's centre to the (closed) square of the cell at (di, dj)
            if cell * math.hypot(max(abs(di) - 0.5, 0.0), max(abs(dj) - 0.5, 0.0)) <= grow + 1e-12:
                valid &= padded[g + dj:g + dj + ny, g + di:g + di + nx]
    return valid


def _hidden_by(di: int, dj: int) -> list[tuple[int, int]]:
    # The cells whose closed square the segment from (0, 0) to (di, dj) touches, ends excluded:
    # exact integer test (doubled coordinates) - the square is met unless its four corners are
    # strictly on the same side of the segment's line (their bounding boxes always overlap here).
    cells = []
    for b in range(min(0, dj), max(0, dj) + 1):
        for a in range(min(0, di), max(0, di) + 1):
            if (a, b) in ((0, 0), (di, dj)):
                continue
            sides = [di * (2 * b + sy) - dj * (2 * a + sx) for sx in (-1, 1) for sy in (-1, 1)]
            if not (all(s > 0 for s in sides) or all(s < 0 for s in sides)):
                cells.append((a, b))
    return cells


@functools.lru_cache(maxsize=8)
def sight_lines(cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The offsets (di, dj) of the cells a candidate evaluates (r_min <= r <= r_max), f(r, 0)
    for each, and the offsets of the cells that hide each (padded with (0, 0), the candidate's
    own free cell): (offsets (n, 2), f (n,), between_i (n, m), between_j (n, m))."""
    reach = int(R_MAX / cell + 1e-9)
    offsets, gains, hiders = [], [], []
    for dj in range(-reach, reach + 1):
        for di in range(-reach, reach + 1):
            f = reliability(cell * math.hypot(di, dj), 0.0)
            if f > 0.0:
                offsets.append((di, dj))
                gains.append(f)
                hiders.append(_hidden_by(di, dj))
    width = max((len(h) for h in hiders), default=0) or 1
    between = np.zeros((len(offsets), width, 2), dtype=np.intp)
    for k, h in enumerate(hiders):
        if h:
            between[k, :len(h)] = h
    return (np.array(offsets, dtype=np.intp).reshape(-1, 2), np.array(gains), between[:, :, 0].copy(),
            between[:, :, 1].copy())


def full_scores(free: np.ndarray, certainty: np.ndarray, cell: float, candidates: np.ndarray) -> np.ndarray:
    """Step 2 for each candidate (rows (i, j)): the sum of (1 - c) f(r, 0) over the free cells
    within r_max that it sees."""
    offsets, gains, bi, bj = sight_lines(cell)
    candidates = np.asarray(candidates, dtype=np.intp).reshape(-1, 2)
    if not len(offsets) or not len(candidates):
        return np.zeros(len(candidates))
    reach = int(R_MAX / cell + 1e-9)
    ny, nx = free.shape
    open_ = np.zeros((ny + 2 * reach, nx + 2 * reach), dtype=bool)
    open_[reach:reach + ny, reach:reach + nx] = free
    gain = np.zeros(open_.shape)
    gain[reach:reach + ny, reach:reach + nx] = 1.0 - np.asarray(certainty, dtype=float)
    scores = np.empty(len(candidates))
    for start in range(0, len(candidates), 16):  # bounded memory: 16 x n x m
        ci = candidates[start:start + 16, 0] + reach
        cj = candidates[start:start + 16, 1] + reach
        ti, tj = ci[:, None] + offsets[None, :, 0], cj[:, None] + offsets[None, :, 1]
        seen = open_[tj, ti] & open_[cj[:, None, None] + bj[None], ci[:, None, None] + bi[None]].all(axis=2)
        scores[start:start + 16] = (seen * gain[tj, ti]) @ gains
    return scores


def radial_scores(free: np.ndarray, certainty: np.ndarray, cell: float, candidates: np.ndarray,
                  axes: int = AXES) -> np.ndarray:
    """The cheaper step 2: the cells are only looked at along ``axes`` radial axes, each stopping
    at the first cell that is not free. Along an axis, a sample every ``RAY_STEP`` cell adds
    (1 - c) f(r, 0) of the cell it falls in, weighted by the area (in cells) of the ring sector
    it stands for, r dθ dr: the sum estimates step 2's, where far cells count as much as near
    ones although the axes meet fewer of them."""
    candidates = np.asarray(candidates, dtype=np.intp).reshape(-1, 2)
    ny, nx = free.shape
    angles = np.arange(axes) * (math.tau / axes)
    radii, weights = _radial_weights(cell, axes)
    dx, dy = np.cos(angles)[:, None] * radii, np.sin(angles)[:, None] * radii  # (axes, samples)
    gain = 1.0 - np.asarray(certainty, dtype=float)
    scores = np.zeros(len(candidates))
    for k, (i, j) in enumerate(candidates):
        si = np.floor(i + 0.5 + dx).astype(np.intp)
        sj = np.floor(j + 0.5 + dy).astype(np.intp)
        inside = (si >= 0) & (si < nx) & (sj >= 0) & (sj < ny)
        open_ = np.zeros(si.shape, dtype=bool)
        open_[inside] = free[sj[inside], si[inside]]
        seen = np.logical_and.accumulate(open_, axis=1)
        gains = np.zeros(si.shape)
        gains[seen] = gain[sj[seen], si[seen]]
        scores[k] = float((gains @ weights).sum())
    return scores


@functools.lru_cache(maxsize=8)
def _radial_weights(cell: float, axes: int) -> tuple[np.ndarray, np.ndarray]:
    """The sample radii along an axis (in cells) and what each sample weighs: f(r, 0) times
    the area of the ring sector it stands for (constant for a grid: computed once)."""
    radii = np.arange(1, int(R_MAX / (RAY_STEP * cell)) + 1) * RAY_STEP
    weights = np.array([reliability(r * cell, 0.0) for r in radii]) * radii * (math.tau / axes) * RAY_STEP
    return radii, weights


def sampled_candidates(valid: np.ndarray, cell: float) -> np.ndarray:
    """The cheaper candidates: one cell every r_max/2 in both directions, those that may hold the
    robot (all of them if none does), as rows (i, j) in row order."""
    step = max(1, round(R_MAX / 2 / cell))
    lattice = np.zeros_like(valid)
    lattice[step // 2::step, step // 2::step] = True
    chosen = valid & lattice
    return all_candidates(chosen if chosen.any() else valid)


def all_candidates(valid: np.ndarray) -> np.ndarray:
    """Rows (i, j) of the true cells, in row order."""
    return np.argwhere(valid)[:, ::-1].astype(np.intp)


def candidates_of(valid: np.ndarray, cell: float, variant: str = VARIANT) -> np.ndarray:
    return all_candidates(valid) if variant == "full" else sampled_candidates(valid, cell)


def scores_of(free: np.ndarray, certainty: np.ndarray, cell: float, candidates: np.ndarray,
              variant: str = VARIANT) -> np.ndarray:
    scorer = full_scores if variant == "full" else radial_scores
    return scorer(free, certainty, cell, candidates)


def best_cell(free: np.ndarray, certainty: np.ndarray, cell: float, grow: float = GROW,
              variant: str = VARIANT) -> tuple[int, int, float] | None:
    """The whole algorithm at once: (i, j, score) of the chosen cell, None if no cell may hold
    the robot."""
    candidates = candidates_of(candidate_cells(free, cell, grow), cell, variant)
    if not len(candidates):
        return None
    scores = scores_of(free, certainty, cell, candidates, variant)
    k = int(np.argmax(scores))  # the first of the best
    return int(candidates[k, 0]), int(candidates[k, 1]), float(scores[k])


def reachable_cells(valid: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """The cells connected (4-neighbours through valid cells) to the valid cell nearest to
    ``start`` (i, j)."""
    ny, nx = valid.shape
    reached = np.zeros_like(valid)
    cells = np.argwhere(valid)
    if not len(cells):
        return reached
    j, i = cells[int(np.argmin((cells[:, 0] - start[1]) ** 2 + (cells[:, 1] - start[0]) ** 2))]
    reached[j, i] = True
    queue = deque([(int(i), int(j))])
    while queue:
        i, j = queue.popleft()
        for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if 0 <= a < nx and 0 <= b < ny and valid[b, a] and not reached[b, a]:
                reached[b, a] = True
                queue.append((a, b))
    return reached


def cells_in_box(nx: int, ny: int, cell: float, xmin: float, ymin: float, xmax: float, ymax: float) -> np.ndarray:
    """The cells of an nx x ny grid wholly inside the box (a boolean grid)."""
    edges_x, edges_y = np.arange(nx + 1) * cell, np.arange(ny + 1) * cell
    in_x = (edges_x[:-1] >= xmin - 1e-6) & (edges_x[1:] <= xmax + 1e-6)
    in_y = (edges_y[:-1] >= ymin - 1e-6) & (edges_y[1:] <= ymax + 1e-6)
    return in_y[:, None] & in_x[None, :]


def model_grid(model, box=None) -> tuple[np.ndarray, np.ndarray]:
    """VISUAL's model as numpy grids (free, certainty); with the room's box, the cells not
    wholly inside it are not free."""
    nx, ny, cell = model.nx, model.ny, model.cellSize
    free = np.array(model.free[:nx * ny], dtype=bool).reshape(ny, nx)
    certainty = np.array(model.certainty[:nx * ny], dtype=float).reshape(ny, nx)
    if box is not None and box.xmin < box.xmax and box.ymin < box.ymax:
        free &= cells_in_box(nx, ny, cell, box.xmin, box.ymin, box.xmax, box.ymax)
    return free, certainty


# ---------------------------------------------------------------- codels


@functools.lru_cache(maxsize=4)
def _candidates(free: bytes, shape: tuple[int, int], cell: float, variant: str) -> np.ndarray:
    """The candidate cells of a free grid: the free cells change only when VISUAL reads the
    obstacles, so the periods of a search (and later searches) share one list."""
    grid = np.frombuffer(free, dtype=bool).reshape(shape)
    return candidates_of(candidate_cells(grid, cell), cell, variant)


def _grid(sdi):
    poster = sdi.read_poster("visual.Model")
    if poster is None:
        return None
    free, certainty = model_grid(poster.model, sdi.read_poster("plan.Env"))
    return free, certainty, poster.model.cellSize


def startCalcGoal(sdi, request):
    """calcGoal start: VISUAL's model is needed; reset the search over candidate cells."""
    if sdi.read_poster("visual.Model") is None:
        return "NO_MODEL"
    sdi.candidate, sdi.bestScore = 0, -1.0
    return "exec"


def scoreCandidates(sdi, request):
    """calcGoal exec: score the next few candidates; at the last one, export the best."""
    grid = _grid(sdi)
    if grid is None:
        return "NO_MODEL"
    free, certainty, cell = grid
    candidates = _candidates(free.tobytes(), free.shape, cell, VARIANT)
    block = candidates[sdi.candidate:sdi.candidate + CANDIDATES_PER_PERIOD[VARIANT]]
    for (i, j), score in zip(block, scores_of(free, certainty, cell, block, VARIANT), strict=True):
        if score > sdi.bestScore:
            sdi.bestScore = float(score)
            sdi.goal.x, sdi.goal.y, sdi.goal.theta = (i + 0.5) * cell, (j + 0.5) * cell, 0.0
    sdi.candidate += len(block)
    if sdi.candidate < len(candidates):
        return "exec"
    if sdi.bestScore < 0.0:
        return "NO_FREE_CELL"
    request.goal = sdi.goal
    if sdi.hardware is not None:  # for the run's picture (the observation goal of §5.6)
        sdi.hardware.trace.goal = (sdi.goal.x, sdi.goal.y)
    sdi.write_poster("Goals")
    return "ether"


def startCalcObj(sdi, request):
    """calcObj start: the robot centre must be at the centre of the object's cell."""
    sdi.object = request.object
    return "exec"


def checkReachable(sdi, request):
    """calcObj exec: UNREACHABLE_CELL unless the robot can stand on the object's cell and get
    there from where it is."""
    grid = _grid(sdi)
    if grid is None:
        return "UNREACHABLE_CELL"
    free, _, cell = grid
    o = sdi.object
    valid = candidate_cells(free, cell)
    ny, nx = valid.shape
    if not (0 <= o.i < nx and 0 <= o.j < ny and valid[o.j, o.i]):
        return "UNREACHABLE_CELL"
    robot = sdi.read_poster("loco.Robot")
    if robot is not None:
        here = (math.floor(robot.robot.x / cell), math.floor(robot.robot.y / cell))
        if not reachable_cells(valid, here)[o.j, o.i]:
            return "UNREACHABLE_CELL"
    sdi.graspPos.x, sdi.graspPos.y, sdi.graspPos.theta = (o.i + 0.5) * cell, (o.j + 0.5) * cell, 0.0
    request.position = sdi.graspPos
    sdi.write_poster("Goals")
    return "ether"


def abortExplor(sdi, request):
    """Inter phase of calcGoal and calcObj."""
    return "ether"
