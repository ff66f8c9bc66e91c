"""The algorithms of three Hilare 2 modules (seed 000 §5.2): PLAN's paths, PILO's trajectories and
EXPLOR's exploration goals, checked against independent geometry written here."""

from __future__ import annotations

import copy
import heapq
import importlib
import math
import sys
import tomllib
from fractions import Fraction
from types import ModuleType, SimpleNamespace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.runtime.sim import load_world
from tests.conftest import EXAMPLES, ROOT

sys.path[:0] = [str(EXAMPLES / "hilare")]
from hilare_codels import explor, pilo, plan, visual  # type: ignore[import-not-found]  # noqa: E402

sys.path.remove(str(EXAMPLES / "hilare"))

ROOM_FILE = EXAMPLES / "hilare" / "worlds" / "room.toml"
ROOM = tomllib.loads(ROOM_FILE.read_text())
OBSTACLES = [[tuple(p) for p in o["polygon"]] for o in ROOM["obstacles"]]
ROOM_BOX = (0.0, 0.0, ROOM["room"]["width"], ROOM["room"]["height"])
Point = tuple[float, float]


def generated(module: str) -> ModuleType:
    sys.path.insert(0, str(ROOT / "generated"))
    try:
        return importlib.import_module(f"hilare.modules.{module}")
    finally:
        sys.path.remove(str(ROOT / "generated"))


# ---------------------------------------------------------------- independent plane geometry


def orientation(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def segments_cross(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Proper crossing (each segment's ends strictly on both sides of the other)."""
    return (orientation(a, b, c) * orientation(a, b, d) < 0) and (orientation(c, d, a) * orientation(c, d, b) < 0)


def point_segment_distance(p: Point, a: Point, b: Point) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    t = 0.0 if dx == dy == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)))
    return math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)


def inside(p: Point, polygon: list[Point]) -> bool:
    """Ray casting (any orientation)."""
    result = False
    for k in range(len(polygon)):
        (x0, y0), (x1, y1) = polygon[k], polygon[(k + 1) % len(polygon)]
        if (y0 > p[1]) != (y1 > p[1]) and p[0] < x0 + (p[1] - y0) * (x1 - x0) / (y1 - y0):
            result = not result
    return result


def segment_polygon_distance(a: Point, b: Point, polygon: list[Point]) -> float:
    edges = [(polygon[k], polygon[(k + 1) % len(polygon)]) for k in range(len(polygon))]
    if inside(a, polygon) or inside(b, polygon) or any(segments_cross(a, b, c, d) for c, d in edges):
        return 0.0
    return min(min(point_segment_distance(a, c, d), point_segment_distance(b, c, d),
                   point_segment_distance(c, a, b), point_segment_distance(d, a, b)) for c, d in edges)


def point_polygon_distance(p: Point, polygon: list[Point]) -> float:
    return segment_polygon_distance(p, p, polygon)


def clearance_of(path: list[Point], obstacles: list[list[Point]]) -> float:
    """The smallest distance between the path and an obstacle."""
    if len(path) == 1:
        return min(point_polygon_distance(path[0], o) for o in obstacles)
    return min(segment_polygon_distance(path[k], path[k + 1], o) for k in range(len(path) - 1) for o in obstacles)


def enters_convex(a: Point, b: Point, piece: list[Point]) -> bool:
    """Does segment ab pass through the interior of a convex polygon? Sampled finely, a point
    deeper than 1e-7 inside counts."""
    n = len(piece)
    if max(a[0], b[0]) < min(x for x, _ in piece) or min(a[0], b[0]) > max(x for x, _ in piece) \
            or max(a[1], b[1]) < min(y for _, y in piece) or min(a[1], b[1]) > max(y for _, y in piece):
        return False
    for t in np.linspace(0.0, 1.0, 201):
        p = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
        depth = min(orientation(piece[k], piece[(k + 1) % n], p) / math.dist(piece[k], piece[(k + 1) % n])
                    for k in range(n))  # > 0: left of every edge of the counter-clockwise piece
        if depth > 1e-7:
            return True
    return False


def roadmap_length(start: Point, goal: Point, obstacles: list[list[Point]], box: tuple[float, float, float, float],
                   margin: float, spacing: float = 0.5, radius: float = 1.2) -> float:
    """Length of the shortest path on a grid roadmap whose every edge keeps more than ``margin``
    from the obstacles and the walls: a feasible path, so an upper bound of the optimum."""
    xmin, ymin, xmax, ymax = box[0] + margin, box[1] + margin, box[2] - margin, box[3] - margin
    points = [start, goal] + [(x, y) for x in np.arange(xmin + 1e-6, xmax, spacing)
                              for y in np.arange(ymin + 1e-6, ymax, spacing)
                              if min(point_polygon_distance((x, y), o) for o in obstacles) > margin]
    best, queue = {0: 0.0}, [(0.0, 0)]
    while queue:
        cost, k = heapq.heappop(queue)
        if k == 1:
            return cost
        if cost > best[k]:
            continue
        for j, q in enumerate(points):
            d = math.dist(points[k], q)
            if 0 < d <= radius or (k, j) in ((0, 1), (1, 0)):
                if cost + d < best.get(j, math.inf) and clearance_of([points[k], q], obstacles) > margin:
                    best[j] = cost + d
                    heapq.heappush(queue, (cost + d, j))
    return math.inf


