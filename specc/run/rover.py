"""The rover missions of seed 004 (§4.1, §4.2), end to end on the simulated ATRV (issue #9).

    run = run_rover_mission("Robot1/2", "M1", "W2", seed=0, log=EventLog("m1w2.jsonl"))
    run.result.success, run.photos, run.communications, run.actions   # what happened
    measure(run)                                  # specc.run.measures: the figures of §4.1.4
    run.draw("m1w2.png")                          # the world, the path, the windows

FTplan (`specc.runtime.ftplan`) plans the mission with the configuration's planners, each in its
own process, and hands every valid plan to `SimExecutor`. The executor carries it out through the
ATRV's six generated modules (RFLEX, SICK, NDD, PLATINE, CAMERA, ANTENNA) on the simulated rover,
on one kernel whose clock is the mission time: planning time charged by FTplan passes on it too,
the robot standing still meanwhile.

How a plan's tasks become module requests (the OpenPRS procedures of §4.1.1, which both models
share, in their simplest form; Modele1's task, then Modele2's):

- MOVE, MOVE_NOMINAL, MOVE_RECOV: ndd.GotoTarget(x, y, 0.3) to where FTplan's state rules put
  the robot when the move ends: (x2, y2) for MOVE, the mission's place for Modele2 (its `view`);
- MOVE_PAN_TILT_UNIT, MOVE_PTU: platine.MoveTo(pan, tilt), to the codels' STRAIGHT and
  AT_MY_FEET, or to Modele2's own angles (degrees);
- TAKE_PICTURE, TAKE_SHOT: camera.TakePicture(target), the world's target (`M2_OBJ1`) of the
  PICTURE fact the photo's end makes DONE;
- COMMUNICATE, COMMUNICATE_ANTENNA: antenna.Communicate(the task's shortest duration);
- INIT_PTU_DRIVER, INIT_PTU: platine.Init;
- INIT_MVT_GENERATION, INIT_FRAME: ndd.Stop, then rflex.Stop.

The modules judge the outcome: NDD fails a move it cannot finish (BLOCKED, NO_PROGRESS when the
robot is trapped, as in W4's pocket), CAMERA a photo whose target is not in the image, ANTENNA a
communication no visibility window holds. The executor adds temporal execution control: an
action still running at its start plus its planned longest duration has failed, and is stopped.
Every move reports `ROBOT_POSITION(x, y)`, the odometry where the robot stands, before its end or
its failure (FTplan's state rules then place the robot, and a replanning starts from there).

What the log holds (`specc.run.events`), each event at its mission time: `mission-start` (the world,
configuration, planners, seed, timing, the windows as drawn, the photo targets), `pose` every 0.5 s, every event of
FTplan's own log as `ftplan` (`event`: plan-request, plan, execute, report, goal-met, watchdog,
invalid-plan, action-failed, safe-state, operator, mission-failure, mission-end; `text`,
`planner`), every `action` as it starts and as it ends, fails or is stopped (`status`, `plan`,
`id`, `task`, `args`, `latest_end` at its start, `why`), every `photo` (`target`, `ok`, `seen`,
where the robot stood, the pan-tilt unit's angles) and `communication` (`window`, `ok`, `start`,
`link`: the window that held it), then `mission-end` (`outcome`, `why`, goals, plannings,
planner failures, distance).

Where the thesis is silent (INVENTED):
- the visibility windows' real opening and closing instants are drawn with the seed, uniformly in
  the bounds of the mission's contingent events (missions.md: "W1 [125..127, 154..156]");
- a communication asks ANTENNA for the task's shortest duration (18 s): the module's 0.5 s period
  lengthens it a little, and asking for the longest would always overrun the plan's bound;
- the initialisations are control requests: they take no time.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from specc.run import RunError
from specc.run.events import EventLog
from specc.run.package import import_generated
from specc.run.plans import FtplanJournal, KernelExecutor, Running, run_ftplan
from specc.run.recording import Emit, PoseRecorder, true_path, world_fields
from specc.run.render import draw_map
from specc.run.rover_tasks import LINK, MOTION_INIT, MOVE, PAN_TILT, PHOTO, PTU_INIT, TASK_KINDS, task_text
from specc.runtime import functional as rt
from specc.runtime.body import RobotConfig
from specc.runtime.ftplan import (
    MissionResult,
    MissionSetup,
    Report,
    UnknownName,
    mission_setup,
)
from specc.runtime.ftplan.config import FtPlanConfig
from specc.runtime.ftplan.execution import Execution
from specc.runtime.ftplan.facts import FactKey
from specc.runtime.ftplan.state import SystemState, consequences, constant, constant_key
from specc.runtime.ftplan.view import View
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Action, Plan, Value, format_value
from specc.runtime.sim import Simulation, Target, Window, World, WorldError, load_world

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ROOT / "generated"  # where `specc compile examples/atrv -o generated` writes the package
EXAMPLE = ROOT / "examples" / "atrv"  # the codels (atrv_codels) and the worlds
WORLDS = EXAMPLE / "worlds"
ROBOT = "atrv"
CODELS = "atrv_codels"
FTPLAN_BLOCK = "rover"  # the `ftplan` block of examples/atrv/ftplan.spec
TIMINGS = ("model", "wall")  # FtPlan's: a deterministic planning charge, or the measured wall time

MOVE_TOLERANCE = 0.3  # m around a move's target that NDD counts as there (run_sim.py's)
# Pan-tilt positions of Modele1 that the codels do not name. OTHER_POSITION is a position that is
# neither (INVENTED: looking up); a plan asks for it only through a faulty model.
OTHER_POSITION = (0.0, 0.5)
SETTLE_LIMIT = 2.0  # s a stopped robot is given to come to rest (the motors ramp at 1 m/s²)
STILL_SPEED = 1e-3  # m/s at the wheel rims: slower than this, the robot stands still
WINDOW_STREAM = 0x57A7E11  # mixed with the seed for the windows' instants, apart from the simulator's streams
POSITION_DIGITS = 2  # the odometry reported to FTplan, to the centimetre

# The state attributes FTplan's rules use for where the robot is and which photo is done.
ROBOT_X, ROBOT_Y = "AT_ROBOT_X", "AT_ROBOT_Y"
PICTURE = "PICTURE"
COMMUNICATION = "COMMUNICATION"

# NDD's failures, as a person reads them (examples/atrv/modules/ndd.spec).
NAVIGATION_FAILURES = {
    "NO_PROGRESS": "the goal came no closer for {progress:g} s: the robot is trapped",
    "BLOCKED": "the wheels turned and the robot did not move",
    "LASER_FAILURE": "the laser scanner returned no echo",
    "POSE_NOT_FOUND": "no odometry to navigate with",
    "BAD_GOAL": "the target is not a valid goal",
}


# ---------------------------------------------------------------- what a run leaves


@dataclass(frozen=True)
class MissionGoal:
    """A goal of the mission, as FTplan stated and judged it. The return home is one goal (FTplan
    has one for each coordinate)."""

    kind: str  # photo | communication | return
    name: str  # the world's photo target (M1_OBJ2), the window (W1), or "home"
    point: tuple[float, float] | None  # where the photo or the return is asked
    text: str  # FTplan's statement of it
    met: bool  # in FTplan's ledger
    why: str = ""  # why FTplan counts it missed


@dataclass(frozen=True)
class Photo:
    """A photograph CAMERA took or failed to take."""

    time: float
    x: float  # the robot's true position
    y: float
    pan: float  # rad, the pan-tilt unit's true position
    tilt: float
    target: str  # the target asked for ("" for any)
    seen: tuple[str, ...]  # the targets in the image
    ok: bool
    why: str = ""


@dataclass(frozen=True)
class Communication:
    """A communication ANTENNA attempted for a window of the mission."""

    window: str  # the window the plan meant it for
    start: float
    end: float
    ok: bool
    link: str = ""  # the window that held it (when ok)
    why: str = ""


@dataclass(frozen=True)
class ExecutedAction:
    """An action of a plan as it ran: for a Gantt chart."""

    plan: int  # which plan FTplan executed, from 1
    id: str  # the plan's id ("MOVE#3")
    task: str
    args: tuple[Value, ...]
    start: float
    end: float
    outcome: str  # ended | failed | stopped (running when another action failed)
    why: str = ""

    def text(self) -> str:
        return task_text(self.task, self.args)


@dataclass(frozen=True)
class PlannedTask:
    """An action of a plan FTplan executed, as planned."""

    plan: int
    domain: str  # the planning model that made the plan
    id: str
    text: str
    dispatch: float
    latest_end: float


@dataclass(frozen=True)
class RoverRun:
    configuration: str
    mission: str
    world: str
    seed: int
    timing: str
    policy: str  # FTplan's recovery: successive (Fig 3.1) or concurrent (Fig 3.2)
    result: MissionResult  # FTplan's: goals met and missed, plannings, planner failures, events, trace
    goals: tuple[MissionGoal, ...]
    windows: tuple[Window, ...]  # the visibility windows as nature opened and closed them
    photos: tuple[Photo, ...]
    communications: tuple[Communication, ...]
    actions: tuple[ExecutedAction, ...]
    planned: tuple[PlannedTask, ...]
    path: tuple[tuple[float, float, float, float], ...]  # t, true x, y, theta every 0.1 s
    distance: float  # m the robot really travelled
    simulated_time: float  # s: the mission time at the end
    wall_time: float  # s
    events: tuple[dict[str, Any], ...]  # the event log
    simulation: Simulation = field(compare=False, repr=False)

    @property
    def final_position(self) -> tuple[float, float]:
        _, x, y, _ = self.path[-1]
        return x, y

    def draw(self, path: str | Path) -> Path:
        """A PNG of the run: the world, the robot's path, the photo targets, the windows. Drawn
        from the events, as `specc replay` draws the run folder's map.png."""
        return draw_map(self.events, path)


