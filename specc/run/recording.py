"""What both runners write into a log so that it can be redrawn alone (`specc replay`): the
world the run took place in, and the robot's true pose at a steady rate."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from specc.runtime.sim import Simulation, World, world_data

POSE_PERIOD = 0.5  # s of simulated time between two `pose` events: 2 Hz draws the paths smoothly enough
POSE_PRIORITY = 1001  # after the physics and the codels of the instant (and after the hunt's motion sampler)
POSE_DIGITS = 3  # mm, and mrad for theta

Emit = Callable[..., Any]  # EventLog.emit's signature: (time, kind, **fields)


def true_path(sim: Simulation) -> tuple[tuple[float, float, float, float], ...]:
    """The simulator's trace of the true pose: t, x, y, theta rows (mm, ms and 0.1 mrad)."""
    return tuple((round(t, 3), round(x, 3), round(y, 3), round(theta, 4))
                 for t, (x, y, theta) in zip(sim.trace.times, sim.trace.poses, strict=True))


def world_fields(world: World) -> dict[str, Any]:
    """The `mission-start` fields that name the world and carry it whole."""
    return {"world": world.name, "world_data": world_data(world)}


class PoseRecorder:
    """Emits `pose` (x, y, theta: the simulator's true pose) every `period` simulated seconds from
    now, on the kernel's clock, for as long as the kernel runs."""

    def __init__(self, emit: Emit, sim: Simulation, period: float = POSE_PERIOD) -> None:
        self.emit = emit
        self.sim = sim
        self.period = period

    def start(self) -> PoseRecorder:
        self._record()
        self.sim.kernel.call_every(self.period, self._record, POSE_PRIORITY)
        return self

    def _record(self) -> None:
        x, y, theta = self.sim.pose
        self.emit(self.sim.kernel.now, "pose", x=round(x, POSE_DIGITS), y=round(y, POSE_DIGITS),
                  theta=round(theta, POSE_DIGITS))