# ---------------------------------------------------------------- PLAN


ROOM_ENV = plan.build_environment(OBSTACLES, ROOM_BOX)


def check_sound(path: list[Point], obstacles: list[list[Point]], env: plan.Environment) -> None:
    """Each segment keeps the clearance from every obstacle, enters no grown piece, and stays in
    the room less the clearance."""
    xmin, ymin, xmax, ymax = env.bounds
    for x, y in path:
        assert xmin - 1e-9 <= x <= xmax + 1e-9 and ymin - 1e-9 <= y <= ymax + 1e-9
    if obstacles:
        assert clearance_of(path, obstacles) >= plan.CLEARANCE - 1e-7
    for a, b in zip(path, path[1:], strict=False):
        for piece in env.pieces:
            assert not enters_convex(a, b, list(piece)), (a, b, piece)


def test_grown_pieces_are_convex_and_hold_the_clearance_disc() -> None:
    for obstacle in OBSTACLES:
        pieces = plan.grow(obstacle, plan.CLEARANCE)
        for piece in pieces:
            assert plan.signed_area(piece) > 0 and plan.is_convex(piece)
        for angle in np.linspace(0, math.tau, 73):
            for x, y in obstacle:  # around each corner: inside at the clearance less a hair, out beyond the extent
                c, s = math.cos(angle), math.sin(angle)
                near = (x + (plan.CLEARANCE - 1e-6) * c, y + (plan.CLEARANCE - 1e-6) * s)
                far = (x + (plan.GROWN_EXTENT + 1e-6) * c, y + (plan.GROWN_EXTENT + 1e-6) * s)
                if point_polygon_distance(near, obstacle) < plan.CLEARANCE:
                    assert any(inside(near, list(p)) for p in pieces)
                if point_polygon_distance(far, obstacle) > plan.GROWN_EXTENT:
                    assert not any(inside(far, list(p)) for p in pieces)


@st.composite
def star_polygons(draw: st.DrawFn) -> list[Point]:
    """Simple polygons, convex or not: vertices at increasing angles around a centre."""
    n = draw(st.integers(3, 9))
    angles = sorted(draw(st.lists(st.floats(0, math.tau - 0.05), min_size=n, max_size=n, unique=True)))
    gaps = [b - a for a, b in zip(angles, angles[1:] + [angles[0] + math.tau], strict=True)]
    if min(gaps) < 0.05 or max(gaps) > math.pi - 0.05:  # the centre must see every edge: simple
        angles = [k * math.tau / n for k in range(n)]
    radii = draw(st.lists(st.floats(0.2, 1.5), min_size=n, max_size=n))
    cx, cy = draw(st.floats(2, 8)), draw(st.floats(2, 6))
    return [(cx + r * math.cos(a), cy + r * math.sin(a)) for r, a in zip(radii, angles, strict=True)]


@settings(max_examples=60, deadline=None)
@given(star_polygons(), st.floats(0.05, 1.0), st.lists(st.tuples(st.floats(0, 10), st.floats(0, 8)), min_size=20,
                                                         max_size=20))
def test_growing_any_polygon_is_conservative_and_bounded(polygon: list[Point], radius: float,
                                                         points: list[Point]) -> None:
    pieces = plan.grow(polygon, radius)
    extent = radius / math.cos(plan.ARC_STEP / 2)
    for piece in pieces:
        assert plan.is_convex(piece)
    for p in points + polygon:
        d = point_polygon_distance(p, polygon)
        held = any(inside(p, list(piece)) for piece in pieces)
        if d < radius - 1e-7:
            assert held, (p, d)
        if d > extent + 1e-7:
            assert not held, (p, d)


def test_a_clear_straight_line_is_the_path() -> None:
    assert plan.shortest_path(ROOM_ENV, (1.0, 1.0), (11.0, 1.0)) == [(1.0, 1.0), (11.0, 1.0)]
    assert plan.shortest_path(ROOM_ENV, (2.0, 2.0), (2.0, 2.0)) == [(2.0, 2.0)]


@pytest.mark.parametrize("start, goal", [((3.0, 4.7), (9.0, 4.7)), ((1.0, 2.4), (6.0, 2.4)),
                                         ((1.0, 1.0), (11.0, 8.0)), ((8.0, 7.5), (8.0, 1.0)),
                                         ((6.2, 4.0), (6.2, 5.5))])
def test_paths_in_the_room_are_sound_and_no_longer_than_any_roadmap_detour(start: Point, goal: Point) -> None:
    path = plan.shortest_path(ROOM_ENV, start, goal)
    assert path[0] == start and path[-1] == goal
    check_sound(path, OBSTACLES, ROOM_ENV)
    length = plan.path_length(path)
    assert length >= math.dist(start, goal) - 1e-9
    # every path on a roadmap that keeps the grown pieces' extent from the obstacles is feasible for
    # PLAN: the shortest path cannot be longer
    assert length <= roadmap_length(start, goal, OBSTACLES, ROOM_BOX, plan.GROWN_EXTENT) + 1e-9


