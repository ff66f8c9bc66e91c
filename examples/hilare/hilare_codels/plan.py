"""Codels of PLAN (seed 000 §5.2.2, Table 5.2): collision-free paths among polygonal obstacles.

§5.2.2: PLAN's geometric planner works on "un modèle de l'environnement où les obstacles sont
représentés par des polygones" read from a file; [Laumond 94] then cuts its collision-free path
into Reeds&Shepp pieces. Only the geometric phase is built here, and its broken line goes to PILO,
which smooths it (§5.2.1):

1. ``grow``: every obstacle is grown by ``CLEARANCE`` (the robot's radius plus the tolerance PILO
   may deviate by while smoothing corners), so the robot shrinks to a point. The growth is an outer
   approximation of the Minkowski sum with a disc: arcs become tangent polygons whose pieces turn by
   at most ``ARC_STEP``; a non-convex polygon is first cut into triangles, so every grown piece is
   convex. The room walls bound where the point may be (``free_bounds``).
2. ``build_environment`` / ``visibility_graph``: the grown vertices that lie in free space, linked
   when the straight segment between them enters no grown piece. This is the "phase initiale" that
   ``replan`` skips when the model has not changed (cached on the model's content).
3. ``shortest_path``: the start and the goal are linked to the graph, then A*. A shortest path
   among polygons bends only at their vertices, so the result is the shortest in the grown model.
4. ``computePlan`` writes it as a BROKEN_LINE trajectory, each point's heading being that of the
   segment leaving it.

A robot standing closer than ``CLEARANCE`` to an obstacle or a wall (odometric drift, local
avoidance, LOCO's initial pose at the room's corner) would otherwise never get a path: as
MoveIt's FixStartStateCollision adapter does, the codel first leaves by the shortest straight
move to free space (``escape_point``), if it is at most ``START_ESCAPE`` long and the robot's
centre is inside the room and outside every (ungrown) obstacle. ``START_ESCAPE = 0`` disables it.
"""

from __future__ import annotations

import enum
import functools
import heapq
import math
import pathlib
from collections.abc import Sequence
from dataclasses import dataclass, replace

from specc.runtime.sim.world import Polygon, WorldError, load_world, signed_area

MAX_POINTS = 64  # capacity of the Trajectory arrays (plan.spec)
ROBOT_RADIUS = 0.35  # m, radius of the circle that holds Hilare 2 (invented)
TOLERANCE = 0.05  # m, how far PILO may leave the broken line when it rounds the corners
CLEARANCE = ROBOT_RADIUS + TOLERANCE  # what obstacles and walls are grown by
ARC_STEP = math.pi / 6  # rad, largest turn of one piece of a grown corner
GROWN_EXTENT = CLEARANCE / math.cos(ARC_STEP / 2)  # no grown piece reaches farther from its obstacle
START_ESCAPE = 2 * CLEARANCE  # m, longest straight move out of the grown obstacles at the start
AUTO_MARGIN = 1.0  # m, free border around the model when the bounds are automatic (autoBox)
EPS = 1e-9  # m, geometric tolerance: touching a grown piece is not entering it

Point = tuple[float, float]
Bounds = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax


class PlanningError(Exception):
    """No path; ``code`` is the request's fail message."""

    def __init__(self, code: str, detail: str = ""):
        super().__init__(f"{code}: {detail}" if detail else code)
        self.code = code


# ---------------------------------------------------------------- polygons


