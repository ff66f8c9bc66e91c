"""A simulated robot's body: its footprint, drive and devices, as a system's `body { }` block
declares them.

    body {
      radius: 0.3;            // m: a disc footprint (or length and width: a box)
      mass: 40;               // kg
      wheel_base: 0.4;        // m between the drive wheels
      max_wheel_speed: 0.6;   // m/s at the wheel rims
      laser_beams: 91;        // a planar laser scanner facing forward
      laser_fov: 180;         // deg
    }

Every key of the block is a field of `RobotConfig`, in the unit its metadata names; angles are
written in degrees and held in radians. This module imports nothing heavy, so that `specc check`
can validate a body without loading the physics.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any, NamedTuple

from specc.runtime.hints import did_you_mean

COUNT, LENGTH, MASS, SPEED, ACCEL, RATIO, ANGLE, TURN_RATE = "", "m", "kg", "m/s", "m/s²", "ratio", "deg", "deg/s"
# The devices of the simulated body (`specc.runtime.sim.simulation`) a module's codels may own.
DEVICES = ("wheels", "encoders", "sonars", "laser", "camera", "pan_tilt", "arm", "antenna", "pose", "objects")


def _key(default: float | int, unit: str, doc: str) -> Any:
    return field(default=default, metadata={"unit": unit, "doc": doc})


@dataclass(frozen=True)
class RobotConfig:
    """The simulated robot's body, drive, and devices (lengths in m, angles in rad)."""

    name: str = "robot"
    radius: float = _key(0.3, LENGTH, "the footprint is a disc of this radius, unless length and width are given")
    length: float = _key(0.0, LENGTH, "with width: a length x width box footprint instead of the disc")
    width: float = _key(0.0, LENGTH, "the box footprint's width")
    mass: float = _key(60.0, MASS, "the body's mass")
    wheel_base: float = _key(0.6, LENGTH, "distance between the two drive wheels")
    max_wheel_speed: float = _key(1.0, SPEED, "speed limit at the wheel rims")
    max_wheel_accel: float = _key(1.0, ACCEL, "the motors' speed loops ramp towards what is asked at this rate")
    traction: float = _key(0.8, RATIO, "friction coefficient: bounds the force the wheels can exert")
    encoder_noise: float = _key(0.0, RATIO, "relative standard deviation of each wheel's measured travel")
    encoder_bias: float = _key(0.0, RATIO, "relative error on the right wheel's radius (a calibration fault)")
    sonars: int = _key(0, COUNT, "a ring of range finders, evenly spaced, the first one facing forward")
    sonar_range: float = _key(5.0, LENGTH, "the sonars' longest range")
    sonar_noise: float = _key(0.01, LENGTH, "standard deviation of a sonar reading")
    laser_beams: int = _key(0, COUNT, "beams of a planar laser scanner facing forward (0: no laser)")
    laser_fov: float = _key(math.pi, ANGLE, "the laser's field of view")
    laser_range: float = _key(30.0, LENGTH, "the laser's longest range")
    laser_noise: float = _key(0.01, LENGTH, "standard deviation of a laser reading")
    camera_r_min: float = _key(0.5, LENGTH, "the camera's detector sees nothing nearer (seed 000 §5.2.4)")
    camera_r_max: float = _key(4.0, LENGTH, "... nor farther")
    camera_open: float = _key(math.radians(60), ANGLE, "the camera's field of view")
    pan_speed: float = _key(math.radians(60), TURN_RATE, "the pan-tilt unit's pan speed")
    tilt_speed: float = _key(math.radians(60), TURN_RATE, "the pan-tilt unit's tilt speed")
    arm_joints: int = _key(0, COUNT, "joints of the arm (0: no arm)")
    arm_speed: float = _key(0.5, TURN_RATE, "each arm joint's speed")

    @classmethod
    def from_spec(cls, name: str, values: Mapping[str, float | int]) -> RobotConfig:
        """The body a `body { }` block declares: its values in the units of BODY_KEYS (degrees
        for angles), every other key at its default. ValueError for a key that is no body key or
        a value it cannot take (`body_problem`: what `specc check` says of a body block)."""
        converted: dict[str, Any] = {}
        for key, value in values.items():
            spec = BODY_KEYS.get(key)
            if spec is None:
                close = did_you_mean(key, BODY_KEYS)
                raise ValueError(f"body '{name}': no key '{key}'" + (close or f"; keys: {', '.join(BODY_KEYS)}"))
            problem = body_problem(key, float(value))
            if problem is not None:
                raise ValueError(f"body '{name}': {problem}")
            if spec.is_count:
                converted[key] = int(value)
            else:  # a float field holds a float (`mass: 120` is 120.0), as a log writes it
                converted[key] = math.radians(value) if spec.unit in (ANGLE, TURN_RATE) else float(value)
        return cls(name=name, **converted)


class BodyKey(NamedTuple):
    name: str
    unit: str  # "" for a count (a whole number)
    default: float | int
    doc: str

    @property
    def is_count(self) -> bool:
        return self.unit == COUNT

    def spec_default(self) -> float | int:
        """The default as a body block writes it (degrees for angles)."""
        return math.degrees(self.default) if self.unit in (ANGLE, TURN_RATE) else self.default


# What a `body { }` block may set, in the block's units.
BODY_KEYS: dict[str, BodyKey] = {
    f.name: BodyKey(f.name, f.metadata["unit"], f.default, f.metadata["doc"])  # type: ignore[arg-type]
    for f in fields(RobotConfig) if "unit" in f.metadata
}


MAX_COUNT = 10_000  # sonars, laser beams, arm joints: past it a reading alone would take seconds and gigabytes


def body_problem(key: str, value: float) -> str | None:
    """Why `value` cannot be the body's `key` (None when it can): counts are whole numbers up to
    MAX_COUNT, every value is finite and not negative, the footprint is not empty."""
    spec = BODY_KEYS[key]
    if not math.isfinite(value) or value < 0:
        return f"'{key}' must be a finite number >= 0 ({spec.unit or 'a count'})"
    if spec.is_count and value != int(value):
        return f"'{key}' is a count: give a whole number"
    if spec.is_count and value > MAX_COUNT:
        return f"'{key}' is {value:g}: at most {MAX_COUNT:,} (each is simulated at every reading)"
    if key in POSITIVE and value == 0:
        return f"'{key}' must be > 0 ({spec.unit}): {POSITIVE[key]}"
    if spec.unit == ANGLE and value > 360:
        return f"'{key}' is {value:g} degrees: at most 360"
    return None


# The keys a zero makes meaningless, and what it would mean.
POSITIVE = {
    "radius": "the footprint would be empty", "wheel_base": "the wheels would be one", "mass": "no body",
    "max_wheel_speed": "the robot could never move", "max_wheel_accel": "the wheels could never speed up",
    "sonar_range": "the sonars would see nothing", "laser_range": "the laser would see nothing",
    "laser_fov": "the laser would see nothing", "camera_r_max": "the camera would see nothing",
    "camera_open": "the camera would see nothing", "pan_speed": "the pan-tilt unit could never pan",
    "tilt_speed": "the pan-tilt unit could never tilt", "arm_speed": "the arm could never move",
}