def test_the_detour_around_the_pillar_is_as_short_as_the_clearance_allows() -> None:
    path = plan.shortest_path(ROOM_ENV, (3.0, 4.7), (9.0, 4.7))
    # The pillar spans y in [4.5, 4.9] at x in [6, 6.4]: at x = 6.2 any sound path is at least the
    # clearance above or below it, so no path is shorter than these two hypotenuses...
    bound = math.hypot(3.2, 0.2 + plan.CLEARANCE) + math.hypot(2.8, 0.2 + plan.CLEARANCE)
    assert plan.path_length(path) >= bound - 1e-9
    # ... and PLAN's is hardly longer: its grown corners are polygons within 1.4 cm of the arcs
    assert plan.path_length(path) <= bound + 0.02
    assert len(path) > 2


@pytest.mark.parametrize("goal", [(3.8, 2.4), (3.8, 1.75), (11.8, 4.0), (13.0, 4.0), (6.2, 4.7), (8.0, 8.55)])
def test_a_goal_in_an_obstacle_near_a_wall_or_out_of_the_room_fails(goal: Point) -> None:
    with pytest.raises(plan.PlanningError) as failure:
        plan.shortest_path(ROOM_ENV, (1.0, 1.0), goal)
    assert failure.value.code == "GOAL_IN_OBSTACLE"
    with pytest.raises(plan.PlanningError) as failure:
        plan.shortest_path(ROOM_ENV, goal, (1.0, 1.0))
    assert failure.value.code == "START_IN_OBSTACLE"


def test_a_goal_walled_off_has_no_path() -> None:
    wall = [(5.0, 0.0), (5.5, 0.0), (5.5, 9.0), (5.0, 9.0)]  # across the whole room
    env = plan.build_environment([wall], ROOM_BOX)
    with pytest.raises(plan.PlanningError) as failure:
        plan.shortest_path(env, (1.0, 1.0), (10.0, 8.0))
    assert failure.value.code == "NO_PATH"


def test_a_non_convex_obstacle_is_walked_around_not_through() -> None:
    u_shape = [(4.0, 2.0), (8.0, 2.0), (8.0, 7.0), (7.0, 7.0), (7.0, 3.0), (5.0, 3.0), (5.0, 7.0), (4.0, 7.0)]
    env = plan.build_environment([u_shape], ROOM_BOX)
    start, goal = (6.0, 6.0), (6.0, 1.0)  # inside the U, to below it
    path = plan.shortest_path(env, start, goal)
    check_sound(path, [u_shape], env)
    assert max(y for _, y in path) > 7.0  # out through the U's mouth


@st.composite
def worlds(draw: st.DrawFn) -> list[list[Point]]:
    """Up to four obstacles in a 10 m x 8 m room: rectangles, or polygons convex or not."""
    obstacles = []
    for _ in range(draw(st.integers(0, 4))):
        if draw(st.booleans()):
            obstacles.append(draw(star_polygons()))
            continue
        x, y = draw(st.floats(0.5, 8.5)), draw(st.floats(0.5, 6.5))
        w, h = draw(st.floats(0.1, 2.0)), draw(st.floats(0.1, 2.0))
        obstacles.append([(x, y), (x + w, y), (x + w, y + h), (x, y + h)])
    return obstacles


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(worlds(), st.tuples(st.floats(0, 10), st.floats(0, 8)), st.tuples(st.floats(0, 10), st.floats(0, 8)))
def test_random_worlds_give_sound_paths_or_the_right_failure(obstacles: list[list[Point]], start: Point,
                                                             goal: Point) -> None:
    box = (0.0, 0.0, 10.0, 8.0)
    env = plan.build_environment(obstacles, box)
    xmin, ymin, xmax, ymax = env.bounds

    def margin(p: Point) -> float:  # distance to the nearest obstacle or wall
        walls = min(p[0] - box[0], box[2] - p[0], p[1] - box[1], box[3] - p[1])
        return min([walls] + [point_polygon_distance(p, o) for o in obstacles])

    try:
        path = plan.shortest_path(env, start, goal)
    except plan.PlanningError as failure:
        if failure.code == "START_IN_OBSTACLE":
            assert margin(start) < plan.GROWN_EXTENT + 1e-7
        elif failure.code == "GOAL_IN_OBSTACLE":
            assert margin(start) >= plan.CLEARANCE - 1e-7 and margin(goal) < plan.GROWN_EXTENT + 1e-7
        else:
            assert failure.code == "NO_PATH"
            assert not plan.segment_is_free(env, start, goal)
        return
    assert margin(start) >= plan.CLEARANCE - 1e-7 and margin(goal) >= plan.CLEARANCE - 1e-7
    assert path[0] == start and path[-1] == goal
    check_sound(path, obstacles, env)
    assert plan.path_length(path) >= math.dist(start, goal) - 1e-9
    if not obstacles or clearance_of([start, goal], obstacles) > plan.GROWN_EXTENT:
        assert path == [start, goal] or start == goal


class PlanSdi:
    """PLAN's generated SDI, posters written nowhere."""

    def __new__(cls):  # type: ignore[no-untyped-def]
        module = generated("plan")

        class Sdi(module.PlanData):  # type: ignore[misc, name-defined]
            def write_poster(self, name: str) -> None:
                self.written.append(name)

        sdi = Sdi()
        sdi.written = []
        return sdi


