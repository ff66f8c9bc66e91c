"""Any robot's mission, run from its `system` block alone.

    robot = load_robot(Path("generated"), Path("examples/tug"), "tug")
    run = run_mission(robot, robot.mission("deliver"), seed=0, log=EventLog("deliver.jsonl"))
    run.outcome, run.why, run.simulated_time

The compiled package says everything (`specc.runtime.system.SystemSpec`): the modules run on one
kernel with the simulated body in the mission's world (codels reach its devices as
`sdi.hardware`), the executive over them (its input functions see the world file as
`ctx.world`), and the supervisor, to which the mission's goals are posted together. The run ends
when every goal has ended or at the mission's horizon; it succeeds when every goal succeeded.
Codels run with the robot's folder as the working directory, so the files they read are named
relative to it, as the specs name their worlds.

A robot's own Python beyond its codels, when a run needs it, is its system's `extension:` module
(beside the codels), whose functions, each optional, the runner calls:

- `prepare(world, setup) -> World`: the world as the run's own random draws make it (`setup`: a
  `RunSetup`, the seed, the mission, and for a planned mission FTplan's setup: its problem);
- `attach(run)`: once everything is built, with a `RunContext` (the kernel, simulation, modules,
  executive, supervisor; `run.emit(kind, **fields)` logs an event of its own kind,
  `run.at_end(callback)` is called when the mission ends);
- `measure(events) -> dict`: the robot's own figures, read from the log alone;
- `judge(events, measures, outcome, why) -> (outcome, why)`: its own success criteria.

What the log holds (`specc.run.events`): `mission-start` (the robot, mission, world, body, seed,
goals, horizon), each `goal` posted and ended, every `request`, `activity`, `reply` and
`warning` of the executive, every `fact` the procedures conclude or retract, `robot-motion`
and `arm-motion` from the simulator's true state, `pose` every 0.5 s, an `alarm` for every
incident (a permanent codel or a listener that raised, the executive's ERROR state, the robot
blocked), `mission-figures` (the distance, the requests, the incidents, FTplan's figures: what
the extension's `measure` reads), and `mission-end`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import importlib
import math
import time
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

from specc.run import RunError
from specc.run.events import EventLog, reply_succeeded
from specc.run.package import import_robot
from specc.run.plans import BoundExecutor, FtplanJournal, run_ftplan
from specc.run.recording import PoseRecorder, world_fields
from specc.runtime import executive as rx
from specc.runtime import functional as rt
from specc.runtime.system import DEFAULT_HORIZON, MissionSpec, SystemSpec

ROBOT_MOVING = 0.005  # m/s at the wheel rims: slower than this, the robot stands still
SAMPLE_PRIORITY = 1000  # the motion sampler runs after the physics and codels of its instant
PROGRESS_PERIOD = 10.0  # s of simulated time between two progress reports
FACT_OP = "=>"  # a mission's `goal: =>(FACT ...);`: concluded before the goals are posted, not one of them
# Characters a one-line summary keeps of one reason, and of what a bracket in it holds: a goal's
# reason may hold every planner's diagnostics, a page of them; the run's report.json keeps it whole.
REASON_WIDTH = 300
DETAIL_WIDTH = 120
OPENING, CLOSING = "([", ")]"


class MissionProgress(NamedTuple):
    """What `progress` receives every PROGRESS_PERIOD simulated seconds and at the end."""

    time: float
    horizon: float
    goals_done: int
    goals: int


@dataclass(frozen=True)
class Robot:
    """A compiled robot, imported: its system and the generated modules it runs."""

    name: str  # the package's
    folder: Path  # the robot's folder: its codels and worlds
    system: SystemSpec
    package: ModuleType

    def part(self, name: str) -> ModuleType:
        module: ModuleType = getattr(self.package, name)
        return module

    def mission(self, name: str) -> MissionSpec:
        """The system's mission `name` (case as written); RunError naming the missions there are."""
        missions = self.system.missions
        if name in missions:
            return missions[name]
        folded = {key.lower(): key for key in missions}
        if name.lower() in folded:
            return missions[folded[name.lower()]]
        known = ", ".join(missions) or "none: add a 'mission NAME { ... }' to the system block"
        raise RunError(f"robot '{self.name}' has no mission '{name}' (its missions: {known})")

    @functools.cached_property
    def extension(self) -> ModuleType | None:
        """The robot's own run hooks (the system's `extension:` module), imported from its folder."""
        name = self.system.extension
        if name is None:
            return None
        try:
            return importlib.import_module(name)
        except Exception as error:  # the user's module: any error is theirs to fix, said in one line
            raise RunError(f"robot '{self.name}': cannot import its extension {name} from {self.folder} "
                           f"({type(error).__name__}: {error})") from None

    def hook(self, name: str) -> Callable[..., Any] | None:
        """The extension's function `name` (prepare, attach, measure or judge: the module's
        docstring), None when it has none. What it raises (but a WorldError, which says what a
        world cannot give) becomes a RunError naming the hook and where it raised."""
        from specc.runtime.functional import where_raised
        from specc.runtime.sim import WorldError

        function = getattr(self.extension, name, None)
        if not callable(function):
            return None

        def guarded(*args: Any, **kwargs: Any) -> Any:
            try:
                return function(*args, **kwargs)
            except (WorldError, RunError):
                raise
            except Exception as error:  # the user's code: said where, as a codel's error is
                raise RunError(f"robot '{self.name}': its extension's {name}() raised {type(error).__name__}: "
                               f"{error}{where_raised(error)}") from error

        return guarded

    def world_file(self, name: str) -> Path:
        """The world file of the system's world `name`, or a world file's path: as given (from the
        current folder), else from the robot's folder, as the system block's worlds are."""
        worlds = self.system.worlds
        folded = {key.lower(): key for key in worlds}
        if name.lower() in folded:
            return self.folder / worlds[folded[name.lower()]]
        path = Path(name)
        if path.suffix == ".toml":
            for candidate in (path, self.folder / path):
                if candidate.is_file():
                    return candidate
            raise RunError(f"no world file '{name}' (looked from the current folder and from the robot's, "
                           f"{self.folder})")
        known = ", ".join(worlds) or "none: add 'worlds { NAME: \"file.toml\"; }' to the system block"
        raise RunError(f"robot '{self.name}' has no world '{name}' (its worlds: {known}; or give a .toml file)")


