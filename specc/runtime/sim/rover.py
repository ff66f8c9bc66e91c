"""The differential-drive rover in a pymunk space, in metres.

The rover is a dynamic body pulled by a kinematic *control body* through a pivot joint and a
gear joint whose forces are bounded (pymunk's top-down "tank" arrangement): the wheels ask for
a velocity, friction-limited forces try to give it, and a wall simply wins. Overwriting the
body's velocity instead would push it through walls, since the solver would then have no say.

Wheel encoders count the travel of each wheel from the body's real motion, with seeded noise;
LOCO integrates them into odometry, which therefore drifts with noise and not without.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
import pymunk

from specc.runtime.body import RobotConfig
from specc.runtime.sim.world import Circle, World

GRAVITY = 9.81


class Rover:
    def __init__(self, world: World, config: RobotConfig, rng: np.random.Generator,
                 blocked_after: float = 2.0) -> None:
        self.config = config
        self.rng = rng
        self.space = pymunk.Space()
        self.space.gravity = (0.0, 0.0)
        # pymunk's defaults are tuned for pixels: 0.1 of slop would be 10 cm here.
        self.space.collision_slop = 0.002
        self.space.iterations = 10
        static = self.space.static_body
        shapes: list[pymunk.Shape] = [pymunk.Segment(static, (x1, y1), (x2, y2), 0.0)
                                      for x1, y1, x2, y2 in world.segments()]
        shapes += [pymunk.Circle(static, o.radius, (o.x, o.y)) for o in world.obstacles if isinstance(o, Circle)]
        for shape in shapes:
            shape.friction = 0.5
        self.space.add(*shapes)

        if config.length > 0:
            moment = pymunk.moment_for_box(config.mass, (config.length, config.width))
            self.body = pymunk.Body(config.mass, moment)
            self.shape: pymunk.Shape = pymunk.Poly.create_box(self.body, (config.length, config.width), 0.01)
        else:
            moment = pymunk.moment_for_circle(config.mass, 0.0, config.radius)
            self.body = pymunk.Body(config.mass, moment)
            self.shape = pymunk.Circle(self.body, config.radius)
        self.shape.friction = 0.5
        x, y, theta = world.start
        self.body.position = (x, y)
        self.body.angle = theta
        self.control = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        self.control.position = (x, y)
        traction = config.traction * config.mass * GRAVITY
        pivot = pymunk.PivotJoint(self.control, self.body, (0.0, 0.0), (0.0, 0.0))
        pivot.max_bias = 0.0  # a velocity constraint only: no position correction
        pivot.max_force = traction
        gear = pymunk.GearJoint(self.control, self.body, 0.0, 1.0)
        gear.error_bias = 0.0
        gear.max_bias = 2.0 * config.max_wheel_speed / config.wheel_base
        gear.max_force = traction * config.wheel_base / 2.0
        self.space.add(self.body, self.shape, self.control, pivot, gear)
        # The body's pose as the last step left it: only a step moves the body, and reading it
        # back from pymunk costs more than the rest of a step's own arithmetic.
        (self._x, self._y), self._angle = self.body.position, self.body.angle

        self.left = self.right = 0.0  # commanded wheel rim speeds, m/s
        self.left_speed = self.right_speed = 0.0  # what the motors give, ramping towards them
        self.left_travel = self.right_travel = 0.0  # encoder counters, m
        self.time = 0.0
        self.distance = 0.0  # true distance travelled
        self.blocked_after = blocked_after
        self._progress: deque[tuple[float, float, float]] = deque()  # (time, commanded, achieved)
        self._asked = self._done = 0.0
        self._stuck = False

    # ------------------------------------------------------------ commands
    def drive(self, v: float, w: float) -> None:
        """Ask for a forward speed v (m/s) and a turn rate w (rad/s): wheel rim speeds, both scaled
        down alike when one would pass the wheels' limit, so that the robot keeps the curvature
        asked for (clipping each wheel alone would drive straight on when both saturate)."""
        half = w * self.config.wheel_base / 2.0
        left, right = v - half, v + half
        over = max(abs(left), abs(right)) / self.config.max_wheel_speed
        if over > 1.0:
            left, right = left / over, right / over
        self.wheels(left, right)

    def forget_progress(self) -> None:
        """A new start: motion asked before now no longer counts towards being blocked."""
        self._progress.clear()
        self._asked = self._done = 0.0
        self._stuck = False

    def wheels(self, left: float, right: float) -> None:
        limit = self.config.max_wheel_speed
        self.left, self.right = max(-limit, min(limit, left)), max(-limit, min(limit, right))

    # ------------------------------------------------------------ physics
    def step(self, dt: float) -> None:
        ramp = self.config.max_wheel_accel * dt
        self.left_speed += max(-ramp, min(ramp, self.left - self.left_speed))
        self.right_speed += max(-ramp, min(ramp, self.right - self.right_speed))
        v = (self.left_speed + self.right_speed) / 2.0
        w = (self.right_speed - self.left_speed) / self.config.wheel_base
        body = self.body
        x0, y0, a0 = self._x, self._y, self._angle
        # pymunk moves a body with the velocity the previous step solved, while it turns: the
        # velocity asked now carries the body during the next step, whose mid-heading is this
        # one, so that a rover that does not slip moves exactly as its odometry assumes.
        course = a0 + body.angular_velocity * dt + w * dt / 2.0
        self.control.velocity = (v * math.cos(course), v * math.sin(course))
        self.control.angular_velocity = w
        self.space.step(dt)
        (x1, y1), a1 = body.position, body.angle
        self._x, self._y, self._angle = x1, y1, a1
        # The encoders see the motion along the mid-step heading (sideways slip escapes them).
        middle = (a0 + a1) / 2.0
        forward = (x1 - x0) * math.cos(middle) + (y1 - y0) * math.sin(middle)
        turn = a1 - a0
        half = turn * self.config.wheel_base / 2.0
        left, right = forward - half, forward + half
        noise = self.config.encoder_noise
        if noise > 0.0:
            left *= 1.0 + noise * self.rng.standard_normal()
            right *= 1.0 + noise * self.rng.standard_normal()
        self.left_travel += left
        self.right_travel += right * (1.0 + self.config.encoder_bias)
        travelled = math.hypot(x1 - x0, y1 - y0)
        self.distance += travelled
        moved = travelled + abs(half)
        self.time += dt
        self._watch(dt, dt * (abs(v) + abs(w) * self.config.wheel_base / 2.0), moved)  # both in wheel metres

    def _watch(self, dt: float, commanded: float, achieved: float) -> None:
        """Blocked: over the last `blocked_after` seconds, the wheels asked for motion and the
        body achieved less than a fifth of it (running sums over a sliding window)."""
        self._progress.append((self.time, commanded, achieved))
        self._asked += commanded
        self._done += achieved
        while self._progress[0][0] <= self.time - self.blocked_after:
            _, old_asked, old_done = self._progress.popleft()
            self._asked -= old_asked
            self._done -= old_done
        full = self.time - self._progress[0][0] >= self.blocked_after - 1.5 * dt
        self._stuck = full and self._asked > 0.02 * self.blocked_after and self._done < 0.2 * self._asked

    # ------------------------------------------------------------ reading
    @property
    def pose(self) -> tuple[float, float, float]:
        """x, y and the heading in (-π, π] (pymunk's angle keeps counting turns)."""
        return float(self._x), float(self._y), math.remainder(float(self._angle), math.tau)

    @property
    def blocked(self) -> bool:
        """Asking for motion and hardly moving, for `blocked_after` seconds on end."""
        return self._stuck

    @property
    def in_contact(self) -> bool:
        """Touching a wall or an obstacle now."""
        return bool(self.space.shape_query(self.shape))
