"""What an `ftplan` block compiles to (seed 004 ch. 3): the planners and their order, the
recovery policy, the watchdog, the plan analyzer's constraints and the rules that keep FTplan's
own state of the system up to date from the execution reports. The back end `ftplan` writes these
as data in the generated package; the runtime reads nothing else."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

from specc.runtime.planner.heuristics import FLAW_ORDERS as PLANNER_FLAW_ORDERS
from specc.runtime.planner.heuristics import HEURISTICS as PLANNER_HEURISTICS
from specc.runtime.planner.model import Interval as Interval  # re-exported: the generated modules name it here

Value = float | str

# Heuristics specc's planner can be configured with (specc.runtime.planner.heuristics):
# a planner block naming another is refused (by `specc check` and by the planner's process)
# rather than silently planned with another one.
HEURISTICS: frozenset[str] = frozenset(PLANNER_HEURISTICS)
FLAW_ORDERS: frozenset[str] = frozenset(PLANNER_FLAW_ORDERS)


@dataclass(frozen=True)
class Var:
    """A `?name` of a rule, bound by matching a task's or a report's arguments."""

    name: str


Term = Var | float | str


@dataclass(frozen=True)
class FactPattern:
    """`ATTRIBUTE(args): value` in a correspondence."""

    attribute: str
    args: tuple[Term, ...]
    value: Term | Interval  # an interval: a value of FTplan's state read within these bounds


@dataclass(frozen=True)
class Correspondence:
    """`planner facts <=> state facts`: where FTplan's state holds the state facts, the planner
    reads the planner facts (`view.View.read`); where a planner-vocabulary rule sets the planner
    facts, FTplan's state gets the state facts (`view.View.write`)."""

    planner_facts: tuple[FactPattern, ...]
    state_facts: tuple[FactPattern, ...]
    line: int = 0


@dataclass(frozen=True)
class PlannerConfig:
    """One of FTplan's planners as the runtime runs it: its domain and search settings."""

    name: str
    domain: str  # the planning domain's name (a module of the generated `planner` package)
    heuristic: str | None = None
    # What its plans must hold against: "strong" (every choice of nature) or "pseudo" (the
    # problem's contingent instants one at a time, as IxTeT: specc.runtime.planner.search).
    controllability: str = "strong"
    # "module:callable" building, inside the planner's own process, the object whose
    # `plan(problem, now)` answers a planning request; the default is specc's planner on `domain`.
    factory: str = "specc.runtime.ftplan.planners:standard_planner"
    # How this planner's vocabulary reads FTplan's state; empty: it speaks the state's vocabulary.
    view: tuple[Correspondence, ...] = ()
    # Partial plans a planning may expand before it gives up (None: no limit); FTplan sets it
    # (component.planners_as_run), the spec does not.
    node_limit: int | None = None
    # IxTeT's plan repair after an action failure, before FTplan's recovery (`repair: on`).
    repair: bool = False
    # Partial plans spent improving each first plan (`improve: N`, anytime); under the cost model
    # the node limit caps them, so an improving planner is never late for it.
    improve: int = 0
    # Which task's open conditions the search solves first (`flaws:`; FLAW_ORDERS), None: the default.
    flaws: str | None = None


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
    """An analyser rule: the task must not last longer than `seconds`."""

    task: str
    seconds: float
    line: int = 0


AnalyzerRule = Requirement | NoOverlap | MaxDuration


@dataclass(frozen=True)
class FactUpdate:
    """A change of FTplan's state that an action's outcome makes."""

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
class MissionProblem:
    """The problem a planner plans for a mission."""

    planner: str
    problem: str  # the planner's statement of the mission
    domain: str  # the problem's domain: the one the planner plans it in


@dataclass(frozen=True)
class Mission:
    """A mission as each planner states it, and the correspondences that depend on it."""

    name: str
    problems: tuple[MissionProblem, ...]
    state_problem: str  # the problem in FTplan's state vocabulary: its facts and goals are FTplan's
    views: tuple[tuple[str, tuple[Correspondence, ...]], ...] = ()  # planner -> correspondences

    def problem_of(self, planner: str) -> MissionProblem | None:
        return next((p for p in self.problems if p.planner == planner), None)


