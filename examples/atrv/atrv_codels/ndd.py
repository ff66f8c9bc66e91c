"""Codels of NDD (seed 004 §4.1.1): reactive navigation to a goal among obstacles.

ASPECT, folded in here, keeps a local map: the obstacle points of the latest laser scans (SICK)
in the odometry frame (RFLEX, POM folded in), those within MAP_RADIUS of the robot, one per
MAP_CELL square, the points inside the scanner's field always replaced by the latest scan. The
map gives the 180° scanner a view all around, as ASPECT gave NDD.

Every period, `decide` picks a motion direction from that map in the spirit of the Nearness
Diagram navigation of [Minguez & Montano 2004] ("divide and conquer": identify the situation,
then apply its law):

* for each direction all around, the *free length* is how far a disc of radius ``CLEARANCE``
  (the robot's bounding circle plus a margin) can travel that way before touching an obstacle
  point: the valleys of the nearness diagram are the runs of directions free for LOOKAHEAD
  (less near the goal), and their borders already stand off by the robot's width;
* high safety (no obstacle within the security distance of the robot's body): HSGR when the
  goal's direction is a free one, go straight to it; otherwise the free direction nearest to the
  goal's, HSWR when its valley is wide (aim just inside its border), HSNR when narrow (its
  middle). The side on which obstacles are passed is kept (hysteresis, SIDE_PENALTY) until the
  goal's direction is free again, so that the robot does not dither in front of an obstacle;
* low safety (an obstacle within the security distance): LS1, the direction is pushed away from
  the nearest obstacle in proportion to how deep it is inside the security zone; LS2, obstacles
  on both sides, pushed from both, which centres the robot between them;
* no free direction at all: TURN in place (towards the side with more room).

The speed follows the direction: forward v = vmax (1 - |dir| / (pi/2)), slowed by the free length
ahead and near the goal, and none while the direction is more than TURN_ONLY off the heading
(the robot turns in place first); the turn rate is proportional to the direction, up to wmax.

Like every method that only sees its surroundings, it can be trapped for good: in W4's U-shaped
pocket opening towards it with the goal behind, the robot goes in, finds the goal's direction
closed, turns and comes out of the pocket, finds the goal's direction free again and goes back
in. The progress watchdog ends the request with NO_PROGRESS when the goal has come no closer (by
PROGRESS_STEP) for ``progressTime`` seconds; RFLEX's blocked wheels end it with BLOCKED.

All constants are INVENTED (the thesis gives none).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atrv_codels import LENGTH, WIDTH


PERIOD = 0.1  # s, NavTask period
HALF_LENGTH, HALF_WIDTH = LENGTH / 2.0, WIDTH / 2.0  # m, the ATRV's body (1.05 m x 0.65 m)
RADIUS = math.hypot(HALF_LENGTH, HALF_WIDTH)  # its bounding circle: what turning in place sweeps
MARGIN = 0.15  # m kept between that circle and obstacles along a chosen direction
CLEARANCE = RADIUS + MARGIN  # the disc a direction's free length is measured with
LOOKAHEAD = 1.5  # m of free length a direction needs (less when the goal is nearer)
DIRECTIONS = np.radians(np.arange(-180.0, 180.0, 1.0))  # the directions examined, from the heading
STEP = float(DIRECTIONS[1] - DIRECTIONS[0])  # rad between two directions examined
WIDE = math.radians(45)  # a valley at least this wide is "wide" (HSWR), else narrow (HSNR)
BORDER_OFFSET = math.radians(6)  # HSWR: aim this far inside the valley from its border
SIDE_PENALTY = math.radians(60)  # hysteresis: a direction on the other side costs this much more
TURN_ONLY = math.radians(40)  # beyond this off the heading, turn in place
TURN_GAIN = 1.5  # rad/s of turn rate per radian of direction
GOAL_GAIN = 0.5  # 1/s: forward speed at most this times the distance to the goal
SLOW_DOWN = 1.5  # m of free length ahead below which the robot slows
BEHIND = math.radians(120)  # LS: obstacles farther than this from the direction do not push
PROGRESS_STEP = 0.25  # m the goal must come closer by to count as progress
MAP_RADIUS = 4.0  # m: ASPECT's local map keeps the points this close to the robot
MAP_CELL = 0.1  # m: one point per cell of this size
MAP_SIZE = 600  # points at most (the nearest are kept): the arrays of ndd.spec's LocalMap
DEFAULT_PARAMS = {"vmax": 0.35, "wmax": 0.6, "security": 0.45, "progressTime": 30.0}
POSE_POSTER = "rflex.Robot"
SCAN_POSTER = "sick.Scan"


# ---------------------------------------------------------------- ASPECT: the local map


def scan_points(ranges, first_angle, step, mount, max_range):
    """The scan's echoes as (x, y) points in the robot's frame (centre, x forward)."""
    r = np.asarray(ranges, dtype=float)
    angles = first_angle + step * np.arange(len(r))
    echo = r < max_range - 1e-6
    d = r[echo] + mount
    return np.column_stack((d * np.cos(angles[echo]), d * np.sin(angles[echo])))


def to_world(points, x, y, theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.column_stack((x + c * points[:, 0] - s * points[:, 1], y + s * points[:, 0] + c * points[:, 1]))


def to_robot(points, x, y, theta):
    c, s = math.cos(theta), math.sin(theta)
    dx, dy = points[:, 0] - x, points[:, 1] - y
    return np.column_stack((c * dx + s * dy, -s * dx + c * dy))


def update_map(memory, fresh, x, y, theta, first_angle, last_angle):
    """ASPECT's map after a scan: the remembered points out of the scanner's field and within
    MAP_RADIUS, then the fresh ones (world frame), one per MAP_CELL, the nearest MAP_SIZE."""
    if len(memory):
        local = to_robot(memory, x, y, theta)
        angle = np.arctan2(local[:, 1], local[:, 0])
        keep = ((angle < first_angle - 1e-3) | (angle > last_angle + 1e-3)) & (np.hypot(*local.T) <= MAP_RADIUS)
        memory = memory[keep]
    near = fresh[np.hypot(fresh[:, 0] - x, fresh[:, 1] - y) <= MAP_RADIUS]
    points = np.vstack((near, memory)) if len(memory) else near
    if not len(points):
        return points
    points = points[first_in_cells(points)]
    if len(points) > MAP_SIZE:
        points = points[np.argsort(np.hypot(points[:, 0] - x, points[:, 1] - y), kind="stable")[:MAP_SIZE]]
    return points


def first_in_cells(points):
    """The indices, in order, of the first point in each MAP_CELL square that holds one."""
    cells = np.floor(points / MAP_CELL).astype(np.int64)
    cells -= cells.min(axis=0)
    # One number per cell (np.unique on rows costs several times more than on numbers); its
    # first index, as the stable sort np.unique makes for return_index finds it.
    _, first = np.unique(cells[:, 0] * (cells[:, 1].max() + 1) + cells[:, 1], return_index=True)
    return np.sort(first)


# ---------------------------------------------------------------- NDD: the method


@dataclass(frozen=True)
class Decision:
    situation: str  # HSGR HSWR HSNR LS1 LS2 TURN
    direction: float  # rad from the heading
    v: float  # m/s
    w: float  # rad/s
    side: int  # the side obstacles are passed on: -1 right, 1 left, 0 none


def free_lengths(points, directions, clearance, horizon):
    """For each direction, how far a disc of radius `clearance` can move along it from the
    robot's centre before touching a point (at most `horizon`)."""
    if len(points):
        # A point d from the centre stops the disc no sooner than d - clearance whatever the
        # direction: the map's points beyond horizon + clearance (most of them, it reaches
        # MAP_RADIUS) cannot shorten a free length, and are left out of the (D, P) products
        # (the 1e-6 keeps rounding from ever mattering: the result is the same to the bit).
        points = points[np.hypot(points[:, 0], points[:, 1]) < horizon + clearance + 1e-6]
    if len(points) == 0:
        return np.full(len(directions), float(horizon))
    ux, uy = np.cos(directions), np.sin(directions)
    px, py = points[:, 0:1], points[:, 1:2]  # (P, 1): a row of the (P, D) arrays per point
    # (P, D) rather than (D, P): the minimum over the points is then elementwise minima of whole
    # rows, and the arrays are worked in place; each element is computed as before, to the bit.
    forward = px * ux
    forward += py * uy
    lateral = py * ux
    lateral -= px * uy
    inside = np.abs(lateral) < clearance
    inside &= forward > 0.0  # the points the disc moves towards
    # reach = forward - sqrt(max(clearance² - lateral², 0)), at least 0
    lateral *= lateral
    np.subtract(clearance * clearance, lateral, out=lateral)
    np.sqrt(np.maximum(lateral, 0.0, out=lateral), out=lateral)
    reach = np.maximum(np.subtract(forward, lateral, out=forward), 0.0, out=forward)
    return np.minimum.reduce(reach, axis=0, where=inside, initial=horizon)