class RoverProgress(NamedTuple):
    """What `progress` receives at every action's start and end, and at the mission's end."""

    time: float  # mission time
    goals_met: int  # so far, in FTplan's ledger
    goals: int
    what: str  # "started MOVE(0, 0, 4, 0)"


# ---------------------------------------------------------------- the generated package


class AtrvPackage(NamedTuple):
    modules: ModuleType  # atrv.modules
    planner: ModuleType  # atrv.planner
    ftplan: ModuleType  # atrv.ftplan.rover
    systems: ModuleType  # atrv.systems: the body

    @property
    def body(self) -> RobotConfig:
        body: RobotConfig = self.systems.SYSTEMS[ROBOT].body
        return body


def load_package(generated: Path = GENERATED, example: Path = EXAMPLE) -> AtrvPackage:
    """The compiled atrv package imported from `generated`, the codels from `example`."""
    return AtrvPackage(*import_generated(generated, example, ROBOT, CODELS,
                                         ("modules", "planner", f"ftplan.{FTPLAN_BLOCK}", "systems")))


def resolve_world(world: str | Path | World, worlds: Path = WORLDS) -> World:
    """A name of the worlds in `worlds` (W1..W4 in examples/atrv/worlds), a path to a world
    file, or a World used as it is."""
    if isinstance(world, World):
        return world
    text = str(world)
    named = {p.stem.upper(): p for p in sorted(worlds.glob("*.toml"))}
    if text.upper() in named:
        path = named[text.upper()]
    elif text.endswith(".toml") or Path(text).is_file():
        path = Path(text)
    else:
        raise RunError(f"unknown world '{text}': give {', '.join(p.stem for p in named.values()) or 'a world name'} "
                       f"({worlds}) or a world file (.toml)")
    try:
        return load_world(path)
    except WorldError as error:
        raise RunError(str(error)) from None


