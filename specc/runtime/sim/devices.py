"""The devices modules' codels drive and read: the counterpart of Pocosim between GenoM modules
and Gazebo (seed 004 §4.1.1). Each reads the rover's true state at the current simulated time
and adds its own seeded noise; nothing here knows about modules.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from specc.runtime.sim.rays import RayCaster, unit_directions
from specc.runtime.sim.world import Window

if TYPE_CHECKING:
    from specc.runtime.sim.rover import Rover


def reliability(r: float, theta: float, r_min: float, r_max: float, theta_open: float) -> float:
    """Seed 000 §5.2.4, Fig. 5.4: how reliably the detector answers for an object at range r and
    bearing θ from the camera axis: exp(-(r/r_max)² - (2θ/θ_open)²) inside the field, else 0."""
    if r_min <= r <= r_max and -theta_open <= 2.0 * theta <= theta_open:
        return math.exp(-((r / r_max) ** 2) - (2.0 * theta / theta_open) ** 2)
    return 0.0


def wrap(angle: float) -> float:
    return math.remainder(angle, math.tau)


class Encoders:
    """Wheel-encoder counters: metres travelled by each wheel since the start."""

    def __init__(self, rover: Rover) -> None:
        self._rover = rover

    def read(self) -> tuple[float, float]:
        return self._rover.left_travel, self._rover.right_travel

    @property
    def wheel_base(self) -> float:
        return self._rover.config.wheel_base


class Wheels:
    """The drive: wheel rim speeds, or a forward speed and turn rate."""

    def __init__(self, rover: Rover) -> None:
        self._rover = rover

    def set_speeds(self, left: float, right: float) -> None:
        self._rover.wheels(left, right)

    def drive(self, v: float, w: float) -> None:
        self._rover.drive(v, w)

    def stop(self) -> None:
        """Zero speeds; what was asked before no longer counts towards being blocked, so a
        module may try again at once after a blocked motion."""
        self._rover.wheels(0.0, 0.0)
        self._rover.forget_progress()

    @property
    def blocked(self) -> bool:
        return self._rover.blocked


class RangeSensor:
    """Range finders around or in front of the robot, occluded by the world's obstacles: a ring
    of sonars, a laser scanner. Angles are relative to the robot's heading; each
    beam is cast from the robot's centre and its range read from `offset` along it (the body's
    edge), so a reading r puts the echo at r + offset from the centre."""

    def __init__(self, rover: Rover, caster: RayCaster, angles: np.ndarray, max_range: float, noise: float,
                 rng: np.random.Generator, offset: float = 0.0) -> None:
        self._rover = rover
        self._caster = caster
        self._angles = angles
        self._units = unit_directions(angles)
        self.max_range = max_range
        self.noise = noise
        self._rng = rng
        self.offset = offset
        # The ranges without noise from the last pose cast from: a robot stands still for most of
        # a mission (planning, photos, waiting for a window), and the world's obstacles never move.
        self._last_cast: tuple[tuple[float, float, float], np.ndarray] | None = None

    @property
    def angles(self) -> np.ndarray:
        """The beams' angles from the heading (fixed: their directions are computed once)."""
        return self._angles

    def read(self) -> np.ndarray:
        pose = self._rover.pose
        if self._last_cast is None or self._last_cast[0] != pose:
            x, y, theta = pose
            self._last_cast = pose, self._caster.fan(x, y, theta, self._units, self.max_range + self.offset)
        distances = self._last_cast[1] - self.offset
        if self.noise > 0.0:
            distances += self.noise * self._rng.standard_normal(len(distances))
        # np.clip costs twice as much on a few dozen values
        return np.minimum(np.maximum(distances, 0.0, out=distances), self.max_range, out=distances)


@dataclass
class Axis:
    """One motorised axis moving towards its target at a bounded speed."""

    position: float
    target: float
    speed: float

    def advance(self, dt: float) -> None:
        if self.position == self.target:
            return
        error = self.target - self.position
        step = self.speed * dt
        self.position = self.target if abs(error) <= step else self.position + math.copysign(step, error)

    @property
    def moving(self) -> bool:
        return self.position != self.target


class PanTilt:
    """The camera's pan-tilt unit (seed 004: PLATINE)."""

    def __init__(self, pan_speed: float, tilt_speed: float) -> None:
        self.pan = Axis(0.0, 0.0, pan_speed)
        self.tilt = Axis(0.0, 0.0, tilt_speed)

    def point(self, pan: float, tilt: float) -> None:
        self.pan.target, self.tilt.target = wrap(pan), max(-math.pi / 2, min(math.pi / 2, tilt))

    def advance(self, dt: float) -> None:
        self.pan.advance(dt)
        self.tilt.advance(dt)

    @property
    def moving(self) -> bool:
        return self.pan.moving or self.tilt.moving


