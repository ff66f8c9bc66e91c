"""What an `ftplan` block compiles to (seed 004 ch. 3): the planners and their order, the
recovery policy, the watchdog, the plan analyzer's constraints and the rules that keep FTplan's
own state of the system up to date from the execution reports. The back end `ftplan` writes these
as data in the generated package; the runtime reads nothing else."""

from __future__ import annotations

from dataclasses import dataclass, replace

Value = float | str

# Heuristics specc's planner can be configured with. It has a single search order so far: a
# planner block naming any heuristic is refused (by `specc check` and by the planner's process)
# rather than silently planned with another one.
HEURISTICS: frozenset[str] = frozenset()


@dataclass(frozen=True)
class Var:
    """A `?name` of a rule, bound by matching a task's or a report's arguments."""

    name: str


Term = Var | float | str


@dataclass(frozen=True)
class PlannerConfig:
    name: str
    domain: str  # the planning domain's name (a module of the generated `planner` package)
    heuristic: str | None = None
    # "module:callable" building, inside the planner's own process, the object whose
    # `plan(problem, now)` answers a planning request; the default is specc's planner on `domain`.
    factory: str = "specc.runtime.ftplan.planners:standard_planner"


@dataclass(frozen=True)
class Requirement:
    """`during|at_start|at_end TASK(args) requires ATTRIBUTE(args): value` (§3.1.1)."""

    kind: str  # during | at_start | at_end
    task: str
    args: tuple[Term, ...]
    attribute: str
    attribute_args: tuple[Term, ...]
    value: Term
    line: int = 0


@dataclass(frozen=True)
class NoOverlap:
    """No instance of `first` overlaps an instance of `second` (a task named twice: of itself)."""

    first: str
    second: str
    line: int = 0


@dataclass(frozen=True)
class MaxDuration:
    task: str
    seconds: float
    line: int = 0


AnalyzerRule = Requirement | NoOverlap | MaxDuration


@dataclass(frozen=True)
class FactUpdate:
    attribute: str
    args: tuple[Term, ...]
    value: Term


@dataclass(frozen=True)
class StateRule:
    """`on ended|failed TASK(args) => updates` or `on report NAME(args) => updates`."""

    report: str  # ended | failed | report
    name: str  # the task, or the report's name
    args: tuple[Term, ...]
    updates: tuple[FactUpdate, ...]
    line: int = 0


@dataclass(frozen=True)
class FtPlanConfig:
    name: str
    planners: tuple[PlannerConfig, ...]  # in the order successive planning tries them
    policy: str = "successive"  # successive | concurrent
    watchdog: float = 10.0  # seconds of planning before a planner is judged failed
    analyzer: tuple[AnalyzerRule, ...] = ()
    state_rules: tuple[StateRule, ...] = ()


def configurations(config: FtPlanConfig) -> dict[str, FtPlanConfig]:
    """The robot configurations of seed 004 §4.2.1.1, named as there: `Robot1`, `Robot2`... (each
    planner alone), `Robot1/2` (all of them, successive planning in the block's order) and
    `Robot1/2c` (all of them, concurrent planning)."""
    numbers = [str(k) for k in range(1, len(config.planners) + 1)]
    made = {f"Robot{n}": replace(config, planners=(planner,), policy="successive")
            for n, planner in zip(numbers, config.planners, strict=True)}
    if len(config.planners) > 1:
        together = "Robot" + "/".join(numbers)
        made[together] = replace(config, policy="successive")
        made[together + "c"] = replace(config, policy="concurrent")
    return made
