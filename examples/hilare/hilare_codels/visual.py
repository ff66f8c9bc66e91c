"""Codels of VISUAL (seed 000 §5.2.4, Table 5.4): perception and modelling.

With a simulator attached (`sdi.hardware`), the camera on the simulated pan-tilt unit takes the
images: the objects are the world's, occluded by its obstacles and detected with probability
f(r, θ). Without one, VISUAL simulates them itself, as the thesis' module did.
"""

from __future__ import annotations

import copy
import math
import pathlib
import random

import numpy as np

from specc.runtime.sim import WorldError, load_world
from specc.runtime.sim import reliability as sim_reliability

NX = NY = 64  # invented grid size (4096 cells)
CELL = 0.30  # m (§5.6)
R_MIN, R_MAX = 0.5, 4.0  # m, invented perception range
THETA_OPEN = math.radians(60)  # invented field of view
MAX_OBJECTS = 16
N_WORLD_OBJECTS = 10  # §5.6: 10 objects scattered in the room
# A sighting this near an object the model holds is that object seen again: the simulated camera
# places what it sees from the pose odometry believes, which drifts a few centimetres, so the
# same object may fall in the next cell. The room's objects stand farther apart than this (the
# simulator keeps them 0.45 m apart; VISUAL's own ones are a cell apart at least).
SAME_OBJECT = 0.3  # m


def reliability(r, theta):
    """Fig 5.4: detection reliability f(r, θ) of an object at range r and bearing θ."""
    return sim_reliability(r, theta, R_MIN, R_MAX, THETA_OPEN)


def initVisual(sdi):
    """VisualTask init: an empty model, camera straight ahead."""
    _reset(sdi)
    sdi.pan = 0.0
    return "exec"


def resetModel(sdi, request):
    """initModel: certainty 0 everywhere, no detected object (obstacles are kept)."""
    _reset(sdi)
    sdi.write_poster("Model")
    return "end"


def openObstacleFile(sdi, request):
    """readObstacles start: check the environment file (the one PLAN reads)."""
    if not pathlib.Path(request.file).is_file():
        return "FILE_NOT_FOUND"
    sdi.modelFile = request.file
    return "exec"


def markObstacleCells(sdi, request):
    """readObstacles exec: mark the cells meeting an obstacle's bounding box as not free,
    then place the simulated objects at random in free cells (§5.2.4)."""
    try:
        room = load_world(sdi.modelFile)
    except WorldError:
        return "FILE_NOT_FOUND"
    sdi.model.free = free_cells(room)
    wanted = 0 if sdi.hardware is not None else N_WORLD_OBJECTS  # the simulator has its own objects
    cells = standing_cells(sdi.model.free, room.bounds) if wanted else []
    chosen = random.sample(cells, min(wanted, len(cells), MAX_OBJECTS))
    for slot, k in zip(sdi.worldObjects, chosen, strict=False):
        slot.i, slot.j = k % NX, k // NX
        slot.x, slot.y = (slot.i + 0.5) * CELL, (slot.j + 0.5) * CELL
    sdi.nbWorldObjects = len(chosen)
    sdi.write_poster("Model")  # the free cells changed
    return "ether"


def free_cells(room):
    """The model's free flags (row-major, NX x NY): a cell meeting an obstacle's bounding box is
    not free (§5.2.4: "les cellules qui ont une intersection avec les obstacles polygonaux")."""
    free = [True] * (NX * NY)
    for polygon in room.polygons():
        xs = [p[0] for p in polygon.points]
        ys = [p[1] for p in polygon.points]
        for i in range(int(min(xs) / CELL), int(max(xs) / CELL) + 1):
            for j in range(int(min(ys) / CELL), int(max(ys) / CELL) + 1):
                if 0 <= i < NX and 0 <= j < NY:
                    free[j * NX + i] = False
    return free