def planned(start: tuple[float, float, float], goal: tuple[float, float, float]):  # type: ignore[no-untyped-def]
    module = generated("plan")
    sdi = PlanSdi()
    world = str(EXAMPLES / "hilare" / "worlds" / "room.toml")
    box = module.Box(*ROOM_BOX)
    assert plan.checkBox(sdi, SimpleNamespace(box=box)) == "end" and sdi.written == ["Env"]
    assert plan.openModelFile(sdi, SimpleNamespace(file=world)) == "exec"
    assert plan.readPolygons(sdi, None) == "ether" and sdi.nbObstacles == 3
    request = SimpleNamespace(start=module.Posit(*start), goal=module.Posit(*goal))
    assert plan.startPlan(sdi, request) == "exec"
    return sdi, plan.computePlan(sdi, request)


def test_the_plan_codels_write_the_path_as_a_broken_line() -> None:
    sdi, result = planned((3.0, 4.7, 0.0), (9.0, 4.7, 0.0))
    assert result == "ether"
    t = sdi.traj
    points = list(zip(t.x[:t.nbPoints], t.y[:t.nbPoints], strict=True))
    assert points == plan.shortest_path(ROOM_ENV, (3.0, 4.7), (9.0, 4.7))
    assert t.kind.name == "BROKEN_LINE" and t.tolerance == plan.TOLERANCE
    for k in range(t.nbPoints - 1):  # theta along each segment
        assert t.theta[k] == pytest.approx(math.atan2(t.y[k + 1] - t.y[k], t.x[k + 1] - t.x[k]))
    assert t.theta[t.nbPoints - 1] == t.theta[t.nbPoints - 2]


def test_the_plan_codels_fail_cleanly_and_leave_no_stale_trajectory() -> None:
    sdi, result = planned((3.0, 4.7, 0.0), (9.0, 4.7, 0.0))
    request = SimpleNamespace(start=sdi.start, goal=type(sdi.goal)(3.8, 2.4, 0.0))  # in the table
    assert plan.startReplan(sdi, request) == "exec"
    assert plan.computePlan(sdi, request) == "GOAL_IN_OBSTACLE"
    assert sdi.traj.nbPoints == 0
    _, result = planned((3.8, 2.4, 0.0), (9.0, 4.7, 0.0))  # deep in the table
    assert result == "START_IN_OBSTACLE"
    module = generated("plan")
    assert plan.startPlan(module.PlanData(), request) == "NO_MODEL"


def test_a_start_against_the_walls_first_escapes_to_free_space() -> None:
    sdi, result = planned((0.0, 0.0, 0.0), (2.0, 5.0, 0.0))  # LOCO's pose without a simulator
    assert result == "ether"
    t = sdi.traj
    points = list(zip(t.x[:t.nbPoints], t.y[:t.nbPoints], strict=True))
    assert points[0] == (0.0, 0.0)
    assert math.dist(points[0], points[1]) <= plan.START_ESCAPE
    check_sound(points[1:], OBSTACLES, ROOM_ENV)


def test_the_fail_messages_the_plan_codels_return_are_declared() -> None:
    module = generated("plan")
    for request in ("plan", "replan"):
        declared = set(module.SPEC.requests[request].fail)
        assert {"NO_MODEL", "NO_PATH", "START_IN_OBSTACLE", "GOAL_IN_OBSTACLE"} <= declared


# ---------------------------------------------------------------- PILO


LIMITS = pilo.Limits(vmax=0.3, wmax=0.6, amax=0.3, dwmax=0.6)


def polyline_distance(p: Point, line: list[Point]) -> float:
    return min(point_segment_distance(p, line[k], line[k + 1]) for k in range(len(line) - 1))


def samples(pieces: list[pilo.Piece], per_piece: int = 25) -> list[tuple[float, float, float]]:
    return [piece.pose(piece.length * k / per_piece) for piece in pieces for k in range(per_piece + 1)]


def check_chain(pieces: list[pilo.Piece]) -> None:
    """Continuous in position, heading and curvature."""
    for a, b in zip(pieces, pieces[1:], strict=False):
        x, y, theta = a.end()
        assert math.hypot(x - b.x, y - b.y) < 1e-7
        assert abs(math.remainder(theta - b.theta, math.tau)) < 1e-7
        assert abs(a.curvature(a.length) - b.curvature(0.0)) < 1e-6


@st.composite
def broken_lines(draw: st.DrawFn) -> list[Point]:
    heading = draw(st.floats(-math.pi, math.pi))
    points = [(draw(st.floats(-5, 5)), draw(st.floats(-5, 5)))]
    for k in range(draw(st.integers(1, 6))):
        if k:
            heading += draw(st.floats(-2.6, 2.6))  # up to about 150 degrees
        length = draw(st.floats(0.1, 3.0))
        points.append((points[-1][0] + length * math.cos(heading), points[-1][1] + length * math.sin(heading)))
    return points


@settings(max_examples=80, deadline=None)
@given(broken_lines(), st.floats(0.005, 0.3))
def test_a_smoothed_broken_line_stays_within_tolerance(line: list[Point], tolerance: float) -> None:
    pieces = pilo.smooth_broken_line(line, tolerance)
    check_chain(pieces)
    assert (pieces[0].x, pieces[0].y) == pytest.approx(line[0], abs=1e-9)
    end = pieces[-1].end()
    assert end[:2] == pytest.approx(line[-1], abs=1e-7)
    assert math.remainder(end[2] - math.atan2(line[-1][1] - line[-2][1], line[-1][0] - line[-2][0]),
                          math.tau) == pytest.approx(0.0, abs=1e-7)
    for x, y, _ in samples(pieces):
        assert polyline_distance((x, y), line) <= tolerance + 1e-7
    assert sum(p.length for p in pieces) <= sum(math.dist(a, b) for a, b in zip(line, line[1:], strict=False)) + 1e-9


