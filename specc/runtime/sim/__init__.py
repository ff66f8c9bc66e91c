"""The simulated robot of specc: a pymunk world in metres, a differential-drive rover and the
devices modules' codels use (range sensors, camera, pan-tilt unit, arm, antenna).

Headless, deterministic for a seed, and stepping on the same event kernel as the modules, so a
mission runs as fast as the computer allows (seed 004 §4.2.2 could only run Gazebo in real time).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from specc.runtime.lazy import lazy_exports

if TYPE_CHECKING:
    from specc.runtime.sim.devices import reliability
    from specc.runtime.sim.rover import RobotConfig, Rover
    from specc.runtime.sim.simulation import Simulation, Trace
    from specc.runtime.sim.world import (
        Circle,
        Polygon,
        Target,
        Window,
        World,
        WorldError,
        load_world,
        parse_world,
        world_data,
    )

# Each name imported where it is defined on first use (specc.runtime.lazy).
_OFFERS = {
    "devices": ("reliability",),
    "rover": ("RobotConfig", "Rover"),
    "simulation": ("Simulation", "Trace"),
    "world": ("Circle", "Polygon", "Target", "Window", "World", "WorldError", "load_world", "parse_world",
              "world_data"),
}

__getattr__ = lazy_exports(__name__, _OFFERS)


__all__ = ["Circle", "Polygon", "RobotConfig", "Rover", "Simulation", "Target",
           "Trace", "Window", "World", "WorldError", "load_world", "parse_world", "reliability", "world_data"]
