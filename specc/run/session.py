"""One run of a compiled robot, as `specc run` does it: compile if stale, run the mission, and
leave a run folder behind.

    outcome = run_in_folder(RunRequest(Path("examples/tug"), mission="shuttle", world="hall",
                                       configuration="Robot1/2"))
    outcome.folder            # runs/tug-shuttle-hall-Robot1-2-s0/
    outcome.report["outcome"], outcome.summary, outcome.pictures

The folder holds `events.jsonl` (the event log, written as the run goes, so a run that crashes
keeps what it logged), `report.json` (the request, the outcome, the measures), `summary.txt`
(the same for a person) and the pictures `specc.run.render` draws from the log alone (the map,
the timeline; the state of Fig 5.11 when the log holds a model).

A robot runs the missions of its system block (`specc.run.mission`), or goals given with
`--goal`; a planned mission with one of FTplan's configurations (`--config`, default: the ftplan
block as written).
"""

from __future__ import annotations

import contextlib
import json
import re
import signal
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from specc.run import RunError
from specc.run.events import EventLog

LOG = "events.jsonl"
REPORT = "report.json"
SUMMARY = "summary.txt"
RUN_FILES = (LOG, REPORT, SUMMARY, "map.png", "timeline.png", "state.png")  # what a run writes in its folder
RUNS = Path("runs")  # where run folders go by default, under the working directory
GENERATED = Path("generated")  # where the specs compile to by default (`specc compile -o generated`)

PLANNER_FAILURES = ("watchdog", "invalid-plan")  # FTplan's events for a planner that gave no usable plan
Progress = Callable[[float, float | None, str], None]  # mission time, horizon (None: unknown), what


DEFAULT_WALL_LIMIT = 3600.0  # s of wall time a run may take: far past any example's, short of "for ever"


class RunCrashed(RunError):
    """The run broke half-way; its folder holds the log so far and a report saying so."""

    def __init__(self, message: str, outcome: RunOutcome, exit_code: int = 1) -> None:
        super().__init__(message)
        self.outcome = outcome
        self.exit_code = exit_code  # 130 when a signal stopped it, as a shell says of Ctrl-C


class Stopped(BaseException):
    """A signal or the wall-clock limit stopped the run (raised in the main thread by its handler,
    wherever the run was: in a codel stuck in a loop too). Not an Exception: nothing the run
    catches may swallow it."""

    def __init__(self, why: str, exit_code: int) -> None:
        super().__init__(why)
        self.why = why
        self.exit_code = exit_code


LONGEST_WALL_LIMIT = 365 * 24 * 3600.0  # s: longer, the operating system's timer cannot hold it