def test_a_right_angle_corner_uses_its_whole_tolerance_with_clothoids_and_an_arc() -> None:
    pieces = pilo.smooth_broken_line([(0.0, 0.0), (3.0, 0.0), (3.0, 3.0)], 0.1)
    assert [p.sharpness != 0 for p in pieces] == [False, True, False, True, False]
    assert pieces[2].kappa > 0 and pieces[2].sharpness == 0  # the arc, turning left
    deepest = max(polyline_distance((x, y), [(0.0, 0.0), (3.0, 0.0), (3.0, 3.0)]) for x, y, _ in samples(pieces, 200))
    assert deepest == pytest.approx(0.1, abs=1e-4)


def check_profile(timed: pilo.TimedTrajectory, limits: pilo.Limits) -> None:
    v = np.array(timed.v)
    assert v[0] == 0.0 and v[-1] == 0.0
    assert (v[1:-1] > 0).all()  # never stops inside
    assert (v <= limits.vmax * (1 + 1e-9)).all()
    times = np.linspace(0.0, timed.duration, max(400, int(timed.duration / 0.01)))
    points = [pilo.sample(timed, t) for t in times]
    speeds = np.array([p.v for p in points])
    turns = np.array([p.w for p in points])
    assert (speeds[1:-1] > 0).all()
    assert (speeds <= limits.vmax * (1 + 1e-9)).all()
    assert (np.abs(turns) <= limits.wmax * (1 + 1e-9)).all()
    dt = np.diff(times)
    assert (np.abs(np.diff(speeds)) / dt <= limits.amax * (1 + 1e-6) + 1e-9).all()
    assert (np.abs(np.diff(turns)) / dt <= limits.dwmax * (1 + 1e-6) + 1e-9).all()
    moved = np.hypot(np.diff([p.x for p in points]), np.diff([p.y for p in points]))
    assert (moved <= limits.vmax * dt * (1 + 1e-6) + 1e-9).all()


@st.composite
def limits(draw: st.DrawFn) -> pilo.Limits:
    return pilo.Limits(draw(st.floats(0.1, 1.0)), draw(st.floats(0.2, 2.0)), draw(st.floats(0.1, 1.0)),
                       draw(st.floats(0.2, 3.0)))


@settings(max_examples=40, deadline=None)
@given(broken_lines(), st.floats(0.02, 0.3), limits())
def test_the_speed_profile_respects_the_dynamic_limits_and_never_stops_inside(line: list[Point], tolerance: float,
                                                                             dynamic: pilo.Limits) -> None:
    timed = pilo.speed_profile(pilo.smooth_broken_line(line, tolerance), dynamic)
    check_profile(timed, dynamic)
    end = pilo.sample(timed, timed.duration)
    assert (end.x, end.y) == pytest.approx(line[-1], abs=1e-7) and end.v == 0.0


def test_a_segment_has_a_trapezoidal_profile() -> None:
    timed = pilo.timed_trajectory("SEGMENT", [(0.0, 0.0), (10.0, 0.0)], [0.0, 0.0], 0.0, LIMITS)
    # 1 s to reach 0.3 m/s over 0.15 m, the same to stop, 9.7 m at 0.3 m/s in between (the grid
    # step where vmax is reached is run at a constant, slightly lower, acceleration)
    assert timed.duration == pytest.approx(2.0 + 9.7 / 0.3, abs=0.01)
    assert pilo.sample(timed, 0.5).v == pytest.approx(0.15)
    assert pilo.sample(timed, 10.0).v == pytest.approx(0.3)
    check_profile(timed, LIMITS)


def test_an_arc_slows_to_keep_the_rotation_speed() -> None:
    piece = pilo.arc_piece((0.0, 0.0), 0.0, (1.0, 1.0))  # a quarter of the unit circle, turning left
    assert piece.length == pytest.approx(math.pi / 2) and piece.kappa == pytest.approx(1.0)
    assert piece.end() == pytest.approx((1.0, 1.0, math.pi / 2))
    slow = pilo.Limits(vmax=0.5, wmax=0.2, amax=0.3, dwmax=1.0)
    timed = pilo.timed_trajectory("ARC", [(0.0, 0.0), (1.0, 1.0)], [0.0, 0.0], 0.0, slow)
    assert max(timed.v) == pytest.approx(0.2)
    check_profile(timed, slow)


@pytest.mark.parametrize("kind, points, tolerance", [("REEDS_SHEPP", [(0, 0), (1, 0)], 0.1),
                                                     ("BROKEN_LINE", [(0, 0), (1, 0), (0, 0)], 0.1),
                                                     ("BROKEN_LINE", [(0, 0), (1, 0), (1, 1)], 0.0),
                                                     ("SEGMENT", [(0, 0), (1, 0), (2, 0)], 0.1),
                                                     ("ARC", [(0, 0), (-1, 0)], 0.1)])