# ---------------------------------------------------------------- the rover on the kernel


class Clients(NamedTuple):
    """A client per module of the ATRV, on one registry with the simulation."""

    rflex: Any
    sick: Any
    ndd: Any
    platine: Any
    camera: Any
    antenna: Any


@dataclass
class Rover:
    registry: rt.Registry
    sim: Simulation
    clients: Clients
    modules: dict[str, Any]  # the module instances, by name (their SDI, for tests and pictures)

    @property
    def kernel(self) -> Any:
        return self.registry.kernel

    def client(self, module: str) -> Any:
        return getattr(self.clients, module)


def build_rover(modules: ModuleType, world: World, seed: int, body: RobotConfig) -> Rover:
    """The six generated modules with the simulated ATRV (`body`, its system block's) in `world`
    (run_sim.py's `build`)."""
    registry = rt.Registry()
    try:
        sim = Simulation(world, body, seed=seed, kernel=registry.kernel).attach(registry)
    except WorldError as error:  # what the world asks cannot be built (objects without room)
        raise RunError(str(error)) from None
    made = modules.create_all(registry)
    clients = Clients(*(modules.MODULES[name].client(made[name]) for name in Clients._fields))
    return Rover(registry, sim, clients, dict(made))


# ---------------------------------------------------------------- the mission on the rover


@dataclass(frozen=True)
class Request:
    """One request of an action to a module, with its inputs."""

    module: str
    name: str
    args: tuple[float | str, ...] = ()

    def text(self) -> str:
        args = ", ".join(f"{a:g}" if isinstance(a, float) else repr(a) for a in self.args)
        return f"{self.module}.{self.name}({args})"