class Arm:
    """A manipulator's joints and gripper (seed 000 §5.2.3: simulated, as in the seed)."""

    def __init__(self, joints: int, speed: float) -> None:
        self.joints = [Axis(0.0, 0.0, speed) for _ in range(joints)]
        self.grip = "OPEN"
        # Who commands the arm: the simulation asks its modules which activity's codel runs, so a
        # log can say which request moved it.
        self.commander: Callable[[], object] = lambda: None
        self.moved_by: object = None  # what `commander` answered at the last command

    def reset(self, q: list[float]) -> None:
        """The arm is at `q` (where it stands when the robot starts)."""
        self.move_to(q)
        for joint in self.joints:
            joint.position = joint.target

    def move_to(self, q: list[float]) -> None:
        if len(q) != len(self.joints):
            raise ValueError(f"the arm has {len(self.joints)} joints, not {len(q)}")
        self.moved_by = self.commander()
        for joint, target in zip(self.joints, q, strict=True):
            joint.target = target

    def advance(self, dt: float) -> None:
        for joint in self.joints:
            joint.advance(dt)

    @property
    def q(self) -> list[float]:
        return [j.position for j in self.joints]

    @property
    def moving(self) -> bool:
        return any(j.moving for j in self.joints)


@dataclass(frozen=True)
class Sighting:
    index: int  # in Simulation.objects
    x: float
    y: float
    r: float  # from the camera
    bearing: float  # from the camera axis
    reliability: float


class Camera:
    """A camera on the pan-tilt unit with the detection model of seed 000 §5.2.4: objects within
    [r_min, r_max] and the field of view, not hidden by an obstacle, are detected each with
    probability f(r, θ)."""

    def __init__(self, rover: Rover, caster: RayCaster, pan_tilt: PanTilt, r_min: float, r_max: float,
                 theta_open: float, rng: np.random.Generator) -> None:
        self._rover = rover
        self._caster = caster
        self._pan_tilt = pan_tilt
        self.r_min, self.r_max, self.theta_open = r_min, r_max, theta_open
        self._rng = rng

    def reliability(self, r: float, theta: float) -> float:
        return reliability(r, theta, self.r_min, self.r_max, self.theta_open)

    def axis(self) -> tuple[float, float, float]:
        """Where the camera is and looks: x, y, heading (world frame)."""
        x, y, theta = self._rover.pose
        return x, y, wrap(theta + self._pan_tilt.pan.position)

    def in_view(self, points: list[tuple[float, float]]) -> list[Sighting]:
        """The points the camera could see now (in range, in the field, not occluded)."""
        x, y, heading = self.axis()
        candidates = []
        for index, (px, py) in enumerate(points):
            r = math.hypot(px - x, py - y)
            bearing = wrap(math.atan2(py - y, px - x) - heading)
            f = self.reliability(r, bearing)
            if f > 0.0:
                candidates.append(Sighting(index, px, py, r, bearing, f))
        if not candidates:
            return []
        # One cast for every candidate: hidden when something is nearer along its line of sight.
        angles = np.array([heading + s.bearing for s in candidates])
        free = self._caster.cast(x, y, angles, self.r_max)
        return [s for s, reach in zip(candidates, free, strict=True) if reach >= s.r - 1e-9]

    def detect(self, points: list[tuple[float, float]]) -> list[Sighting]:
        """One image: each point in view is detected with probability f (one random draw each)."""
        return [s for s in self.in_view(points) if self._rng.random() < s.reliability]


class Antenna:
    """Communication with the orbiter: possible only inside a visibility window (seed 004)."""

    def __init__(self, windows: tuple[Window, ...], now: Callable[[], float]) -> None:
        self.windows = windows
        self._now = now
        self.sent: list[tuple[float, float, str]] = []  # (start, end, window name) of each communication

    def window(self) -> Window | None:
        t = self._now()
        return next((w for w in self.windows if w.start <= t <= w.end), None)

    def record(self, start: float, end: float) -> Window | None:
        """A communication from start to end: it succeeds when one window holds all of it, and
        that window is returned (None when it failed)."""
        window = next((w for w in self.windows if w.start <= start and end <= w.end), None)
        if window is not None:
            self.sent.append((start, end, window.name))
        return window
