"""Codels of PILO (seed 000 §5.2.1, Table 5.1): trajectory execution from a poster.

§5.2.1: from "un chemin géométrique de référence", PILO computes and executes a trajectory that
respects the vehicle's kinematic and dynamic constraints; executing it means moving a setpoint
along it, exported in a poster that LOCO (through AVOID when avoidance is on) servoes on. As
[Fleury 95] requires, the motion is smooth and never stops except at the start and the end, it
stays within the tolerance of the reference, and it goes forwards.

* ``geometry``: the reference becomes a chain of pieces of linearly varying curvature (segments,
  circular arcs, clothoids). SEGMENT: two points. ARC: the circle leaving the first point with the
  first heading and passing through the second. BROKEN_LINE: ``smooth_broken_line`` rounds every
  corner with a circular arc entered and left through clothoids (curvature growing linearly from
  0), so the rotation speed, hence the wheel speeds, stays continuous - which an arc alone, tangent
  to both segments, would break. Each corner is as large as the ``tolerance`` (the farthest point
  from the reference) and the neighbouring corners allow. REEDS_SHEPP paths (with cusps, backwards
  motion) are not executed: INVALID_TRAJECTORY.
* ``speed_profile``: v(s) on a grid of the path, as fast as vmax, the rotation speed
  |w| = v |curvature| <= wmax and the rotational acceleration |dw/dt| = |a curvature + v^2 dcurvature/ds|
  <= dwmax allow, accelerating and braking at most at amax (forward and backward passes: a
  trapezoid on straight lines), from rest to rest.
* ``sample``: the setpoint (x, y, theta, v, w) at time t; the exec codel moves it every PERIOD.
"""

from __future__ import annotations

import bisect
import enum
import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

PERIOD = 0.05  # s, TrajTask period
CLOTHOID_SHARE = 0.5  # share of a corner's turn made along its two clothoids (the rest on the arc)
DS = 0.02  # m, step of the speed profile's grid along the path

Point = tuple[float, float]

_GAUSS = np.polynomial.legendre.leggauss(24)


class InvalidTrajectory(ValueError):
    """The reference cannot be executed as given."""


@dataclass(frozen=True)
class Limits:
    vmax: float  # m/s
    wmax: float  # rad/s
    amax: float  # m/s^2
    dwmax: float  # rad/s^2


@dataclass(frozen=True)
class Piece:
    """A stretch of path whose curvature varies linearly: kappa(s) = kappa + sharpness * s."""

    x: float
    y: float
    theta: float  # start pose
    length: float
    kappa: float = 0.0  # 1/m, positive when turning left
    sharpness: float = 0.0  # 1/m^2: 0 for segments and arcs
    target: int = 1  # index of the reference point this piece heads for (PILO's nextPoint)

    def curvature(self, s: float) -> float:
        return self.kappa + self.sharpness * s

    def pose(self, s: float) -> tuple[float, float, float]:
        """Position and heading after ``s`` metres along the piece."""
        theta = self.theta + self.kappa * s + 0.5 * self.sharpness * s * s
        if self.sharpness == 0.0:
            if self.kappa == 0.0:
                return self.x + s * math.cos(self.theta), self.y + s * math.sin(self.theta), theta
            # The chord, 2 sin(κs/2)/κ along the mid heading: no cancellation for a nearly
            # straight arc, where (sin θ - sin θ0)/κ loses digits.
            chord = 2.0 * math.sin(0.5 * self.kappa * s) / self.kappa
            middle = self.theta + 0.5 * self.kappa * s
            return self.x + chord * math.cos(middle), self.y + chord * math.sin(middle), theta
        nodes, weights = _GAUSS  # a clothoid: Fresnel integrals, by Gauss-Legendre quadrature
        u = 0.5 * s * (nodes + 1.0)
        angles = self.theta + self.kappa * u + 0.5 * self.sharpness * u * u
        half = 0.5 * s
        return (self.x + half * float(weights @ np.cos(angles)), self.y + half * float(weights @ np.sin(angles)),
                theta)

    def end(self) -> tuple[float, float, float]:
        return self.pose(self.length)


