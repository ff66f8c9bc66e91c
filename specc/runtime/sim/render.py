"""Pictures of a simulated run, in the spirit of seed 000's interface (§5.6, Fig. 5.11): the
obstacles, the robot's path (true, and as its odometry believed), the last planned trajectories,
objects undetected / detected / taken, the observation goal, cell certainties in three colours
(below 1/3, between, above 2/3), photo targets, and the antenna's windows on a time strip.

    draw(sim, "run.png")            # one picture of the whole run
    animate(sim, "run.gif")         # the robot moving along its path

matplotlib is imported here only, so simulating needs no display and no plotting.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from specc.runtime.sim.simulation import Simulation
from specc.runtime.sim.world import Circle, Polygon

CERTAINTY_COLOURS = ("#f4f1de", "#f2cc8f", "#81b29a")  # c < 1/3, 1/3 <= c < 2/3, c >= 2/3
FOCUS_MARGIN = 1.5  # m around what happened, when the walls are far (the ATRV's worlds)


def draw(sim: Simulation, path: str | Path, *, title: str = "") -> Path:
    """Write a PNG of the run so far and return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    windows = bool(sim.world.windows)
    fig = plt.figure(figsize=(9.0, 8.2 if windows else 7.0), dpi=110)
    if windows:
        grid = fig.add_gridspec(2, 1, height_ratios=(7, 1), hspace=0.25)
        ax = fig.add_subplot(grid[0])
        strip = fig.add_subplot(grid[1])
    else:
        ax = fig.add_subplot(1, 1, 1)
        strip = None
    _scene(ax, sim)
    poses = sim.trace.path_array()
    if len(poses):
        ax.plot(poses[:, 0], poses[:, 1], color="#1d4ed8", lw=1.6, label="path (true)", zorder=5)
        _footprint(ax, sim, poses[0], "#1d4ed8", fill=False)
        _footprint(ax, sim, poses[-1], "#1d4ed8", fill=True)
    if sim.trace.estimated:
        estimated = np.asarray(sim.trace.estimated)
        ax.plot(estimated[:, 1], estimated[:, 2], color="#1d4ed8", lw=1.0, ls=(0, (3, 2)), alpha=0.7,
                label="path (odometry)", zorder=5)
    if sim.trace.blocked_at is not None and len(poses):
        index = min(len(poses) - 1, int(np.searchsorted(sim.trace.times, sim.trace.blocked_at)))
        ax.plot(*poses[index, :2], marker="X", ms=13, color="#dc2626", ls="", label="blocked", zorder=7)
    heading = f" — {sim.robot.name}, seed {sim.seed}, {sim.now:.0f} s"
    ax.set_title((title or sim.world.name) + heading, fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, framealpha=0.9)
    if strip is not None:
        _windows(strip, sim)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, bbox_inches="tight")
    plt.close(fig)
    return out


