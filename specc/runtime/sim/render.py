"""Pictures of a simulated run, in the spirit of seed 000's interface (§5.6, Fig. 5.11): the
obstacles, the robot's path (true, and as its odometry believed), the planned trajectories,
objects undetected / detected / retrieved / taken, the observation goal, cell certainties in three
colours (below 1/3, between, above 2/3), photo targets and the photos taken, and the antenna's
windows on a time strip.

    draw(sim, "run.png")            # one picture of the whole run
    animate(sim, "run.gif")         # the robot moving along its path

Both draw a `Scene`: what a map shows, whoever recorded it. `Scene.of(sim)` takes it from a live
simulation; `specc.run.render` builds one from a run's event log alone and draws it with the same
pieces (`map_figure`, `draw_scene`), so that a run and its replay look alike.

matplotlib is imported here only, when drawing, so simulating needs no display and no plotting.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from specc.runtime.sim.rover import RobotConfig
from specc.runtime.sim.simulation import Simulation
from specc.runtime.sim.world import Circle, Polygon, Target, Window, World

CERTAINTY_COLOURS = ("#f4f1de", "#f2cc8f", "#81b29a")  # c < 1/3, 1/3 <= c < 2/3, c >= 2/3
CERTAINTY_BANDS = (1 / 3, 2 / 3)  # Fig 5.11's three bands of certainty
CERTAINTY_LABELS = ("c < 1/3", "1/3 <= c < 2/3", "c >= 2/3")
# What became of an object, most advanced first (specc.run.render's LoggedObject.state).
OBJECT_COLOURS = {"taken": "#16a34a", "retrieved": "#f97316", "detected": "#eab308", "undetected": "#9ca3af"}
PATH_COLOUR = "#1d4ed8"
WALL_COLOUR, OBSTACLE_COLOUR, OBSTACLE_EDGE = "#374151", "#6b7280", "#1f2937"
PLANNED_COLOUR = "#7c3aed"
FOCUS_MARGIN = 1.5  # m around what happened, when the walls are far (a large outdoor world)
NEAR_WALLS = 16.0  # m: a world no wider than this is drawn whole
WALL_MARGIN = 0.3  # m outside the walls
LEGEND_GAP = 0.08  # of the figure's width, right of the colour bar: room for its labels


class Certainty(NamedTuple):
    """A model's certainty c in [0, 1] per cell (seed 000 §5.2.4), row-major from (0, 0)."""

    cell: float  # m
    nx: int
    ny: int
    values: Sequence[float]

    def grid(self) -> np.ndarray:
        return np.asarray(self.values, dtype=float).reshape(self.ny, self.nx)


class Shot(NamedTuple):
    """A photo the camera took (ok) or failed to take, where the robot stood."""

    time: float
    target: str
    ok: bool
    x: float
    y: float


class Link(NamedTuple):
    """A communication with the orbiter, from start to end."""

    start: float
    end: float
    ok: bool


class Mark(NamedTuple):
    """Places on the map where something worth a marker happened (blocked, a move interrupted)."""

    label: str
    points: tuple[tuple[float, float], ...]
    marker: str = "X"
    colour: str = "#dc2626"