@contextlib.contextmanager
def stoppable(wall_limit: float | None) -> Iterator[None]:
    """While the run goes: SIGTERM, SIGINT and the wall-clock limit raise Stopped in it. Only the
    main thread can take signals: elsewhere (a worker thread) the run goes unguarded."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    from specc.runtime.functional import where_running

    def on_signal(number: int, frame: Any) -> None:
        raise Stopped(f"stopped by {signal.Signals(number).name}{where_running(frame)}", 130)

    def on_limit(number: int, frame: Any) -> None:
        del number
        # Where the run stood: most often a codel stuck in a loop, which the reason then names.
        raise Stopped(f"stopped: the run took longer than its wall-clock limit of {wall_limit:g} s (--wall-limit)"
                      f"{where_running(frame)}", 1)

    before = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    before_alarm = signal.signal(signal.SIGALRM, on_limit)
    if wall_limit is not None:
        signal.setitimer(signal.ITIMER_REAL, wall_limit)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, before_alarm)
        for number, handler in before.items():
            signal.signal(number, handler)


@dataclass(frozen=True)
class RunRequest:
    specs: Path  # the robot's spec folder (its codels and worlds beside the specs)
    mission: str | None = None  # a mission of the robot's system block
    world: str | None = None  # one of its worlds, or a world file; default: the mission's
    configuration: str | None = None  # FTplan's, for a planned mission; default: the ftplan block's own
    seed: int = 0
    generated: Path = GENERATED
    runs: Path = RUNS
    folder: Path | None = None  # the run folder itself, instead of runs/<name>
    timing: str = "model"  # FTplan's planning charge: model (deterministic) or wall
    horizon: float | None = None  # s of simulated time; default: the mission's own
    goals: tuple[str, ...] = ()  # PRS goals to post instead of a mission's (`--goal '!(...)'`)
    wall_limit: float | None = DEFAULT_WALL_LIMIT  # s of wall time before the run is stopped (None: no limit)
    pictures: bool = True  # draw them now (`specc replay RUN` draws them later from the log)
    mutant: InjectedModel | None = None  # a mutant of a planning domain in place of that domain


@dataclass(frozen=True)
class InjectedModel:
    """A mutant of a planning model (`specc.mutation`) a run plans in, in place of the model of
    its name: what `specc run --mutant` reruns of a campaign."""

    id: str  # "model1-0131"
    description: str  # where and what was mutated
    domain: Any  # specc.runtime.planner.model.PlanningDomain


@dataclass
class RunOutcome:
    folder: Path
    robot: str
    report: dict[str, Any]
    summary: str
    pictures: list[Path] = field(default_factory=list)

    @property
    def succeeded(self) -> bool:
        return bool(self.report.get("outcome") == "succeeded")


GOALS_IN_NAME = 40  # characters of the goals a `--goal` run's folder is named by


def folder_name(robot: str, mission: str, world: str, configuration: str | None, seed: int) -> str:
    """runs/<robot>-<mission>-<world>[-<configuration>]-s<seed>, readable and safe as a path."""
    parts = [robot, mission, world, *([configuration] if configuration else [])]
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", "-".join(parts)) + f"-s{seed}"


def compile_robot(specs: Path, generated: Path, note: Callable[[str], None] | None = None) -> str:
    """The robot `specs` (a robot's spec folder) compiles to, into `generated`, compiled only when
    the package there is stale (`note` hears when it was)."""
    from specc.run.package import ensure_compiled

    if not specs.is_dir():
        raise RunError(f"'{specs}' is not a robot's spec folder: give the folder holding its specs, codels "
                       "and worlds, e.g. examples/tug")
    compiled = ensure_compiled(specs, generated)
    if compiled.rewritten and note is not None:
        note(f"compiled {specs} into {compiled.folder} (it was stale)")
    if note is not None:
        for warning in compiled.warnings:  # every run, as `specc check` would say them
            note(warning)
    return compiled.robot


def run_in_folder(request: RunRequest, progress: Progress | None = None,
                  compiled_note: Callable[[str], None] | None = None) -> RunOutcome:
    """Compile `request.specs` if stale, run its mission and write the run folder. Bad input is a
    RunError before anything runs; a run that breaks half-way still leaves its log and a report
    saying so, then raises RunCrashed."""
    return run_compiled(compile_robot(request.specs, request.generated, compiled_note), request, progress)


@dataclass(frozen=True)
class PlannedRun:
    """A run whose names are all checked, ready to go into its folder."""

    robot: str
    request: RunRequest
    plan: _Plan
    folder: Path


def plan_run(robot: str, request: RunRequest) -> PlannedRun:
    """Check every name and option of `request` for `robot` (compiled into request.generated);
    RunError when one is wrong. Nothing is written."""
    from specc.run.mission import load_robot

    if request.wall_limit is not None and not 0 < request.wall_limit <= LONGEST_WALL_LIMIT:
        raise RunError(f"--wall-limit {request.wall_limit:g}: give a positive number of seconds, at most "
                       f"{LONGEST_WALL_LIMIT:g} (a year)")
    plan = _plan_system(load_robot(request.generated, request.specs, robot), request)
    if request.folder is not None:
        return PlannedRun(robot, request, plan, request.folder)
    # Options that change what a run does name its folder too: it never holds another run's files.
    variant = f"-horizon{request.horizon:g}" if request.horizon is not None else ""
    variant += "-wall" if request.timing != "model" else ""
    if request.goals:  # the goals posted, readable (cut short past a length), and a digest of them all
        import hashlib

        said = re.sub(r"[^A-Za-z0-9_.-]+", "-", " ".join(request.goals)).strip("-")[:GOALS_IN_NAME]
        digest = hashlib.sha256("\0".join(request.goals).encode()).hexdigest()[:6]
        variant = f"-{said}-{digest}{variant}"
    variant += f"-{request.mutant.id}" if request.mutant is not None else ""
    name = folder_name(robot, *plan.name_parts, request.seed)
    return PlannedRun(robot, request, plan, request.runs / (name + variant))


def run_compiled(robot: str, request: RunRequest, progress: Progress | None = None) -> RunOutcome:
    """`run_in_folder` once the specs are compiled into `request.generated`/<robot>."""
    return run_planned(plan_run(robot, request), progress)


def run_planned(planned: PlannedRun, progress: Progress | None = None) -> RunOutcome:
    """Run what `plan_run` checked and write its folder (see `run_in_folder`)."""
    request, plan, folder = planned.request, planned.plan, planned.folder
    outcome = RunOutcome(folder, planned.robot, {}, "")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for name in RUN_FILES:  # what an earlier run left here must not pass for this one's
            (folder / name).unlink(missing_ok=True)
    except OSError as error:
        raise RunError(f"cannot make the run folder '{folder}': {error.strerror or error}") from None
    started = time.perf_counter()
    with EventLog(folder / LOG) as log:
        try:
            with stoppable(request.wall_limit):
                report, summary = plan.run(log, progress)
        except Stopped as stop:  # a signal, or the wall-clock limit: the report says so, nothing is lost
            report = {"outcome": "interrupted", "why": stop.why}
            summary = f"the run was {stop.why} at {log.events[-1]['t'] if log.events else 0.0:.1f} s of mission"
            _finish(outcome, request, plan, report, summary, log, started)
            raise RunCrashed(f"the run was {stop.why} (what it logged is in {folder / LOG}, the report in "
                             f"{folder / REPORT})", outcome, stop.exit_code) from None
        except (Exception, SystemExit) as error:  # a failure half-way (even a RunError, a user's sys.exit): keep what
            # the log holds, say what broke
            report = {"outcome": "crashed", "why": f"{type(error).__name__}: {error}"}
            summary = f"the run crashed at {log.events[-1]['t'] if log.events else 0.0:.1f} s: {report['why']}"
            _finish(outcome, request, plan, report, summary, log, started)
            raise RunCrashed(f"the run crashed: {report['why']} (what it logged is in {folder / LOG}, the "
                             f"report in {folder / REPORT}; rerun with SPECC_DEBUG=1 for the traceback)",
                             outcome) from error
    _finish(outcome, request, plan, report, summary, log, started)
    return outcome


def _finish(outcome: RunOutcome, request: RunRequest, plan: _Plan, report: dict[str, Any], summary: str,
            log: EventLog, started: float) -> None:
    folder = outcome.folder
    if request.pictures and log.events:
        from specc.run.render import render_run

        try:
            outcome.pictures = render_run(log.events, folder)
        except RunError as error:  # a log too short to draw: the report says so, nothing is lost
            summary += f"\nno pictures: {error}"
    outcome.report = {
        "robot": outcome.robot, "mission": plan.name_parts[0], "world": plan.name_parts[1],
        "configuration": plan.name_parts[2], "seed": request.seed, **report,
        "wall_time": round(time.perf_counter() - started, 3),
        "log": LOG, "pictures": [p.name for p in outcome.pictures]}
    outcome.summary = summary + "".join(f"\n  picture: {p}" for p in outcome.pictures) + f"\n  log: {folder / LOG}"
    try:
        (folder / REPORT).write_text(json.dumps(outcome.report, indent=2, sort_keys=True) + "\n", encoding="utf-8")
        (folder / SUMMARY).write_text(outcome.summary + "\n", encoding="utf-8")
    except OSError as error:
        raise RunError(f"cannot write the report into '{folder}': {error.strerror or error}") from None


# ---------------------------------------------------------------- a mission of the system block


@dataclass(frozen=True)
class _Plan:
    name_parts: tuple[str, str, str | None]  # mission, world, configuration
    run: Callable[[EventLog, Progress | None], tuple[dict[str, Any], str]]


def _plan_system(robot: Any, request: RunRequest) -> _Plan:
    """A mission of any robot, from its system block (`specc.run.mission`)."""
    from specc.run.mission import check_mission, run_mission
    from specc.runtime.system import MissionSpec

    if request.goals:
        if request.mission is not None:
            raise RunError("give --mission or --goal, not both: --goal posts its goals instead of a mission's")
        worlds = list(robot.system.worlds)
        if request.world is None and not worlds:
            raise RunError(f"--goal needs --world: robot '{robot.name}' names no world (give a .toml file)")
        # Without --world, the first world the system block names.
        goals = tuple(_checked_goal(robot, g, request.specs) for g in request.goals)
        mission = MissionSpec("goal", request.world or worlds[0], goals)
    elif request.mission is None:
        missions = list(robot.system.missions)
        if len(missions) != 1:
            raise RunError(f"robot '{robot.name}' needs --mission ({', '.join(missions) or 'it has none'}) "
                           "or --goal '!(...)'")
        mission = robot.mission(missions[0])
    else:
        mission = robot.mission(request.mission)
    injected = request.mutant
    checked = check_mission(robot, mission, request.world, request.seed, request.horizon, request.configuration,
                            request.timing, {injected.domain.name: injected.domain} if injected is not None else None)
    if checked.planning is None and request.timing != "model":
        raise RunError(f"timing '{request.timing}': FTplan's planning charge; mission {mission.name} is not planned")
    world = request.world or mission.world
    world_name = Path(world).stem if world.endswith(".toml") else world
    configuration = checked.configuration

    def run(log: EventLog, progress: Progress | None) -> tuple[dict[str, Any], str]:
        def tell(step: Any) -> None:
            if progress is not None:
                progress(step.time, step.horizon, f"{step.goals_done}/{step.goals} goal(s) ended")

        result = run_mission(robot, mission, request.seed, world=request.world, horizon=request.horizon, log=log,
                             progress=tell, configuration=configuration, timing=request.timing, checked=checked)
        why = result.why
        planners_said = [e["text"] for e in result.events if e["kind"] == "ftplan" and e["event"] in PLANNER_FAILURES]
        if result.extension_measures.get("planning_failure") and planners_said:  # what the planner itself said
            why += f"; last planner failure: {planners_said[-1]}"
        report = {"outcome": "succeeded" if result.outcome == "succeeded" else result.outcome, "why": why,
                  "simulated_time": round(result.simulated_time, 3), "goals": [list(g) for g in result.goals],
                  "measures": result.measures(), "incidents": list(result.incidents)}
        summary = result.summary()
        if injected is not None:
            report["mutant"] = {"id": injected.id, "description": injected.description}
            summary = f"with mutant {injected.id}: {injected.description}\n{summary}"
        return report, summary

    return _Plan((mission.name, world_name, configuration), run)


def _checked_goal(robot: Any, text: str, specs: Path) -> str:
    """A goal given on the command line: PRS syntax, for a goal some KA of the supervisor is invoked by."""
    from specc.runtime.procedures import parse_goal

    if robot.system.supervisor is None:
        raise RunError(f"--goal {text}: robot '{robot.name}' has no supervisor to post it to "
                       "(give its system 'supervisor: NAME;')")
    try:
        goal = parse_goal(text)
    except ValueError as error:
        raise RunError(f"--goal {text}: not a PRS goal ({error}); write e.g. '!(GO 3 4)'") from None
    library = robot.part("supervisor").LIBRARIES[robot.system.supervisor].LIBRARY
    invoked = {ka.trigger.head: len(ka.trigger.args) for ka in library.kas if ka.goal_invoked}
    head = goal.expr.head
    if goal.op not in ("!", "?") or _has_variables(goal.expr):
        raise RunError(f"--goal {text}: post an achieve '!(...)' or test '?(...)' goal of constants")
    if goal.op == "?":  # a test reads the database: a predicate the procedures declare (or a goal's)
        declared = {p.name: p.arity for p in library.predicates} | invoked
        if head not in declared:
            from specc.diagnostics import did_you_mean

            raise RunError(f"--goal {text}: procedures '{library.name}' declare no predicate {head}"
                           f"{did_you_mean(head, declared)}")
        if declared[head] != len(goal.expr.args):
            raise RunError(f"--goal {text}: {head} takes {declared[head]} argument(s), {len(goal.expr.args)} given")
        return text
    if head not in invoked:
        from specc.diagnostics import did_you_mean

        raise RunError(f"--goal {text}: no KA of procedures '{library.name}' is invoked by {head}"
                       f"{did_you_mean(head, invoked)}")
    if invoked[head] != len(goal.expr.args):
        raise RunError(f"--goal {text}: {head} takes {invoked[head]} argument(s), {len(goal.expr.args)} given")
    procedures = _procedures_of(specs, library.name)
    if procedures is not None:  # the domains and numbers the goal's KAs need, as check holds a mission's goals to
        from specc.check.system import goal_argument_problem, numeric_positions

        needs = numeric_positions(procedures)
        for position, value in enumerate(goal.expr.args):
            problem = goal_argument_problem(procedures, needs, head, position, value)
            if problem is not None:
                raise RunError(f"--goal {text}: {problem}")
    from specc.runtime.supervisor import match

    triggers = [ka.trigger for ka in library.kas if ka.goal_invoked and ka.trigger.head == head]
    if not any(match(trigger, goal.expr, {}) for trigger in triggers):  # `!(GO-PLACE E)`, no KA for E
        shown = ", ".join(dict.fromkeys(f"!{trigger}" for trigger in triggers))
        raise RunError(f"--goal {text}: no KA of procedures '{library.name}' is invoked by it (they are invoked by "
                       f"{shown})")
    return text


def _procedures_of(specs: Path, name: str) -> Any:
    """The procedures block `name` of the robot's specs (read back from the parse cache), or None."""
    from specc.model import nodes as m
    from specc.pipeline import load

    loaded = load([specs], check=False)
    items = loaded.program.items if loaded.program is not None else ()
    return next((i for i in items if isinstance(i, m.Procedures) and i.name == name), None)


def _has_variables(term: Any) -> bool:
    from specc.runtime.procedures import Compound, Var

    return isinstance(term, Var) or isinstance(term, Compound) and any(_has_variables(a) for a in term.args)


def load_report(folder: Path) -> Mapping[str, Any]:
    """A run folder's report.json."""
    path = folder / REPORT
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise RunError(f"{path}: cannot read the report ({error.strerror or error})") from None
    except json.JSONDecodeError as error:
        raise RunError(f"{path}: not a report (line {error.lineno}: {error.msg})") from None
    if not isinstance(data, dict):
        raise RunError(f"{path}: not a report (a JSON object is expected)")
    return data