@dataclass(frozen=True)
class RoverTasks:
    """How the tasks of one mission's plans become the ATRV's requests: where a move goes and
    which target a photo is of, read from FTplan's own state rules and each planner's view (a
    Modele2 place is where the mission's view puts it), so that nothing of a mission is written
    twice."""

    mission: str
    config: FtPlanConfig  # the configuration on the mission (`FtPlanConfig.for_mission`)
    targets: Mapping[str, Target]  # the world's photo target of each PICTURE object ("OBJ1")

    @classmethod
    def of(cls, config: FtPlanConfig, problem: pm.Problem, mission: str, world: World) -> RoverTasks:
        """The mission's photo targets must be in the world, where the mission asks for them."""
        in_world = {t.name: t for t in world.targets}
        targets = {}
        for goal in SystemState.from_problem(problem).goals:
            if goal.attribute != PICTURE or len(goal.args) != 3:
                continue
            obj, x, y = goal.args
            name = target_name(mission, str(obj))
            target = in_world.get(name)
            if target is None or not (math.isclose(target.x, float(x), abs_tol=1e-6)
                                      and math.isclose(target.y, float(y), abs_tol=1e-6)):
                raise RunError(f"world {world.name} ({world.source or 'no file'}) has no photo target {name} at "
                               f"({format_value(x)}, {format_value(y)}), which mission {mission} photographs")
            targets[str(obj)] = target
        return cls(mission, config, targets)

    def view(self, plan: Plan) -> View | None:
        """The correspondences of the planner whose model made `plan` (None: FTplan's vocabulary)."""
        planner = next((p for p in self.config.planners if p.domain == plan.domain), None)
        return View(planner.view) if planner is not None and planner.view else None

    def effects(self, plan: Plan, action: Action) -> dict[FactKey, Value]:
        """What FTplan's state becomes when the action ends, in FTplan's vocabulary."""
        return dict(consequences(self.config.state_rules, "ended", action.task, action.args, self.view(plan)))

    def requests(self, plan: Plan, action: Action) -> tuple[Request, ...]:
        """The requests that carry `action` out, one after the other. Raises RunError for a task
        the rover cannot carry out (the message is the action's failure)."""
        from atrv_codels.platine import AT_MY_FEET, STRAIGHT  # importable once the package is loaded

        kind = TASK_KINDS.get(action.task)
        if kind == MOVE:
            effects = self.effects(plan, action)
            x, y = effects.get((ROBOT_X, ())), effects.get((ROBOT_Y, ()))
            if not isinstance(x, float) or not isinstance(y, float):
                raise RunError(f"FTplan's state rules and views do not say where {action.text()} goes")
            return (Request("ndd", "GotoTarget", (x, y, MOVE_TOLERANCE)),)
        if kind == PAN_TILT:
            if action.task == "MOVE_PTU":  # Modele2's angles, in degrees
                pan, tilt = (math.radians(float(a)) for a in action.args[2:4])
            else:
                named = {"STRAIGHT": STRAIGHT, "AT_MY_FEET": AT_MY_FEET, "OTHER_POSITION": OTHER_POSITION}
                if str(action.args[-1]) not in named:
                    raise RunError(f"{action.text()}: no pan-tilt position is called {format_value(action.args[-1])}")
                pan, tilt = named[str(action.args[-1])]
            return (Request("platine", "MoveTo", (pan, tilt)),)
        if kind == PHOTO:
            # The photo of the PICTURE(obj, x, y) its end makes DONE; a photo that makes none (a
            # Modele2 SHOT of a place no target stands at) is of whatever target the image shows.
            done = [args for (attribute, args) in self.effects(plan, action) if attribute == PICTURE and args]
            target = target_name(self.mission, format_value(done[0][0])) if done else ""
            return (Request("camera", "TakePicture", (target,)),)
        if kind == LINK:
            return (Request("antenna", "Communicate", (max(action.duration[0], 1.0),)),)
        if kind == PTU_INIT:
            return (Request("platine", "Init"),)
        if kind == MOTION_INIT:
            return (Request("ndd", "Stop"), Request("rflex", "Stop"))
        raise RunError(f"the ATRV has no procedure for task {action.task}")


def target_name(mission: str, obj: str) -> str:
    """The world's name of a mission's photo target: OBJ2 of M1 is M1_OBJ2."""
    return f"{mission}_{obj}"


