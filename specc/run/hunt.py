"""Hilare 2's object hunt (seed 000 ch. 5), end to end on the simulated kernel.

    result = run_hunt(seed=3, log=EventLog("hunt.jsonl"))
    result.success, result.objects_taken, result.simulated_time
    detection_interruptions(result.events)   # §5.5: a detection stops the exploration move
    arm_motion_overlaps(result.events)       # §5.1: the robot stands still while the arm takes
    draw_hunt(result, "hunt.png")            # the room, the path, and the state of Fig 5.11

The compiled hilare package (`specc compile examples/hilare -o generated`) runs whole: the eight
modules on the simulated robot and room (`specc.runtime.sim`), the executive of §5.3 over them,
and the PRS supervisor of §5.4 posting `!(COLLECT-OBJECTS n)`, whose base procedure runs the
take-object, exploration and modelling cycles in parallel (Fig 5.1, 5.7). The run ends when that
goal ends or at the horizon. The outcome is the goal's, except that a hunt whose procedures
counted an object the gripper never held (VISUAL saw it where none lies) fails.

The seed places the room's objects (§5.6: 10, from worlds/room.toml) and drives every random
draw of the run (sensor noise, camera detections, the order of applicable KAs), so a seed gives
one run and one event log. The objects lie at random on cells where Hilare can stand: §5.2.5
assumes "que le centre du robot doit être dans le centre de la cellule de l'objet à saisir", and
EXPLOR's calcObj refuses any other cell (UNREACHABLE_CELL), which fails the take-object cycle and
the hunt with it (§5.4.1); VISUAL's own simulation places its objects the same way. (The
simulator's own scattering only keeps objects 0.45 m from the obstacles: with it, 4 hunts of
seeds 0-29 failed so, EXPLOR refusing the cell of the object to take.)

What the log holds (kinds in `specc.run.events`): every request the task level sends and every
reply and warning the executive answers, every phase change of the executive's activities,
every fact the procedures conclude or retract, when the robot and the arm start and stop moving
(from the simulator's true state), when the camera first sees each object, when an object is
retrieved and when it is on the robot, alarms, and the mission's start and end.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import re
import time
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from specc.run import RunError
from specc.run.events import EventLog
from specc.run.hunt_log import (
    EXPLORATION_MOVE,
    TAKE_CYCLE,
    DetectionReport,
    HuntObject,
    Interruption,
    MissedDetection,
    Overlap,
    Span,
    arm_motion_overlaps,
    detection_interruptions,
    motion_stretches,
)
from specc.run.package import import_generated
from specc.run.pictures import write_hunt
from specc.run.recording import PoseRecorder, true_path, world_fields
from specc.run.render import hunt_scene, run_info
from specc.runtime import executive as rx
from specc.runtime import functional as rt
from specc.runtime.sim import HILARE, Simulation, World, WorldError, load_world
from specc.runtime.sim.render import Certainty
from specc.runtime.sim.simulation import OBJECT_CLEARANCE

# The readings of the log (specc.run.hunt_log) stay part of the hunt's interface: one asks them of run_hunt's events.
__all__ = ["EXPLORATION_MOVE", "TAKE_CYCLE", "DetectionReport", "HuntObject", "HuntProgress", "HuntResult",
           "Interruption", "MissedDetection", "Overlap", "PlannedPath", "Span", "arm_motion_overlaps",
           "detection_interruptions", "draw_hunt", "load_package", "motion_stretches", "place_objects", "run_hunt"]

ROOT = Path(__file__).resolve().parents[2]
GENERATED = ROOT / "generated"  # where `specc compile examples/hilare -o generated` writes the package
EXAMPLE = ROOT / "examples" / "hilare"  # its codels (hilare_codels) and its room
ROBOT = "hilare"
CODELS = "hilare_codels"
# The executive's READ-MODEL and READ-OBST name the room relative to the robot's folder
# (executive.spec), so the hunt runs from there.
WORLD = "worlds/room.toml"
GOAL = "!(COLLECT-OBJECTS {n})"
MAX_OBJECTS_WANTED = 5  # the domain of COLLECT-OBJECTS and OBJECTS-WANTED in procedures.spec
HORIZON = 900.0  # s of simulated time: 5 objects take 94-139 s (seeds 0-29); 15 minutes is a hunt gone wrong
OBJECT_STREAM = 0x0B1EC7  # mixed with the seed for the objects' places, apart from the simulator's streams
OBJECT_JITTER = 0.1  # m: an object lies within this of its cell's centre, on each axis
ROBOT_MOVING = 0.005  # m/s at the wheel rims: slower than this, the robot stands still
SAMPLE_PRIORITY = 1000  # the motion sampler runs after the physics and codels of its instant
CERTAINTY_DIGITS = 3  # the model's certainty per cell, as the log keeps it
PROGRESS_PERIOD = 10.0  # s of simulated time between two progress reports

LIVE_PHASES = ("INIT", "EXEC", "INTER")  # an activity its module is working on


# ---------------------------------------------------------------- results


@dataclass(frozen=True)
class PlannedPath:
    """A trajectory PLAN computed (CALC-TRAJ-GOAL or CALC-TRAJ-OBJ answered OK)."""

    time: float
    service: str
    points: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class HuntResult:
    seed: int
    objects_wanted: int
    objects_taken: int
    outcome: str  # succeeded | failed | horizon (the goal was still running)
    why: str  # one line for a person
    simulated_time: float  # s
    wall_time: float  # s
    distance: float  # m the robot really travelled
    world: World  # the room, with the objects where the seed put them
    objects: tuple[HuntObject, ...]
    path: tuple[tuple[float, float, float, float], ...]  # t, true x, y, theta every 0.1 s
    planned: tuple[PlannedPath, ...]
    goal: tuple[float, float] | None  # the last observation position EXPLOR chose (Fig 5.11)
    certainty: Certainty | None  # VISUAL's model at the end
    replies: Mapping[str, int]  # "SERVICE RESULT" -> how many
    events: tuple[dict[str, Any], ...]  # the event log

    @property
    def success(self) -> bool:
        return self.outcome == "succeeded"

    @property
    def explored_cells(self) -> int:
        """Cells of the room whose certainty reached 1/3 (the lowest band of Fig 5.11's model)."""
        if self.certainty is None:
            return 0
        return int(np.count_nonzero(self._room_cells() & (self.certainty.grid() >= 1 / 3)))

    @property
    def explored_fraction(self) -> float:
        if self.certainty is None:
            return 0.0
        return self.explored_cells / max(1, int(np.count_nonzero(self._room_cells())))

    def _room_cells(self) -> np.ndarray:
        assert self.certainty is not None
        c = self.certainty
        xmin, xmax, ymin, ymax = self.world.bounds
        centres_x = (np.arange(c.nx) + 0.5) * c.cell
        centres_y = (np.arange(c.ny) + 0.5) * c.cell
        inside_y = (centres_y >= ymin) & (centres_y <= ymax)
        inside_x = (centres_x >= xmin) & (centres_x <= xmax)
        return inside_y[:, None] & inside_x[None, :]


class HuntProgress(NamedTuple):
    """What `progress` receives every PROGRESS_PERIOD simulated seconds, at each object taken and
    at the end."""

    time: float
    horizon: float
    objects_taken: int
    objects_wanted: int


def draw_hunt(result: HuntResult, path: str | Path, *, title: str = "") -> Path:
    """Write a PNG of the hunt and of its final state (Fig 5.11), from the result's events;
    returns its path. `title` replaces the run's description in the headline."""
    events = result.events
    return write_hunt(hunt_scene(events), path, title or run_info(events).title())


# ---------------------------------------------------------------- the run


def run_hunt(seed: int, objects_wanted: int = MAX_OBJECTS_WANTED, horizon: float = HORIZON,
             log: EventLog | None = None, progress: Callable[[HuntProgress], None] | None = None, *,
             generated: Path | None = None, example: Path | None = None) -> HuntResult:
    """Hunt `objects_wanted` objects in Hilare's room for at most `horizon` simulated seconds.

    `generated` is the folder holding the compiled hilare package (default: the repository's
    generated/), `example` the robot's folder with its codels and worlds (examples/hilare/);
    both go on sys.path. Events go to `log` (one in memory when none is given) and to the
    result. Bad arguments raise RunError."""
    check_arguments(seed, objects_wanted, horizon)
    example = (example or EXAMPLE).resolve()
    package = load_package(generated or GENERATED, example)
    world = place_objects(_load_room(example), seed)
    log = log if log is not None else EventLog()
    goal = GOAL.format(n=objects_wanted)
    started = time.perf_counter()
    with contextlib.chdir(example):
        registry = rt.Registry()
        sim = Simulation(world, HILARE, seed=seed, kernel=registry.kernel).attach(registry)
        package.modules.create_all(registry)
        executive = package.executive.create(registry, world=str(example / WORLD))
        kernel = registry.kernel
        recorder = _Recorder(log, sim, executive, objects_wanted, horizon, progress)
        # The supervisor listens to the executive after the recorder: a reply is logged before
        # what the procedures make of it.
        supervisor = package.supervisor.create(kernel=kernel, executive=executive, seed=seed,
                                               log=recorder.operator)
        recorder.watch_facts(supervisor.database)
        log.emit(kernel.now, "mission-start", robot=ROBOT, mission="hunt", seed=seed, goal=goal,
                 objects_wanted=objects_wanted, horizon=horizon, objects=[[x, y] for x, y in sim.objects],
                 **world_fields(world))
        intention = supervisor.post(goal)
        log.emit(kernel.now, "goal", goal=goal, status="posted")
        recorder.start()
        PoseRecorder(log.emit, sim).start()

        def running() -> bool:
            recorder.poll_facts()
            return intention.status == "running"

        kernel.run_while(running, kernel.now + horizon)
        recorder.finish()
    taken = recorder.taken_count
    if intention.status == "running":
        outcome = "horizon"
        why = f"still running at the {horizon:g} s horizon, {taken} of {objects_wanted} object(s) taken"
    else:
        log.emit(kernel.now, "goal", goal=goal, status=intention.status)
        outcome = intention.status
        why = (f"{taken} of {objects_wanted} object(s) taken in {kernel.now:.1f} s" if outcome == "succeeded"
               else _why_failed(intention.trace, log.events))
        if outcome == "succeeded" and taken < objects_wanted:  # the procedures counted a ghost
            outcome = "failed"
            why = (f"the procedures took {objects_wanted} object(s), but {recorder.empty_takes} take cycle(s) "
                   f"found nothing where VISUAL had seen an object: {taken} on the robot")
    log.emit(kernel.now, "mission-end", outcome=outcome, why=why, objects_taken=taken,
             objects_wanted=objects_wanted, distance=round(sim.rover.distance, 3),
             requests=recorder.requests)
    if progress is not None:
        progress(HuntProgress(kernel.now, horizon, taken, objects_wanted))
    return HuntResult(
        seed=seed, objects_wanted=objects_wanted, objects_taken=taken, outcome=outcome, why=why,
        simulated_time=kernel.now, wall_time=time.perf_counter() - started, distance=sim.rover.distance,
        world=world, objects=recorder.objects(), path=true_path(sim), planned=tuple(recorder.planned),
        goal=sim.trace.goal, certainty=_certainty(sim),
        replies=dict(sorted(recorder.replies.items())), events=tuple(log.events))


def check_arguments(seed: int, objects_wanted: int, horizon: float) -> None:
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise RunError(f"seed {seed!r}: give a whole number >= 0")
    if not isinstance(objects_wanted, int) or isinstance(objects_wanted, bool) \
            or not 0 <= objects_wanted <= MAX_OBJECTS_WANTED:
        raise RunError(f"{objects_wanted!r} objects wanted: COLLECT-OBJECTS takes 0 to {MAX_OBJECTS_WANTED} "
                       "(its domain in examples/hilare/procedures.spec)")
    if not isinstance(horizon, int | float) or isinstance(horizon, bool) or not math.isfinite(horizon) \
            or horizon <= 0:
        raise RunError(f"horizon {horizon!r}: give a positive number of simulated seconds")


def load_package(generated: Path, example: Path) -> Any:
    """The compiled package's modules, executive and supervisor, imported from `generated`,
    with the codels from `example`."""
    return _Package(*import_generated(generated, example, ROBOT, CODELS,
                                      ("modules", f"executive.{ROBOT}", f"supervisor.{ROBOT}_tasks")))


class _Package(NamedTuple):
    modules: ModuleType
    executive: ModuleType
    supervisor: ModuleType


def _load_room(example: Path) -> World:
    try:
        return load_world(example / WORLD)
    except WorldError as error:
        raise RunError(str(error)) from None


def place_objects(world: World, seed: int) -> World:
    """The room with its random objects placed from `seed` on cells where Hilare can stand
    (see the module's docstring), each within OBJECT_JITTER of its cell's centre and, as the
    simulator places its own, OBJECT_CLEARANCE from the others (VISUAL tells objects apart by
    where it sees them). VISUAL's grid decides, so the example's codels must be importable
    (`load_package` puts them on sys.path)."""
    from hilare_codels import visual  # the model's grid: the cells EXPLOR will judge

    cells = visual.standing_cells(visual.free_cells(world), world.bounds)
    rng = np.random.default_rng([OBJECT_STREAM, seed])
    placed: list[tuple[float, float]] = []
    for k in rng.permutation(len(cells)):
        if len(placed) == world.random_objects:
            break
        i, j = cells[int(k)] % visual.NX, cells[int(k)] // visual.NX
        dx, dy = rng.uniform(-OBJECT_JITTER, OBJECT_JITTER, size=2)
        x, y = round((i + 0.5) * visual.CELL + float(dx), 3), round((j + 0.5) * visual.CELL + float(dy), 3)
        if all(math.hypot(x - px, y - py) >= OBJECT_CLEARANCE for px, py in (*world.objects, *placed)):
            placed.append((x, y))
    if len(placed) < world.random_objects:
        raise RunError(f"{world.source or world.name}: no room for {world.random_objects} objects on cells where "
                       f"Hilare can stand, {OBJECT_CLEARANCE} m apart")
    return dataclasses.replace(world, objects=world.objects + tuple(placed), random_objects=0)


class _Recorder:
    """Writes what happens to the event log, and keeps what the result needs."""

    def __init__(self, log: EventLog, sim: Simulation, executive: rx.Executive, wanted: int, horizon: float,
                 progress: Callable[[HuntProgress], None] | None) -> None:
        self.log = log
        self.sim = sim
        self.executive = executive
        self.kernel = sim.kernel
        self.wanted = wanted
        self.horizon = horizon
        self.progress = progress
        self.requests = 0
        self.replies: Counter[str] = Counter()
        self.planned: list[PlannedPath] = []
        self.taken_count = 0
        self.empty_takes = 0  # take cycles that ended with nothing in the gripper
        self._detected: dict[int, float] = {}
        self._retrieved: dict[int, float] = {}
        self._taken: dict[int, float] = {}
        self._in_hand: int | None = None  # the object of the take cycle under way
        self._claimed: set[int] = set()  # what VISUAL marked retrieved in the simulator's trace
        self._pose = sim.pose
        self._robot_moving = False
        self._arm_moving = False
        self._arm_service: str | None = None
        self._blocked = False
        self._incidents = 0
        self._next_progress = self.kernel.now + PROGRESS_PERIOD
        self._database: Any = None
        self._facts: dict[str, list[Any]] = {}
        executive.observers.append(self._activity)
        executive.listeners.append(self._message)

    # ------------------------------------------------------------ the executive
    def _activity(self, activity: rx.Activity, source: rx.Phase, target: rx.Phase) -> None:
        self.poll_facts()  # what the procedures concluded before sending this request comes first
        service = activity.service.name
        if source is rx.Phase.ETHER and target is rx.Phase.WAIT:
            self.requests += 1
            self.log.emit(self.kernel.now, "request", service=service, id=activity.id)
        else:
            self.log.emit(self.kernel.now, "activity", service=service, id=activity.id, **{"from": source.value},
                          to=target.value)

    def _message(self, message: rx.Message) -> None:
        now = self.kernel.now
        self.poll_facts()
        self._check_detections()
        if message.kind == "WARNING":
            self.log.emit(now, "warning", service=message.service, id=message.id, type=str(message.result),
                          detail=message.detail)
            if message.service == "EXECUTIVE":
                self.log.emit(now, "alarm", what="executive-error", detail=message.detail)
            return
        result = message.result if isinstance(message.result, int | float | str) else str(message.result)
        self.replies[f"{message.service} {result}"] += 1
        self.log.emit(now, "reply", service=message.service, id=message.id, result=result, detail=message.detail)
        if result != "OK":
            return
        if message.service == "GET-NEAR-OBJ":
            self._retrieve(now)
        elif message.service == "OPEN-GRIP":
            self._put_on_robot(now)
        elif message.service in ("CALC-TRAJ-GOAL", "CALC-TRAJ-OBJ"):
            self._keep_trajectory(now, message.service)

    def _retrieve(self, now: float) -> None:
        """VISUAL's getObject marks the simulator's object it handed over in the trace's
        `taken`, or none when no object lies where it believed one (a ghost)."""
        claimed = self.sim.trace.taken - self._claimed
        self._claimed |= claimed
        believed = self.executive.context.vars.get("object")  # GET-NEAR-OBJ's output function keeps it
        seen = {"seen_x": round(believed["x"], 3), "seen_y": round(believed["y"], 3)} if believed else {}
        if not claimed:
            self._in_hand = None
            self.log.emit(now, "object-retrieved", object=None, x=None, y=None, **seen)
            return
        index = min(claimed)
        self._in_hand = index
        self._retrieved[index] = now
        x, y = self.sim.objects[index]
        self.log.emit(now, "object-retrieved", object=index, x=x, y=y, **seen)

    def _put_on_robot(self, now: float) -> None:
        index, self._in_hand = self._in_hand, None
        if index is None:
            self.empty_takes += 1
            self.log.emit(now, "alarm", what="empty-take",
                          detail="a take cycle ended, but no object lay where VISUAL had seen one")
            return
        self._taken[index] = now
        self.taken_count += 1
        x, y = self.sim.objects[index]
        self.log.emit(now, "object-taken", object=index, x=x, y=y, taken=self.taken_count)
        self._report(now)

    def _keep_trajectory(self, now: float, service: str) -> None:
        poster = self.executive.context.read_poster("plan.Traj")
        if poster is None:
            return
        traj = poster.traj
        points = tuple((round(float(x), 3), round(float(y), 3))
                       for x, y in zip(traj.x[: traj.nbPoints], traj.y[: traj.nbPoints], strict=True))
        self.planned.append(PlannedPath(now, service, points))
        self.log.emit(now, "trajectory", service=service, points=[list(p) for p in points])

    # ------------------------------------------------------------ the supervisor
    def operator(self, text: str) -> None:
        self.log.emit(self.kernel.now, "operator", text=text)

    def watch_facts(self, database: Any) -> None:
        """The facts the procedures share (closed and functional predicates, §4.4.2): the
        supervisor has no listener for its database, so it is compared after each kernel event
        and before each executive event is logged (a KA that concludes a fact and then sends a
        request does both in one turn of the supervisor)."""
        self._database = database
        self._facts = {p.name: [] for p in database.predicates.values() if p.kind in ("closed", "functional")}

    def poll_facts(self) -> None:
        if self._database is None:
            return
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

    # ------------------------------------------------------------ the simulator
    def start(self) -> None:
        # On the physics grid, as the simulator's own ticks, after them (SAMPLE_PRIORITY).
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
                self._arm_service = self._arm_activity()
            self.log.emit(now, "arm-motion", moving=arm.moving, service=self._arm_service)
        self._check_detections()
        if self.sim.trace.blocked_at is not None and not self._blocked:
            self._blocked = True
            self.log.emit(now, "alarm", what="blocked", detail=f"the robot is blocked at ({x:.2f}, {y:.2f})")
        self._check_incidents()
        if now >= self._next_progress:
            self._next_progress += PROGRESS_PERIOD
            self._report(now)

    def _arm_activity(self) -> str | None:
        """The arm service the executive is running (its module moves the arm)."""
        for activity in self.executive.activities.values():
            if activity.service.module == "arm" and not activity.service.control \
                    and activity.state.value in LIVE_PHASES:
                return activity.service.name
        return None

    def _check_detections(self) -> None:
        if len(self.sim.trace.detected) == len(self._detected):
            return
        for index in sorted(self.sim.trace.detected - self._detected.keys()):
            self._detected[index] = self.kernel.now
            x, y = self.sim.objects[index]
            self.log.emit(self.kernel.now, "object-detected", object=index, x=x, y=y)

    def _report(self, now: float) -> None:
        if self.progress is not None:
            self.progress(HuntProgress(now, self.horizon, self.taken_count, self.wanted))

    def _check_incidents(self) -> None:
        """A listener or observer of the executive that raised (ours included): the executive
        keeps going and notes it; the log says so."""
        for incident in self.executive.incidents[self._incidents:]:
            self.log.emit(self.kernel.now, "alarm", what="incident", detail=incident)
        self._incidents = len(self.executive.incidents)

    def finish(self) -> None:
        self._check_detections()
        self.poll_facts()
        self._check_incidents()
        certainty = _certainty(self.sim)
        goal = self.sim.trace.goal
        self.log.emit(self.kernel.now, "model", goal=list(goal) if goal is not None else None,
                      certainty=None if certainty is None else {
                          "cell": certainty.cell, "nx": certainty.nx, "ny": certainty.ny,
                          "values": [round(v, CERTAINTY_DIGITS) for v in certainty.values]})

    def objects(self) -> tuple[HuntObject, ...]:
        return tuple(HuntObject(k, x, y, self._detected.get(k), self._retrieved.get(k), self._taken.get(k))
                     for k, (x, y) in enumerate(self.sim.objects))


_SERVICE_CALL = re.compile(r"^!\((?:EXEC-REQUEST-OK|EXEC-REQUEST|EXEC-COUNT) (\S+?)[ )]")
_PROTOCOL_KAS = ("ExecRequest", "ExecRequestOk", "ExecCount", "SendRequest", "SendInterrupt", "WarnOperator")


def _why_failed(trace: Iterable[Any], events: Sequence[Mapping[str, Any]]) -> str:
    """The first statement of a task procedure that failed, and what its service answered."""
    failures = [entry for entry in trace if " failed" in entry.text]
    for entry in failures:
        if entry.ka in _PROTOCOL_KAS:
            continue
        call = _SERVICE_CALL.match(entry.text)
        statement = entry.text.partition(" failed")[0]
        if call is None:
            return f"{entry.ka}:{entry.line}: {entry.text}"
        service = call.group(1)
        answer = next((e for e in reversed(events) if e["kind"] == "reply" and e["service"] == service), None)
        if answer is None:
            return f"{entry.ka}:{entry.line}: {statement} failed: {service} never answered"
        detail = f" ({answer['detail']})" if answer.get("detail") else ""
        return f"{entry.ka}:{entry.line}: {statement} failed: {service} answered {answer['result']}{detail} " \
               f"at {answer['t']:.1f} s"
    return f"the goal failed ({failures[-1]})" if failures else "the goal failed"


def _certainty(sim: Simulation) -> Certainty | None:
    if sim.trace.certainty is None:
        return None
    cell, nx, ny, values = sim.trace.certainty
    return Certainty(cell, nx, ny, tuple(float(v) for v in values))
