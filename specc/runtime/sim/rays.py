"""Vectorised ray casting against a world's static edges and circles.

One numpy pass intersects every ray with every edge and circle: for a ring of 32 sonars that
is a few dozen microseconds, where 32 `Space.segment_query_first` calls of pymunk would
dominate the simulation step (each crosses the Python/C boundary and allocates a result). At
that size numpy's cost is per operation, not per element, so the pass is arranged to take few
operations: the rays of a sensor are its fixed unit directions turned by the heading, and one
matrix product gives, for every ray and edge, both cross products the intersection needs.
"""

from __future__ import annotations

import math

import numpy as np

from specc.runtime.sim.world import World

PARALLEL = 1e-12  # |cross(ray, edge)| (m) at or below which a ray runs along the edge


def unit_directions(angles: np.ndarray) -> np.ndarray:
    """(N, 2) unit vectors at `angles`, the form `RayCaster.fan` takes."""
    return np.stack((np.cos(angles), np.sin(angles)), axis=1)


class RayCaster:
    def __init__(self, segments: list[tuple[float, float, float, float]],
                 circles: list[tuple[float, float, float]]) -> None:
        s = np.asarray(segments, dtype=float).reshape(-1, 4)
        ax, ay, ex, ey = s[:, 0], s[:, 1], s[:, 2] - s[:, 0], s[:, 3] - s[:, 1]
        self._edges = len(s)
        # Ray p + t d meets edge a + u e where t = cross(a - p, e) / cross(d, e) and
        # u = cross(a - p, d) / cross(d, e). u needs no division: with m = a + e / 2 the edge's
        # middle (u = 1/2), u is in [0, 1] when |2 cross(m - p, d)| <= |cross(d, e)|.
        # With the ray written (d_x, d_y, cross(d, p)):
        #   cross(d, e)       = d_x e_y - d_y e_x
        #   2 cross(m - p, d) = -2 m_y d_x + 2 m_x d_y + 2 cross(d, p)
        # both are rows of one product with this fixed (3, 2S) matrix.
        mx, my = ax + ex / 2.0, ay + ey / 2.0
        self._across = np.block([[ey, -2.0 * my], [-ex, 2.0 * mx], [np.zeros(len(s)), np.full(len(s), 2.0)]])
        # cross(a - p, e) = cross(a, e) - x e_y + y e_x: (1, -x, y) times this (3, S) matrix.
        self._t_rows = np.stack((ax * ey - ay * ex, ey, ex))
        c = np.asarray(circles, dtype=float).reshape(-1, 3)
        self._centres = c[:, 0:2].T.copy()  # (2, C)
        self._r2 = c[:, 2] ** 2

    @classmethod
    def for_world(cls, world: World) -> RayCaster:
        return cls(world.segments(), world.circles())

    def cast(self, x: float, y: float, angles: np.ndarray, max_range: float) -> np.ndarray:
        """The distance along each ray from (x, y) at `angles` (world frame) to the first edge or
        circle it meets, `max_range` when none is nearer."""
        return self.fan(x, y, 0.0, unit_directions(angles), max_range)

    def fan(self, x: float, y: float, heading: float, units: np.ndarray, max_range: float) -> np.ndarray:
        """`cast` for rays fixed on a body: `units` (N, 2), from `unit_directions` of the angles
        relative to the body, turned by `heading`."""
        c, s = math.cos(heading), math.sin(heading)
        # Each row (u_x, u_y) becomes (d_x, d_y, cross(d, p)): the turn and the origin's moment
        # in one (2, 3) matrix built from scalars.
        rays = units @ np.array(((c, s, c * y - s * x), (-s, c, -s * y - c * x)))  # (N, 3)
        if self._edges:
            # Turned to (2S, N), one row per edge (one copy): the minimum over the edges is then
            # S - 1 elementwise minima of whole rows, several times cheaper than N reductions along
            # short rows (the laser's 181 beams against a world's few dozen edges). Same values.
            crosses = (rays @ self._across).T.copy()  # (2S, N)
            denom, off_middle = crosses[:self._edges], crosses[self._edges:]
            t_num = (np.array((1.0, -x, y)) @ self._t_rows)[:, None]  # (S, 1)
            span = np.abs(denom)
            # A ray (nearly) parallel to an edge misses it: from a point on the edge's line,
            # rounding alone would decide t and u (a ray from (2, 2) heading west met the edge
            # (3, 2)-(4.6, 2) behind it, at t = -0). The edge's ends are its neighbours' too.
            # Skipping those pairs also spares the division by zero its warning.
            crossing = span > PARALLEL
            t = np.divide(t_num, denom, out=None, where=crossing)  # undefined where not crossing
            hits = crossing & (np.abs(off_middle) <= span) & (t >= 0.0)
            # the ufunc's own reduce: np.min's Python wrapper costs as much as the work here
            best = np.minimum.reduce(t, axis=0, where=hits, initial=max_range)
        else:
            best = np.full(len(units), float(max_range))
        if len(self._r2):
            offset = np.array(((x,), (y,))) - self._centres  # (2, C): p - centre
            b = (rays[:, :2] @ offset).T.copy()  # (C, N), as the edges' rows
            disc = b * b - ((offset * offset).sum(axis=0) - self._r2)[:, None]
            reach = disc >= 0.0
            if reach.any():
                root = np.sqrt(np.where(reach, disc, 0.0))
                near = -b - root
                t = np.where(near >= 0.0, near, root - b)  # from inside a circle, its far side
                nearest = np.minimum.reduce(t, axis=0, where=reach & (t >= 0.0), initial=max_range)
                np.minimum(best, nearest, out=best)
        return best

    def visible(self, x: float, y: float, tx: float, ty: float) -> bool:
        """Is (tx, ty) in sight from (x, y): no edge or circle between them?"""
        distance = math.hypot(tx - x, ty - y)
        if distance == 0.0:
            return True
        unit = np.array(((tx - x) / distance, (ty - y) / distance))[None, :]
        return bool(self.fan(x, y, 0.0, unit, distance)[0] >= distance - 1e-9)
