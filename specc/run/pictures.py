"""Pictures of a run (matplotlib's Agg backend: no display needed).

`draw_hunt(result, path)` draws Hilare's hunt side by side:

- the hunt: the room, the obstacles, the cells the camera explored, the robot's true path from
  start to end, the objects (taken, in the order taken; retrieved but not taken; seen; never
  seen) and where the detection of an object interrupted an exploration move (§5.5);
- the state of the system at the end, as the interface of seed 000 §5.6 shows it (Fig 5.11):
  the robot, the obstacles, the objects not detected, detected and not yet retrieved, and
  retrieved, the cell of the best observation position, the last planned trajectory, and the
  model's cells by certainty (below 1/3, between 1/3 and 2/3, above 2/3).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from specc.run import RunError
from specc.runtime.sim import Circle, Polygon
from specc.runtime.sim.render import CERTAINTY_COLOURS

if TYPE_CHECKING:
    from specc.run.hunt import HuntResult

ROBOT_RADIUS = 0.35  # m, Hilare's footprint in the simulator (specc.runtime.sim.HILARE)
OBJECT_COLOURS = {"taken": "#16a34a", "retrieved": "#f97316", "detected": "#eab308", "undetected": "#9ca3af"}
EXPLORED = 1 / 3  # certainty from which a cell counts as explored (Fig 5.11's lowest band ends there)


def draw_hunt(result: HuntResult, path: str | Path, *, title: str = "") -> Path:
    """Write a PNG of the hunt and of its final state (Fig 5.11); returns its path."""
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise RunError(f"{out}: the picture's file name must end in .png")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (hunt, state) = plt.subplots(1, 2, figsize=(15.0, 6.2), dpi=110)
    _draw_hunt_panel(hunt, result)
    _draw_state_panel(state, result)
    headline = title or f"Hilare 2's object hunt, seed {result.seed}"
    figure.suptitle(f"{headline}: {result.outcome}, {result.objects_taken} of {result.objects_wanted} object(s) "
                    f"in {result.simulated_time:.0f} s, {result.distance:.1f} m travelled", fontsize=11)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(out, bbox_inches="tight")
    except OSError as error:
        raise RunError(f"{out}: cannot write the picture ({error.strerror or error})") from None
    finally:
        plt.close(figure)
    return out


def _draw_hunt_panel(ax: Any, result: HuntResult) -> None:
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap

    from specc.run.hunt import detection_interruptions

    if result.certainty is not None:
        explored = (result.certainty.grid() >= EXPLORED).astype(float)
        c = result.certainty
        image = ax.imshow(np.ma.masked_equal(explored, 0.0), origin="lower",
                          extent=(0, c.nx * c.cell, 0, c.ny * c.cell), cmap=ListedColormap(["#dbeafe"]), vmin=0,
                          vmax=1, interpolation="nearest", zorder=0)
        _clip_to_room(ax, image, result)
        ax.plot([], [], marker="s", ls="", ms=8, color="#dbeafe", label=f"explored (c >= {EXPLORED:.2f})")
    _room(ax, result)
    path = np.asarray([p[:3] for p in result.path], dtype=float).reshape(-1, 3)
    if len(path) > 1:
        segments = list(np.stack([path[:-1, 1:3], path[1:, 1:3]], axis=1))
        line = LineCollection(segments, cmap="viridis", linewidths=1.6, zorder=5)
        line.set_array(path[:-1, 0])
        ax.add_collection(line)
        ax.figure.colorbar(line, ax=ax, fraction=0.03, pad=0.01, label="simulated time (s)")
        ax.plot(*path[0, 1:3], marker="o", ms=7, color="#1d4ed8", ls="", label="start", zorder=6)
    taken = sorted((o for o in result.objects if o.taken_at is not None), key=lambda o: o.taken_at or 0.0)
    for state in ("taken", "retrieved", "detected", "undetected"):
        chosen = [o for o in result.objects if o.state == state]
        if chosen:
            ax.plot([o.x for o in chosen], [o.y for o in chosen], marker="o", ls="", ms=8,
                    mfc=OBJECT_COLOURS[state] if state != "undetected" else "none", mec=OBJECT_COLOURS[state],
                    label=f"object {state}", zorder=7)
    for number, obj in enumerate(taken, 1):
        ax.annotate(str(number), (obj.x, obj.y), textcoords="offset points", xytext=(5, 5), fontsize=8,
                    color="#14532d", zorder=8)
    stops = [_pose_at(result, i.interrupted_at) for i in detection_interruptions(result.events).interruptions]
    if stops:
        ax.plot([p[0] for p in stops], [p[1] for p in stops], marker="X", ms=9, ls="", color="#dc2626",
                label="exploration move interrupted", zorder=8)
    ax.set_title("The hunt: path, objects, explored cells", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=3, fontsize=7, framealpha=0.9)


def _draw_state_panel(ax: Any, result: HuntResult) -> None:
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Rectangle

    if result.certainty is not None:
        c = result.certainty
        level = np.digitize(c.grid(), (1 / 3, 2 / 3))
        image = ax.imshow(level, origin="lower", extent=(0, c.nx * c.cell, 0, c.ny * c.cell),
                          cmap=ListedColormap(CERTAINTY_COLOURS), vmin=0, vmax=2, interpolation="nearest", zorder=0)
        _clip_to_room(ax, image, result)
        for colour, label in zip(CERTAINTY_COLOURS, ("c < 1/3", "1/3 <= c < 2/3", "c >= 2/3"), strict=True):
            ax.plot([], [], marker="s", ls="", ms=8, color=colour, label=label)
    _room(ax, result)
    states = {"undetected": "undetected", "detected": "detected, not retrieved", "retrieved": "retrieved"}
    for state, label in states.items():
        chosen = [o for o in result.objects if (o.state if o.state != "taken" else "retrieved") == state]
        if chosen:
            ax.plot([o.x for o in chosen], [o.y for o in chosen], marker="o", ls="", ms=8,
                    mfc=OBJECT_COLOURS[state] if state != "undetected" else "none", mec=OBJECT_COLOURS[state],
                    label=f"object {label}", zorder=7)
    if result.goal is not None and result.certainty is not None:
        cell = result.certainty.cell
        gx, gy = (math.floor(result.goal[0] / cell) * cell, math.floor(result.goal[1] / cell) * cell)
        ax.add_patch(Rectangle((gx, gy), cell, cell, fill=False, ec="#dc2626", lw=2.0, zorder=6,
                               label="best observation cell"))
    if result.planned:
        last = result.planned[-1]
        if len(last.points) > 1:
            xs, ys = zip(*last.points, strict=True)
            ax.plot(xs, ys, color="#7c3aed", lw=1.4, ls="--", label=f"last planned trajectory ({last.service})",
                    zorder=5)
    if result.path:
        _, x, y, theta = result.path[-1]
        ax.add_patch(CirclePatch((x, y), ROBOT_RADIUS, fc="#1d4ed8", alpha=0.35, ec="#1d4ed8", zorder=8,
                                 label="robot"))
        ax.plot([x, x + ROBOT_RADIUS * math.cos(theta)], [y, y + ROBOT_RADIUS * math.sin(theta)], color="#1d4ed8",
                lw=1.5, zorder=9)
    ax.set_title(f"The state at {result.simulated_time:.0f} s (seed 000 Fig 5.11)", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=3, fontsize=7, framealpha=0.9)


def _clip_to_room(ax: Any, image: Any, result: HuntResult) -> None:
    """VISUAL's grid is larger than the room: show only its cells inside the walls."""
    from matplotlib.patches import Rectangle

    xmin, xmax, ymin, ymax = result.world.bounds
    image.set_clip_path(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, transform=ax.transData))


def _room(ax: Any, result: HuntResult) -> None:
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Polygon as PolygonPatch
    from matplotlib.patches import Rectangle

    world = result.world
    xmin, xmax, ymin, ymax = world.bounds
    ax.add_patch(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=2.5, ec="#374151", zorder=3))
    for obstacle in world.obstacles:
        if isinstance(obstacle, Polygon):
            ax.add_patch(PolygonPatch(obstacle.points, closed=True, fc="#6b7280", ec="#1f2937", zorder=3))
        elif isinstance(obstacle, Circle):
            ax.add_patch(CirclePatch((obstacle.x, obstacle.y), obstacle.radius, fc="#6b7280", ec="#1f2937", zorder=3))
    ax.set_aspect("equal")
    ax.set_xlim(xmin - 0.3, xmax + 0.3)
    ax.set_ylim(ymin - 0.3, ymax + 0.3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, lw=0.3, alpha=0.5)


def _pose_at(result: HuntResult, instant: float) -> tuple[float, float]:
    """The robot's recorded position nearest to `instant` at or before it."""
    times = [p[0] for p in result.path]
    index = max(0, int(np.searchsorted(times, instant, side="right")) - 1)
    return result.path[index][1], result.path[index][2]
