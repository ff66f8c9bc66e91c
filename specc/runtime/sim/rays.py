"""Vectorised ray casting against a world's static edges and circles.

One numpy pass intersects every ray with every edge and circle: for the 32 sonars of Hilare
that is a few dozen microseconds, where 32 `Space.segment_query_first` calls of pymunk would
dominate the simulation step (each crosses the Python/C boundary and allocates a result).
"""

from __future__ import annotations

import numpy as np

from specc.runtime.sim.world import World


class RayCaster:
    def __init__(self, segments: list[tuple[float, float, float, float]],
                 circles: list[tuple[float, float, float]]) -> None:
        s = np.asarray(segments, dtype=float).reshape(-1, 4)
        self._a = s[:, 0:2]  # (S, 2) edge starts
        self._e = s[:, 2:4] - s[:, 0:2]  # (S, 2) edge vectors
        ex, ey = self._e[:, 0], self._e[:, 1]
        ax, ay = self._a[:, 0], self._a[:, 1]
        # d @ [e_y; -e_x] = cross(d, e); d @ [-(a_y - y); a_x - x] = cross(a - p, d): the first
        # block is fixed, the second moves with the origin p by [y; -x], hence `_second`.
        self._across = np.block([[ey[None, :], -ay[None, :]], [-ex[None, :], ax[None, :]]])  # (2, 2S)
        self._second = np.concatenate((np.zeros(len(ax)), np.ones(len(ax))))[None, :]  # (1, 2S)
        self._a_cross_e = ax * ey - ay * ex
        c = np.asarray(circles, dtype=float).reshape(-1, 3)
        self._centres = c[:, 0:2]
        self._r2 = c[:, 2] ** 2

    @classmethod
    def for_world(cls, world: World) -> RayCaster:
        return cls(world.segments(), world.circles())

    def cast(self, x: float, y: float, angles: np.ndarray, max_range: float) -> np.ndarray:
        """The distance along each ray from (x, y) at `angles` (world frame) to the first edge or
        circle it meets, `max_range` when none is nearer."""
        dx, dy = np.cos(angles), np.sin(angles)  # (N,)
        best = np.full(angles.shape, float(max_range))
        if len(self._a):
            # Ray p + t d meets edge a + u e where t = cross(a - p, e) / cross(d, e) and
            # u = cross(a - p, d) / cross(d, e). Both cross products with d come from one matrix
            # product; a parallel pair divides by zero into inf or nan, which no test accepts.
            directions = np.stack((dx, dy), axis=1)  # (N, 2)
            crosses = directions @ (self._across + np.array([[y], [-x]]) * self._second)
            n = len(self._a)
            denom, u_num = crosses[:, :n], crosses[:, n:]
            t_num = self._a_cross_e - (x * self._e[:, 1] - y * self._e[:, 0])  # cross(a - p, e): (S,)
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                t = t_num / denom
                u = u_num / denom
            t[~((t >= 0.0) & (u >= 0.0) & (u <= 1.0))] = np.inf
            np.minimum(best, t.min(axis=1), out=best)
        if len(self._r2):
            mx, my = x - self._centres[:, 0], y - self._centres[:, 1]  # (C,)
            b = np.multiply.outer(dx, mx) + np.multiply.outer(dy, my)  # (N, C)
            disc = b * b - (mx * mx + my * my - self._r2)
            reach = disc >= 0.0
            if reach.any():
                root = np.sqrt(np.where(reach, disc, 0.0))
                near = -b - root
                t = np.where(near >= 0.0, near, root - b)  # from inside a circle, its far side
                t[~reach | (t < 0.0)] = np.inf
                np.minimum(best, t.min(axis=1), out=best)
        return best

    def visible(self, x: float, y: float, tx: float, ty: float) -> bool:
        """Is (tx, ty) in sight from (x, y): no edge or circle between them?"""
        distance = float(np.hypot(tx - x, ty - y))
        if distance == 0.0:
            return True
        angle = np.array([np.arctan2(ty - y, tx - x)])
        return bool(self.cast(x, y, angle, distance)[0] >= distance - 1e-9)
