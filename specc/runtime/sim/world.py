"""World files: the static obstacles, objects, photo targets and visibility windows a simulated
robot lives among (seed 000 §5.6, seed 004 §4.1.2.1), read from TOML.

```toml
[world]                      # optional
name = "W2"
description = "a few cylinders"
[room]                       # walls around [0, width] x [0, height] ...
width = 12.0
height = 9.0
[bounds]                     # ... or around [xmin, xmax] x [ymin, ymax]
xmin = -20.0                 # (seed 004, note 3: far walls at 20 m keep the laser fed)
xmax = 20.0
ymin = -20.0
ymax = 20.0
[start]                      # the robot's pose at t = 0 (default: the middle of the walls, heading 0)
x = 0.0
y = 0.0
theta = 0.0
[[obstacles]]
polygon = [[3.0, 2.0], [4.6, 2.0], [4.6, 2.8], [3.0, 2.8]]   # counter-clockwise corners
[[obstacles]]
circle = [2.0, 1.5, 0.3]     # centre x, centre y, radius
[objects]                    # objects for the camera to find, placed at random (seeded) ...
count = 10
[[objects.at]]               # ... or where they are
x = 1.0
y = 2.0
[[targets]]                  # photo targets
name = "OBJ1"
x = -5.0
y = 5.0
[[windows]]                  # the antenna's visibility windows, in mission seconds
name = "W1"
start = 60.0
end = 90.0
```

Units are metres, radians and seconds. Every mistake of a file is reported in one `WorldError`
(a line each) naming the file, the entry and what to write instead.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, overload


class WorldError(ValueError):
    """A world file that cannot be used, with where and why: every problem found in it, one per
    line (`problems`), so that a file is fixed in one go."""

    def __init__(self, *problems: str) -> None:
        super().__init__("\n".join(problems))
        self.problems = problems


@dataclass(frozen=True)
class Polygon:
    """An obstacle whose outline is a polygon."""

    points: tuple[tuple[float, float], ...]  # counter-clockwise

    def edges(self) -> list[tuple[float, float, float, float]]:
        n = len(self.points)
        return [(*self.points[k], *self.points[(k + 1) % n]) for k in range(n)]

    def contains(self, x: float, y: float) -> bool:
        inside = False
        n = len(self.points)
        for k in range(n):
            (x1, y1), (x2, y2) = self.points[k], self.points[(k + 1) % n]
            if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
                inside = not inside
        return inside

    def distance(self, x: float, y: float) -> float:
        """0 inside, else the distance to the nearest edge."""
        if self.contains(x, y):
            return 0.0
        return min(_segment_distance(x, y, *edge) for edge in self.edges())


@dataclass(frozen=True)
class Circle:
    """A round obstacle."""

    x: float
    y: float
    radius: float

    def contains(self, x: float, y: float) -> bool:
        return math.hypot(x - self.x, y - self.y) <= self.radius

    def distance(self, x: float, y: float) -> float:
        return max(0.0, math.hypot(x - self.x, y - self.y) - self.radius)

    def outline(self, sides: int = 12) -> Polygon:
        """The circumscribed regular polygon: covers the disc, for polygon-only algorithms."""
        reach = self.radius / math.cos(math.pi / sides)
        return Polygon(tuple((self.x + reach * math.cos(math.tau * k / sides),
                              self.y + reach * math.sin(math.tau * k / sides)) for k in range(sides)))


Obstacle = Polygon | Circle


@dataclass(frozen=True)
class _Box:
    """A body's box footprint at a pose: centre, heading, half-length and half-width."""

    x: float
    y: float
    theta: float
    half_length: float
    half_width: float

    @property
    def corners(self) -> list[tuple[float, float]]:
        cos, sin = math.cos(self.theta), math.sin(self.theta)
        return [(self.x + u * cos - v * sin, self.y + u * sin + v * cos)
                for u, v in ((self.half_length, self.half_width), (-self.half_length, self.half_width),
                             (-self.half_length, -self.half_width), (self.half_length, -self.half_width))]

    def distance(self, x: float, y: float) -> float:
        """0 inside, else the distance from (x, y) to the box."""
        cos, sin = math.cos(self.theta), math.sin(self.theta)
        u, v = (x - self.x) * cos + (y - self.y) * sin, -(x - self.x) * sin + (y - self.y) * cos
        return math.hypot(max(abs(u) - self.half_length, 0.0), max(abs(v) - self.half_width, 0.0))

    def meets(self, polygon: Polygon) -> bool:
        """Do the box and the polygon overlap: a corner of one inside the other, or edges that cross
        (a thin wall across the box has neither corner inside)?"""
        corners = self.corners
        if any(polygon.contains(cx, cy) for cx, cy in corners) or any(self.distance(px, py) == 0
                                                                      for px, py in polygon.points):
            return True
        sides = list(zip(corners, corners[1:] + corners[:1], strict=True))
        edges = [((ax, ay), (bx, by)) for ax, ay, bx, by in polygon.edges()]
        return any(_segments_cross(a, b, c, d) for a, b in sides for c, d in edges)