def animate(sim: Simulation, path: str | Path, *, frames: int = 80, title: str = "") -> Path:
    """Write an animated GIF of the robot moving along its recorded path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter

    poses = sim.trace.path_array()
    if not len(poses):
        raise ValueError("nothing to animate: the run recorded no pose")
    fig, ax = plt.subplots(figsize=(6, 6), dpi=80)
    _scene(ax, sim)
    ax.set_title(title or sim.world.name, fontsize=10)
    (line,) = ax.plot([], [], color="#1d4ed8", lw=1.6)
    body = _footprint(ax, sim, poses[0], "#1d4ed8", fill=True)
    steps = np.linspace(0, len(poses) - 1, min(frames, len(poses))).astype(int)
    stamp = ax.text(0.98, 0.02, "", transform=ax.transAxes, ha="right", fontsize=8)

    def frame(k: int) -> tuple[Any, ...]:
        i = steps[k]
        line.set_data(poses[: i + 1, 0], poses[: i + 1, 1])
        _move(body, sim, poses[i])
        stamp.set_text(f"t = {sim.trace.times[i]:.1f} s")
        return line, body, stamp

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    FuncAnimation(fig, frame, frames=len(steps), blit=False).save(out, writer=PillowWriter(fps=12))
    plt.close(fig)
    return out


# ---------------------------------------------------------------- pieces


def _scene(ax: Any, sim: Simulation) -> None:
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Polygon as PolygonPatch
    from matplotlib.patches import Rectangle

    world, trace = sim.world, sim.trace
    if trace.certainty is not None:
        cell, nx, ny, values = trace.certainty
        c = np.asarray(values, dtype=float).reshape(ny, nx)
        level = np.digitize(c, (1 / 3, 2 / 3))
        from matplotlib.colors import ListedColormap

        image = ax.imshow(level, origin="lower", extent=(0, nx * cell, 0, ny * cell),
                          cmap=ListedColormap(CERTAINTY_COLOURS), vmin=0, vmax=2, interpolation="nearest", zorder=0)
        xmin, xmax, ymin, ymax = world.bounds
        inside = Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, transform=ax.transData)
        image.set_clip_path(inside)  # the model's grid is larger than the room
        for k, colour in enumerate(CERTAINTY_COLOURS):
            ax.add_patch(Rectangle((0, 0), 0, 0, color=colour, label=("c < 1/3", "1/3 <= c < 2/3", "c >= 2/3")[k]))
    xmin, xmax, ymin, ymax = world.bounds
    ax.add_patch(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=2.5, ec="#374151"))
    for obstacle in world.obstacles:
        if isinstance(obstacle, Polygon):
            ax.add_patch(PolygonPatch(obstacle.points, closed=True, fc="#6b7280", ec="#1f2937", zorder=2))
        elif isinstance(obstacle, Circle):
            ax.add_patch(CirclePatch((obstacle.x, obstacle.y), obstacle.radius, fc="#6b7280", ec="#1f2937", zorder=2))
    for k, planned in enumerate(trace.paths[-3:]):
        if len(planned) > 1:
            xs, ys = zip(*planned, strict=True)
            ax.plot(xs, ys, color="#9ca3af", lw=1.0, ls="--", label="planned" if k == 0 else None, zorder=3)
    states = [("taken", "#16a34a", "o"), ("detected", "#f59e0b", "o"), ("undetected", "#9ca3af", "o")]
    for name, colour, marker in states:
        chosen = [p for i, p in enumerate(sim.objects) if _object_state(trace, i) == name]
        if chosen:
            xs, ys = zip(*chosen, strict=True)
            ax.plot(xs, ys, marker=marker, ls="", ms=6, mfc=colour if name != "undetected" else "none",
                    mec=colour, label=f"object {name}", zorder=4)
    photographed = {name for _, name, ok in trace.photos if ok}
    for target in world.targets:
        done = target.name in photographed
        ax.plot(target.x, target.y, marker="*", ms=12, ls="", color="#16a34a" if done else "#7c3aed", zorder=4)
        ax.annotate(target.name, (target.x, target.y), textcoords="offset points", xytext=(5, 5), fontsize=7)
    if world.targets:
        ax.plot([], [], marker="*", ls="", color="#7c3aed", label="photo target")
    if trace.goal is not None:
        ax.plot(*trace.goal, marker="s", ms=9, mfc="none", mec="#dc2626", ls="", label="goal", zorder=4)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_xlim(*_focus(sim, 0))
    ax.set_ylim(*_focus(sim, 1))
    ax.grid(True, lw=0.3, alpha=0.5)


def _focus(sim: Simulation, axis: int) -> tuple[float, float]:
    """The walls when they are near; otherwise what happened, with a margin."""
    xmin, xmax, ymin, ymax = sim.world.bounds
    low, high = (xmin, xmax) if axis == 0 else (ymin, ymax)
    if high - low <= 16.0:
        return low - 0.3, high + 0.3
    points = [p[axis] for p in sim.trace.poses] + [p[axis] for p in sim.objects]
    points += [(t.x, t.y)[axis] for t in sim.world.targets] + [sim.world.start[axis]]
    for obstacle in sim.world.obstacles:
        if isinstance(obstacle, Polygon):
            points += [p[axis] for p in obstacle.points]
        else:
            centre = (obstacle.x, obstacle.y)[axis]
            points += [centre - obstacle.radius, centre + obstacle.radius]
    return max(low, min(points) - FOCUS_MARGIN), min(high, max(points) + FOCUS_MARGIN)


def _object_state(trace: Any, index: int) -> str:
    if index in trace.taken:
        return "taken"
    return "detected" if index in trace.detected else "undetected"


def _footprint(ax: Any, sim: Simulation, pose: np.ndarray, colour: str, fill: bool) -> Any:
    from matplotlib.patches import Polygon as PolygonPatch

    patch = PolygonPatch(_outline(sim, pose), closed=True, fc=colour if fill else "none", ec=colour,
                         alpha=0.35 if fill else 0.8, zorder=6)
    ax.add_patch(patch)
    return patch


def _move(patch: Any, sim: Simulation, pose: np.ndarray) -> None:
    patch.set_xy(_outline(sim, pose))


def _outline(sim: Simulation, pose: np.ndarray) -> np.ndarray:
    """The robot's footprint with a notch at the front, at `pose`."""
    robot = sim.robot
    if robot.length > 0:
        hl, hw = robot.length / 2, robot.width / 2
        local = np.array([(hl, 0.0), (hl * 0.7, hw), (-hl, hw), (-hl, -hw), (hl * 0.7, -hw)])
    else:
        angles = np.linspace(0.25, math.tau - 0.25, 24)
        local = np.vstack([[robot.radius, 0.0], np.c_[np.cos(angles), np.sin(angles)] * robot.radius])
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return local @ np.array([[c, s], [-s, c]]) + (x, y)


def _windows(ax: Any, sim: Simulation) -> None:
    end = max([sim.now] + [w.end for w in sim.world.windows])
    for w in sim.world.windows:
        ax.barh(1, w.end - w.start, left=w.start, height=0.6, color="#bfdbfe", ec="#1d4ed8")
        ax.text((w.start + w.end) / 2, 1, w.name, ha="center", va="center", fontsize=7)
    for start, stop, _name in sim.antenna.sent:
        ax.barh(0, stop - start, left=start, height=0.6, color="#16a34a")
    for t, _name, ok in sim.trace.photos:
        ax.plot(t, 0, marker="*", color="#16a34a" if ok else "#dc2626", ls="")
    ax.axvline(sim.now, color="#374151", lw=0.8)
    ax.set_yticks((0, 1), ("done", "windows"))
    ax.set_xlim(0, end * 1.02)
    ax.set_ylim(-0.6, 1.6)
    ax.set_xlabel("mission time (s)")