@dataclass(frozen=True, eq=False)
class Scene:
    """What a map of a run shows. Objects and their states go together, one state per object
    (a key of OBJECT_COLOURS); `taken_order` numbers the objects taken, in the order taken."""

    world: World
    robot: RobotConfig
    path: np.ndarray  # (n, 4): t, true x, y, theta
    estimated: np.ndarray | None = None  # (n, 4): t, x, y, theta as the odometry believed
    objects: tuple[tuple[float, float], ...] = ()
    object_states: tuple[str, ...] = ()
    taken_order: tuple[int, ...] = ()
    targets: tuple[Target, ...] = ()
    shots: tuple[Shot, ...] = ()
    planned: tuple[tuple[tuple[float, float], ...], ...] = ()  # in the order planned
    certainty: Certainty | None = None
    goal: tuple[float, float] | None = None
    marks: tuple[Mark, ...] = ()
    links: tuple[Link, ...] = ()
    now: float = 0.0  # the instant the scene shows
    windows: tuple[Window, ...] = ()  # the antenna's, as they opened (default: the world's)

    def __post_init__(self) -> None:
        if len(self.objects) != len(self.object_states):
            raise ValueError(f"{len(self.objects)} object(s) but {len(self.object_states)} state(s)")
        if not self.windows and self.world.windows:
            object.__setattr__(self, "windows", self.world.windows)

    @classmethod
    def of(cls, sim: Simulation) -> Scene:
        """The scene of a live simulation, as it stands now."""
        trace = sim.trace
        path = np.column_stack([np.asarray(trace.times, dtype=float).reshape(-1), trace.path_array()])
        states = tuple("taken" if k in trace.taken else "detected" if k in trace.detected else "undetected"
                       for k in range(len(sim.objects)))
        shots = tuple(Shot(t, name, ok, *position_at(path, sim.world, t)) for t, name, ok in trace.photos)
        blocked = (Mark("blocked", (position_at(path, sim.world, trace.blocked_at),)),) \
            if trace.blocked_at is not None else ()
        return cls(sim.world, sim.robot, path,
                   estimated=np.asarray(trace.estimated, dtype=float).reshape(-1, 4) if trace.estimated else None,
                   objects=tuple(sim.objects), object_states=states, targets=sim.world.targets, shots=shots,
                   planned=tuple(tuple(p) for p in trace.paths),
                   certainty=Certainty(*trace.certainty) if trace.certainty is not None else None,
                   goal=trace.goal, marks=blocked,
                   links=tuple(Link(start, end, True) for start, end, _ in sim.antenna.sent), now=sim.now)

    @property
    def photographed(self) -> frozenset[str]:
        return frozenset(shot.target for shot in self.shots if shot.ok)


def position_at(path: np.ndarray, world: World, instant: float) -> tuple[float, float]:
    """Where the robot was at `instant` on `path` (t, x, y, theta rows): its last recorded pose
    at or before it (the world's start when nothing was recorded)."""
    if not len(path):
        return world.start[0], world.start[1]
    index = max(0, int(np.searchsorted(path[:, 0], instant, side="right")) - 1)
    return float(path[index, 1]), float(path[index, 2])


# ---------------------------------------------------------------- whole pictures


def draw(sim: Simulation, path: str | Path, *, title: str = "") -> Path:
    """Write a PNG of the run so far and return its path."""
    heading = f" — {sim.robot.name}, seed {sim.seed}, {sim.now:.0f} s"
    plt = pyplot()
    figure = map_figure(Scene.of(sim), (title or sim.world.name) + heading)
    try:
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(out, bbox_inches="tight")
    finally:
        plt.close(figure)
    return out


def map_figure(scene: Scene, title: str) -> Any:
    """A figure of the map of `scene`, with the antenna's windows on a time strip below when there
    are any; the caller saves and closes it."""
    plt = pyplot()
    figure = plt.figure(figsize=(9.0, 8.2 if scene.windows else 7.0), dpi=110)
    if scene.windows:
        grid = figure.add_gridspec(2, 1, height_ratios=(7, 1), hspace=0.25)
        ax = figure.add_subplot(grid[0])
        draw_windows(figure.add_subplot(grid[1]), scene)
    else:
        ax = figure.add_subplot(1, 1, 1)
    draw_scene(ax, scene)
    # Wrapped to the map's own width: a long title (robot, mission, world, outcome) would otherwise
    # run under the colour bar beside it.
    ax.set_title(textwrap.fill(title, MAP_TITLE_WIDTH), fontsize=10)
    legend_beside(figure, ax)
    return figure


MAP_TITLE_WIDTH = 80  # characters of a map title's line at its font size