def mission_windows(problem: pm.Problem, seed: int) -> tuple[Window, ...]:
    """The visibility windows of the mission, each opening and closing at an instant nature draws
    (with the seed) uniformly within the bounds of its contingent events."""
    dates = SystemState.from_problem(problem).dates
    opening: dict[str, tuple[float, float]] = {}
    closing: dict[str, tuple[float, float]] = {}
    for a in problem.assertions:
        if not (isinstance(a, pm.Event) and a.kind == "contingent" and a.attribute == "VISIBILITY_WINDOW"):
            continue
        key, before, after = constant_key(a.attribute, a.args), constant(a.before), constant(a.after)
        if key is None or a.time == problem.start or a.time not in dates or len(key[1]) != 1:
            continue
        if (before, after) == ("OUT", "IN"):
            opening[str(key[1][0])] = dates[a.time]
        elif (before, after) == ("IN", "OUT"):
            closing[str(key[1][0])] = dates[a.time]
    rng = np.random.default_rng([WINDOW_STREAM, seed])
    windows = []
    for name in sorted(opening, key=lambda n: opening[n]):
        if name not in closing or not (_drawable(opening[name]) and _drawable(closing[name])):
            continue  # an inconsistent problem leaves nature no instant: no window, and no plan either
        start = round(float(rng.uniform(*opening[name])), 3)
        end = round(float(rng.uniform(*closing[name])), 3)
        windows.append(Window(name, start, max(end, start)))
    return tuple(windows)


def _drawable(bounds: tuple[float, float]) -> bool:
    low, high = bounds
    return math.isfinite(low) and math.isfinite(high) and low <= high


def mission_goals(problem: pm.Problem, mission: str, state: SystemState | None = None) -> tuple[MissionGoal, ...]:
    """The mission's goals by kind, as FTplan judged them in `state` (its ledger at the end)."""
    ledger = state or SystemState.from_problem(problem)
    goals: list[MissionGoal] = []
    home: list[Any] = []
    for goal in ledger.goals:
        met = goal.line in ledger.met
        why = ledger.missed.get(goal.line, "")
        if goal.attribute == PICTURE and len(goal.args) == 3:
            obj, x, y = goal.args
            goals.append(MissionGoal("photo", target_name(mission, str(obj)), (float(x), float(y)), goal.text(), met,
                                     why))
        elif goal.attribute == COMMUNICATION and len(goal.args) == 1:
            goals.append(MissionGoal("communication", str(goal.args[0]), None, goal.text(), met, why))
        elif goal.attribute in (ROBOT_X, ROBOT_Y) and not goal.args:
            home.append((goal, met, why))
    if home:
        point = {g.attribute: float(g.value) for g, _, _ in home if isinstance(g.value, float)}
        goals.append(MissionGoal("return", "home", (point.get(ROBOT_X, 0.0), point.get(ROBOT_Y, 0.0)),
                                 "; ".join(g.text() for g, _, _ in home), all(met for _, met, _ in home),
                                 "; ".join(why for _, _, why in home if why)))
    return tuple(goals)


# ---------------------------------------------------------------- the executor


@dataclass
class _Chain:
    """The requests that carry an action out, sent one after the other."""

    requests: tuple[Request, ...]
    step: int = 0
    rqst_id: int | None = None