# ---------------------------------------------------------------- geometry


def segment_piece(a: Point, b: Point, target: int = 1) -> Piece:
    return Piece(a[0], a[1], math.atan2(b[1] - a[1], b[0] - a[0]), math.dist(a, b), target=target)


def arc_piece(a: Point, heading: float, b: Point, target: int = 1) -> Piece:
    """The circular arc leaving ``a`` with ``heading`` and reaching ``b`` (a segment if b is
    straight ahead)."""
    chord = math.dist(a, b)
    half = math.remainder(math.atan2(b[1] - a[1], b[0] - a[0]) - heading, math.tau)  # half the turn
    if chord <= 1e-12:
        raise InvalidTrajectory("an arc needs two distinct points")
    if abs(half) > math.pi - 1e-9:
        raise InvalidTrajectory("the end of the arc is straight behind its start")
    if abs(half) < 1e-12:
        return Piece(a[0], a[1], heading, chord, target=target)
    radius = chord / (2 * abs(math.sin(half)))
    return Piece(a[0], a[1], heading, 2 * abs(half) * radius, math.copysign(1 / radius, half), target=target)


@functools.lru_cache(maxsize=256)
def _unit_corner(turn: float, share: float) -> tuple[float, float]:
    """For a corner turning by |turn| with a unit-radius arc: (distance from the vertex to where
    the corner leaves the segments, farthest distance of the corner from the broken line)."""
    clothoid = Piece(0.0, 0.0, 0.0, share * turn, 0.0, 1.0 / (share * turn)) if share > 0 else None
    x, y, theta = clothoid.end() if clothoid else (0.0, 0.0, 0.0)
    x, y, _ = Piece(x, y, theta, (1 - share) * turn / 2, 1.0).end()  # to the middle of the arc
    return x + y * math.tan(turn / 2), y


def smooth_broken_line(points: Sequence[Point], tolerance: float, share: float = CLOTHOID_SHARE) -> list[Piece]:
    """The broken line with its corners rounded (clothoid, arc, clothoid), never farther than
    ``tolerance`` from it; the pieces are continuous in position, heading and curvature."""
    line, index = _clean(points)
    if len(line) < 2:
        return []
    n = len(line)
    directions = [math.atan2(line[k + 1][1] - line[k][1], line[k + 1][0] - line[k][0]) for k in range(n - 1)]
    lengths = [math.dist(line[k], line[k + 1]) for k in range(n - 1)]
    corners: list[tuple[float, float, float]] = []  # per inner vertex: turn, distance T, radius
    for k in range(1, n - 1):
        turn = math.remainder(directions[k] - directions[k - 1], math.tau)
        if abs(turn) > math.pi - 1e-6:
            raise InvalidTrajectory(f"the broken line turns back at point {k}")
        if tolerance <= 0:
            raise InvalidTrajectory("a broken line with corners needs a positive tolerance")
        reach, deviation = _unit_corner(abs(turn), share)
        room_before = lengths[k - 1] if k == 1 else lengths[k - 1] / 2
        room_after = lengths[k] if k == n - 2 else lengths[k] / 2
        radius = min(tolerance / deviation, room_before / reach, room_after / reach)
        corners.append((turn, reach * radius, radius))
    pieces: list[Piece] = []
    here = line[0]
    for k in range(1, n):
        vertex, heading = line[k], directions[k - 1]
        if k == n - 1:
            entry = vertex
        else:
            turn, reach, radius = corners[k - 1]
            entry = (vertex[0] - reach * math.cos(heading), vertex[1] - reach * math.sin(heading))
        if math.dist(here, entry) > 1e-12:
            pieces.append(Piece(here[0], here[1], heading, math.dist(here, entry), target=index[k]))
        if k == n - 1:
            break
        side = math.copysign(1.0, turn)
        clothoid = share * abs(turn) * radius
        arc = (1 - share) * abs(turn) * radius
        pose = (entry[0], entry[1], heading)
        for length, kappa, sharpness, target in ((clothoid, 0.0, side / (clothoid * radius) if clothoid else 0,
                                                  index[k]),
                                                 (arc, side / radius, 0.0, index[k]),
                                                 (clothoid, side / radius, -side / (clothoid * radius) if clothoid
                                                  else 0, index[k + 1])):
            if length > 1e-12:
                piece = Piece(*pose, length, kappa, sharpness, target)
                pieces.append(piece)
                pose = piece.end()
        here = (vertex[0] + reach * math.cos(directions[k]), vertex[1] + reach * math.sin(directions[k]))
    return pieces