def test_trajectories_pilo_cannot_execute_are_refused(kind: str, points: list[Point], tolerance: float) -> None:
    with pytest.raises(pilo.InvalidTrajectory):
        pilo.timed_trajectory(kind, points, [0.0] * len(points), tolerance, LIMITS)


def pilo_sdi(traj):  # type: ignore[no-untyped-def]
    module = generated("pilo")

    class Sdi(module.PiloData):  # type: ignore[misc, name-defined]
        def read_poster(self, name: str):  # type: ignore[no-untyped-def]
            return copy.deepcopy(traj) if name == "plan.Traj" else None

        def send_request(self, name: str, **inputs) -> None:  # type: ignore[no-untyped-def]
            self.sent.append(name)

    sdi = Sdi()
    sdi.sent = []
    pilo.initPilo(sdi)
    return sdi


def test_the_pilo_codels_run_the_setpoint_along_a_planned_path() -> None:
    sdi, _ = planned((3.0, 4.7, 0.0), (9.0, 4.7, 0.0))
    pilot = pilo_sdi(sdi.traj)
    pilot.avoidOn = True
    assert pilo.readTrajPoster(pilot, SimpleNamespace(trajPoster="plan.Traj")) == "exec"
    assert pilot.sent == ["avoid.Filter"]
    sp = pilot.setpoint
    trace = [(sp.x, sp.y, sp.v, sp.w, pilot.nextPoint)]
    for _ in range(10_000):
        result = pilo.generateSetpoint(pilot, None)
        trace.append((sp.x, sp.y, sp.v, sp.w, pilot.nextPoint))
        if result == "end":
            break
    assert result == "end" and pilo.endTraj(pilot, None) == "ether"
    line = [(sdi.traj.x[k], sdi.traj.y[k]) for k in range(sdi.traj.nbPoints)]
    assert trace[-1][:3] == pytest.approx((9.0, 4.7, 0.0))
    assert all(v > 0 for _, _, v, _, _ in trace[1:-1])
    assert all(math.dist(a[:2], b[:2]) <= LIMITS.vmax * pilo.PERIOD + 1e-9 for a, b in zip(trace, trace[1:],
                                                                                           strict=False))
    assert all(polyline_distance(p[:2], line) <= sdi.traj.tolerance + 1e-7 for p in trace)
    assert [p[4] for p in trace] == sorted(p[4] for p in trace)  # nextPoint only moves on
    assert len(trace) * pilo.PERIOD == pytest.approx(plan.path_length(line) / LIMITS.vmax, rel=0.25)


def test_the_pilo_codels_refuse_an_empty_or_unknown_trajectory() -> None:
    sdi, _ = planned((3.0, 4.7, 0.0), (3.8, 2.4, 0.0))  # failed: empty trajectory
    pilot = pilo_sdi(sdi.traj)
    assert pilo.readTrajPoster(pilot, SimpleNamespace(trajPoster="plan.Traj")) == "INVALID_TRAJECTORY"
    assert pilo.readTrajPoster(pilot, SimpleNamespace(trajPoster="nobody.Traj")) == "POSTER_NOT_FOUND"
    assert pilot.sent == []


# ---------------------------------------------------------------- EXPLOR


F = [visual.reliability(r, 0.0) for r in range(6)]  # f(r, 0) at 0..5 cells of 1 m


def test_f_is_visuals_reliability() -> None:
    assert F[1] == pytest.approx(math.exp(-(1 / visual.R_MAX) ** 2)) and F[0] == 0.0 and F[5] == 0.0


def test_the_full_algorithm_picks_the_best_cell_of_a_hand_checked_row() -> None:
    free = np.ones((1, 5), dtype=bool)
    certainty = np.array([[0.0, 0.0, 0.0, 0.9, 1.0]])
    # each candidate scores sum (1 - c) f(r, 0) over the other cells (its own is at r = 0 < r_min)
    expected = [F[1] + F[2] + 0.1 * F[3], 2 * F[1] + 0.1 * F[2], F[2] + F[1] + 0.1 * F[1], F[3] + F[2] + F[1],
                F[4] + F[3] + F[2] + 0.1 * F[1]]
    candidates = explor.all_candidates(explor.candidate_cells(free, 1.0, 0.0))
    assert candidates.tolist() == [[i, 0] for i in range(5)]
    assert explor.full_scores(free, certainty, 1.0, candidates) == pytest.approx(expected)
    assert explor.best_cell(free, certainty, 1.0, 0.0, "full") == (3, 0, pytest.approx(expected[3]))


def test_cells_hidden_by_an_obstacle_do_not_count() -> None:
    free = np.array([[True, True, True, False, True, True, True]])
    certainty = np.zeros((1, 7))
    scores = explor.full_scores(free, certainty, 1.0, np.array([[i, 0] for i in (0, 1, 2, 4)]))
    assert scores == pytest.approx([F[1] + F[2], 2 * F[1], F[1] + F[2], F[1] + F[2]])
    square = np.ones((5, 5), dtype=bool)
    square[2, 2] = False  # a pillar in the middle; only cell (3, 2) is left to explore
    certainty = np.ones((5, 5))
    certainty[2, 3] = 0.0
    score = dict(zip([(0, 0), (0, 2), (1, 0), (3, 0), (4, 2), (4, 4)],
                     explor.full_scores(square, certainty, 1.0, np.array([(0, 0), (0, 2), (1, 0), (3, 0), (4, 2),
                                                                          (4, 4)])), strict=True))
    assert score[(0, 0)] == score[(0, 2)] == 0.0  # behind the pillar
    assert score[(1, 0)] == 0.0  # the line of sight grazes the pillar's corner (2.5, 1.5)
    assert score[(3, 0)] == pytest.approx(F[2]) and score[(4, 2)] == pytest.approx(F[1])
    assert score[(4, 4)] == pytest.approx(visual.reliability(math.sqrt(5), 0.0))