class SimExecutor(KernelExecutor):
    """FTplan's `Executor` on the simulated ATRV: each action of a plan is carried out by the
    generated modules on the simulation's kernel (see the module's docstring), in mission time,
    scheduled as `specc.run.plans.KernelExecutor` does for any robot."""

    def __init__(self, rover: Rover, tasks: RoverTasks, emit: Emit | None = None) -> None:
        super().__init__(rover.kernel, emit)
        self.rover = rover
        self.tasks = tasks
        self.photos: list[Photo] = []
        self.communications: list[Communication] = []
        self.actions: list[ExecutedAction] = []
        self.planned: list[PlannedTask] = []
        self._stopping: list[tuple[Any, int]] = []  # (client, request) interrupted, not yet ended
        self._replied_since = False  # a module answered a request of ours since the actions last advanced
        for client in rover.clients:
            client.final_listeners.append(self._final_reply)

    def execute(self, plan: Plan, now: float, report: Callable[[Report], None]) -> Execution:
        number = self.plans + 1
        for action in plan.ordered():
            self.planned.append(PlannedTask(number, plan.domain, action.id, action.text(), action.dispatch,
                                            plan.ends_by(action)))
        return super().execute(plan, now, report)

    # ------------------------------------------------------------ one action
    def begin(self, run: Running, plan: Plan) -> None:
        try:
            run.handle = _Chain(self.tasks.requests(plan, run.action))
        except RunError as error:
            run.handle = _Chain(())
            run.finished, run.why = run.started, f"{run.action.text()} cannot be carried out: {error}"

    def _final_reply(self, reply: rt.Reply) -> None:
        self._replied_since = True

    def await_progress(self, wake: float) -> None:
        # Every action advanced after each kernel event in which a module answered (each sends
        # its next request at the instant the one before ended), and once now for what was
        # answered while the actions before concluded.
        self._replied_since = True
        super().await_progress(wake)

    def nothing_over(self) -> bool:
        """An action waiting for a reply has nothing to do before a module answered."""
        if not self._replied_since:
            return True
        self._replied_since = False
        return super().nothing_over()

    def advance(self, run: Running) -> bool:
        """Send the action's next request when the one before has ended well; True when the
        action is over (ended or failed)."""
        if run.finished is not None:
            return True
        chain = run.handle
        while True:
            request = chain.requests[chain.step]
            client = self.rover.client(request.module)
            if chain.rqst_id is None:
                chain.rqst_id = getattr(client, request.name)(*request.args)
            reply = client.reply(chain.rqst_id)
            if reply.status is rt.Status.WAITING:
                return False
            self._replied(run, request, reply)
            # Over when the executor has the reply (a module replies once its children have ended).
            if not reply.ok:
                run.finished, run.why = self.kernel.now, self._failure(run, request, reply)
                return True
            chain.step, chain.rqst_id = chain.step + 1, None
            if chain.step == len(chain.requests):
                run.finished, run.ok = self.kernel.now, True
                return True

    def interrupt(self, run: Running) -> None:
        """Abort the action's request under way; `come_to_rest` waits for it to wind down."""
        chain = run.handle
        if chain.rqst_id is not None and chain.step < len(chain.requests):
            client = self.rover.client(chain.requests[chain.step].module)
            if client.reply(chain.rqst_id).status is rt.Status.WAITING:
                client.abort(chain.rqst_id)
                self._stopping.append((client, chain.rqst_id))

    def wind_down(self, failed: Running) -> None:
        """A move that failed: the robot comes to rest before it reports where it stands."""
        if TASK_KINDS.get(failed.action.task) == MOVE:
            self.come_to_rest()

    def reports(self, run: Running) -> list[Report]:
        """Where the robot stands after a move (once it has come to rest when the move failed),
        then its end or its failure."""
        said = super().reports(run)
        if TASK_KINDS.get(run.action.task) == MOVE:
            x, y = self._odometry()
            said.insert(0, Report("report", "ROBOT_POSITION", (x, y), said[0].time, run.action.id))
        return said

    def record(self, run: Running, outcome: str, why: str, end: float | None = None) -> None:
        end = self.kernel.now if end is None else end
        action = run.action
        self.actions.append(ExecutedAction(run.plan, action.id, action.task, action.args, run.started, end, outcome,
                                           why))
        super().record(run, outcome, why, end)

    # ------------------------------------------------------------ what the modules answered
    def _replied(self, run: Running, request: Request, reply: rt.Reply) -> None:
        """Keep the photos and the communications as the modules report them."""
        if request.name == "TakePicture":
            x, y, _ = self.rover.sim.pose
            unit = self.rover.sim.pan_tilt
            seen = tuple(t for t in reply.output.photo.targets.split(",") if t) if reply.ok else ()
            photo = Photo(reply.time, round(x, 3), round(y, 3), round(unit.pan.position, 4),
                          round(unit.tilt.position, 4), str(request.args[0]), seen, reply.ok,
                          "" if reply.ok else _reply_text(reply))
            self.photos.append(photo)
            self.event(reply.time, "photo", target=photo.target, ok=photo.ok, seen=list(seen), x=photo.x, y=photo.y,
                       pan=photo.pan, tilt=photo.tilt, **({"why": photo.why} if photo.why else {}))
        elif request.name == "Communicate":
            window = format_value(run.action.args[0]) if run.action.args else ""
            link = reply.output.window if reply.ok else ""
            communication = Communication(window, run.started, reply.time, reply.ok, link,
                                          "" if reply.ok else _reply_text(reply))
            self.communications.append(communication)
            self.event(reply.time, "communication", window=window, ok=reply.ok, start=round(run.started, 6),
                       link=link, **({"why": communication.why} if communication.why else {}))

    def _failure(self, run: Running, request: Request, reply: rt.Reply) -> str:
        """Why the action failed, in one line."""
        text = f"{run.action.text()} failed: {request.text()} -> {_reply_text(reply)}"
        if request.name == "GotoTarget":
            arrival = reply.output.arrival if reply.output is not None else None
            explained = NAVIGATION_FAILURES.get(reply.report.code, "")
            if explained:
                progress = self.rover.clients.ndd.module.sdi.params.progressTime
                text += f" ({explained.format(progress=progress)})"
            if arrival is not None and reply.report.code != "BAD_GOAL":
                text += f", at ({arrival.x:.2f}, {arrival.y:.2f}) {arrival.distance:.2f} m from the goal"
        return text

    # ------------------------------------------------------------ the robot
    def _odometry(self) -> tuple[float, float]:
        """Where the robot believes it stands (RFLEX's odometry, POM's position)."""
        snapshot = self.rover.clients.rflex.poster_Robot()
        if snapshot is None:
            x, y, _ = self.rover.sim.world.start
        else:
            x, y = snapshot.data.pose.x, snapshot.data.pose.y
        return round(x, POSITION_DIGITS) + 0.0, round(y, POSITION_DIGITS) + 0.0

    def come_to_rest(self) -> None:
        """Stop the navigation and the wheels; wait (SETTLE_LIMIT at most) for the robot to stand
        and for the interrupted requests to end."""
        self.rover.clients.ndd.Stop()
        self.rover.clients.rflex.Stop()
        rover = self.rover.sim.rover

        def busy() -> bool:
            self._stopping = [(c, k) for c, k in self._stopping if c.reply(k).status is rt.Status.WAITING]
            return bool(self._stopping) or abs(rover.left_speed) + abs(rover.right_speed) > STILL_SPEED

        self.kernel.run_while(busy, self.kernel.now + SETTLE_LIMIT)