def load_robot(generated: Path, folder: Path, robot: str, system: str | None = None) -> Robot:
    """The compiled package `robot` from `generated`, with the codels of `folder`; its system
    `system` (default: its only one)."""
    package = import_robot(generated, folder, robot)
    systems: Mapping[str, SystemSpec] = package.systems.SYSTEMS if hasattr(package, "systems") else {}
    if not systems:
        raise RunError(f"robot '{robot}' has no system block: add 'system {robot} {{ modules: ...; }}' to its "
                       "specs to say how it runs")
    if system is None:
        if len(systems) > 1:
            raise RunError(f"robot '{robot}' has {len(systems)} systems ({', '.join(systems)}): name one")
        system = next(iter(systems))
    if system not in systems:
        raise RunError(f"robot '{robot}' has no system '{system}' (its systems: {', '.join(systems)})")
    return Robot(robot, folder.resolve(), systems[system], package)


@dataclass(frozen=True)
class RunSetup:
    """What a run is, before anything is built (an extension's `prepare`)."""

    robot: Robot
    mission: MissionSpec
    seed: int
    planning: Any = None  # specc.runtime.ftplan.MissionSetup for a planned mission (`.problem`...)


@dataclass
class RunContext:
    """What a robot's extension sees of a run in its `attach(run)` hook: the parts running, and
    the log to add its own events to."""

    robot: Robot
    mission: MissionSpec
    seed: int
    world: Any  # specc.runtime.sim.World, with what `prepare` drew
    sim: Any  # specc.runtime.sim.Simulation
    registry: rt.Registry
    executive: rx.Executive | None
    supervisor: Any  # specc.runtime.supervisor.Supervisor, or None
    log: FtplanJournal  # `log.events`: what the run logged so far
    ending: list[Callable[[], None]] = dataclasses.field(default_factory=list)

    @property
    def kernel(self) -> Any:
        return self.registry.kernel

    def emit(self, kind: str, **fields: Any) -> None:
        """An event of the extension's own kind, at the mission time now."""
        self.log.emit(self.kernel.now, kind, **fields)

    def at_end(self, callback: Callable[[], None]) -> None:
        """Call `callback` once the mission has ended, before `mission-end` is logged."""
        self.ending.append(callback)