def meets(p: tuple[int, int], q: tuple[int, int], cell: tuple[int, int]) -> bool:
    """Does the segment between two cell centres meet the closed square of ``cell``? (exact
    Liang-Barsky clipping)"""
    t0, t1 = Fraction(0), Fraction(1)
    for axis in (0, 1):
        start, delta = Fraction(p[axis]), Fraction(q[axis] - p[axis])
        low, high = cell[axis] - Fraction(1, 2), cell[axis] + Fraction(1, 2)
        if delta == 0:
            if not low <= start <= high:
                return False
            continue
        a, b = (low - start) / delta, (high - start) / delta
        t0, t1 = max(t0, min(a, b)), min(t1, max(a, b))
        if t0 > t1:
            return False
    return True


def reference_scores(free: np.ndarray, certainty: np.ndarray, cell: float, grow: float) -> dict[tuple[int, int], float]:
    """§5.2.5 literally, cell by cell: the score of every candidate."""
    ny, nx = free.shape
    blocked = [(i, j) for j in range(ny) for i in range(nx) if not free[j, i]]
    scores = {}
    for j in range(ny):
        for i in range(nx):
            walls = cell * min(i + 0.5, nx - i - 0.5, j + 0.5, ny - j - 0.5)
            near = [cell * math.hypot(max(abs(a - i) - 0.5, 0), max(abs(b - j) - 0.5, 0)) for a, b in blocked]
            if not free[j, i] or walls <= grow or min(near, default=math.inf) <= grow:
                continue
            total = 0.0
            for b in range(ny):
                for a in range(nx):
                    r = cell * math.hypot(a - i, b - j)
                    if (a, b) == (i, j) or not free[b, a] or r > visual.R_MAX:
                        continue
                    if not any(meets((i, j), (a, b), o) for o in blocked):
                        total += (1 - certainty[b, a]) * visual.reliability(r, 0.0)
            scores[i, j] = total
    return scores


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 8), st.integers(1, 7), st.data())
def test_the_full_algorithm_matches_the_literal_one(nx: int, ny: int, data: st.DataObject) -> None:
    free = np.array(data.draw(st.lists(st.booleans(), min_size=nx * ny, max_size=nx * ny)), dtype=bool).reshape(ny, nx)
    certainty = np.array(data.draw(st.lists(st.floats(0, 1), min_size=nx * ny, max_size=nx * ny))).reshape(ny, nx)
    cell, grow = data.draw(st.sampled_from([(1.0, 0.0), (1.0, 0.6), (0.5, 0.3)]))
    expected = reference_scores(free, certainty, cell, grow)
    candidates = explor.all_candidates(explor.candidate_cells(free, cell, grow))
    assert sorted(map(tuple, candidates.tolist())) == sorted(expected)
    scores = explor.full_scores(free, certainty, cell, candidates)
    assert scores == pytest.approx([expected[i, j] for i, j in candidates.tolist()], abs=1e-9)
    best = explor.best_cell(free, certainty, cell, grow, "full")
    if expected:
        top = max(expected.values())
        assert best is not None and best[2] == pytest.approx(top)
        assert expected[best[0], best[1]] == pytest.approx(top)
    else:
        assert best is None


def visual_free_cells() -> list[bool]:
    """VISUAL's free cells as readObstacles marks them (64 x 64 cells of 0.3 m, row-major;
    obstacles' bounding boxes not free), those outside the room included."""
    return visual.free_cells(load_world(ROOM_FILE))


def room_model() -> tuple[np.ndarray, float]:
    """VISUAL's grid of the room less the cells outside the room (PLAN's Env box)."""
    cell, n = visual.CELL, visual.NX
    model = SimpleNamespace(nx=n, ny=n, cellSize=cell, free=visual_free_cells(),
                            certainty=[0.0] * (n * n))
    box = SimpleNamespace(xmin=ROOM_BOX[0], ymin=ROOM_BOX[1], xmax=ROOM_BOX[2], ymax=ROOM_BOX[3])
    return explor.model_grid(model, box)[0], cell


def test_every_cell_explor_may_choose_is_free_for_plan() -> None:
    free, cell = room_model()
    valid = explor.candidate_cells(free, cell)
    assert valid.sum() > 500 and not valid[:, 40:].any() and not valid[30:, :].any()  # only in the room
    for j, i in np.argwhere(valid):
        assert plan.is_free(ROOM_ENV, ((i + 0.5) * cell, (j + 0.5) * cell))