def animate(sim: Simulation, path: str | Path, *, frames: int = 80, title: str = "") -> Path:
    """Write an animated GIF of the robot moving along its recorded path."""
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter

    scene = Scene.of(sim)
    poses = scene.path
    if not len(poses):
        raise ValueError("nothing to animate: the run recorded no pose")
    fig, ax = plt.subplots(figsize=(6, 6), dpi=80)
    draw_background(ax, scene)
    ax.set_title(title or sim.world.name, fontsize=10)
    (line,) = ax.plot([], [], color=PATH_COLOUR, lw=1.6)
    body = draw_footprint(ax, scene.robot, poses[0, 1:], PATH_COLOUR, fill=True)
    steps = np.linspace(0, len(poses) - 1, min(frames, len(poses))).astype(int)
    stamp = ax.text(0.98, 0.02, "", transform=ax.transAxes, ha="right", fontsize=8)

    def frame(k: int) -> tuple[Any, ...]:
        i = steps[k]
        line.set_data(poses[: i + 1, 1], poses[: i + 1, 2])
        body.set_xy(outline(scene.robot, poses[i, 1:]))
        stamp.set_text(f"t = {poses[i, 0]:.1f} s")
        return line, body, stamp

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    FuncAnimation(fig, frame, frames=len(steps), blit=False).save(out, writer=PillowWriter(fps=12))
    plt.close(fig)
    return out


def legend_beside(figure: Any, ax: Any) -> None:
    """The legend of `ax` to the right of it and of its colour bar."""
    box = ax.get_position()
    right = max(a.get_position().x1 for a in figure.axes if a.get_position().y1 >= box.y0)
    figure.legend(*ax.get_legend_handles_labels(), loc="upper left", bbox_to_anchor=(right + LEGEND_GAP, box.y1),
                  fontsize=7, framealpha=0.9)


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg backend (pictures need no display), text taken as written:
    a why or a goal holding `$RESULT` ... `$R` would otherwise be set as mathematics."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["text.parse_math"] = False
    import matplotlib.pyplot as plt

    return plt


# ---------------------------------------------------------------- pieces


def draw_scene(ax: Any, scene: Scene) -> None:
    """Everything a map shows, on `ax` (the caller places the legend)."""
    draw_background(ax, scene)
    draw_path(ax, scene)
    if scene.estimated is not None and len(scene.estimated):
        ax.plot(scene.estimated[:, 1], scene.estimated[:, 2], color=PATH_COLOUR, lw=1.0, ls=(0, (3, 2)), alpha=0.7,
                label="path (odometry)", zorder=5)
    for ok, label, colour in ((True, "photo taken", "#16a34a"), (False, "photo failed", "#dc2626")):
        chosen = [s for s in scene.shots if s.ok == ok]
        if chosen:
            ax.plot([s.x for s in chosen], [s.y for s in chosen], marker="^", ms=7, ls="", mfc="none", mec=colour,
                    mew=1.5, label=label, zorder=7)
    for mark in scene.marks:
        if mark.points:
            ax.plot([p[0] for p in mark.points], [p[1] for p in mark.points], marker=mark.marker, ms=10, ls="",
                    color=mark.colour, label=mark.label, zorder=8)


def draw_background(ax: Any, scene: Scene) -> None:
    """The world and what the robot knew or aimed at, without the path: the model's certainty,
    the walls and obstacles, the planned trajectories, the objects, the photo targets, the goal."""
    if scene.certainty is not None:
        draw_certainty(ax, scene.world, scene.certainty)
    draw_world(ax, scene.world)
    for k, planned in enumerate(scene.planned[:-1]):
        if len(planned) > 1:
            xs, ys = zip(*planned, strict=True)
            ax.plot(xs, ys, color="#9ca3af", lw=0.8, ls="--", alpha=0.6,
                    label="planned trajectories" if k == 0 else None, zorder=3)
    draw_last_planned(ax, scene, zorder=4)
    draw_objects(ax, scene.objects, scene.object_states)
    for number, index in enumerate(scene.taken_order, 1):
        ax.annotate(str(number), scene.objects[index], textcoords="offset points", xytext=(5, 5), fontsize=8,
                    color="#14532d", zorder=8)
    photographed = scene.photographed
    for target in scene.targets:
        done = target.name in photographed
        ax.plot(target.x, target.y, marker="*", ms=12, ls="", color="#16a34a" if done else PLANNED_COLOUR, zorder=4)
        ax.annotate(target.name, (target.x, target.y), textcoords="offset points", xytext=(5, 5), fontsize=7)
    if any(t.name not in photographed for t in scene.targets):
        ax.plot([], [], marker="*", ls="", color=PLANNED_COLOUR, label="target")
    if any(t.name in photographed for t in scene.targets):
        ax.plot([], [], marker="*", ls="", color="#16a34a", label="target, done (photographed)")
    if scene.goal is not None:
        ax.plot(*scene.goal, marker="s", ms=9, mfc="none", mec="#dc2626", ls="", label="observation goal", zorder=4)
    ax.set_xlim(*focus(scene, 0))
    ax.set_ylim(*focus(scene, 1))