@dataclass(frozen=True)
class MissionRun:
    robot: str
    mission: str
    world: str
    seed: int
    outcome: str  # succeeded | failed | horizon
    why: str
    goals: tuple[tuple[str, str], ...]  # (goal, status) in the order posted
    simulated_time: float
    wall_time: float
    distance: float  # m the robot really travelled
    requests: int
    replies: Mapping[str, int]  # "SERVICE RESULT" -> how many
    incidents: tuple[str, ...]
    events: tuple[dict[str, Any], ...]
    extension_measures: Mapping[str, Any] = dataclasses.field(default_factory=dict)  # the extension's `measure`

    def measures(self) -> dict[str, Any]:
        return {"goals_succeeded": sum(1 for _, status in self.goals if status == "succeeded"),
                "goals": len(self.goals), "distance": round(self.distance, 3), "requests": self.requests,
                "replies": dict(self.replies), "incidents": len(self.incidents), **self.extension_measures}

    def summary(self) -> str:
        lines = [f"{self.robot}'s mission {self.mission} in {self.world} (seed {self.seed}): "
                 f"{self.outcome}: {brief_why(self.why)}"]
        lines += [f"  {goal}: {status}" for goal, status in self.goals]
        lines.append(f"  {self.distance:.1f} m travelled, {self.requests} service request(s), "
                     f"{len(self.incidents)} incident(s)")
        lines += [f"  incident: {text}" for text in self.incidents[:5]]
        lines += self._measure_lines()
        factor = f" ({self.simulated_time / self.wall_time:.0f}x real time)" if self.wall_time > 0 else ""
        lines.append(f"  {self.simulated_time:.0f} s of mission in {self.wall_time:.1f} s of wall time{factor}")
        return "\n".join(lines)


    def _measure_lines(self) -> list[str]:
        """The run's figures: seed 004 §4.1.4's as its notation reads when the extension measured
        them; else each figure that is a number or a word."""
        from specc.run.measures import Measures, planned_measures

        if Measures.readable(self.extension_measures):
            return ["  " + line for line in Measures.from_json(self.extension_measures).summary().splitlines()]
        lines, shown = [], dict(self.extension_measures)
        if self.events and "planned_goals" in self.events[0]:  # FTplan's figures, read as seed 004 §4.1.4's
            measured = planned_measures(self.events)
            lines = ["  " + line for line in measured.summary().splitlines()]
            lines.append("  (each goal as FTplan's ledger counted it: the robot's extension judges none itself)")
            shown = {name: value for name, value in shown.items() if name not in PLANNED_FIGURES}
        return lines + [f"  {name}: {value}" for name, value in shown.items()
                        if isinstance(value, int | float | str) and value != ""]


# What a planned run reports of FTplan (`run_mission`), which its measures' summary says in seed
# 004's notation.
PLANNED_FIGURES = frozenset({"planned_goals_met", "planned_goals", "planned_goals_met_each", "plannings",
                             "replannings", "repairs", "repaired", "planner_failures", "planning_failure"})


@dataclass(frozen=True)
class CheckedMission:
    world: Path  # the world file
    planning: Any = None  # specc.runtime.ftplan.MissionSetup when FTplan plans the mission
    configuration: str | None = None  # FTplan's, the default one resolved (None: not planned)
    ground: Any = None  # the world read and prepared for the run (the extension's draws made)


TIMINGS = ("model", "wall")  # FtPlan's: a deterministic planning charge, or the measured wall time


def check_mission(robot: Robot, mission: MissionSpec, world: str | None, seed: int, horizon: float | None,
                  configuration: str | None = None, timing: str = "model",
                  domains: Mapping[str, Any] | None = None) -> CheckedMission:
    """Check what a run is asked before anything is built: the world file (the mission's unless
    `world` names another), the seed, the horizon, and for a planned mission FTplan's
    configuration (default: every planner, in the block's policy) and the planning `domains`
    that replace the generated ones of the same names (a mutant, seed 004 §4.1.3); RunError when
    one is wrong."""
    from specc.runtime.ftplan import UnknownName, mission_setup

    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise RunError(f"seed {seed!r}: give a whole number >= 0")
    if horizon is not None and (not math.isfinite(horizon) or horizon <= 0):
        raise RunError(f"horizon {horizon!r}: give a positive number of simulated seconds")
    if mission.goals and robot.system.supervisor is None:
        raise RunError(f"mission {mission.name} posts goals, but robot '{robot.name}' has no supervisor "
                       "(give its system 'supervisor: NAME;')")
    if timing not in TIMINGS:
        raise RunError(f"timing '{timing}': give {' or '.join(TIMINGS)}")
    import_user_code(robot)
    world_file = robot.world_file(world or mission.world)
    if mission.plan is None:
        if configuration is not None or domains:
            raise RunError(f"{'--config' if configuration is not None else 'a planning domain'}: mission "
                           f"{mission.name} of robot '{robot.name}' is not planned (it has no 'plan:'), and only "
                           "a planned mission has FTplan's configurations and domains: run it without them")
        return CheckedMission(world_file, ground=prepared_world(robot, mission, seed, world_file, None))
    block = robot.part("ftplan").FTPLANS[robot.system.planning]
    try:
        chosen = configuration or default_configuration(block)
        setup = mission_setup(block.CONFIGURATIONS, chosen, mission.plan,
                              robot.part("planner"))
    except UnknownName as error:
        raise RunError(str(error)) from None
    if not any(getattr(a, "goal", None) is not None for a in setup.problem.assertions):
        raise RunError(f"mission {mission.name} plans problem '{setup.problem.name}', which has no goal: FTplan "
                       "would have nothing to plan (mark its goals `goal(priority, ...)`)")
    if domains:
        unused = sorted(set(domains) - setup.planned_in)
        if unused:
            raise RunError(f"configuration {chosen} plans in "
                           f"{', '.join(sorted(setup.planned_in))}, not in {', '.join(unused)}")
        setup = dataclasses.replace(setup, domains={**setup.domains, **domains})
    return CheckedMission(world_file, setup, chosen, prepared_world(robot, mission, seed, world_file, setup))