@settings(max_examples=8, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 12), st.floats(0, 9)), min_size=1, max_size=4))
def test_the_sampled_variant_picks_a_cell_almost_as_good_as_the_best(visited: list[Point]) -> None:
    free, cell = room_model()
    x, y = np.meshgrid((np.arange(free.shape[1]) + 0.5) * cell, (np.arange(free.shape[0]) + 0.5) * cell)
    certainty = np.zeros(free.shape)
    for vx, vy in visited:  # explored around each place visited
        certainty = 1 - (1 - certainty) * (1 - np.exp(-((x - vx) ** 2 + (y - vy) ** 2) / 4))
    best = explor.best_cell(free, certainty, cell, variant="full")
    sampled = explor.best_cell(free, certainty, cell, variant="sampled")
    assert best is not None and sampled is not None
    full_of_sampled = explor.full_scores(free, certainty, cell, np.array([sampled[:2]]))[0]
    assert full_of_sampled >= 0.85 * best[2]
    step = round(visual.R_MAX / 2 / cell)
    assert sampled[0] % step == step // 2 and sampled[1] % step == step // 2  # a cell every r_max / 2


def test_the_radial_score_estimates_the_full_one() -> None:
    free, certainty = np.ones((41, 41), dtype=bool), np.zeros((41, 41))
    centre = np.array([[20, 20]])
    full = explor.full_scores(free, certainty, visual.CELL, centre)[0]
    radial = explor.radial_scores(free, certainty, visual.CELL, centre)[0]
    assert radial == pytest.approx(full, rel=0.05)
    free[20, 22] = False  # on the axis at 0: what is behind it is hidden
    assert explor.radial_scores(free, certainty, visual.CELL, centre)[0] < radial - 0.5
    certainty[:, :20] = 1.0  # the west half explored already
    assert explor.radial_scores(free, certainty, visual.CELL, centre)[0] < 0.6 * radial


def explor_sdi(certainty: np.ndarray | None = None, robot: Point = (1.0, 1.0)):  # type: ignore[no-untyped-def]
    module, vis = generated("explor"), generated("visual")
    free, cell = room_model()
    n = visual.NX
    # VISUAL's own model: the cells outside the room are free for VISUAL, EXPLOR masks them
    model = vis.Model(nx=n, ny=n, cellSize=cell, free=visual_free_cells(),
                      certainty=(np.zeros(n * n) if certainty is None else certainty.ravel()).tolist())
    posters = {"visual.Model": SimpleNamespace(model=model, pan=0.0),
               "plan.Env": generated("plan").Box(*ROOM_BOX),
               "loco.Robot": SimpleNamespace(robot=SimpleNamespace(x=robot[0], y=robot[1], theta=0.0))}

    class Sdi(module.ExplorData):  # type: ignore[misc, name-defined]
        def read_poster(self, name: str):  # type: ignore[no-untyped-def]
            return copy.deepcopy(posters.get(name))

        def write_poster(self, name: str) -> None:
            self.written.append(name)

    sdi = Sdi()
    sdi.written = []
    return sdi, free, cell


@pytest.mark.parametrize("variant", ["full", "sampled"])
def test_calc_goal_spreads_its_search_and_exports_the_best(variant: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(explor, "VARIANT", variant)
    certainty = np.zeros((visual.NY, visual.NX))
    certainty[:, :20] = 0.95  # the west half of the room is explored
    sdi, free, cell = explor_sdi(certainty)
    request = SimpleNamespace(goal=None)
    assert explor.startCalcGoal(sdi, request) == "exec"
    calls = 0
    while (result := explor.scoreCandidates(sdi, request)) == "exec":
        calls += 1
    expected = explor.best_cell(free, certainty, cell, variant=variant)
    assert result == "ether" and sdi.written == ["Goals"] and request.goal is sdi.goal
    assert calls + 1 == math.ceil(len(explor.candidates_of(explor.candidate_cells(free, cell), cell, variant))
                                  / explor.CANDIDATES_PER_PERIOD[variant])
    assert (sdi.goal.x, sdi.goal.y) == pytest.approx(((expected[0] + 0.5) * cell, (expected[1] + 0.5) * cell))
    assert sdi.goal.x > 6.0  # east, where it is not explored yet
    assert plan.is_free(ROOM_ENV, (sdi.goal.x, sdi.goal.y))


@pytest.mark.parametrize("cell, reachable", [((5, 20), True), ((16, 8), False), ((10, 5), False),
                                              ((45, 10), False), ((0, 10), False), ((70, 3), False)])
def test_calc_obj_puts_the_robot_on_the_objects_cell_if_it_can_get_there(cell: tuple[int, int],
                                                                         reachable: bool) -> None:
    sdi, _, size = explor_sdi()
    request = SimpleNamespace(object=generated("explor").Object(x=0.0, y=0.0, i=cell[0], j=cell[1]), position=None)
    assert explor.startCalcObj(sdi, request) == "exec"
    result = explor.checkReachable(sdi, request)
    if reachable:
        assert result == "ether" and request.position is sdi.graspPos
        assert (sdi.graspPos.x, sdi.graspPos.y) == pytest.approx(((cell[0] + 0.5) * size, (cell[1] + 0.5) * size))
    else:
        assert result == "UNREACHABLE_CELL"


def test_calc_obj_refuses_a_cell_the_robot_cannot_get_to() -> None:
    valid = np.ones((5, 9), dtype=bool)
    valid[:, 4] = False  # a wall between the robot's side and the object's
    assert explor.reachable_cells(valid, (0, 0))[2, 8] == np.False_
    assert explor.reachable_cells(valid, (-3, -3))[4, 3] == np.True_  # from outside: the nearest valid cell