def body_distance(points):
    """Distance from each point (robot frame) to the robot's rectangular body (0 inside)."""
    dx = np.maximum(np.abs(points[:, 0]) - HALF_LENGTH, 0.0)
    dy = np.maximum(np.abs(points[:, 1]) - HALF_WIDTH, 0.0)
    return np.hypot(dx, dy)


def _wrap(angles):
    return np.remainder(np.asarray(angles) + math.pi, math.tau) - math.pi


def _valley(open_, best):
    """The run of open directions (circular) holding `best`: its two ends and its size."""
    n = len(open_)
    if open_.all():
        return best, best, n
    low = high = best
    while open_[(low - 1) % n]:
        low -= 1
    while open_[(high + 1) % n]:
        high += 1
    return low % n, high % n, high - low + 1


def decide(points, goal_distance, goal_bearing, params, side=0, tolerance=0.0):
    """One nearness-diagram decision from the obstacle points around the robot (robot frame)."""
    vmax, wmax, security = params["vmax"], params["wmax"], params["security"]
    need = max(min(goal_distance - tolerance, LOOKAHEAD), 0.05)
    # Straight ahead and towards the goal in one call; the goal's free length is not capped at
    # LOOKAHEAD, which changes no comparison with `need` (at most LOOKAHEAD).
    ahead, towards_goal = free_lengths(points, np.array([0.0, goal_bearing]), CLEARANCE,
                                       LOOKAHEAD + SLOW_DOWN).tolist()

    if towards_goal >= need:
        situation, direction, side = "HSGR", goal_bearing, 0
    else:
        free = free_lengths(points, DIRECTIONS, CLEARANCE, LOOKAHEAD)
        open_ = free >= need
        if not open_.any():
            more_left = free[DIRECTIONS > 0].sum() >= free[DIRECTIONS < 0].sum()
            turn = side or (1 if more_left else -1)
            situation, direction, side = "TURN", turn * math.pi / 2, turn
        else:
            offset = _wrap(DIRECTIONS - goal_bearing)  # from the goal's direction, signed
            cost = np.abs(offset) + (SIDE_PENALTY * (np.sign(offset) == -side) if side else 0.0)
            cost[~open_] = np.inf
            best = int(np.argmin(cost))
            low, high, size = _valley(open_, best)
            if size * STEP >= WIDE:
                situation = "HSWR"
                inward = 1.0 if best == low else -1.0 if best == high else 0.0
                direction = float(DIRECTIONS[best]) + inward * min(BORDER_OFFSET, size * STEP / 2)
            else:
                situation = "HSNR"
                direction = float(DIRECTIONS[low]) + (size - 1) * STEP / 2
            side = 1 if offset[best] > 0 else -1

    if situation != "TURN" and len(points):
        distances = body_distance(points)
        relative = _wrap(np.arctan2(points[:, 1], points[:, 0]) - direction)
        near = (distances < security) & (np.abs(relative) <= BEHIND)
        if near.any():
            push, sides = 0.0, 0
            for sign in (1.0, -1.0):  # obstacles left of the direction push right, and back
                mask = near & (np.sign(relative) == sign)
                if mask.any():
                    push -= sign * (security - float(distances[mask].min())) / security * math.pi / 2
                    sides += 1
            direction += push
            situation = "LS2" if sides == 2 else "LS1"

    direction = math.remainder(direction, math.tau)
    if situation == "TURN":
        return Decision(situation, direction, 0.0, math.copysign(wmax, direction), side)
    w = max(-wmax, min(wmax, TURN_GAIN * direction))
    v = 0.0
    if abs(direction) <= TURN_ONLY:
        v = vmax * (1.0 - abs(direction) / (math.pi / 2))
        v = max(0.0, min(v, vmax * min(1.0, (ahead - 0.1) / SLOW_DOWN), GOAL_GAIN * goal_distance))
    return Decision(situation, direction, v, w, side)