def prepared_world(robot: Robot, mission: MissionSpec, seed: int, world_file: Path, planning: Any) -> Any:
    """The world file read, then as the extension's `prepare` draws it for this run (where its
    objects lie...); RunError when the file is not a world or its draws cannot be made, before
    anything of the run is built or written."""
    from specc.runtime.sim import WorldError, load_world

    try:
        ground = load_world(world_file)
    except WorldError as error:
        raise RunError(str(error)) from None
    prepare = robot.hook("prepare")
    if prepare is not None:
        try:
            ground = prepare(ground, RunSetup(robot, mission, seed, planning))
        except WorldError as error:  # what the world asks cannot be drawn
            raise RunError(str(error)) from None
    body = robot.system.body
    # The run would go on from somewhere the world file never said (after the draws too: `specc
    # check` sees the file's start, before any).
    overlap = ground.start_overlap(body.radius, body.length, body.width)
    if overlap is not None:
        raise RunError(f"{world_file}: {overlap}")
    return ground


def default_configuration(block: ModuleType) -> str:
    """The configuration of a generated ftplan module that is its block as written: every planner,
    in the block's order and policy."""
    whole = block.CONFIG
    return next((name for name, config in block.CONFIGURATIONS.items()
                 if config.planners == whole.planners and config.policy == whole.policy), next(iter(
                     block.CONFIGURATIONS)))