def _clean(points: Sequence[Point]) -> tuple[list[Point], list[int]]:
    """Without repeated points, nor points on the straight line between their neighbours; and the
    index each point kept had in ``points``."""
    line: list[Point] = []
    index: list[int] = []
    for k, p in enumerate(points):
        p = (float(p[0]), float(p[1]))
        if not line or math.dist(line[-1], p) > 1e-9:
            line.append(p)
            index.append(k)
        else:
            index[-1] = k  # a repeated point: heading for the last copy
    k = 1
    while k < len(line) - 1:
        a, b, c = line[k - 1], line[k], line[k + 1]
        turn = math.remainder(math.atan2(c[1] - b[1], c[0] - b[0]) - math.atan2(b[1] - a[1], b[0] - a[0]), math.tau)
        if abs(turn) < 1e-9:
            del line[k], index[k]
        else:
            k += 1
    return line, index


def reference_pieces(kind: str, points: Sequence[Point], thetas: Sequence[float], tolerance: float) -> list[Piece]:
    """The geometric path of one of PILO's four kinds of trajectory."""
    if not all(math.isfinite(v) for p in points for v in p) or not all(math.isfinite(t) for t in thetas):
        raise InvalidTrajectory("a coordinate is not a finite number")
    if len(points) == 1:
        return []
    if kind == "SEGMENT":
        if len(points) != 2:
            raise InvalidTrajectory("a segment has two points")
        return [segment_piece(points[0], points[1])] if math.dist(points[0], points[1]) > 1e-12 else []
    if kind == "ARC":
        if len(points) != 2:
            raise InvalidTrajectory("an arc has two points (and the first one's heading)")
        return [arc_piece(points[0], thetas[0], points[1])]
    if kind == "BROKEN_LINE":
        return smooth_broken_line(points, tolerance)
    raise InvalidTrajectory(f"{kind} trajectories are not executed (only SEGMENT, ARC, BROKEN_LINE)")


# ---------------------------------------------------------------- time


@dataclass(frozen=True)
class TimedTrajectory:
    """The pieces, and on a grid of arc lengths s the speed v and the time t it is reached."""

    pieces: tuple[Piece, ...]
    starts: tuple[float, ...]  # arc length where each piece starts
    s: tuple[float, ...]
    v: tuple[float, ...]
    t: tuple[float, ...]

    @property
    def duration(self) -> float:
        return self.t[-1] if self.t else 0.0

    @property
    def length(self) -> float:
        return self.s[-1] if self.s else 0.0

    def piece_at(self, s: float) -> tuple[Piece, float]:
        k = max(0, bisect.bisect_right(self.starts, s) - 1)
        return self.pieces[k], s - self.starts[k]


