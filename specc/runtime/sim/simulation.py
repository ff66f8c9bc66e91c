"""A simulated robot in a world, stepping on the event kernel the modules run on.

    sim = Simulation(load_world("worlds/W2.toml"), RobotConfig(radius=0.3, laser_beams=181), seed=7)
    sim.attach(registry)          # codels reach the devices as `sdi.hardware`
    registry.kernel.run_for(60.0)
    sim.trace                     # what happened, for pictures and tests

Physics runs on the kernel at a fixed period, before any exec task due at the same instant, so
every codel reads the state of its instant and every command takes effect at the next step.
Each source of randomness has its own stream spawned from the seed: the same seed gives the same
run, and drawing more sonar noise does not change where the objects are.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from specc.runtime.body import DEVICES as DEVICES  # re-exported: the devices a body has
from specc.runtime.hints import did_you_mean
from specc.runtime.kernel import Kernel
from specc.runtime.sim.devices import Antenna, Arm, Camera, Encoders, PanTilt, RangeSensor, Wheels
from specc.runtime.sim.rays import RayCaster
from specc.runtime.sim.rover import RobotConfig, Rover
from specc.runtime.sim.world import World, WorldError

PHYSICS_PRIORITY = -1000  # before the exec tasks of the same instant
OBJECT_CLEARANCE = 0.45  # m: random objects are placed at least this far from walls and obstacles
SCATTER_TRIES = 1000  # random places tried in a row for one object before giving up


# What a system's `devices { module: device, ...; }` may give a module's codels (`sdi.hardware`):
# actuators and sensors, the robot's true pose (a localisation), the world's objects. Whatever a
# module is given, it also sees the world, the body, the trace and the clock (COMMON).
COMMON = ("world", "robot", "trace", "now", "physics_period", "kernel", "seed")


class DeviceView:
    """A module's view of the simulation: the devices the system gives it, and COMMON."""

    def __init__(self, sim: Simulation, module: str, devices: tuple[str, ...]) -> None:
        object.__setattr__(self, "_sim", sim)
        object.__setattr__(self, "_module", module)
        object.__setattr__(self, "_allowed", frozenset(devices) | frozenset(COMMON))

    def __getattr__(self, name: str) -> Any:
        if name not in self._allowed:
            given = ", ".join(sorted(self._allowed - frozenset(COMMON))) or "none"
            raise AttributeError(f"module '{self._module}' has no device '{name}'{did_you_mean(name, self._allowed)}: "
                                 f"the system gives it {given} (add it to the system's devices "
                                 f"{{ {self._module}: ...; }})")
        return getattr(self._sim, name)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"module '{self._module}' cannot replace the simulation's '{name}'")


class _Grants(dict[str, DeviceView]):
    """Each module's view, made when its codels first ask (a module no grant names gets none)."""

    def __init__(self, sim: Simulation, devices: Mapping[str, tuple[str, ...]]) -> None:
        super().__init__()
        self.sim = sim
        self.devices = devices

    def __missing__(self, module: str) -> DeviceView:
        view = self[module] = DeviceView(self.sim, module, tuple(self.devices.get(module, ())))
        return view


@dataclass
class Trace:
    """What a run leaves behind: the true path, and what the codels chose to note."""

    times: list[float] = field(default_factory=list)
    poses: list[tuple[float, float, float]] = field(default_factory=list)  # true x, y, theta
    estimated: list[tuple[float, float, float, float]] = field(default_factory=list)  # t, odometry x, y, theta
    paths: list[list[tuple[float, float]]] = field(default_factory=list)  # planned trajectories
    detected: set[int] = field(default_factory=set)  # objects seen by the camera
    taken: set[int] = field(default_factory=set)  # objects picked up or photographed
    photos: list[tuple[float, str, bool]] = field(default_factory=list)  # time, target, success
    certainty: tuple[float, int, int, list[float]] | None = None  # cell size, nx, ny, c per cell
    goal: tuple[float, float] | None = None  # the observation position last chosen
    blocked_at: float | None = None  # when the rover was first found blocked

    def path_array(self) -> np.ndarray:
        return np.asarray(self.poses, dtype=float).reshape(-1, 3)