@dataclass(frozen=True)
class Target:
    """A named place of the world (a photo's object, a station)."""

    name: str
    x: float
    y: float


@dataclass(frozen=True)
class Window:
    """A named period of the mission (a communication window)."""

    name: str
    start: float
    end: float


@dataclass(frozen=True)
class World:
    """A simulated world: its walls, obstacles, targets and windows (a world file)."""

    name: str
    bounds: tuple[float, float, float, float]  # xmin, xmax, ymin, ymax: walls all around
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    obstacles: tuple[Obstacle, ...] = ()
    objects: tuple[tuple[float, float], ...] = ()  # where they are (fixed in the file)
    random_objects: int = 0  # how many more to scatter in free space (seeded)
    targets: tuple[Target, ...] = ()
    windows: tuple[Window, ...] = ()
    description: str = ""
    source: str = field(default="", compare=False)

    def clearance(self, x: float, y: float) -> float:
        """Distance from (x, y) to the nearest obstacle or wall (0 inside one)."""
        xmin, xmax, ymin, ymax = self.bounds
        walls = min(x - xmin, xmax - x, y - ymin, ymax - y)
        if walls <= 0:
            return 0.0
        return min([walls] + [o.distance(x, y) for o in self.obstacles])

    def footprint_clearance(self, pose: tuple[float, float, float], radius: float, length: float = 0.0,
                            width: float = 0.0) -> float:
        """How far a body at `pose` stands from the nearest obstacle or wall (0 or less: they
        overlap): a disc of `radius`, or a `length` x `width` box turned by the pose's heading."""
        return min(distance for distance, _ in self._clearances(pose, radius, length, width))

    def _clearances(self, pose: tuple[float, float, float], radius: float, length: float,
                    width: float) -> Iterator[tuple[float, str]]:
        """How far the body stands from the walls, then from each obstacle, with what it is."""
        x, y, theta = pose
        xmin, xmax, ymin, ymax = self.bounds
        if length <= 0:
            yield min(x - xmin, xmax - x, y - ymin, ymax - y) - radius, "the walls"
            for k, obstacle in enumerate(self.obstacles):
                yield obstacle.distance(x, y) - radius, f"obstacles[{k}]"
            return
        box = _Box(x, y, theta, length / 2, width / 2)
        # A box is convex: its corners come nearest the walls.
        yield min(min(cx - xmin, xmax - cx, cy - ymin, ymax - cy) for cx, cy in box.corners), "the walls"
        for k, obstacle in enumerate(self.obstacles):
            if isinstance(obstacle, Circle):
                yield box.distance(obstacle.x, obstacle.y) - obstacle.radius, f"obstacles[{k}]"
            elif box.meets(obstacle):
                yield 0.0, f"obstacles[{k}]"
            else:
                yield min(*(obstacle.distance(cx, cy) for cx, cy in box.corners),
                          *(box.distance(px, py) for px, py in obstacle.points)), f"obstacles[{k}]"

    def start_overlap(self, radius: float, length: float = 0.0, width: float = 0.0) -> str | None:
        """Why a body (a disc of `radius`, or a `length` x `width` box) cannot start at the world's
        start: it overlaps obstacles or the walls, named (the physics would shove it out at once, or
        wedge it); None when it stands clear."""
        overlapped = [part for distance, part in self._clearances(self.start, radius, length, width) if distance <= 0]
        if not overlapped:
            return None
        x, y, theta = self.start
        shape = f"its {length:g} x {width:g} m box" if length > 0 else f"its {radius:g} m radius"
        return (f"the robot's body ({shape}) at its start ({x:g}, {y:g}, heading {theta:g} rad) overlaps "
                f"{', '.join(overlapped)}: move [start] in the world file, or the obstacle")

    def segments(self) -> list[tuple[float, float, float, float]]:
        """Every straight edge: the polygons' and the four walls'."""
        xmin, xmax, ymin, ymax = self.bounds
        walls = [(xmin, ymin, xmax, ymin), (xmax, ymin, xmax, ymax), (xmax, ymax, xmin, ymax),
                 (xmin, ymax, xmin, ymin)]
        return walls + [e for o in self.obstacles if isinstance(o, Polygon) for e in o.edges()]

    def circles(self) -> list[tuple[float, float, float]]:
        return [(o.x, o.y, o.radius) for o in self.obstacles if isinstance(o, Circle)]

    def polygons(self) -> list[Polygon]:
        """Every obstacle as a polygon (circles by their circumscribed outline)."""
        return [o if isinstance(o, Polygon) else o.outline() for o in self.obstacles]


