"""Simple temporal networks: incremental propagation agrees with Floyd-Warshall from scratch,
inconsistent constraints are refused without damage, schedules satisfy every constraint, and a
strongly controllable network's schedule holds for every duration nature may choose."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specc.runtime.stn import STN, Inconsistent

POINTS = ["origin", "a", "b", "c", "d"]
constraints = st.lists(st.tuples(st.sampled_from(POINTS), st.sampled_from(POINTS), st.integers(-10, 10),
                                 st.integers(0, 15)), max_size=10)


def floyd_warshall(edges: list[tuple[int, int, float]], n: int) -> list[list[float]] | None:
    d = [[0.0 if i == j else math.inf for j in range(n)] for i in range(n)]
    for i, j, w in edges:
        d[i][j] = min(d[i][j], w)
    for k in range(n):
        for i in range(n):
            for j in range(n):
                d[i][j] = min(d[i][j], d[i][k] + d[k][j])
    return None if any(d[i][i] < 0 for i in range(n)) else d


@settings(max_examples=200, deadline=None)
@given(constraints)
def test_incremental_propagation_is_floyd_warshall(given_constraints: list[tuple[str, str, int, int]]) -> None:
    network = STN()
    for name in POINTS:
        network.point(name)
    kept: list[tuple[int, int, float]] = [(i, 0, 0.0) for i in range(1, len(POINTS))]  # after the origin
    for first, second, low, width in given_constraints:
        i, j = network.index[first], network.index[second]
        candidate = [*kept, (i, j, float(low + width)), (j, i, float(-low))]
        expected = floyd_warshall(candidate, len(POINTS))
        before = network.distances.copy()
        if expected is None:
            with pytest.raises(Inconsistent):
                network.add(first, second, low, low + width)
            assert (network.distances == before).all()  # a refused constraint leaves no trace
            continue
        network.add(first, second, low, low + width)
        kept = candidate
        assert network.distances.tolist() == expected
    schedule = network.earliest_schedule()
    for i, j, w in kept:
        assert schedule[POINTS[j]] - schedule[POINTS[i]] <= w + 1e-9


def test_windows_and_bounds_read_the_minimal_network() -> None:
    network = STN()
    network.add("origin", "start", 10, 20)
    network.add("start", "end", 5, 30)
    network.add("origin", "end", high=40)
    assert network.window("end") == (15, 40)
    assert network.bounds("start", "end") == (5, 30)
    assert network.window("start") == (10, 20)
    with pytest.raises(Inconsistent, match="contradicts"):
        network.add("origin", "end", 41, 50)


def test_a_move_of_uncertain_duration_and_a_visibility_window() -> None:
    """Seed 004's M4 in miniature: a move nature makes last 42 to 123 s must end inside a window."""
    network = STN()
    network.add_contingent("depart", "arrive", 42, 123)
    network.add("origin", "depart", 0, 1000)
    network.add("origin", "arrive", 100, 200)  # the window
    schedule = network.strongly_controllable()
    assert schedule is not None and schedule["depart"] == 58  # 100 - 42 <= depart <= 200 - 123
    narrow = network.copy()
    narrow.add("origin", "closing", 130, 130)
    narrow.add("arrive", "closing", 0)  # arrive by 130: no departure works for every duration
    assert narrow.strongly_controllable() is None
    # ...though the network read as if the planner chose the duration (as peers do) is consistent:
    assert narrow.window("depart") == (0, 88)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.sampled_from(["origin", "x", "y", "e1", "e2"]),
                          st.sampled_from(["origin", "x", "y", "e1", "e2"]),
                          st.integers(-20, 20), st.integers(0, 30)), max_size=6),
       st.integers(0, 10), st.integers(0, 10), st.integers(0, 10), st.integers(0, 10))
def test_a_strongly_controllable_schedule_holds_for_every_duration(
        requirements: list[tuple[str, str, int, int]], low1: int, width1: int, low2: int, width2: int) -> None:
    network = STN()
    network.add_contingent("x", "e1", low1, low1 + width1)
    network.add_contingent("e1", "e2", low2, low2 + width2)  # a chain: e2 hangs on another end
    try:
        for first, second, low, width in requirements:
            network.add(first, second, low, low + width)
    except Inconsistent:
        return
    schedule = network.strongly_controllable()
    if schedule is None:
        return
    for d1, d2 in itertools.product((low1, low1 + width1), (low2, low2 + width2)):  # linear: vertices suffice
        times = dict(schedule)
        times["e1"] = times["x"] + d1
        times["e2"] = times["e1"] + d2
        for c in network.constraints:
            value = times[network.names[c.second]] - times[network.names[c.first]]
            assert c.low - 1e-9 <= value <= c.high + 1e-9, (c, d1, d2, times)