def standing_cells(free, bounds):
    """The cells (row-major indices) where the robot can stand, as EXPLOR's calcObj requires of
    an object's cell (its centre on the cell's, §5.2.5): inside the room, clear of the grown
    obstacles. Objects are placed on them, here and by the object hunt (hunt.py's prepare)."""
    from hilare_codels.explor import candidate_cells, cells_in_box  # EXPLOR imports this module: import late

    xmin, xmax, ymin, ymax = bounds
    grid = np.array(free, dtype=bool).reshape(NY, NX) & cells_in_box(NX, NY, CELL, xmin, ymin, xmax, ymax)
    return [int(k) for k in np.flatnonzero(candidate_cells(grid, CELL))]


def setCameraPan(sdi, request):
    """moveCamera: point the camera (angle relative to the robot's heading)."""
    if not math.isfinite(request.pan):
        return "BAD_ORIENTATION"
    sdi.pan = math.atan2(math.sin(request.pan), math.cos(request.pan))
    if sdi.hardware is not None:
        sdi.hardware.pan_tilt.point(sdi.pan, 0.0)
    sdi.write_poster("Model")
    return "end"


def grabImage(sdi, request):
    """takeImage: store the pose from which the (simulated) image is taken."""
    pose = sdi.read_poster("loco.Robot").robot
    hardware = sdi.hardware
    # Where the camera really points: the pan-tilt unit may still be turning towards sdi.pan.
    pan = hardware.pan_tilt.pan.position if hardware is not None else sdi.pan
    sdi.image.pose, sdi.image.pan, sdi.image.valid = pose, pan, True
    sdi.image.nbSeen = 0
    if hardware is not None:
        # The camera sees the world from where the robot really is; the model places what it
        # saw from where the robot believes it is (odometry drift shifts the objects with it).
        candidates = [k for k in range(len(hardware.objects)) if k not in hardware.trace.taken]
        for sighting in hardware.camera.detect([hardware.objects[k] for k in candidates])[: MAX_OBJECTS]:
            hardware.trace.detected.add(candidates[sighting.index])
            heading = pose.theta + pan + sighting.bearing
            x, y = pose.x + sighting.r * math.cos(heading), pose.y + sighting.r * math.sin(heading)
            slot = sdi.image.seen[sdi.image.nbSeen]
            slot.x, slot.y, slot.i, slot.j = x, y, int(x // CELL), int(y // CELL)
            sdi.image.nbSeen += 1
    return "end"


def startSearch(sdi, request):
    """searchObject start: an image must have been taken."""
    return "exec" if sdi.image.valid else "NO_IMAGE"


# The cells' centres, for the certainty update: only the cells the camera may see are computed
# cell by cell (about 90 of the 4096), found with a slightly wider test so that a cell on the
# field's edge is never missed by rounding (the exact test is `reliability`'s, as before).
_CELLS = np.arange(NX * NY)
_CELL_X, _CELL_Y = (_CELLS % NX + 0.5) * CELL, (_CELLS // NX + 0.5) * CELL
_EDGE = 1e-6


def _cells_in_view(x, y, heading):
    """The indexes of the cells that may lie in the camera's field from (x, y), in order."""
    dx, dy = _CELL_X - x, _CELL_Y - y
    r = np.hypot(dx, dy)
    bearing = np.angle(np.exp(1j * (np.arctan2(dy, dx) - heading)))  # wrapped to [-pi, pi]
    near = (r >= R_MIN - _EDGE) & (r <= R_MAX + _EDGE) & (np.abs(bearing) <= THETA_OPEN / 2.0 + _EDGE)
    return np.flatnonzero(near).tolist()


def analyseImage(sdi, request):
    """searchObject exec: detect objects in view with probability f, update certainties."""
    pose, found = sdi.image.pose, 0
    heading = pose.theta + sdi.image.pan
    for k in _cells_in_view(pose.x, pose.y, heading):
        x, y = (k % NX + 0.5) * CELL, (k // NX + 0.5) * CELL
        r = math.hypot(x - pose.x, y - pose.y)
        f = reliability(r, math.remainder(math.atan2(y - pose.y, x - pose.x) - heading, math.tau))
        if f > 0.0:
            c = sdi.model.certainty[k]
            sdi.model.certainty[k] = c + (1.0 - c) * f
    known = [(o.x, o.y) for o in sdi.objects[: sdi.nbObjects]]
    if sdi.hardware is not None:
        seen = sdi.image.seen[: sdi.image.nbSeen]  # the camera's detections, at takeImage
    else:
        seen = []
        for obj in sdi.worldObjects[: sdi.nbWorldObjects]:
            r = math.hypot(obj.x - pose.x, obj.y - pose.y)
            bearing = math.remainder(math.atan2(obj.y - pose.y, obj.x - pose.x) - heading, math.tau)
            if random.random() < reliability(r, bearing):
                seen.append(obj)
    for obj in seen:
        if sdi.nbObjects < MAX_OBJECTS and all(math.hypot(obj.x - x, obj.y - y) >= SAME_OBJECT for x, y in known):
            # A copy: the image's slots are written again by the next takeImage (a C struct
            # assignment copies; a Python one would leave the model pointing at the slot).
            sdi.objects[sdi.nbObjects] = copy.copy(obj)
            sdi.nbObjects += 1
            known.append((obj.x, obj.y))
            found += 1
    sdi.image.valid = False
    request.nbFound = found
    if sdi.hardware is not None:
        sdi.hardware.trace.certainty = (CELL, NX, NY, list(sdi.model.certainty))
    sdi.write_poster("Model")  # the certainties changed
    return "ether"


def nearestObject(sdi, request):
    """getObject: return the nearest detected object, which is then "récupéré" (§5.6)."""
    if sdi.nbObjects == 0:
        return "NO_OBJECT"
    robot = sdi.read_poster("loco.Robot").robot
    objects = sdi.objects[: sdi.nbObjects]
    k = min(
        range(len(objects)),
        key=lambda n: math.hypot(objects[n].x - robot.x, objects[n].y - robot.y),
    )
    sdi.nearest = objects[k]
    sdi.objects[k] = objects[-1]
    sdi.nbObjects -= 1
    world = sdi.worldObjects[: sdi.nbWorldObjects]
    for n, obj in enumerate(world):  # retrieved: no longer to be detected
        if (obj.i, obj.j) == (sdi.nearest.i, sdi.nearest.j):
            sdi.worldObjects[n] = world[-1]
            sdi.nbWorldObjects -= 1
            break
    # Nor in the image taken before and not analysed yet: searchObject would count it anew.
    # (Copies, so that no two slots share a record that takeImage writes in place.)
    kept = [copy.copy(o) for o in sdi.image.seen[: sdi.image.nbSeen]
            if math.hypot(o.x - sdi.nearest.x, o.y - sdi.nearest.y) >= SAME_OBJECT]
    sdi.image.seen[: len(kept)], sdi.image.nbSeen = kept, len(kept)
    hardware = sdi.hardware
    if hardware is not None:  # the simulator's object where VISUAL believes this one is, if any
        distance = {n: math.hypot(obj[0] - sdi.nearest.x, obj[1] - sdi.nearest.y)
                    for n, obj in enumerate(hardware.objects) if n not in hardware.trace.taken}
        nearest = min(distance, key=distance.__getitem__, default=None)
        if nearest is not None and distance[nearest] < SAME_OBJECT:
            hardware.trace.taken.add(nearest)
    request.object = sdi.nearest
    return "end"


def abortVisual(sdi, request):
    """Inter phase of readObstacles and searchObject."""
    return "ether"


def _reset(sdi):
    sdi.model.nx, sdi.model.ny, sdi.model.cellSize = NX, NY, CELL
    sdi.model.certainty = [0.0] * (NX * NY)
    sdi.nbObjects = 0
    sdi.image.valid = False