MAX_EXTENT = 100_000.0  # m from the origin a world's walls may reach


def load_world(path: str | Path) -> World:
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as error:
        raise WorldError(f"{path}: cannot read the world file ({error.strerror or error})") from None
    except UnicodeDecodeError:
        raise WorldError(f"{path}: not a text file (a world file is TOML)") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise WorldError(f"{path}: not valid TOML: {error}") from None
    return parse_world(data, str(path), default_name=path.stem)


def parse_world(data: Mapping[str, Any], source: str = "<world>", default_name: str = "world") -> World:
    """The world `data` (a world file's TOML) describes; a WorldError listing every problem found."""
    where = _Where(source)
    known = {"world", "room", "bounds", "start", "obstacles", "objects", "targets", "windows"}
    for key in data:
        if key not in known:
            where.problem(f"unknown section [{key}] (known: {', '.join(sorted(known))})")
    header = where.table(data, "world", ("name", "description")) or {}
    name = where.text(header, "name", "world", default_name)
    description = where.text(header, "description", "world", "")
    bounds: tuple[float, float, float, float] | None = None
    if "room" in data and "bounds" in data:
        where.problem("give [room] or [bounds], not both")
    elif "room" in data:
        room = where.table(data, "room", ("width", "height"))
        width, height = (where.number(room, "width", "room", None), where.number(room, "height", "room", None)) \
            if room is not None else (None, None)
        if width is not None and height is not None:
            if width <= 0 or height <= 0:
                where.problem("[room] width and height must be positive")
            else:
                bounds = (0.0, width, 0.0, height)
    elif "bounds" in data:
        corners = ("xmin", "xmax", "ymin", "ymax")
        box = where.table(data, "bounds", corners)
        given = [where.number(box, k, "bounds", None) for k in corners] if box is not None else [None]
        if all(b is not None for b in given):
            xmin, xmax, ymin, ymax = (float(b) for b in given if b is not None)
            if not (xmin < xmax and ymin < ymax):
                where.problem("[bounds] needs xmin < xmax and ymin < ymax")
            else:
                bounds = (xmin, xmax, ymin, ymax)
    else:
        where.problem("the world needs walls: a [room] (width, height) or [bounds] (xmin, xmax, ymin, ymax)")
    if bounds is not None and max(abs(b) for b in bounds) > MAX_EXTENT:
        where.problem(f"the walls reach {max(abs(b) for b in bounds):g} m from the origin: at most {MAX_EXTENT:g} m "
                      "(the physics and the pictures lose precision beyond)")
        bounds = None
    said = len(where.problems)
    start_table = where.table(data, "start", ("x", "y", "theta")) or {}
    # Without [start], the middle of the walls: (0, 0) is a corner of every [room], on its walls.
    middle = ((bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2) if bounds is not None else (0.0, 0.0)
    start = (where.number(start_table, "x", "start", middle[0]), where.number(start_table, "y", "start", middle[1]),
             where.number(start_table, "theta", "start", 0.0))
    # A [start] already found wrong (`xx = 1.5`) is not placed again from its defaults: one error.
    start_read = len(where.problems) == said
    obstacles: list[Obstacle] = []
    labels: list[str] = []  # each obstacle's place in the file, for what is said of it
    for k, entry in enumerate(where.array(data, "obstacles", ("polygon", "circle"))):
        obstacle = _obstacle(where, f"obstacles[{k}]", entry)
        if obstacle is not None:
            obstacles.append(obstacle)
            labels.append(f"obstacles[{k}]")
    objects_table = where.table(data, "objects", ("count", "at")) or {}
    count = where.number(objects_table, "count", "objects", 0.0)
    if count < 0 or count != int(count):
        where.problem("[objects] count must be a whole number >= 0")
        count = 0.0
    placed = tuple((where.number(o, "x", f"objects.at[{k}]", None), where.number(o, "y", f"objects.at[{k}]", None))
                   for k, o in enumerate(where.array(objects_table, "at", ("x", "y"), "objects.at")))
    targets = tuple((where.text(t, "name", f"targets[{k}]", f"T{k + 1}"), where.number(t, "x", f"targets[{k}]", None),
                     where.number(t, "y", f"targets[{k}]", None))
                    for k, t in enumerate(where.array(data, "targets", ("name", "x", "y"))))
    windows = []
    for k, w in enumerate(where.array(data, "windows", ("name", "start", "end"))):
        label = f"windows[{k}]"
        opens, closes = where.number(w, "start", label, None), where.number(w, "end", label, None)
        if opens is not None and closes is not None:
            if not 0 <= opens < closes:
                where.problem(f"{label}: needs 0 <= start < end")
            windows.append(Window(where.text(w, "name", label, f"W{k + 1}"), opens, closes))
    # Codels and missions find a target or a window by its name: a second one of a name is never
    # found, and which one a lookup meets depends on the file's order.
    for kind, names in (("targets", [n for n, _, _ in targets]), ("windows", [w.name for w in windows])):
        for k, repeated in enumerate(names):
            if repeated in names[:k]:
                where.problem(f"{kind}[{k}]: a second one named '{repeated}' ({kind}[{names.index(repeated)}] is the "
                              "first): give each its own name")
    if bounds is None:  # nothing can be placed without walls
        raise WorldError(*where.problems)
    # Built from what could be read, so that what stands in the way is said with the rest.
    world = World(name, bounds, start, tuple(obstacles), tuple((x, y) for x, y in placed if x is not None
                                                               and y is not None),
                  int(count), tuple(Target(n, x, y) for n, x, y in targets if x is not None and y is not None),
                  tuple(windows), description, source)
    # Targets too: a station a robot is sent to inside a crate or past a wall fails its every
    # mission, far from the line that put it there.
    spots = ([("start", start[:2])] if start_read else []) + [
        (f"objects.at[{k}]", (x, y)) for k, (x, y) in enumerate(placed)] + [
        (f"targets[{k}] ({n})", (x, y)) for k, (n, x, y) in enumerate(targets)]
    xmin, xmax, ymin, ymax = bounds
    for label, (x, y) in spots:
        if x is None or y is None or world.clearance(x, y) > 0:
            continue
        if not (xmin < x < xmax and ymin < y < ymax):
            where.problem(f"{label} ({x:g}, {y:g}) is outside the walls (x strictly between {xmin:g} and "
                          f"{xmax:g}, y between {ymin:g} and {ymax:g})")
        else:
            inside = [name for name, o in zip(labels, obstacles, strict=True) if o.distance(x, y) <= 0]
            where.problem(f"{label} ({x:g}, {y:g}) is inside {', '.join(inside) or 'an obstacle'}")
    # An obstacle wholly past the walls is never met, and the map leaves it out: a typo.
    for name, obstacle in zip(labels, obstacles, strict=True):
        xs, ys = ((obstacle.x - obstacle.radius, obstacle.x + obstacle.radius),
                  (obstacle.y - obstacle.radius, obstacle.y + obstacle.radius)) if isinstance(obstacle, Circle) else (
            tuple(p[0] for p in obstacle.points), tuple(p[1] for p in obstacle.points))
        if max(xs) <= xmin or min(xs) >= xmax or max(ys) <= ymin or min(ys) >= ymax:
            where.problem(f"{name} lies wholly outside the walls (x in [{xmin:g}, {xmax:g}], "
                          f"y in [{ymin:g}, {ymax:g}]): it is never met; move it inside or remove it")
    if where.problems:
        raise WorldError(*where.problems)
    return world


def _obstacle(where: _Where, label: str, entry: Mapping[str, Any]) -> Obstacle | None:
    """One `[[obstacles]]` entry, or None (the problem recorded)."""
    if "polygon" in entry and "circle" not in entry:
        points = entry["polygon"]
        if not isinstance(points, list) or len(points) < 3 or not all(
                isinstance(p, list) and len(p) == 2 and all(_finite(c) for c in p) for p in points):
            where.problem(f"{label}: polygon must list at least 3 [x, y] corners (finite numbers)")
            return None
        polygon = tuple((float(x), float(y)) for x, y in points)
        crossing = self_crossing(polygon)
        if crossing is not None:
            where.problem(f"{label}: the polygon crosses itself (its edges from corner {crossing[0]} and from corner "
                          f"{crossing[1]}, counted from 0): list its corners in order around it")
            return None
        area = signed_area(polygon)
        if abs(area) < 1e-9:
            where.problem(f"{label}: the polygon has no area")
            return None
        return Polygon(polygon[::-1] if area < 0 else polygon)  # the simulator wants counter-clockwise corners
    if "circle" in entry and "polygon" not in entry:
        c = entry["circle"]
        if not (isinstance(c, list) and len(c) == 3 and all(_finite(v) for v in c) and c[2] > 0):
            where.problem(f"{label}: circle must be [x, y, radius] (finite numbers) with radius > 0")
            return None
        return Circle(float(c[0]), float(c[1]), float(c[2]))
    where.problem(f"{label}: give either polygon = [[x, y], ...] or circle = [x, y, r]")
    return None


def world_data(world: World) -> dict[str, Any]:
    """The world as `parse_world` reads it (TOML's tables as dicts), so a run's log can carry
    its world and be redrawn without the file: parse_world(world_data(w)) == w."""
    xmin, xmax, ymin, ymax = world.bounds
    return {
        "world": {"name": world.name, "description": world.description},
        "bounds": {"xmin": xmin, "xmax": xmax, "ymin": ymin, "ymax": ymax},
        "start": dict(zip(("x", "y", "theta"), world.start, strict=True)),
        "obstacles": [{"polygon": [list(p) for p in o.points]} if isinstance(o, Polygon)
                      else {"circle": [o.x, o.y, o.radius]} for o in world.obstacles],
        "objects": {"count": world.random_objects, "at": [{"x": x, "y": y} for x, y in world.objects]},
        "targets": [{"name": t.name, "x": t.x, "y": t.y} for t in world.targets],
        "windows": [{"name": w.name, "start": w.start, "end": w.end} for w in world.windows],
    }


class _Where:
    """Reads a world file's tables, recording each problem (`problems`) and going on with a
    stand-in value, so that one reading finds them all."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.problems: list[str] = []

    def problem(self, message: str) -> None:
        self.problems.append(f"{self.source}: {message}")

    def only(self, table: Mapping[str, Any], label: str, known: tuple[str, ...]) -> None:
        """A misspelt key would otherwise be ignored silently (`thetaa` leaving theta at 0)."""
        for key in table:
            if key not in known:
                self.problem(f"{label}: unknown key '{key}' (known: {', '.join(known)})")

    def table(self, data: Mapping[str, Any], key: str, known: tuple[str, ...]) -> Mapping[str, Any] | None:
        """The table `[key]` (empty when absent); None when it is something else (said once: what
        its keys would be missing is not said again)."""
        value = data.get(key, {})
        if not isinstance(value, dict):
            self.problem(f"[{key}] must be a table")
            return None
        self.only(value, f"[{key}]", known)
        return value

    def array(self, data: Mapping[str, Any], key: str, known: tuple[str, ...],
              label: str = "") -> list[Mapping[str, Any]]:
        label = label or key
        value = data.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            self.problem(f"{label} must be an array of tables ([[{label}]])")
            return []
        for k, entry in enumerate(value):
            self.only(entry, f"{label}[{k}]", known)
        return value

    @overload
    def number(self, table: Mapping[str, Any], key: str, label: str, default: float) -> float: ...

    @overload
    def number(self, table: Mapping[str, Any], key: str, label: str, default: None) -> float | None: ...

    def number(self, table: Mapping[str, Any], key: str, label: str, default: float | None) -> float | None:
        """The number at `key`; `default` when absent (None: it must be given) or malformed."""
        if key not in table:
            if default is None:
                self.problem(f"{label}: missing '{key}' (a number)")
            return default
        value = table[key]
        if not _finite(value):
            self.problem(f"{label}: '{key}' must be a finite number, not {value!r}")
            return default
        return float(value)

    def text(self, table: Mapping[str, Any], key: str, label: str, default: str) -> str:
        value = table.get(key, default)
        if not isinstance(value, str):
            self.problem(f"{label}: '{key}' must be a string")
            return default
        return value


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def self_crossing(points: Sequence[tuple[float, float]]) -> tuple[int, int] | None:
    """Two edges of the polygon that cross (by the corners they start from), else None: a bow
    tie is no obstacle the simulator can hold (its inside is not what was meant)."""
    n = len(points)
    for i in range(n):
        a, b = points[i], points[(i + 1) % n]
        for j in range(i + 2, n):
            if (j + 1) % n == i:
                continue  # the edge before the first one: they share a corner
            if _segments_cross(a, b, points[j], points[(j + 1) % n]):
                return i, j
    return None


def _segments_cross(a: tuple[float, float], b: tuple[float, float], c: tuple[float, float],
                    d: tuple[float, float]) -> bool:
    """Do the segments ab and cd cross (each one's ends strictly on both sides of the other)?"""
    def side(p: tuple[float, float], q: tuple[float, float], r: tuple[float, float]) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return side(a, b, c) * side(a, b, d) < 0 and side(c, d, a) * side(c, d, b) < 0


def signed_area(points: Sequence[tuple[float, float]]) -> float:
    """Positive for counter-clockwise corners."""
    n = len(points)
    return 0.5 * sum(points[k][0] * points[(k + 1) % n][1] - points[(k + 1) % n][0] * points[k][1]
                     for k in range(n))


def _segment_distance(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    ex, ey = bx - ax, by - ay
    length2 = ex * ex + ey * ey
    u = 0.0 if length2 == 0 else max(0.0, min(1.0, ((px - ax) * ex + (py - ay) * ey) / length2))
    return math.hypot(px - ax - u * ex, py - ay - u * ey)