# ---------------------------------------------------------------- codels


def initNavigation(sdi):
    """NavTask init: default parameters, robot still, empty local map."""
    for name, value in DEFAULT_PARAMS.items():
        setattr(sdi.params, name, value)
    sdi.speed.v = sdi.speed.w = 0.0
    sdi.state.situation = "IDLE"
    _store_map(sdi, np.empty((0, 2)))
    return "exec"


def checkParams(sdi, request):
    """SetParams (control): positive speeds, security distance and progress time."""
    p = request.params
    values = (p.vmax, p.wmax, p.security, p.progressTime)
    if not all(math.isfinite(v) and v > 0 for v in values) or p.vmax > 1.0 or p.wmax > 2.0:
        return "BAD_PARAMS"
    sdi.params = p
    return "end"


def checkGoal(sdi, request):
    """GotoTarget validation: finite coordinates, a positive tolerance."""
    if not all(math.isfinite(v) for v in (request.x, request.y, request.tolerance)) or request.tolerance <= 0:
        return "BAD_GOAL"
    return "end"


def startNavigation(sdi, request):
    """GotoTarget start: the goal, the watchdog, and RFLEX set to follow ndd.Speed."""
    robot = sdi.read_poster(POSE_POSTER)
    if robot is None:
        return "POSE_NOT_FOUND"
    sdi.goal.x, sdi.goal.y, sdi.goal.tolerance = request.x, request.y, request.tolerance
    distance = math.hypot(request.x - robot.pose.x, request.y - robot.pose.y)
    state = sdi.state
    state.situation, state.distance, state.best = "START", distance, distance
    state.bestTime = state.elapsed = 0.0
    state.side = 0
    sdi.speed.v = sdi.speed.w = 0.0
    hardware = sdi.hardware
    if hardware is not None:
        hardware.trace.goal = (request.x, request.y)
    _arrival(request, robot.pose, distance)
    if distance <= request.tolerance:
        return "end"
    sdi.send_request("rflex.TrackSpeed", speedPoster="ndd.Speed")
    return "exec"


