"""Simple temporal networks, the temporal core of the planner (seed 004 §3.2.1.2: IxTeT keeps a
plan's timepoints in such a network and propagates each new constraint at once).

A network holds timepoints, each at or after the origin, and constraints
`low <= t(j) - t(i) <= high`. It is kept minimal:
the distance matrix holds, for every pair, the tightest bound the constraints imply (all-pairs
shortest paths), updated incrementally in O(n^2) per constraint, so a planner learns at once
whether a resolver makes its plan inconsistent, and reads any timepoint's window.

Contingent links (`low <= t(end) - t(start) <= high` chosen by nature, not by the plan: a move's
real duration, a visibility window's instants) make it an STNU. `strongly_controllable` tells
whether one fixed schedule of the plan's own timepoints works whatever nature chooses, and gives
it (Vidal & Fargier's reduction: each requirement on a contingent end becomes a tighter one on
its start).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

ORIGIN = "origin"  # timepoint 0: every date is measured from it
INF = math.inf


class Inconsistent(ValueError):
    """The constraints cannot all hold (a negative cycle)."""


class Constraint(NamedTuple):  # not a dataclass: a tuple is made faster, and a search makes thousands
    first: int
    second: int
    low: float  # t(second) - t(first) >= low
    high: float  # t(second) - t(first) <= high


class Contingent(NamedTuple):
    start: int
    end: int
    low: float
    high: float


def for_every_offset(low: float, high: float, first: tuple[float, float],
                     second: tuple[float, float]) -> tuple[float, float]:
    """Bounds on t(b') - t(a') that keep `low <= t(b) - t(a) <= high` whatever nature picks, when
    t(a) = t(a') + an offset in `first` and t(b) = t(b') + an offset in `second` (Vidal & Fargier's
    reduction for strong controllability)."""
    return (low - (second[0] - first[1]) if low > -INF else -INF,
            high - (second[1] - first[0]) if high < INF else INF)


class STN:
    def __init__(self) -> None:
        self.names: list[str] = []
        self.index: dict[str, int] = {}
        # distances[i, j]: the tightest upper bound on t(j) - t(i) (read it, never write it). Exactly
        # n x n, with no room to grow: numpy updates a contiguous matrix in one sweep but a slice of
        # a larger one row by row, twice as slowly, and a plan adds far fewer points than constraints.
        self.distances = np.zeros((0, 0))
        self.constraints: list[Constraint] = []
        self.contingent: list[Contingent] = []
        self.point(ORIGIN)

    # ------------------------------------------------------------ building
    def point(self, name: str) -> int:
        """The timepoint called `name`, created unconstrained if new."""
        known = self.index.get(name)
        if known is not None:
            return known
        n = len(self.names)
        d = self.distances
        grown = np.empty((n + 1, n + 1))
        grown[:n, :n] = d
        grown[:, n] = INF
        # Every timepoint comes at or after the origin, so nothing comes later after it than
        # after the origin: the propagation of `t(origin) - t(new) <= 0`, written at once.
        if n:
            grown[n, :n] = d[0]
        grown[n, n] = 0.0
        self.distances = grown
        self.names.append(name)
        self.index[name] = n
        return n

    def add(self, first: str | int, second: str | int, low: float = -INF, high: float = INF) -> None:
        """Require `low <= t(second) - t(first) <= high`; raises Inconsistent (and changes nothing)
        when the network cannot take it."""
        i, j = self._id(first), self._id(second)
        if low > high:
            raise Inconsistent(f"{self.names[j]} - {self.names[i]} in [{low}, {high}]: an empty interval")
        d = self.distances
        # An edge i -> j of weight w means t(j) - t(i) <= w.
        if high + d.item(j, i) < 0 or -low + d.item(i, j) < 0:
            raise Inconsistent(f"{self.names[j]} - {self.names[i]} in [{low}, {high}] contradicts "
                               f"[{-d.item(j, i)}, {d.item(i, j)}], which the network already implies")
        self.constraints.append(Constraint(i, j, low, high))
        self._tighten(i, j, high)
        self._tighten(j, i, -low)

    def add_contingent(self, start: str | int, end: str | int, low: float, high: float) -> None:
        """Nature puts `end` between `low` and `high` after `start` (0 <= low <= high)."""
        if not 0 <= low <= high < INF:
            raise ValueError(f"a contingent duration needs 0 <= low <= high < inf, not [{low}, {high}]")
        i, j = self._id(start), self._id(end)
        if any(c.end == j for c in self.contingent):
            raise ValueError(f"'{self.names[j]}' already ends a contingent link")
        self.add(i, j, low, high)
        self.constraints.pop()  # a contingent link is not a requirement
        self.contingent.append(Contingent(i, j, low, high))

    def _tighten(self, i: int, j: int, w: float) -> None:
        d = self.distances
        if w >= d.item(i, j):
            return
        # Every path k -> i -> j -> l may now be shorter.
        np.minimum(d, d[:, i:i + 1] + w + d[j:j + 1, :], out=d)

    def _id(self, point: str | int) -> int:
        if isinstance(point, int):
            return point
        known = self.index.get(point)  # point(), inlined for the usual case
        return self.point(point) if known is None else known

    # ------------------------------------------------------------ reading
    def bounds(self, first: str | int, second: str | int) -> tuple[float, float]:
        """The tightest [low, high] the network implies for t(second) - t(first)."""
        i, j = self._id(first), self._id(second)
        d = self.distances
        return float(-d[j, i]), float(d[i, j])

    def window(self, point: str | int) -> tuple[float, float]:
        """[earliest, latest] date of a timepoint."""
        return self.bounds(0, point)

    def copy(self) -> STN:
        other = STN.__new__(STN)
        other.names = list(self.names)
        other.index = dict(self.index)
        other.distances = self.distances.copy()
        other.constraints = list(self.constraints)
        other.contingent = list(self.contingent)
        return other

    def earliest_schedule(self) -> dict[str, float]:
        """Every timepoint at its earliest date: a consistent schedule of a minimal network."""
        d = self.distances
        return {name: float(-d[i, 0]) for i, name in enumerate(self.names)}

    def strongly_controllable(self) -> dict[str, float] | None:
        """A schedule of the timepoints nature does not choose, valid for every duration of the
        contingent links, or None when there is none (strong controllability)."""
        ends = {c.end: c for c in self.contingent}
        reduced = STN()
        for name in self.names:
            if self.index[name] not in ends:
                reduced.point(name)

        def anchor(point: int) -> tuple[int, float, float]:
            """An executable timepoint and the range of the point's offset from it."""
            link = ends.get(point)
            if link is None:
                return point, 0.0, 0.0
            base, low, high = anchor(link.start)
            return base, low + link.low, high + link.high

        try:
            for c in self.constraints:
                (a, a_low, a_high), (b, b_low, b_high) = anchor(c.first), anchor(c.second)
                low, high = for_every_offset(c.low, c.high, (a_low, a_high), (b_low, b_high))
                reduced.add(self.names[a], self.names[b], low, high)
        except Inconsistent:
            return None
        return reduced.earliest_schedule()