@dataclass(frozen=True)
class FtPlanConfig:
    """The whole FTplan component as the runtime runs it."""

    name: str
    planners: tuple[PlannerConfig, ...]  # in the order successive planning tries them
    policy: str = "successive"  # successive | concurrent
    watchdog: float = 10.0  # seconds of planning before a planner is judged failed
    analyzer: tuple[AnalyzerRule, ...] = ()
    state_rules: tuple[StateRule, ...] = ()
    missions: tuple[Mission, ...] = ()

    def mission(self, name: str) -> Mission:
        found = next((m for m in self.missions if m.name == name), None)
        if found is None:
            known = ", ".join(m.name for m in self.missions) or "none"
            raise KeyError(f"ftplan '{self.name}' has no mission '{name}' (it has: {known})")
        return found

    def for_mission(self, name: str) -> FtPlanConfig:
        """This configuration on mission `name`: each planner plans in its problem's domain and
        reads FTplan's state through the mission's correspondences first, then its own."""
        mission = self.mission(name)
        views = dict(mission.views)
        planners = []
        for planner in self.planners:
            problem = mission.problem_of(planner.name)
            if problem is None:
                raise KeyError(f"mission '{name}' of ftplan '{self.name}' names no problem for planner "
                               f"'{planner.name}'")
            planners.append(replace(planner, domain=problem.domain,
                                    view=views.get(planner.name, ()) + planner.view))
        return replace(self, planners=tuple(planners))


WITHOUT_ANALYZER = "-noanalyzer"  # a configuration's name with this suffix: the same, plan analyzer off
WITH_REPAIR = "-repair"  # ... every planner repairing its plans after an action failure (IxTeT's)
WITHOUT_REPAIR = "-norepair"  # ... no planner repairing (seed 004 §4.2.1.2's Robot1*, Robot1/1*)
VARIANTS: dict[str, Callable[[FtPlanConfig], FtPlanConfig]] = {
    WITHOUT_ANALYZER: lambda c: replace(c, analyzer=()),
    WITH_REPAIR: lambda c: replace(c, planners=tuple(replace(p, repair=True) for p in c.planners)),
    WITHOUT_REPAIR: lambda c: replace(c, planners=tuple(replace(p, repair=False) for p in c.planners)),
}
VARIANTS_HELP = (f"add {WITHOUT_ANALYZER} to one for it without the plan analyzer, {WITH_REPAIR} or "
                 f"{WITHOUT_REPAIR} for every planner repairing its plans or none")


def configuration_named(configurations: Mapping[str, FtPlanConfig], name: str) -> FtPlanConfig:
    """The configuration `name` of `configurations`, or one of them with variant suffixes
    (VARIANTS, in any order): `<name>-noanalyzer` is it without the plan analyzer (the thesis'
    own FTplan, which never had one), `<name>-repair` / `<name>-norepair` with every planner
    repairing its plans after an action failure or none. A planner's own name stands for the
    configuration of that planner alone (`quick` for the Robot1 whose planner is quick). KeyError
    when unknown; ValueError when it names a variant twice, or both -repair and -norepair (which
    one was meant?)."""
    alone = {config.planners[0].name: key for key, config in configurations.items() if len(config.planners) == 1}
    base, applied = name, []
    while base not in configurations and base not in alone:
        suffix = next((v for v in VARIANTS if base.endswith(v)), None)
        if suffix is None:
            raise KeyError(name)
        if suffix in applied:
            raise ValueError(f"configuration '{name}' says {suffix} twice: once is enough")
        base = base.removesuffix(suffix)
        applied.append(suffix)
    if {WITH_REPAIR, WITHOUT_REPAIR} <= set(applied):
        raise ValueError(f"configuration '{name}' turns repair both on ({WITH_REPAIR}) and off ({WITHOUT_REPAIR}): "
                         "keep one of them")
    config = configurations[base] if base in configurations else configurations[alone[base]]
    for suffix in reversed(applied):
        config = VARIANTS[suffix](config)
    return config


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