def _cross(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def normalise(polygon: Sequence[Point]) -> list[Point]:
    """Counter-clockwise, without repeated or collinear vertices."""
    points = [(float(x), float(y)) for x, y in polygon]
    if signed_area(points) < 0:
        points.reverse()
    changed = True
    while changed and len(points) >= 3:
        changed = False
        for k in range(len(points)):
            prev, here, nxt = points[k - 1], points[k], points[(k + 1) % len(points)]
            if math.dist(prev, here) <= EPS or abs(_cross(prev, here, nxt)) <= EPS * max(1.0, math.dist(prev, nxt)):
                del points[k]
                changed = True
                break
    return points


def is_convex(polygon: Sequence[Point]) -> bool:
    """For a counter-clockwise polygon: no vertex turns clockwise."""
    n = len(polygon)
    return all(_cross(polygon[k - 1], polygon[k], polygon[(k + 1) % n]) >= -EPS for k in range(n))


def is_simple(polygon: Sequence[Point]) -> bool:
    """No two non-adjacent edges meet (and at least three distinct vertices)."""
    n = len(polygon)
    if n < 3 or abs(signed_area(polygon)) <= EPS:
        return False
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue
            if _segments_meet(polygon[i], polygon[(i + 1) % n], polygon[j], polygon[(j + 1) % n]):
                return False
    return True


def _segments_meet(a: Point, b: Point, c: Point, d: Point) -> bool:
    d1, d2 = _cross(c, d, a), _cross(c, d, b)
    d3, d4 = _cross(a, b, c), _cross(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True

    def on(p: Point, q: Point, r: Point) -> bool:  # r on segment pq, knowing the three are collinear
        return min(p[0], q[0]) <= r[0] <= max(p[0], q[0]) and min(p[1], q[1]) <= r[1] <= max(p[1], q[1])

    return ((d1 == 0 and on(c, d, a)) or (d2 == 0 and on(c, d, b)) or (d3 == 0 and on(a, b, c))
            or (d4 == 0 and on(a, b, d)))


def triangulate(polygon: Sequence[Point]) -> list[list[Point]]:
    """Ear clipping of a simple counter-clockwise polygon."""
    points = list(polygon)
    triangles: list[list[Point]] = []
    while len(points) > 3:
        n = len(points)
        for k in range(n):
            a, b, c = points[k - 1], points[k], points[(k + 1) % n]
            if _cross(a, b, c) <= EPS:
                continue  # reflex (or flat) vertex: not an ear
            if any(_inside_triangle(p, a, b, c) for p in points if p not in (a, b, c)):
                continue
            triangles.append([a, b, c])
            del points[k]
            break
        else:  # numerically degenerate: no ear found; keep the rest as a fan (still covers it)
            triangles.extend([points[0], points[k], points[k + 1]] for k in range(1, len(points) - 1))
            return triangles
    triangles.append(points)
    return triangles


def _inside_triangle(p: Point, a: Point, b: Point, c: Point) -> bool:
    return _cross(a, b, p) >= 0 and _cross(b, c, p) >= 0 and _cross(c, a, p) >= 0


def grow(polygon: Sequence[Point], radius: float, arc_step: float = ARC_STEP) -> list[list[Point]]:
    """Convex counter-clockwise pieces whose union holds every point within ``radius`` of the
    polygon, and no point farther than ``radius / cos(arc_step / 2)`` from it."""
    points = normalise(polygon)
    if len(points) < 3 or not is_simple(points):
        raise ValueError("an obstacle must be a simple polygon (three vertices at least, edges not crossing)")
    pieces = [points] if is_convex(points) else triangulate(points)
    return [_grow_convex(piece, radius, arc_step) for piece in pieces]


def _grow_convex(polygon: Sequence[Point], radius: float, arc_step: float) -> list[Point]:
    # Each edge moves out by `radius`; around vertex k the arc from the previous edge's normal to
    # the next one's is replaced by the polygon circumscribed to it (m pieces of angle delta).
    n = len(polygon)
    normals = []
    for k in range(n):
        (x0, y0), (x1, y1) = polygon[k], polygon[(k + 1) % n]
        normals.append(math.atan2(-(x1 - x0), y1 - y0))  # outward normal of edge k (CCW polygon)
    grown: list[Point] = []
    for k in range(n):
        start = normals[k - 1]
        turn = (normals[k] - start) % math.tau
        if turn > math.pi + 1e-12:  # a convex polygon only turns left; guard against -0
            turn = 0.0
        m = max(1, math.ceil(turn / arc_step - 1e-12))
        delta = turn / m
        reach = radius / math.cos(delta / 2)
        vx, vy = polygon[k]
        for j in range(m):
            angle = start + (j + 0.5) * delta
            grown.append((vx + reach * math.cos(angle), vy + reach * math.sin(angle)))
    return grown


# ---------------------------------------------------------------- the environment


@dataclass(frozen=True)
class Environment:
    """The grown model: where the robot's centre may be, and the visibility graph of its vertices."""

    obstacles: tuple[tuple[Point, ...], ...]  # as read (counter-clockwise)
    pieces: tuple[tuple[Point, ...], ...]  # grown, convex, counter-clockwise
    room: Bounds  # the environment's bounds (walls)
    bounds: Bounds  # where the robot's centre may be: the room less the clearance
    nodes: tuple[Point, ...]
    graph: tuple[tuple[tuple[int, float], ...], ...]  # per node: (neighbour, length)
    _planes: tuple[tuple[tuple[float, float, float], ...], ...] = ()  # per piece, per edge: a, b, c
    _boxes: tuple[Bounds, ...] = ()


def free_bounds(room: Bounds, clearance: float = CLEARANCE) -> Bounds:
    """The room less ``clearance`` along its walls: where the robot's centre may be."""
    xmin, ymin, xmax, ymax = room
    return xmin + clearance, ymin + clearance, xmax - clearance, ymax - clearance


def build_environment(obstacles: Sequence[Sequence[Point]], room: Bounds,
                      clearance: float = CLEARANCE) -> Environment:
    """Grow the obstacles, bound them by the walls and build the visibility graph (the part of
    the planning that ``replan`` reuses)."""
    polygons = tuple(tuple(normalise(o)) for o in obstacles)
    pieces = tuple(tuple(piece) for polygon in polygons for piece in grow(polygon, clearance))
    planes = tuple(_half_planes(piece) for piece in pieces)
    boxes = tuple((min(p[0] for p in piece), min(p[1] for p in piece), max(p[0] for p in piece),
                   max(p[1] for p in piece)) for piece in pieces)
    env = Environment(polygons, pieces, room, free_bounds(room, clearance), (), (), planes, boxes)
    nodes = tuple(p for piece in pieces for p in piece if is_free(env, p))
    return replace(env, nodes=nodes, graph=visibility_graph(nodes, env))


def _half_planes(piece: Sequence[Point]) -> tuple[tuple[float, float, float], ...]:
    # Inside the convex piece: a x + b y < c for every edge, (a, b) its outward unit normal.
    planes = []
    n = len(piece)
    for k in range(n):
        (x0, y0), (x1, y1) = piece[k], piece[(k + 1) % n]
        length = math.hypot(x1 - x0, y1 - y0)
        a, b = (y1 - y0) / length, -(x1 - x0) / length
        planes.append((a, b, a * x0 + b * y0))
    return tuple(planes)


def is_free(env: Environment, p: Point) -> bool:
    """The robot's centre may be at ``p``: inside the bounds, in no grown piece's interior."""
    x, y = p
    xmin, ymin, xmax, ymax = env.bounds
    if not (xmin - EPS <= x <= xmax + EPS and ymin - EPS <= y <= ymax + EPS):
        return False
    return not any(_strictly_inside(planes, p) for planes in env._planes)


def _strictly_inside(planes: Sequence[tuple[float, float, float]], p: Point) -> bool:
    return all(a * p[0] + b * p[1] < c - EPS for a, b, c in planes)


def segment_is_free(env: Environment, a: Point, b: Point, ignore: frozenset[int] = frozenset(),
                    bounded: bool = True) -> bool:
    """The straight move from ``a`` to ``b`` stays in the bounds (unless not ``bounded``) and
    enters no grown piece (pieces numbered in ``ignore`` aside)."""
    xmin, ymin, xmax, ymax = env.bounds
    for x, y in (a, b) if bounded else ():  # the bounds are convex: both ends inside is enough
        if not (xmin - EPS <= x <= xmax + EPS and ymin - EPS <= y <= ymax + EPS):
            return False
    sx0, sx1 = min(a[0], b[0]), max(a[0], b[0])
    sy0, sy1 = min(a[1], b[1]), max(a[1], b[1])
    for k, (planes, box) in enumerate(zip(env._planes, env._boxes, strict=True)):
        if k in ignore or sx1 < box[0] or sx0 > box[2] or sy1 < box[1] or sy0 > box[3]:
            continue
        if _enters(planes, a, b):
            return False
    return True


def _enters(planes: Sequence[tuple[float, float, float]], a: Point, b: Point) -> bool:
    # Cyrus-Beck clipping of the segment by the piece shrunk by EPS: does a stretch remain?
    t0, t1 = 0.0, 1.0
    dx, dy = b[0] - a[0], b[1] - a[1]
    for pa, pb, c in planes:
        num = c - EPS - (pa * a[0] + pb * a[1])
        den = pa * dx + pb * dy
        if abs(den) < 1e-15:
            if num <= 0:
                return False  # parallel to this edge and outside (or on) it
            continue
        t = num / den
        if den > 0:
            t1 = min(t1, t)
        else:
            t0 = max(t0, t)
        if t0 >= t1:
            return False
    return (t1 - t0) * math.hypot(dx, dy) > EPS


def visibility_graph(nodes: Sequence[Point], env: Environment) -> tuple[tuple[tuple[int, float], ...], ...]:
    """For each node, the nodes it sees (a free straight segment) and the distance to them."""
    edges: list[list[tuple[int, float]]] = [[] for _ in nodes]
    for i in range(len(nodes)):
        for j in range(i + 1, len(nodes)):
            if segment_is_free(env, nodes[i], nodes[j]):
                d = math.dist(nodes[i], nodes[j])
                edges[i].append((j, d))
                edges[j].append((i, d))
    return tuple(tuple(e) for e in edges)


def shortest_path(env: Environment, start: Point, goal: Point) -> list[Point]:
    """The shortest collision-free broken line from ``start`` to ``goal`` in the grown model
    (A* over the visibility graph). Raises PlanningError START_IN_OBSTACLE, GOAL_IN_OBSTACLE
    (inside a grown obstacle, or closer than the clearance to a wall or out of the room) or
    NO_PATH."""
    if not is_free(env, start):
        raise PlanningError("START_IN_OBSTACLE", f"({start[0]:.2f}, {start[1]:.2f}) is not free")
    if not is_free(env, goal):
        raise PlanningError("GOAL_IN_OBSTACLE", f"({goal[0]:.2f}, {goal[1]:.2f}) is not free")
    if math.dist(start, goal) <= EPS:
        return [start]
    if segment_is_free(env, start, goal):
        return [start, goal]
    nodes = list(env.nodes) + [start, goal]
    s, g = len(nodes) - 2, len(nodes) - 1
    extra: dict[int, list[tuple[int, float]]] = {s: [], g: []}
    for k, node in enumerate(env.nodes):
        for end in (s, g):
            if segment_is_free(env, nodes[end], node):
                d = math.dist(nodes[end], node)
                extra[end].append((k, d))
                extra.setdefault(k, []).append((end, d))
    best = {s: 0.0}
    previous: dict[int, int] = {}
    queue = [(math.dist(start, goal), 0.0, s)]
    done: set[int] = set()
    while queue:
        _, cost, k = heapq.heappop(queue)
        if k in done:
            continue
        if k == g:
            path = [goal]
            while k != s:
                k = previous[k]
                path.append(nodes[k])
            return path[::-1]
        done.add(k)
        neighbours = (env.graph[k] if k < len(env.nodes) else ()) + tuple(extra.get(k, ()))
        for other, d in neighbours:
            new = cost + d
            if other not in done and new < best.get(other, math.inf) - 1e-12:
                best[other] = new
                previous[other] = k
                heapq.heappush(queue, (new + math.dist(nodes[other], goal), new, other))
    raise PlanningError("NO_PATH", "the goal is not connected to the start in the grown model")


def escape_point(env: Environment, p: Point, max_distance: float = START_ESCAPE) -> Point | None:
    """The nearest free point that a straight move from ``p`` reaches without entering another
    grown piece, if ``p`` is in the room, outside every obstacle, and that point at most
    ``max_distance`` away; ``p`` itself if it is free; None otherwise."""
    if is_free(env, p):
        return p
    x, y = p
    rxmin, rymin, rxmax, rymax = env.room
    if not (rxmin <= x <= rxmax and rymin <= y <= rymax):
        return None
    if any(Polygon(tuple(o)).contains(*p) for o in env.obstacles):
        return None
    xmin, ymin, xmax, ymax = env.bounds

    def clamp(q: Point) -> Point:
        return min(max(q[0], xmin), xmax), min(max(q[1], ymin), ymax)

    candidates = [clamp(p)]
    for piece in env.pieces:
        n = len(piece)
        for k in range(n):
            q = _push_out(piece[k], piece[(k + 1) % n], p)
            candidates += [q, clamp(q), piece[k]]
    inside = frozenset(k for k, planes in enumerate(env._planes) if _strictly_inside(planes, p))
    found = [q for q in candidates if math.dist(p, q) <= max_distance and is_free(env, q)
             and segment_is_free(env, p, q, inside, bounded=False)]
    return min(found, key=lambda q: math.dist(p, q), default=None)


def _push_out(a: Point, b: Point, p: Point) -> Point:
    # The projection of p on edge ab, moved 10 EPS outward (the piece is counter-clockwise).
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = min(1.0, max(0.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2))
    length = math.sqrt(length2)
    return a[0] + t * dx + 10 * EPS * dy / length, a[1] + t * dy - 10 * EPS * dx / length


def path_length(path: Sequence[Point]) -> float:
    return sum(math.dist(path[k], path[k + 1]) for k in range(len(path) - 1))


def auto_bounds(obstacles: Sequence[Sequence[Point]], points: Sequence[Point],
                margin: float = AUTO_MARGIN + CLEARANCE) -> Bounds:
    """autoBox: the bounding box of the model, the start and the goal, plus a margin."""
    xs = [p[0] for o in obstacles for p in o] + [p[0] for p in points]
    ys = [p[1] for o in obstacles for p in o] + [p[1] for p in points]
    return min(xs) - margin, min(ys) - margin, max(xs) + margin, max(ys) + margin


@functools.lru_cache(maxsize=4)
def _environment(obstacles: tuple[tuple[Point, ...], ...], room: Bounds) -> Environment:
    return build_environment(obstacles, room)


# ---------------------------------------------------------------- codels


def setAutoBox(sdi, request):
    """autoBox: choose automatic or manual environment bounds."""
    sdi.autoBox = bool(request.auto)
    return "end"


def checkBox(sdi, request):
    """setPlannerEnv: accept a non-empty bounding box; EXPLOR reads it from the Env poster."""
    b = request.box
    if not all(math.isfinite(v) for v in (b.xmin, b.ymin, b.xmax, b.ymax)) or b.xmin >= b.xmax or b.ymin >= b.ymax:
        return "BAD_BOX"
    sdi.box = b
    sdi.write_poster("Env")
    return "end"


def openModelFile(sdi, request):
    """readModelFile start: check that the obstacle file exists."""
    if not pathlib.Path(request.file).is_file():
        return "FILE_NOT_FOUND"
    sdi.modelFile = request.file
    return "exec"


def readPolygons(sdi, request):
    """readModelFile exec: load the polygonal obstacles ([[obstacles]] polygon = [[x, y], ...]);
    BAD_MODEL (and no model) if one is not a simple polygon or does not fit the SDI."""
    polygons = _read_polygons(sdi.modelFile, len(sdi.obstacles), len(sdi.obstacles[0].x) if sdi.obstacles else 0)
    if polygons is None:
        sdi.modelFile, sdi.nbObstacles = "", 0
        return "BAD_MODEL"
    for slot, polygon in zip(sdi.obstacles, polygons, strict=False):
        slot.n = len(polygon)
        for k, (x, y) in enumerate(polygon):
            slot.x[k], slot.y[k] = x, y
    sdi.nbObstacles = len(polygons)
    return "ether"


def _read_polygons(path: str, max_polygons: int, max_vertices: int) -> list[list[Point]] | None:
    """The world file's obstacles as simple counter-clockwise polygons (circles by their
    outline), or None if the file is unusable or does not fit the SDI."""
    try:
        polygons = load_world(path).polygons()
    except WorldError:
        return None
    if len(polygons) > max_polygons:
        return None
    result = []
    for obstacle in polygons:
        polygon = normalise(obstacle.points)
        if not 3 <= len(polygon) <= max_vertices or not is_simple(polygon):
            return None
        result.append(polygon)
    return result


def startPlan(sdi, request):
    """plan start: full planning, the grown model and its visibility graph are rebuilt."""
    _environment.cache_clear()
    return _start(sdi, request)


def startReplan(sdi, request):
    """replan start: "utilise le même modèle de la planification précédente": the grown model
    and its visibility graph are reused if the obstacles and bounds have not changed."""
    return _start(sdi, request)


def computePlan(sdi, request):
    """plan/replan exec: the shortest collision-free broken line, written into the trajectory
    (emptied on failure, so that PILO never executes a stale one)."""
    t = sdi.traj
    t.nbPoints = 0
    s, g = sdi.start, sdi.goal
    obstacles = tuple(tuple(zip(o.x[: o.n], o.y[: o.n], strict=True)) for o in sdi.obstacles[: sdi.nbObstacles])
    box = sdi.box
    if sdi.autoBox or box.xmin >= box.xmax or box.ymin >= box.ymax:
        room = auto_bounds(obstacles, [(s.x, s.y), (g.x, g.y)])
    else:
        room = (box.xmin, box.ymin, box.xmax, box.ymax)
    env = _environment(obstacles, room)
    start = escape_point(env, (s.x, s.y), START_ESCAPE)
    if start is None:
        return "START_IN_OBSTACLE"
    try:
        path = shortest_path(env, start, (g.x, g.y))
    except PlanningError as error:
        return error.code
    if start != (s.x, s.y):
        path.insert(0, (s.x, s.y))
    if len(path) > min(MAX_POINTS, len(t.x)):
        return "NO_PATH"
    write_broken_line(t, path, TOLERANCE, s.theta)
    return "ether"


def write_broken_line(traj, path: Sequence[Point], tolerance: float, heading: float = 0.0) -> None:
    """Fill a Trajectory record: the points, each with the heading of the segment leaving it
    (the last one keeps the last segment's; a single point keeps ``heading``)."""
    for k, (x, y) in enumerate(path):
        traj.x[k], traj.y[k] = x, y
        if k + 1 < len(path):
            heading = math.atan2(path[k + 1][1] - y, path[k + 1][0] - x)
        traj.theta[k] = heading
    traj.nbPoints = len(path)
    traj.kind = _enum_like(traj.kind, "BROKEN_LINE")
    traj.tolerance = tolerance


def _enum_like(current, name: str):
    """The TrajKind member called ``name`` (the generated enum), or the name itself."""
    return type(current)[name] if isinstance(current, enum.Enum) else name


def abortPlanning(sdi, request):
    """Inter phase of the three exec requests: drop the current computation."""
    return "ether"


def _start(sdi, request):
    if not sdi.modelFile:
        return "NO_MODEL"
    sdi.start, sdi.goal = request.start, request.goal
    return "exec"