def run_mission(robot: Robot, mission: MissionSpec, seed: int = 0, *, world: str | None = None,
                horizon: float | None = None, log: EventLog | None = None,
                progress: Callable[[MissionProgress], None] | None = None, configuration: str | None = None,
                timing: str = "model", domains: Mapping[str, Any] | None = None,
                checked: CheckedMission | None = None) -> MissionRun:
    """Run `mission` on `robot` (see the module's docstring), in `world` (a name of the system's
    worlds or a world file) instead of the mission's when given, for `horizon` seconds of
    simulated time instead of the mission's; a planned mission with FTplan's `configuration`
    (Robot1, Robot1/2...), planning charge `timing`, and `domains` (planning domains by name)
    in place of the generated ones. Bad arguments raise RunError before anything runs; `checked`:
    what `check_mission` said of these very arguments already (its world prepared once)."""
    from specc.runtime.ftplan.state import SystemState

    if checked is None:
        checked = check_mission(robot, mission, world, seed, horizon, configuration, timing, domains)
    world_path, ground = checked.world, checked.ground
    limit = horizon if horizon is not None else mission.horizon if mission.horizon is not None else DEFAULT_HORIZON
    events = log if log is not None else EventLog()
    # Everything is logged through the journal, so that FTplan's own events come in time order.
    journal = FtplanJournal(events)
    system = robot.system
    started = time.perf_counter()
    with contextlib.chdir(robot.folder):
        parts = assemble(robot, ground, world_path, seed, log=lambda text: recorder.operator(text))
        registry, sim, executive, supervisor = parts.registry, parts.sim, parts.executive, parts.supervisor
        kernel = registry.kernel
        # `goal: =>(FACT ...);` states what the supervisor knows from the start; the rest are goals.
        facts = [g for g in mission.goals if g.startswith(FACT_OP)]
        posted = [g for g in mission.goals if not g.startswith(FACT_OP)]
        recorder = Recorder(journal, sim, registry, executive, limit, len(posted) + bool(mission.plan), progress)
        if supervisor is not None:
            recorder.watch_facts(supervisor.database)
        setup = checked.planning
        goals_planned = SystemState.from_problem(setup.problem).goals if setup else ()  # FTplan's to achieve
        planned = {"plan": mission.plan, "configuration": checked.configuration, "timing": timing,
                   "planners": [f"{p.name} ({p.domain})" for p in setup.config.planners],
                   "planned_goals": [[g.attribute, list(g.args), g.value] for g in goals_planned]} if setup else {}
        journal.emit(kernel.now, "mission-start", robot=robot.name, mission=mission.name, seed=seed,
                     goals=posted, horizon=limit, body=dataclasses.asdict(system.body),
                     objects=[list(o) for o in sim.objects], **planned, **world_fields(ground),
                     **({"facts": facts} if facts else {}))
        context = RunContext(robot, mission, seed, ground, sim, registry, executive, supervisor, journal)
        attach = robot.hook("attach")
        if attach is not None:
            attach(context)
        intentions = []
        if mission.goals:
            assert supervisor is not None  # check_mission: goals need a supervisor
            for fact in facts:
                supervisor.conclude(fact[len(FACT_OP):])
            for goal in posted:
                intentions.append((goal, supervisor.post(goal)))
                journal.emit(kernel.now, "goal", goal=goal, status="posted")
        planning: list[Any] = []  # FTplan's result, once it has run
        recorder.start(lambda: sum(1 for _, i in intentions if i.status != "running") + len(planning))
        PoseRecorder(journal.emit, sim).start()
        ended: set[int] = set()  # the goals whose end is logged, by their place (one goal may be posted twice)

        def running() -> bool:
            recorder.poll()
            for k, (goal, intention) in enumerate(intentions):
                if intention.status != "running" and k not in ended:
                    ended.add(k)
                    journal.emit(kernel.now, "goal", goal=goal, status=intention.status)
            # One goal failed: so has the mission (docs/language.md), whatever the others do.
            return any(i.status == "running" for _, i in intentions) and not any(
                i.status == "failed" for _, i in intentions)

        if setup is not None:
            planning.append(_plan_and_execute(robot, setup, timing, journal, parts, limit))
        kernel.run_while(running, max(kernel.now, limit))
        recorder.poll()
        for callback in context.ending:
            callback()
    statuses = tuple((goal, intention.status) for goal, intention in intentions)
    outcome, why = _outcome(intentions, limit, events.events)
    planned_figures: dict[str, Any] = {}
    if planning:
        result, stopped = planning[0]
        met = set(result.met)
        planned_figures = {"planned_goals_met": len(result.met), "planned_goals": len(result.met) + len(result.missed),
                           # mission-start's planned_goals, each as FTplan's ledger judged it at the end
                           "planned_goals_met_each": [g.text() in met for g in goals_planned],
                           "plannings": result.plannings, "replannings": result.replannings,
                           "repairs": result.repairs, "repaired": result.repaired,
                           "planner_failures": result.planner_failures,
                           # the mission exception: no plan in time (not the horizon stopping the run)
                           "planning_failure": "" if stopped else result.failure}
        # What went wrong on the way, which the goals' reasons (a plan leaving them aside) hide:
        # a reason of its own, so that a summary cutting the goals' reasons short still says it.
        failed = [e.text for e in result.events if e.kind == "action-failed"]
        failures = f"; {len(failed)} action failure(s); the last: {failed[-1]}" if failed else ""
        if stopped:
            outcome, why = "horizon", f"{result.failure}: {len(result.met)} of {len(met) + len(result.missed)} " \
                                      f"planned goal(s) met{failures}"
        elif outcome == "succeeded" and (result.failure or result.missed):
            outcome, why = "failed", (result.failure or missed_goals(result.missed)) + failures
        elif outcome == "succeeded":
            why = f"every goal achieved ({len(intentions)} posted, {len(result.met)} planned)" if intentions \
                else f"every planned goal achieved ({len(result.met)})"
    if recorder.incidents:  # software trouble the robot lived on with: a success, but not a clean one
        why += f"; {len(recorder.incidents)} incident(s), the first: {recorder.incidents[0]}"
    # What the run measured, logged before the robot's own measures and judgement read the log.
    figures = {"distance": round(sim.rover.distance, 3), "requests": recorder.requests,
               "incidents": len(recorder.incidents), **planned_figures}
    journal.emit(kernel.now, "mission-figures", **figures)
    measure, judge = robot.hook("measure"), robot.hook("judge")
    extension_measures = dict(measure(events.events)) if measure is not None else {}
    if judge is not None:  # the robot's own success criteria, on top of its goals'
        outcome, why = judge(events.events, extension_measures, outcome, why)
    journal.emit(kernel.now, "mission-end", outcome=outcome, why=why, goals=[list(s) for s in statuses],
                 **figures)
    recorder.report(kernel.now)
    return MissionRun(robot.name, mission.name, ground.name, seed, outcome, why, statuses, kernel.now,
                      time.perf_counter() - started, sim.rover.distance, recorder.requests,
                      dict(sorted(recorder.replies.items())), tuple(recorder.incidents), tuple(events.events),
                      {**planned_figures, **extension_measures})


@dataclass
class Assembly:
    """A robot's parts on one kernel, nothing run yet."""

    registry: rt.Registry
    sim: Any  # specc.runtime.sim.Simulation
    executive: rx.Executive | None
    supervisor: Any  # specc.runtime.supervisor.Supervisor, or None

    @property
    def kernel(self) -> Any:
        return self.registry.kernel


def import_user_code(robot: Robot) -> None:
    """Import the Python the run will call, as `assemble` will (from the robot's folder): each
    module's codels, the executive's input and output functions, the procedures' bindings. One
    that cannot be imported is bad input, said before anything runs (RunError), not a run that
    crashes at its start; what is imported stays imported for the run."""
    from specc.runtime import executive as rx
    from specc.runtime import procedures as rp

    system = robot.system
    try:
        with contextlib.chdir(robot.folder):
            for generated in robot.part("modules").MODULES.values():
                rt.load_codels(generated.SPEC)
            if system.executive:
                rx.load_codels(robot.part("executive").EXECUTIVES[system.executive].SPEC)
            if system.supervisor:
                rp.load_functions(robot.part("supervisor").LIBRARIES[system.supervisor].LIBRARY)
    except ImportError as error:
        raise RunError(str(error)) from None


