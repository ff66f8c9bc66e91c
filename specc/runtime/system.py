"""How a compiled robot runs, as its `system` block says: the blocks it is made of, its
simulated body, its worlds and its missions (`generated/<robot>/systems/<name>.py` holds one
`SystemSpec`; `specc.run` drives any robot from it)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from specc.runtime.body import RobotConfig
from specc.runtime.ftplan.config import Term

DEFAULT_HORIZON = 600.0  # s of simulated time a mission without a horizon may run


@dataclass(frozen=True)
class MissionSpec:
    """What a mission asks: the goals posted to the supervisor together at the start, and/or the
    mission of the ftplan block FTplan plans and carries out, in one of the system's worlds, for
    at most `horizon` seconds of simulated time."""

    name: str
    world: str  # a name of SystemSpec.worlds
    goals: tuple[str, ...] = ()  # PRS goals, as text: "!(DELIVER A)"
    horizon: float | None = None
    plan: str | None = None  # a mission of the ftplan block


@dataclass(frozen=True)
class StateValue:
    """A binding's argument: the value FTplan's state rules give `attribute(args)` when the action
    ends (in FTplan's vocabulary, whichever planner's task it is)."""

    attribute: str
    args: tuple[Term, ...] = ()


@dataclass(frozen=True)
class ReportSpec:
    """`report NAME(module.Poster.field, ...)`: what is reported to FTplan when the action is over."""

    name: str
    paths: tuple[str, ...] = ()


@dataclass(frozen=True)
class StateCondition:
    """`where ATTR(?o, ...) := VALUE`: the first of FTplan's state changes at the action's end
    that reads so binds the ?variables of `args`."""

    attribute: str
    args: tuple[Term, ...]
    value: Term


@dataclass(frozen=True)
class BindingSpec:
    """How the planners' task `task` is carried out: `kind` goal (the supervisor achieves the
    goal `target`), service (the executive runs the service `target`) or request (the module
    request `target`, module.request), with `target_args` made of the task's arguments."""

    task: str
    args: tuple[Term, ...]  # ?variables (or constants the action's arguments must equal)
    kind: str
    target: str
    target_args: tuple[Term | StateValue, ...] = ()
    report: ReportSpec | None = None
    where: StateCondition | None = None


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
    bindings: Mapping[str, BindingSpec] = field(default_factory=dict)  # by task
    devices: Mapping[str, tuple[str, ...]] | None = None  # module -> the devices its codels drive; None: all