def draw_world(ax: Any, world: World) -> None:
    """The walls and the obstacles, on equal axes in metres."""
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Polygon as PolygonPatch
    from matplotlib.patches import Rectangle

    xmin, xmax, ymin, ymax = world.bounds
    ax.add_patch(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=2.5, ec=WALL_COLOUR, zorder=3))
    for obstacle in world.obstacles:
        if isinstance(obstacle, Polygon):
            ax.add_patch(PolygonPatch(obstacle.points, closed=True, fc=OBSTACLE_COLOUR, ec=OBSTACLE_EDGE, zorder=3))
        elif isinstance(obstacle, Circle):
            ax.add_patch(CirclePatch((obstacle.x, obstacle.y), obstacle.radius, fc=OBSTACLE_COLOUR, ec=OBSTACLE_EDGE,
                                     zorder=3))
    ax.set_aspect("equal")
    ax.set_xlim(xmin - WALL_MARGIN, xmax + WALL_MARGIN)
    ax.set_ylim(ymin - WALL_MARGIN, ymax + WALL_MARGIN)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, lw=0.3, alpha=0.5)


def draw_certainty(ax: Any, world: World, certainty: Certainty) -> None:
    """The model's cells in Fig 5.11's three bands of certainty, inside the walls."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Rectangle

    level = np.digitize(certainty.grid(), CERTAINTY_BANDS)
    c = certainty
    image = ax.imshow(level, origin="lower", extent=(0, c.nx * c.cell, 0, c.ny * c.cell),
                      cmap=ListedColormap(CERTAINTY_COLOURS), vmin=0, vmax=2, interpolation="nearest", zorder=0)
    xmin, xmax, ymin, ymax = world.bounds
    # The model's grid is larger than the room: only its cells inside the walls are shown.
    image.set_clip_path(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, transform=ax.transData))
    for colour, label in zip(CERTAINTY_COLOURS, CERTAINTY_LABELS, strict=True):
        ax.plot([], [], marker="s", ls="", ms=8, color=colour, label=label)


def draw_objects(ax: Any, objects: Sequence[tuple[float, float]], states: Sequence[str],
                 labels: dict[str, str] | None = None) -> None:
    """The objects, coloured by state (hollow: never seen); `labels` renames states in the legend."""
    for state, colour in OBJECT_COLOURS.items():
        chosen = [p for p, s in zip(objects, states, strict=True) if s == state]
        if chosen:
            xs, ys = zip(*chosen, strict=True)
            ax.plot(xs, ys, marker="o", ls="", ms=7, mfc=colour if state != "undetected" else "none", mec=colour,
                    label=f"object {(labels or {}).get(state, state)}", zorder=7)


def draw_last_planned(ax: Any, scene: Scene, zorder: float) -> None:
    """The last trajectory planned, when there is one."""
    if scene.planned and len(scene.planned[-1]) > 1:
        xs, ys = zip(*scene.planned[-1], strict=True)
        ax.plot(xs, ys, color=PLANNED_COLOUR, lw=1.4, ls="--", label="last planned trajectory", zorder=zorder)


def draw_path(ax: Any, scene: Scene) -> None:
    """The true path coloured by time (with its colour bar), the robot where it started (hollow)
    and where it is (filled)."""
    from matplotlib.collections import LineCollection

    path = scene.path
    if len(path) > 1:
        segments = np.stack([path[:-1, 1:3], path[1:, 1:3]], axis=1)
        line = LineCollection(list(segments), cmap="viridis", linewidths=1.6, zorder=5)
        line.set_array(path[:-1, 0])
        ax.add_collection(line)
        ax.figure.colorbar(line, ax=ax, fraction=0.035, pad=0.02, label="time (s)")
        ax.plot([], [], color=PATH_COLOUR, lw=1.6, label="path (true)")
    if len(path):
        draw_footprint(ax, scene.robot, path[0, 1:], PATH_COLOUR, fill=False, label="start")
        draw_footprint(ax, scene.robot, path[-1, 1:], PATH_COLOUR, fill=True, label="end")


def draw_footprint(ax: Any, robot: RobotConfig, pose: np.ndarray | Sequence[float], colour: str, fill: bool,
                   label: str | None = None) -> Any:
    from matplotlib.patches import Polygon as PolygonPatch

    patch = PolygonPatch(outline(robot, pose), closed=True, fc=colour if fill else "none", ec=colour,
                         alpha=0.35 if fill else 0.8, zorder=6, label=label)
    ax.add_patch(patch)
    return patch


def outline(robot: RobotConfig, pose: np.ndarray | Sequence[float]) -> np.ndarray:
    """The robot's footprint with a notch at the front, at `pose` (x, y, theta). The notch is cut
    into the front edge, so that the outline keeps the body's whole extent (its corners are where
    it hits things)."""
    if robot.length > 0:
        hl, hw = robot.length / 2, robot.width / 2
        depth = min(0.3 * hl, 0.5 * hw)
        local = np.array([(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw), (hl, -0.4 * hw), (hl - depth, 0.0),
                          (hl, 0.4 * hw)])
    else:
        angles = np.linspace(0.25, math.tau - 0.25, 24)
        local = np.vstack([[robot.radius, 0.0], np.c_[np.cos(angles), np.sin(angles)] * robot.radius])
    x, y, theta = (float(v) for v in pose)
    c, s = math.cos(theta), math.sin(theta)
    return local @ np.array([[c, s], [-s, c]]) + (x, y)


def focus(scene: Scene, axis: int) -> tuple[float, float]:
    """The walls when they are near; otherwise what happened, with a margin."""
    xmin, xmax, ymin, ymax = scene.world.bounds
    low, high = (xmin, xmax) if axis == 0 else (ymin, ymax)
    if high - low <= NEAR_WALLS:
        return low - WALL_MARGIN, high + WALL_MARGIN
    points = [float(v) for v in scene.path[:, 1 + axis]] + [p[axis] for p in scene.objects]
    points += [(t.x, t.y)[axis] for t in scene.targets] + [scene.world.start[axis]]
    for obstacle in scene.world.obstacles:
        if isinstance(obstacle, Polygon):
            points += [p[axis] for p in obstacle.points]
        else:
            centre = (obstacle.x, obstacle.y)[axis]
            points += [centre - obstacle.radius, centre + obstacle.radius]
    return max(low, min(points) - FOCUS_MARGIN), min(high, max(points) + FOCUS_MARGIN)


def draw_windows(ax: Any, scene: Scene) -> None:
    """The antenna's visibility windows, and below them the communications and photos done."""
    end = max([scene.now] + [w.end for w in scene.windows])
    for w in scene.windows:
        ax.barh(1, w.end - w.start, left=w.start, height=0.6, color="#bfdbfe", ec=PATH_COLOUR)
        ax.text((w.start + w.end) / 2, 1, w.name, ha="center", va="center", fontsize=7)
    for link in scene.links:
        ax.barh(0, link.end - link.start, left=link.start, height=0.6, color="#16a34a" if link.ok else "#dc2626")
    for shot in scene.shots:
        ax.plot(shot.time, 0, marker="*", color="#16a34a" if shot.ok else "#dc2626", ls="")
    ax.axvline(scene.now, color=WALL_COLOUR, lw=0.8)
    ax.set_yticks((0, 1), ("done", "windows"))
    ax.set_xlim(0, end * 1.02)
    ax.set_ylim(-0.6, 1.6)
    ax.set_xlabel("mission time (s)")
