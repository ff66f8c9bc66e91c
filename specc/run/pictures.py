"""Pictures of a run's state (matplotlib's Agg backend: no display needed), drawn from its event
log: a `Scene` that `specc.run.render.scene_of` reads from the events alone.

- `draw_state(ax, scene)`: the state of the system at the end, as the interface of seed 000 §5.6
  shows it (Fig 5.11): the robot, the obstacles, the objects not detected, detected and not yet
  retrieved, and retrieved, the cell of the best observation position, the last planned
  trajectory, and the model's cells by certainty (below 1/3, between 1/3 and 2/3, above 2/3);
- `write_state(scene, path, title)`: that state alone (a run folder's state.png).

It draws scenes and reads no log itself: `specc.run.render` imports it, never the other way round.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from specc.run import RunError
from specc.runtime.sim.render import (
    PATH_COLOUR,
    Scene,
    draw_certainty,
    draw_last_planned,
    draw_objects,
    draw_world,
    pyplot,
)

# Fig 5.11 tells apart the objects not detected, detected and retrieved: one taken was retrieved.
STATE_OF_FIG_5_11 = {"taken": "retrieved", "retrieved": "retrieved", "detected": "detected",
                     "undetected": "undetected"}
STATE_LABELS = {"detected": "detected, not retrieved"}


def write_state(scene: Scene, path: str | Path, title: str) -> Path:
    """The state of Fig 5.11 alone."""
    plt = pyplot()
    figure, ax = plt.subplots(figsize=(8.5, 7.0), dpi=110)
    try:
        draw_state(ax, scene)
        ax.set_title(f"{title}\n{ax.get_title()}", fontsize=9)
        ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.1), ncol=3, fontsize=7, framealpha=0.9)
        return save(figure, path)
    finally:
        plt.close(figure)


def draw_state(ax: Any, scene: Scene) -> None:
    """Fig 5.11: the state of the system at `scene.now`."""
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Rectangle

    if scene.certainty is not None:
        draw_certainty(ax, scene.world, scene.certainty)
    draw_world(ax, scene.world)
    draw_objects(ax, scene.objects, [STATE_OF_FIG_5_11[s] for s in scene.object_states], STATE_LABELS)
    if scene.goal is not None and scene.certainty is not None:
        cell = scene.certainty.cell
        gx, gy = (math.floor(scene.goal[0] / cell) * cell, math.floor(scene.goal[1] / cell) * cell)
        ax.add_patch(Rectangle((gx, gy), cell, cell, fill=False, ec="#dc2626", lw=2.0, zorder=6,
                               label="best observation cell"))
    draw_last_planned(ax, scene, zorder=5)
    if len(scene.path):
        _, x, y, theta = (float(v) for v in scene.path[-1])
        radius = scene.robot.radius
        ax.add_patch(CirclePatch((x, y), radius, fc=PATH_COLOUR, alpha=0.35, ec=PATH_COLOUR, zorder=8, label="robot"))
        ax.plot([x, x + radius * math.cos(theta)], [y, y + radius * math.sin(theta)], color=PATH_COLOUR, lw=1.5,
                zorder=9)
    ax.set_title(f"The state at {scene.now:.0f} s (seed 000 Fig 5.11)", fontsize=10)


def save(figure: Any, path: str | Path) -> Path:
    """Write `figure` as the PNG `path` (RunError when it cannot); returns the path."""
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise RunError(f"{out}: the picture's file name must end in .png")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(out, bbox_inches="tight")
    except OSError as error:
        raise RunError(f"{out}: cannot write the picture ({error.strerror or error})") from None
    return out