def speed_profile(pieces: Sequence[Piece], limits: Limits, ds: float = DS) -> TimedTrajectory:
    """The fastest speed profile from rest to rest within ``limits`` (see the module's doc)."""
    if min(limits.vmax, limits.wmax, limits.amax, limits.dwmax) <= 0:
        raise InvalidTrajectory("the dynamic limits must be positive")
    pieces = tuple(p for p in pieces if p.length > 0)
    if not pieces:
        return TimedTrajectory((), (), (0.0,), (0.0,), (0.0,))
    s, vlim, alim, starts = [0.0], [math.inf], [], []
    for piece in pieces:
        starts.append(s[-1])
        steps = max(2, math.ceil(piece.length / ds))
        for j in range(1, steps + 1):
            # |curvature| is largest at one end of the step, and v^2 is linear in s within it (constant
            # acceleration): limits that hold at both ends with the step's largest |curvature| hold all along.
            kappa = max(abs(piece.curvature((j - 1) * piece.length / steps)),
                        abs(piece.curvature(j * piece.length / steps)))
            alim.append(min(limits.amax, limits.dwmax / (2 * kappa)) if kappa > 0 else limits.amax)
            limit = _speed_limit(kappa, piece.sharpness, limits)
            vlim[-1] = min(vlim[-1], limit)
            vlim.append(limit)
            s.append(starts[-1] + j * piece.length / steps)
    n = len(s)
    v = [0.0] * n
    for k in range(n - 1):  # accelerate as much as allowed...
        v[k + 1] = min(vlim[k + 1], math.sqrt(v[k] ** 2 + 2 * alim[k] * (s[k + 1] - s[k])))
    v[-1] = 0.0
    for k in range(n - 2, -1, -1):  # ... and brake in time
        v[k] = min(v[k], math.sqrt(v[k + 1] ** 2 + 2 * alim[k] * (s[k + 1] - s[k])))
    v[0] = 0.0
    t = [0.0]
    for k in range(n - 1):  # constant acceleration within each step
        t.append(t[-1] + 2 * (s[k + 1] - s[k]) / (v[k] + v[k + 1]))
    return TimedTrajectory(pieces, tuple(starts), tuple(s), tuple(v), tuple(t))


def _speed_limit(kappa: float, sharpness: float, limits: Limits) -> float:
    limit = limits.vmax
    if kappa > 0:
        limit = min(limit, limits.wmax / kappa)
    if sharpness:  # v^2 |dkappa/ds| <= dwmax / 2, the other half is for a |kappa|
        limit = min(limit, math.sqrt(limits.dwmax / (2 * abs(sharpness))))
    return limit


@dataclass(frozen=True)
class Setpoint:
    x: float
    y: float
    theta: float
    v: float
    w: float
    target: int  # index of the reference point being headed for


def sample(timed: TimedTrajectory, t: float) -> Setpoint:
    """Where the setpoint is at time ``t`` (clamped to the trajectory's duration)."""
    if not timed.pieces:
        raise InvalidTrajectory("an empty trajectory has no setpoint")
    if t >= timed.duration:
        x, y, theta = timed.pieces[-1].end()
        return Setpoint(x, y, theta, 0.0, 0.0, timed.pieces[-1].target)
    t = max(t, 0.0)
    k = min(max(0, bisect.bisect_right(timed.t, t) - 1), len(timed.t) - 2)
    tau, dt = t - timed.t[k], timed.t[k + 1] - timed.t[k]
    accel = (timed.v[k + 1] - timed.v[k]) / dt
    s = min(timed.s[k] + timed.v[k] * tau + 0.5 * accel * tau * tau, timed.length)
    v = max(0.0, timed.v[k] + accel * tau)
    piece, local = timed.piece_at(s)
    x, y, theta = piece.pose(local)
    return Setpoint(x, y, theta, v, v * piece.curvature(local), piece.target)


def timed_trajectory(kind: str, points: Sequence[Point], thetas: Sequence[float], tolerance: float,
                     limits: Limits) -> TimedTrajectory:
    """The reference's geometry, then its speed profile."""
    return speed_profile(reference_pieces(kind, points, thetas, tolerance), limits)


@functools.lru_cache(maxsize=8)
def _timed(kind: str, points: tuple[Point, ...], thetas: tuple[float, ...], tolerance: float,
           limits: Limits) -> TimedTrajectory:
    return timed_trajectory(kind, points, thetas, tolerance, limits)


