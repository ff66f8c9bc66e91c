"""How a compiled robot runs, as its `system` block says: the blocks it is made of, its
simulated body, its worlds and its missions (`generated/<robot>/systems/<name>.py` holds one
`SystemSpec`; `specc.run` drives any robot from it)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from specc.runtime.body import RobotConfig

DEFAULT_HORIZON = 600.0  # s of simulated time a mission without a horizon may run


@dataclass(frozen=True)
class MissionSpec:
    """What a mission asks: the goals posted to the supervisor together at the start, in one of
    the system's worlds, for at most `horizon` seconds of simulated time."""

    name: str
    world: str  # a name of SystemSpec.worlds
    goals: tuple[str, ...] = ()  # PRS goals, as text: "!(DELIVER A)"
    horizon: float | None = None


@dataclass(frozen=True)
class SystemSpec:
    name: str
    modules: tuple[str, ...] = ()
    executive: str | None = None  # the executive block's name
    supervisor: str | None = None  # the procedures block's name
    planning: str | None = None  # the ftplan block's name
    extension: str | None = None  # Python module of the robot's own run hooks (specc.run.mission)
    body: RobotConfig = field(default_factory=RobotConfig)
    worlds: Mapping[str, str] = field(default_factory=dict)  # name -> world file, relative to the robot's folder
    missions: Mapping[str, MissionSpec] = field(default_factory=dict)