def navigate(sdi, request):
    """GotoTarget exec: update the local map, then one decision, until the goal is within
    tolerance."""
    robot = sdi.read_poster(POSE_POSTER)
    if robot is None:
        return "POSE_NOT_FOUND"
    scan = sdi.read_poster(SCAN_POSTER)
    if scan is None or not scan.echo:
        return "LASER_FAILURE"
    state, goal, pose = sdi.state, sdi.goal, robot.pose
    state.elapsed += PERIOD
    dx, dy = goal.x - pose.x, goal.y - pose.y
    state.distance = math.hypot(dx, dy)
    _arrival(request, pose, state.distance)
    if state.distance <= goal.tolerance:
        return "end"
    if robot.blocked:
        return "BLOCKED"
    if state.distance < state.best - PROGRESS_STEP:
        state.best, state.bestTime = state.distance, state.elapsed
    elif state.elapsed - state.bestTime > sdi.params.progressTime:
        return "NO_PROGRESS"
    last = scan.firstAngle + scan.step * (len(scan.ranges) - 1)
    fresh = to_world(scan_points(scan.ranges, scan.firstAngle, scan.step, scan.mount, scan.maxRange),
                     pose.x, pose.y, pose.theta)
    memory = update_map(_load_map(sdi), fresh, pose.x, pose.y, pose.theta, scan.firstAngle, last)
    _store_map(sdi, memory)
    bearing = math.remainder(math.atan2(dy, dx) - pose.theta, math.tau)
    params = {"vmax": sdi.params.vmax, "wmax": sdi.params.wmax, "security": sdi.params.security}
    decision = decide(to_robot(memory, pose.x, pose.y, pose.theta), state.distance, bearing, params, state.side,
                      goal.tolerance)
    state.situation, state.side = decision.situation, decision.side
    sdi.speed.v, sdi.speed.w = decision.v, decision.w
    return "exec"


def stopNavigation(sdi, request):
    """GotoTarget end and inter: zero speed (the TrackSpeed child ends with it and stops)."""
    sdi.speed.v = sdi.speed.w = 0.0
    sdi.state.situation = "IDLE"
    return "ether"


def stopNavigationNow(sdi, request):
    """Stop (control): zero speed; the navigation, incompatible, is interrupted."""
    sdi.speed.v = sdi.speed.w = 0.0
    return "end"


def _arrival(request, pose, distance):
    request.arrival.x, request.arrival.y, request.arrival.distance = pose.x, pose.y, distance


def _load_map(sdi):
    n = sdi.map.count
    return np.column_stack((sdi.map.x[:n], sdi.map.y[:n]))


def _store_map(sdi, points):
    n = len(points)
    sdi.map.count = n
    sdi.map.x = points[:, 0].tolist() + [0.0] * (MAP_SIZE - n)
    sdi.map.y = points[:, 1].tolist() + [0.0] * (MAP_SIZE - n)