def _timed_of(sdi) -> TimedTrajectory:
    traj, n = sdi.traj, sdi.traj.nbPoints
    kind = traj.kind.name if isinstance(traj.kind, enum.Enum) else str(traj.kind)
    d = sdi.limits
    return _timed(kind, tuple(zip(traj.x[:n], traj.y[:n], strict=True)), tuple(traj.theta[:n]), traj.tolerance,
                  Limits(d.vmax, d.wmax, d.amax, d.dwmax))


# ---------------------------------------------------------------- codels


def initPilo(sdi):
    """TrajTask init: avoidance off, conservative default dynamics."""
    sdi.avoidOn = False
    sdi.dynamic.vmax, sdi.dynamic.wmax = 0.3, 0.6
    sdi.dynamic.amax, sdi.dynamic.dwmax = 0.3, 0.6
    return "exec"


def setAvoidMode(sdi, request):
    """avoidOnOff: enable or disable local obstacle avoidance for the next trajectories."""
    sdi.avoidOn = bool(request.on)
    return "end"


def checkDynamic(sdi, request):
    """setDynamic: accept positive maximum speeds and accelerations (for the next trajectories)."""
    d = request.dynamic
    values = (d.vmax, d.wmax, d.amax, d.dwmax)
    if not all(math.isfinite(v) for v in values) or min(values) <= 0:
        return "BAD_DYNAMIC_PARAMS"
    sdi.dynamic = d
    return "end"


def readTrajPoster(sdi, request):
    """Start phase: read the trajectory, time it, and have LOCO (through AVOID if on) track the
    setpoint."""
    traj = sdi.read_poster(request.trajPoster)
    if traj is None:
        return "POSTER_NOT_FOUND"
    if not 1 <= traj.nbPoints <= len(traj.x):
        return "INVALID_TRAJECTORY"
    sdi.trajPoster, sdi.traj = request.trajPoster, traj
    d = sdi.dynamic
    sdi.limits.vmax, sdi.limits.wmax, sdi.limits.amax, sdi.limits.dwmax = d.vmax, d.wmax, d.amax, d.dwmax
    try:
        timed = _timed_of(sdi)
    except InvalidTrajectory:
        return "INVALID_TRAJECTORY"
    sp = sdi.setpoint
    if timed.pieces:
        sp.x, sp.y, sp.theta = _start_pose(timed)
    else:
        sp.x, sp.y, sp.theta = traj.x[0], traj.y[0], traj.theta[0]
    sp.v = sp.w = 0.0
    sdi.elapsed, sdi.nextPoint = 0.0, 1
    if sdi.avoidOn:
        sdi.send_request("avoid.Filter", setpointPoster="pilo.Setpoint")
    else:
        sdi.send_request("loco.Track", trackedPoster="pilo.Setpoint")
    return "exec"


def _start_pose(timed: TimedTrajectory) -> tuple[float, float, float]:
    first = timed.pieces[0]
    return first.x, first.y, first.theta


def generateSetpoint(sdi, request):
    """Exec phase: move the setpoint one period further along the timed trajectory."""
    timed = _timed_of(sdi)
    sdi.elapsed += PERIOD
    sp = sdi.setpoint
    if not timed.pieces or sdi.elapsed >= timed.duration:
        if timed.pieces:
            sp.x, sp.y, sp.theta = timed.pieces[-1].end()
        sp.v = sp.w = 0.0
        sdi.nextPoint = sdi.traj.nbPoints
        return "end"
    here = sample(timed, sdi.elapsed)
    sp.x, sp.y, sp.theta, sp.v, sp.w = here.x, here.y, here.theta, here.v, here.w
    sdi.nextPoint = here.target
    return "exec"


def endTraj(sdi, request):
    """End phase: the last point is reached, the setpoint stops there."""
    sdi.setpoint.v = sdi.setpoint.w = 0.0
    return "ether"


def stopTraj(sdi, request):
    """Inter phase: interrupted, the setpoint stops where it is."""
    sdi.setpoint.v = sdi.setpoint.w = 0.0
    return "ether"