def assemble(robot: Robot, ground: Any, world_path: Path, seed: int,
             log: Callable[[str], None] | None = None) -> Assembly:
    """The robot's modules on one kernel with the simulated body in `ground` (the world as the run
    draws it, from `world_path`), its executive and its supervisor (`log` hears what the
    procedures tell the operator), as its system block says. Call it with the robot's folder as
    the working directory: codels name their files relative to it."""
    from specc.runtime.sim import Simulation, WorldError

    system = robot.system
    registry = rt.Registry()
    try:
        sim = Simulation(ground, system.body, seed=seed, kernel=registry.kernel).attach(registry, system.devices)
    except WorldError as error:  # what the world asks cannot be built (objects without room)
        raise RunError(str(error)) from None
    robot.part("modules").create_all(registry)
    executive = robot.part("executive").EXECUTIVES[system.executive].create(
        registry, world=str(world_path.resolve())) if system.executive else None
    supervisor = robot.part("supervisor").LIBRARIES[system.supervisor].create(
        kernel=registry.kernel, executive=executive, seed=seed, log=log) if system.supervisor else None
    return Assembly(registry, sim, executive, supervisor)


def _plan_and_execute(robot: Robot, setup: Any, timing: str, journal: FtplanJournal, parts: Assembly,
                      horizon: float) -> tuple[Any, bool]:
    """FTplan plans the mission with the configuration's planners, each in its own process, and
    the system's bindings carry every plan out (`specc.run.plans`) until the run's horizon;
    FTplan's result, and whether the horizon stopped it."""
    executor = BoundExecutor(parts.kernel, robot.system.bindings, parts.registry, parts.executive, parts.supervisor,
                             parts.sim.rover, setup.config, journal.emit, horizon)
    return run_ftplan(setup, executor, journal, timing)[1], executor.horizon_reached


def _outcome(intentions: list[tuple[str, Any]], horizon: float,
             events: Iterable[Mapping[str, Any]]) -> tuple[str, str]:
    failed = [(goal, intention) for goal, intention in intentions if intention.status == "failed"]
    if failed:  # the mission ends there: a goal still running would not change the verdict
        goal, intention = failed[0]
        return "failed", f"{goal} failed: {why_failed(intention.trace, list(events))}"
    running = [goal for goal, intention in intentions if intention.status == "running"]
    if running:
        return "horizon", f"{', '.join(running)} still running at the {horizon:g} s horizon" + waiting_on(events)
    return "succeeded", f"every goal achieved ({len(intentions)})"


OUTSTANDING_SHOWN = 3  # services named in a horizon's reason


def waiting_on(events: Iterable[Mapping[str, Any]]) -> str:
    """`; waiting on: SERVICE (id N) in PHASE since T s, ...`: the requests the log shows without
    a final reply when the run ended, each in the phase its activity last entered (a ZOMBIE the
    procedures never interrupted, a WAIT never granted): what a goal still running waited for.
    Empty when none is."""
    asked: dict[Any, str] = {}
    phases: dict[Any, tuple[str, float]] = {}
    for e in events:
        if e["kind"] == "request":
            asked[e["id"]] = str(e.get("service") or e.get("request"))
            if e.get("service"):  # an executive service's activity starts in WAIT (the log's `request`)
                phases[e["id"]] = ("WAIT", float(e["t"]))
        elif e["kind"] == "reply":
            asked.pop(e["id"], None)
        elif e["kind"] == "activity":
            phases[e["id"]] = (str(e["to"]), float(e["t"]))
    shown = [f"{service} (id {ident})" + (f" in {phases[ident][0]} since {phases[ident][1]:.1f} s"
                                          if ident in phases else "")
             for ident, service in list(asked.items())[:OUTSTANDING_SHOWN]]
    more = f" and {len(asked) - OUTSTANDING_SHOWN} more" if len(asked) > OUTSTANDING_SHOWN else ""
    return f"; waiting on {', '.join(shown)}{more}" if shown else ""


def missed_goals(missed: Mapping[str, str]) -> str:
    """The planned goals missed (goal -> why), each reason said once, after the goals it stands
    for: FTplan gives every goal it abandons at once the same reason, every planner's
    diagnostics, which would otherwise be repeated for each."""
    goals_of: dict[str, list[str]] = {}
    for goal, reason in missed.items():
        goals_of.setdefault(reason, []).append(goal)
    return f"{len(missed)} planned goal(s) missed: " + "; ".join(
        f"{', '.join(goals)}: {reason}" for reason, goals in goals_of.items())


def brief_why(why: str, width: int = REASON_WIDTH, detail_width: int = DETAIL_WIDTH) -> str:
    """`why` for a one-line summary: in each of its reasons (its parts between "; " outside any
    brackets), what a bracket holds (a planner's diagnostics...) cut after about `detail_width`
    characters, then the reason after about `width`, each cut marked by an ellipsis and the
    brackets it leaves open closed. The full text is the run's report's."""
    return "; ".join(_cut(_cut_details(reason, detail_width), width) for reason in _reasons(why))