def _reply_text(reply: rt.Reply) -> str:
    detail = f" ({reply.report.detail})" if reply.report.detail else ""
    return f"{reply.status.value} {reply.report.code}{detail}"


# ---------------------------------------------------------------- the run


class _Journal(FtplanJournal):
    """The run's event log: FTplan's own events as they come (kind `ftplan`), then the
    executor's (actions, photos, communications), each at its mission time; and the progress."""

    def __init__(self, log: EventLog, progress: Callable[[RoverProgress], None] | None, goals: int) -> None:
        super().__init__(log)
        self.progress = progress
        self.goals = goals

    def emit(self, time_: float, kind: str, **fields: Any) -> dict[str, Any]:
        event = super().emit(time_, kind, **fields)
        if kind == "action" and self.progress is not None:
            self.report_progress(time_, f"{fields.get('status')} {task_text(fields['task'], fields['args'])}")
        return event

    def report_progress(self, time_: float, what: str) -> None:
        if self.progress is not None:
            met = len(self.ftplan.state.met) if self.ftplan is not None else 0
            self.progress(RoverProgress(time_, met, self.goals, what))


@dataclass
class PreparedMission:
    """A mission ready to run, nothing started yet: FTplan's side (the configuration on the
    mission, the problems and domains) and the rover's (the modules on the simulated rover in
    the world, with the windows nature drew)."""

    configuration: str
    mission: str
    seed: int
    setup: MissionSetup
    world: World
    rover: Rover
    tasks: RoverTasks


def check_mission(configuration: str, mission: str, world: str | Path | World, seed: int = 0, *,
                  generated: Path = GENERATED, example: Path = EXAMPLE,
                  domains: Mapping[str, pm.PlanningDomain] | None = None) -> CheckedMission:
    """Check the names and read what the mission needs, nothing built yet; RunError when a name
    is unknown or the package is not compiled. `domains` replace the generated planning domains
    of the same names (a mutant of Modele1, seed 004 §4.1.3)."""
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise RunError(f"seed {seed!r}: give a whole number >= 0")
    package = load_package(generated, example)
    try:
        setup = mission_setup(package.ftplan.CONFIGURATIONS, configuration, mission, package.planner)
    except UnknownName as error:
        raise RunError(str(error)) from None
    if domains:
        unused = sorted(set(domains) - setup.planned_in)
        if unused:
            raise RunError(f"configuration {configuration} plans in {', '.join(sorted(setup.planned_in))}, "
                           f"not in {', '.join(unused)}")
        setup = dataclasses.replace(setup, domains={**setup.domains, **domains})
    ground = resolve_world(world, example / "worlds")
    tasks = RoverTasks.of(setup.config, setup.problem, mission, ground)
    # The antenna's windows, and those the picture's time strip shows.
    ground = dataclasses.replace(ground, windows=mission_windows(setup.problem, seed))
    return CheckedMission(setup, ground, tasks, package.modules, package.body)