class Simulation:
    if not TYPE_CHECKING:  # hidden from mypy, which would otherwise accept any attribute of specc's own code
        def __getattr__(self, name: str) -> Any:
            """Only for a name the simulation lacks: a codel's misspelt device, named with a hint."""
            if name.startswith("_"):  # Python's own lookups (copying, pickling): the usual error
                raise AttributeError(name)
            known = [n for n in (*dir(type(self)), *vars(self)) if not n.startswith("_")]
            raise AttributeError(f"the simulation has no device '{name}'{did_you_mean(name, known)}")

    def __init__(self, world: World, robot: RobotConfig | None = None, *, seed: int = 0, kernel: Kernel | None = None,
                 physics_period: float = 0.025, trace_period: float = 0.1) -> None:
        self.world = world
        robot = robot if robot is not None else RobotConfig()
        self.robot = robot
        self.seed = seed
        self.kernel = kernel or Kernel()
        self.physics_period = physics_period
        streams = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(4)]
        encoder_rng, range_rng, camera_rng, object_rng = streams
        self.rover = Rover(world, robot, encoder_rng)
        self.caster = RayCaster.for_world(world)
        self.wheels = Wheels(self.rover)
        self.encoders = Encoders(self.rover)
        edge = robot.radius if robot.length == 0 else robot.length / 2.0
        self.sonars = RangeSensor(self.rover, self.caster, np.linspace(0.0, math.tau, robot.sonars, endpoint=False),
                                  robot.sonar_range, robot.sonar_noise, range_rng, offset=edge) \
            if robot.sonars else None
        self.laser = RangeSensor(self.rover, self.caster,
                                 np.linspace(-robot.laser_fov / 2.0, robot.laser_fov / 2.0, robot.laser_beams),
                                 robot.laser_range, robot.laser_noise, range_rng, offset=edge) \
            if robot.laser_beams else None
        self.pan_tilt = PanTilt(robot.pan_speed, robot.tilt_speed)
        self.camera = Camera(self.rover, self.caster, self.pan_tilt, robot.camera_r_min, robot.camera_r_max,
                             robot.camera_open, camera_rng)
        self.arm = Arm(robot.arm_joints, robot.arm_speed) if robot.arm_joints else None
        self.antenna = Antenna(world.windows, lambda: self.kernel.now)
        self.objects = list(world.objects) + self._scatter(world.random_objects, object_rng)
        self.trace = Trace()
        self._trace_every = max(1, round(trace_period / physics_period))
        self._steps = 0
        self._record()
        self.kernel.call_every(physics_period, self._tick, PHYSICS_PRIORITY)

    # ------------------------------------------------------------ set-up
    def attach(self, registry: Any, devices: Mapping[str, tuple[str, ...]] | None = None) -> Simulation:
        """Give a module registry's codels this robot's devices (`sdi.hardware`): every device to
        every module, or when `devices` is given (module -> device names, DEVICES), to each
        module those it names alone (a module it does not name gets none)."""
        if registry.kernel is not self.kernel:
            raise ValueError("the simulation and the modules must share one kernel: "
                             "create the Simulation with kernel=registry.kernel")
        registry.hardware = self
        if devices is not None:
            registry.hardware_for = _Grants(self, devices)
        if self.arm is not None:
            self.arm.commander = lambda: registry.current  # the activity whose codel moves it
        return self

    def _scatter(self, count: int, rng: np.random.Generator) -> list[tuple[float, float]]:
        xmin, xmax, ymin, ymax = self.world.bounds
        placed: list[tuple[float, float]] = []
        misses = 0  # in a row: a count the room cannot hold ends the search, however large it is
        while len(placed) < count and misses < SCATTER_TRIES:
            x, y = float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax))
            if self.world.clearance(x, y) >= OBJECT_CLEARANCE and all(
                    math.hypot(x - px, y - py) >= OBJECT_CLEARANCE for px, py in placed):
                placed.append((round(x, 3), round(y, 3)))
                misses = 0
            else:
                misses += 1
        if len(placed) < count:
            raise WorldError(f"{self.world.source or self.world.name}: no room for {count} objects "
                             f"{OBJECT_CLEARANCE} m clear of the obstacles")
        return placed

    # ------------------------------------------------------------ running
    def _tick(self) -> None:
        dt = self.physics_period
        self.rover.step(dt)
        self.pan_tilt.advance(dt)
        if self.arm is not None:
            self.arm.advance(dt)
        self._steps += 1
        if self.trace.blocked_at is None and self.rover.blocked:
            self.trace.blocked_at = self.now
        if self._steps % self._trace_every == 0:
            self._record()

    def _record(self) -> None:
        self.trace.times.append(self.kernel.now)
        self.trace.poses.append(self.rover.pose)

    def run_for(self, seconds: float) -> None:
        self.kernel.run_for(seconds)

    @property
    def now(self) -> float:
        return self.kernel.now

    @property
    def pose(self) -> tuple[float, float, float]:
        """The robot's true pose (what odometry estimates)."""
        return self.rover.pose