def _reasons(text: str) -> list[str]:
    reasons: list[str] = []
    depth = start = 0
    for k, char in enumerate(text):
        if char in OPENING:
            depth += 1
        elif char in CLOSING:
            depth = max(0, depth - 1)
        elif depth == 0 and text.startswith("; ", k):
            reasons.append(text[start:k])
            start = k + 2
    return [*reasons, text[start:]]


def _cut_details(text: str, width: int) -> str:
    """`text` with what each of its outermost brackets holds cut after about `width` characters."""
    parts: list[str] = []
    depth = start = 0
    for k, char in enumerate(text):
        if char in OPENING:
            if depth == 0:
                parts.append(text[start:k + 1])
                start = k + 1
            depth += 1
        elif char in CLOSING and depth:
            depth -= 1
            if depth == 0:
                parts.append(_cut(text[start:k], width))
                start = k
    parts.append(_cut(text[start:], width) if depth else text[start:])
    return "".join(parts)


def _cut(text: str, width: int) -> str:
    """`text` cut at a word's end before `width` characters, with an ellipsis and the brackets
    the cut leaves open closed."""
    if len(text) <= width:
        return text
    kept = text[:width]
    if " " in kept:
        kept = kept[: kept.rindex(" ")]
    kept = kept.rstrip(" ,;:" + OPENING)
    still_open: list[str] = []
    for char in kept:
        if char in OPENING:
            still_open.append(CLOSING[OPENING.index(char)])
        elif char in CLOSING and still_open:
            still_open.pop()
    return kept + "…" + "".join(reversed(still_open))


def why_failed(trace: Iterable[Any], events: list[Mapping[str, Any]]) -> str:
    """The first statement that failed in the goal's intention (or the user's function that raised,
    which made it fail), and the last service reply that was a failure before it (what the
    procedures most likely reacted to)."""
    failure = next((entry for entry in trace if " failed" in entry.text or " raised " in entry.text
                    or entry.text == "fail"  # `fail;`: the statement itself is the reason
                    or entry.text.startswith("abandoned: ")), None)
    if failure is None:
        return "no applicable KA succeeded"
    refused = next((e for e in reversed(events) if e["kind"] == "reply" and e["t"] <= failure.time
                    and not reply_succeeded(e)), None)
    answer = ""
    if refused is not None:
        detail = f" ({refused['detail']})" if refused.get("detail") else ""
        answer = f"; service {refused['service']} answered {refused['result']}{detail} at {refused['t']:.1f} s"
    return f"{failure.ka}:{failure.line}: {failure.text}{answer}"