class CheckedMission(NamedTuple):
    setup: MissionSetup
    world: World  # with the windows nature drew
    tasks: RoverTasks
    modules: ModuleType  # the generated atrv.modules
    body: RobotConfig  # the simulated rover's, as its system block says


def prepare_mission(configuration: str, mission: str, world: str | Path | World, seed: int = 0, *,
                    generated: Path = GENERATED, example: Path = EXAMPLE,
                    domains: Mapping[str, pm.PlanningDomain] | None = None) -> PreparedMission:
    """`check_mission`, then the modules on the simulated rover: what `run_rover_mission` runs."""
    checked = check_mission(configuration, mission, world, seed, generated=generated, example=example,
                            domains=domains)
    return PreparedMission(configuration, mission, seed, checked.setup, checked.world,
                           build_rover(checked.modules, checked.world, seed, checked.body), checked.tasks)


def run_rover_mission(configuration: str, mission: str, world: str | Path | World, seed: int = 0, *,
                      log: EventLog | None = None, progress: Callable[[RoverProgress], None] | None = None,
                      generated: Path = GENERATED, example: Path = EXAMPLE, timing: str = "model",
                      domains: Mapping[str, pm.PlanningDomain] | None = None) -> RoverRun:
    """Run `mission` (M1..M4) with the robot `configuration` of seed 004 §4.2.1.1 (Robot1,
    Robot2, Robot1/2, Robot1/2c) in `world` (W1..W4, a world file or a World), the simulation and the
    visibility windows drawn from `seed`.

    `generated` holds the compiled atrv package (`specc compile examples/atrv -o generated`),
    `example` the codels (atrv_codels) and the worlds;
    `timing` is FTplan's planning charge ("model": deterministic, "wall": measured); `domains`
    replace the generated planning domains of the same names (check_mission). Events go to
    `log` (one in memory when none is given) and to the result. Anything the caller can get wrong
    raises RunError, whose message is one line."""
    if timing not in TIMINGS:
        raise RunError(f"timing '{timing}': give {' or '.join(TIMINGS)}")
    prepared = prepare_mission(configuration, mission, world, seed, generated=generated, example=example,
                               domains=domains)
    setup, rover, windows = prepared.setup, prepared.rover, prepared.world.windows
    log = log if log is not None else EventLog()
    journal = _Journal(log, progress, len(SystemState.from_problem(setup.problem).goals))
    executor = SimExecutor(rover, prepared.tasks, journal.emit)
    started = time.perf_counter()
    log.emit(rover.kernel.now, "mission-start", robot=ROBOT, body=dataclasses.asdict(rover.sim.robot),
             configuration=configuration, mission=mission,
             **world_fields(prepared.world), seed=seed, timing=timing, policy=setup.config.policy,
             planners=[f"{p.name} ({p.domain})" for p in setup.config.planners],
             windows=[[w.name, w.start, w.end] for w in windows],
             targets=[[t.name, t.x, t.y] for t in prepared.tasks.targets.values()])
    PoseRecorder(journal.emit, rover.sim).start()
    ftplan, result = run_ftplan(setup, executor, journal, timing)
    goals = mission_goals(setup.problem, mission, ftplan.state)
    sim = rover.sim
    if result.failure:
        outcome, why = "failed", result.failure
    elif result.missed:
        outcome, why = "failed", f"{len(result.missed)} goal(s) missed: " + "; ".join(
            f"{goal}: {reason}" for goal, reason in result.missed.items())
    else:
        outcome, why = "succeeded", f"every goal met ({len(result.met)})"
    log.emit(rover.kernel.now, "mission-end", outcome=outcome, why=why, goals_met=len(result.met),
             goals=len(result.met) + len(result.missed), plannings=result.plannings,
             planner_failures=result.planner_failures, distance=round(sim.rover.distance, 3))
    journal.report_progress(rover.kernel.now, f"mission {outcome}")
    return RoverRun(
        configuration=configuration, mission=mission, world=prepared.world.name, seed=seed, timing=timing,
        policy=setup.config.policy, result=result, goals=goals, windows=windows, photos=tuple(executor.photos),
        communications=tuple(executor.communications), actions=tuple(executor.actions),
        planned=tuple(executor.planned), path=true_path(sim), distance=sim.rover.distance,
        simulated_time=rover.kernel.now, wall_time=time.perf_counter() - started, events=tuple(log.events),
        simulation=sim)
