"""Print the Modele2 distance fragment of a rover mission (seed 004, annex A, Modele2-distances).

    python model2_distances.py M2 > fragment text for missions/M2_model2.spec

How the values are obtained (reverse-engineered from the annex's M1 table, see README.md):

* Singular points O1..On: O1 is the start/lander (0, 0); O2.. are the mission's photo targets
  in the order of ../shared/missions.md (in M1 the first target is (0, 0) itself, so the
  annex uses O1 for both: M1 is kept verbatim in missions/M1_model2.spec, not generated).
* distance (MOVE_NOMINAL, O_i -> O_j): Euclidean distance + 2 m, truncated to 2 decimals
  (annex: O1-O2 4 -> 6, O1-O3 4.24 -> 6.24, O2-O3 3.16 -> 5.16). One DIST symbol per ordered
  pair, numbered by destination then origin (at most 6 x 5 = 30 = |DIST|). Distinct symbols per
  ordered pair also forbid O_i -> O_i moves, as the annex's table does.
* distance_recov (MOVE_RECOV, localisation point -> O_j): plain Euclidean distance, truncated.
  G1..G16 is the 4 x 4 grid {6, 3, -3, -6}^2 ordered by x then y, both descending (G1 = (6, 6),
  G4 = (6, -6), G16 = (-6, -6)); U1..U8 = (8, 8) (8, 3) (8, -8) (-3, -8) (-8, -8) (-8, 3)
  (-8, 8) (-3, 8). These coordinates reproduce every annex value exactly or from below: the
  annex merges close values of one destination upward into one ENSDIST symbol. Here the
  distinct values of one destination are merged upward (never underestimating a distance)
  when they lie within MERGE_SPAN of the smallest value of their group, so that six singular
  points fit the 68 symbols of ENSDIST. Symbols are numbered by destination, then in order of
  first use over G1..G16, U1..U8, as in the annex.
"""
from __future__ import annotations

import math
import sys

MISSION_POINTS = {
    "M1": [(0, 0), (4, 0), (3, -3)],
    "M2": [(0, 0), (-5, 3), (5, 5), (4, -5)],
    "M3": [(0, 0), (2, 1), (-1, 2), (-2, -2), (1, -3)],
    "M4": [(0, 0), (-5, 5), (5, 6), (6, -2), (2, -6), (-6, -4)],
}
GRID = [6, 3, -3, -6]
LOCALISATION = {f"G{k + 1}": (x, y) for k, (x, y) in enumerate((x, y) for x in GRID for y in GRID)}
LOCALISATION.update({f"U{k + 1}": p for k, p in enumerate(
    [(8, 8), (8, 3), (8, -8), (-3, -8), (-8, -8), (-8, 3), (-8, 8), (-3, 8)])})
NOMINAL_MARGIN = 2.0
MERGE_SPAN = 0.75
DIST_SIZE, ENSDIST_SIZE = 30, 68


def truncate(value: float) -> float:
    return math.floor(value * 100 + 1e-9) / 100


def fmt(value: float) -> str:
    return f"{value:.2f}".rstrip("0").rstrip(".")


def merged(values: list[float]) -> dict[float, float]:
    """Map each value to the largest value of its group (groups span at most MERGE_SPAN)."""
    groups: list[list[float]] = []
    for v in sorted(set(values)):
        if groups and v - groups[-1][0] <= MERGE_SPAN:
            groups[-1].append(v)
        else:
            groups.append([v])
    return {v: g[-1] for g in groups for v in g}


def nominal(points: list[tuple[int, int]]) -> list[str]:
    names = [f"O{i + 1}" for i in range(len(points))]
    symbol: dict[tuple[int, int], int] = {}
    for j in range(len(points)):
        for i in range(len(points)):
            if i != j:
                symbol[i, j] = len(symbol) + 1
    assert len(symbol) <= DIST_SIZE
    out = ["macro distance(_p1, _p2, _d) {", "    variable ?D;", "    ?D in DIST;"]
    for j, name in enumerate(names):
        ds = ",".join(f"D{symbol[i, j]}" for i in range(len(points)) if i != j)
        out.append(f"    _p2 in {{{name}}} => ?D in {{{ds}}};")
    for i, name in enumerate(names):
        ds = ",".join(f"D{symbol[i, j]}" for j in range(len(points)) if j != i)
        out.append(f"    _p1 in {{{name}}} => ?D in {{{ds}}};")
    for (i, j), d in sorted(symbol.items(), key=lambda kv: kv[1]):
        value = truncate(math.dist(points[i], points[j]) + NOMINAL_MARGIN)
        out.append(f"    ?D in {{D{d}}} => _d =. {fmt(value)};   // O{i + 1} -> O{j + 1}")
    return out + ["}"]


def recov(points: list[tuple[int, int]]) -> list[str]:
    symbols: dict[tuple[int, float], int] = {}
    of_source: dict[str, list[int]] = {loc: [] for loc in LOCALISATION}
    for j, target in enumerate(points):
        exact = {loc: truncate(math.dist(p, target)) for loc, p in LOCALISATION.items()}
        up = merged(list(exact.values()))
        for loc in LOCALISATION:
            key = (j, up[exact[loc]])
            symbols.setdefault(key, len(symbols) + 1)
            of_source[loc].append(symbols[key])
    assert len(symbols) <= ENSDIST_SIZE, len(symbols)
    out = ["macro distance_recov(_p1, _p2, _d) {", "    variable ?D;", "    ?D in ENSDIST;"]
    for j in range(len(points)):
        ds = ",".join(f"D{s}" for (jj, _), s in symbols.items() if jj == j)
        out.append(f"    _p2 in {{O{j + 1}}} => ?D in {{{ds}}};")
    for loc, ss in of_source.items():
        out.append(f"    _p1 in {{{loc}}} => ?D in {{{','.join(f'D{s}' for s in ss)}}};")
    for (_, value), s in symbols.items():
        out.append(f"    ?D in {{D{s}}} => _d =. {fmt(value)};")
    return out + ["}"]


def main(mission: str) -> None:
    points = MISSION_POINTS[mission]
    where = ", ".join(f"O{i + 1} = ({x}, {y})" for i, (x, y) in enumerate(points))
    print(f"// generated by tools/model2_distances.py {mission}: {where}")
    print(f"fragment model2_distances_{mission} {{")
    print("\n".join(nominal(points)))
    print()
    print("\n".join(recov(points)))
    print("}")


if __name__ == "__main__":
    main(sys.argv[1])