class Recorder:
    """Writes what any robot's run does to the event log: the executive's requests, replies and
    activities, the supervisor's facts, the robot's and the arm's motion, incidents."""

    def __init__(self, log: FtplanJournal, sim: Any, registry: rt.Registry, executive: rx.Executive | None,
                 horizon: float, goals: int, progress: Callable[[MissionProgress], None] | None) -> None:
        self.log = log
        self.sim = sim
        self.registry = registry
        self.executive = executive
        self.kernel = sim.kernel
        self.horizon = horizon
        self.goals = goals
        self.progress = progress
        self.requests = 0
        self.replies: Counter[str] = Counter()
        self.incidents: list[str] = []
        self._done: Callable[[], int] = lambda: 0
        self._pose = sim.pose
        self._robot_moving = False
        self._arm_moving = False
        self._arm_service: str | None = None
        self._blocked = False
        self._seen = {"registry": 0, "executive": 0}
        self._next_progress = self.kernel.now + PROGRESS_PERIOD
        self._database: Any = None
        self._facts: dict[str, list[Any]] = {}
        self._facts_seen = -1  # the database's `changes` when the facts were last compared
        if executive is not None:
            executive.observers.append(self._activity)
            executive.listeners.append(self._message)
            executive.reflex_listeners.append(self._reflex)

    # ------------------------------------------------------------ the executive
    def _activity(self, activity: rx.Activity, source: rx.Phase, target: rx.Phase) -> None:
        service = activity.service.name
        if source is rx.Phase.ETHER and target is rx.Phase.WAIT:
            self.requests += 1
            self.log.emit(self.kernel.now, "request", service=service, id=activity.id,
                          request=f"{activity.service.module}.{activity.service.request}")
        else:
            self.log.emit(self.kernel.now, "activity", service=service, id=activity.id, **{"from": source.value},
                          to=target.value)

    def _reflex(self, reflex: rx.ReflexSpec, code: str) -> None:
        self.log.emit(self.kernel.now, "reflex", reflex=reflex.name, on=f"{reflex.trigger} {reflex.source}",
                      code=str(code), actions=[f"{verb} {target}" for verb, target in reflex.actions])

    def _message(self, message: rx.Message) -> None:
        now = self.kernel.now
        if message.kind == "WARNING":
            self.log.emit(now, "warning", service=message.service, id=message.id, type=str(message.result),
                          detail=message.detail)
            if message.service == "EXECUTIVE":  # its general ERROR state: trouble the robot lives on with
                self.incidents.append(f"{now:.3f} the executive entered its ERROR state: {message.detail}")
                self.log.emit(now, "alarm", what="executive-error", detail=message.detail)
            return
        result = message.result if isinstance(message.result, int | float | str) else str(message.result)
        self.replies[f"{message.service} {result}"] += 1
        self.log.emit(now, "reply", service=message.service, id=message.id, result=result, detail=message.detail,
                      ok=message.ok)

    # ------------------------------------------------------------ the supervisor
    def operator(self, text: str) -> None:
        self.log.emit(self.kernel.now, "operator", text=text)

    def watch_facts(self, database: Any) -> None:
        """The facts the procedures share (closed and functional predicates): the supervisor has
        no listener for its database, so it is compared after each kernel event and before any
        other event is logged (an action's end, a request...), when its count of changes says it
        changed."""
        self._database = database
        self._facts = {p.name: [] for p in database.predicates.values() if p.kind in ("closed", "functional")}
        self.log.before_each.append(self.poll_facts)

    def poll_facts(self) -> None:
        if self._database is None or self._database.changes == self._facts_seen:
            return
        self._facts_seen = self._database.changes
        for head, before in self._facts.items():
            now = self._database.facts(head)
            if now == before:
                continue
            for fact in before:
                if fact not in now:
                    self.log.emit(self.kernel.now, "fact", fact=str(fact), change="retracted")
            for fact in now:
                if fact not in before:
                    self.log.emit(self.kernel.now, "fact", fact=str(fact), change="concluded")
            self._facts[head] = now

    def poll(self) -> None:
        self.poll_facts()
        self._check_incidents()

    # ------------------------------------------------------------ the simulator
    def start(self, done: Callable[[], int]) -> None:
        """Sample the motion on the physics grid, after the simulator's own ticks; `done` counts
        the goals ended, for the progress reports."""
        self._done = done
        self.kernel.call_every(self.sim.physics_period, self._sample, SAMPLE_PRIORITY)

    def _sample(self) -> None:
        now = self.kernel.now
        x, y, theta = pose = self.sim.pose
        dt = self.sim.physics_period
        turned = abs(math.remainder(theta - self._pose[2], math.tau))
        rims = (math.hypot(x - self._pose[0], y - self._pose[1]) + turned * self.sim.robot.wheel_base / 2.0) / dt
        self._pose = pose
        moving = rims > ROBOT_MOVING
        if moving != self._robot_moving:
            self._robot_moving = moving
            self.log.emit(now, "robot-motion", moving=moving, x=round(x, 3), y=round(y, 3), theta=round(theta, 3))
        arm = self.sim.arm
        if arm is not None and arm.moving != self._arm_moving:
            self._arm_moving = arm.moving
            if arm.moving:
                self._arm_service = self._service_of(arm.moved_by)
            self.log.emit(now, "arm-motion", moving=arm.moving, service=self._arm_service)
        if self.sim.trace.blocked_at is not None and not self._blocked:
            self._blocked = True
            self.log.emit(now, "alarm", what="blocked", detail=f"the robot is blocked at ({x:.2f}, {y:.2f})")
        self._check_incidents()
        if now >= self._next_progress:
            self._next_progress += PROGRESS_PERIOD
            self.report(now)

    def _service_of(self, activity: Any) -> str | None:
        """The executive service whose module request is `activity` (a module's activity), else
        the request as module.request; None when nothing commanded."""
        if activity is None:
            return None
        module, request = activity.module.name, activity.spec.name
        for running in (self.executive.activities.values() if self.executive is not None else ()):
            if running.module_id == activity.id and running.service.module == module:
                return str(running.service.name)
        return f"{module}.{request}"

    def _check_incidents(self) -> None:
        """A permanent codel, a listener or an observer that raised: the robot keeps going and
        notes it; the log says so."""
        if len(self.registry.incidents) == self._seen["registry"] and (
                self.executive is None or len(self.executive.incidents) == self._seen["executive"]):
            return  # asked after every kernel event: most often nothing new
        sources: list[tuple[str, list[str]]] = [("registry", self.registry.incidents)]
        if self.executive is not None:
            sources.append(("executive", self.executive.incidents))
        for key, incidents in sources:
            for incident in incidents[self._seen[key]:]:
                self.incidents.append(incident)
                self.log.emit(self.kernel.now, "alarm", what="incident", detail=incident)
            self._seen[key] = len(incidents)

    def report(self, now: float) -> None:
        if self.progress is not None:
            self.progress(MissionProgress(now, self.horizon, self._done(), self.goals))
