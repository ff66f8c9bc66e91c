"""Hilare 2's object hunt (seed 000 ch. 5): what a run needs to know of it beyond the specs.

The system block names this module as its `extension:`; specc's generic runner
(`specc.run.mission`) runs the mission `hunt` (`!(COLLECT-OBJECTS 5)` in the room) and calls:

- `prepare(world, setup)`: the room's objects, placed from the seed on cells where Hilare can
  stand. §5.2.5 assumes "que le centre du robot doit être dans le centre de la cellule de l'objet
  à saisir", and EXPLOR's calcObj refuses any other cell (UNREACHABLE_CELL), which fails the
  take-object cycle and the hunt with it (§5.4.1). (The simulator's own scattering only keeps
  objects 0.45 m from the obstacles: with it, 4 hunts of seeds 0-29 failed so.)
- `attach(run)`: logs when the camera first sees each object (`object-detected`), when
  GET-NEAR-OBJ hands one over (`object-retrieved`, null when VISUAL saw a ghost), when a take
  cycle ends with it on the robot (`object-taken`), the trajectories PLAN computes
  (`trajectory`), and at the end EXPLOR's model (`model`, Fig 5.11) and where a detection
  interrupted an exploration move (`mark`, §5.5);
- `measure(events)`: the objects taken, the room explored, and the §5.5 properties, from the
  log alone;
- `judge(...)`: a hunt whose procedures counted an object the gripper never held fails.

The §5.5 checks (`detection_interruptions`, `arm_motion_overlaps`) read any hunt's log.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from specc.run.render import logged_objects, motion_stretches, run_world
from specc.runtime.sim import World, WorldError
from specc.runtime.sim.simulation import OBJECT_CLEARANCE

OBJECT_STREAM = 0x0B1EC7  # mixed with the seed for the objects' places, apart from the simulator's streams
OBJECT_JITTER = 0.1  # m: an object lies within this of its cell's centre, on each axis
SAMPLE_PRIORITY = 1000  # the detection sampler runs after the physics and codels of its instant
CERTAINTY_DIGITS = 3  # the model's certainty per cell, as the log keeps it
EXPLORED = 1 / 3  # a cell whose certainty reached this (Fig 5.11's lowest band) counts as explored

# The services of the take-object cycle, in TakeObject's order (procedures.spec).
TAKE_CYCLE = ("GET-NEAR-OBJ", "CALC-OBJ", "CALC-TRAJ-OBJ", "EXEC-TRAJ-OBJ", "ARM-OBJ", "CLOSE-GRIP", "ARM-BACK",
              "OPEN-GRIP")
EXPLORATION_MOVE = "EXEC-TRAJ-GOAL"
DETECTION = "SEARCH-OBJ"  # its result is the number of objects the image showed (§5.3)
TAKING = ("ARM-OBJ",)  # §5.1: "la prise d'un objet (mais pas la pose) exige l'immobilité du robot"
PLANNING = ("CALC-TRAJ-GOAL", "CALC-TRAJ-OBJ")
INTERRUPTED_MOVE = "exploration move interrupted"
COLLECT = re.compile(r"^!\(COLLECT-OBJECTS (\d+)\)$")


# ---------------------------------------------------------------- the run's hooks


def prepare(world: World, setup: Any) -> World:
    """The room with its random objects placed from the run's seed (`setup.seed`)."""
    return place_objects(world, setup.seed)


def place_objects(world: World, seed: int) -> World:
    """The room with its random objects placed from `seed` on cells where Hilare can stand,
    each within OBJECT_JITTER of its cell's centre and, as the simulator places its own,
    OBJECT_CLEARANCE from the others (VISUAL tells objects apart by where it sees them)."""
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
        raise WorldError(f"{world.source or world.name}: no room for {world.random_objects} objects on cells "
                         f"where Hilare can stand, {OBJECT_CLEARANCE} m apart")
    return dataclasses.replace(world, objects=world.objects + tuple(placed), random_objects=0)


def attach(run: Any) -> None:
    _Observer(run)


class _Observer:
    """Logs what becomes of the room's objects, the planned trajectories and the final model."""

    def __init__(self, run: Any) -> None:
        self.run = run
        self.sim = run.sim
        self.taken = 0
        self._detected: set[int] = set()
        self._claimed: set[int] = set()  # what VISUAL marked retrieved in the simulator's trace
        self._in_hand: int | None = None  # the object of the take cycle under way
        run.executive.listeners.append(self._message)
        run.kernel.call_every(self.sim.physics_period, self._check_detections, SAMPLE_PRIORITY)
        run.at_end(self._finish)

    def _message(self, message: Any) -> None:
        self._check_detections()
        if message.kind != "REPLY" or message.result != "OK":
            return
        if message.service == TAKE_CYCLE[0]:
            self._retrieve()
        elif message.service == TAKE_CYCLE[-1]:
            self._put_on_robot()
        elif message.service in PLANNING:
            self._keep_trajectory(message.service)

    def _check_detections(self) -> None:
        for index in sorted(self.sim.trace.detected - self._detected):
            self._detected.add(index)
            x, y = self.sim.objects[index]
            self.run.emit("object-detected", object=index, x=x, y=y)

    def _retrieve(self) -> None:
        """VISUAL's getObject marks the simulator's object it handed over in the trace's
        `taken`, or none when no object lies where it believed one (a ghost)."""
        claimed = self.sim.trace.taken - self._claimed
        self._claimed |= claimed
        believed = self.run.executive.context.vars.get("object")  # GET-NEAR-OBJ's output function keeps it
        seen = {"seen_x": round(believed["x"], 3), "seen_y": round(believed["y"], 3)} if believed else {}
        if not claimed:
            self._in_hand = None
            self.run.emit("object-retrieved", object=None, x=None, y=None, **seen)
            return
        index = min(claimed)
        self._in_hand = index
        x, y = self.sim.objects[index]
        self.run.emit("object-retrieved", object=index, x=x, y=y, **seen)

    def _put_on_robot(self) -> None:
        index, self._in_hand = self._in_hand, None
        if index is None:
            self.run.emit("alarm", what="empty-take",
                          detail="a take cycle ended, but no object lay where VISUAL had seen one")
            return
        self.taken += 1
        x, y = self.sim.objects[index]
        self.run.emit("object-taken", object=index, x=x, y=y, taken=self.taken)

    def _keep_trajectory(self, service: str) -> None:
        poster = self.run.executive.context.read_poster("plan.Traj")
        if poster is None:
            return
        traj = poster.traj
        points = [[round(float(x), 3), round(float(y), 3)]
                  for x, y in zip(traj.x[: traj.nbPoints], traj.y[: traj.nbPoints], strict=True)]
        self.run.emit("trajectory", service=service, points=points)

    def _finish(self) -> None:
        self._check_detections()
        trace = self.sim.trace
        certainty = None
        if trace.certainty is not None:
            cell, nx, ny, values = trace.certainty
            certainty = {"cell": cell, "nx": nx, "ny": ny,
                         "values": [round(float(v), CERTAINTY_DIGITS) for v in values]}
        self.run.emit("model", goal=list(trace.goal) if trace.goal is not None else None, certainty=certainty)
        for interruption in detection_interruptions(self.run.log.events).interruptions:
            self.run.emit("mark", label=INTERRUPTED_MOVE, at=interruption.interrupted_at)


def objects_wanted(events: Sequence[Mapping[str, Any]]) -> int | None:
    """N of the `!(COLLECT-OBJECTS N)` the run posted."""
    goals = next((e.get("goals", ()) for e in events if e["kind"] == "mission-start"), ())
    wanted = [int(match.group(1)) for g in goals if (match := COLLECT.match(g))]
    return wanted[0] if wanted else None


def measure(events: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The hunt's figures, from its log: objects taken and wanted, the room explored (cells of
    EXPLOR's model whose certainty reached 1/3), and §5.5's properties."""
    detections = detection_interruptions(events)
    taken = sum(1 for e in events if e["kind"] == "object-taken")
    return {"objects_taken": taken, "objects_wanted": objects_wanted(events),
            "empty_takes": sum(1 for e in events if e["kind"] == "alarm" and e.get("what") == "empty-take"),
            "explored_fraction": round(explored_fraction(events), 4),
            "detections_interrupting_exploration": len(detections.interruptions),
            "detections_not_interrupting": len(detections.missed),
            "arm_moves_while_robot_moves": len(arm_motion_overlaps(events))}


def judge(events: Sequence[Mapping[str, Any]], measures: Mapping[str, Any], outcome: str,
          why: str) -> tuple[str, str]:
    """The goal's outcome, except that a hunt whose procedures counted an object the gripper
    never held (VISUAL saw it where none lies) fails."""
    wanted, taken = measures["objects_wanted"], measures["objects_taken"]
    if outcome == "succeeded" and wanted is not None and taken < wanted:
        return "failed", (f"the procedures took {wanted} object(s), but {measures['empty_takes']} take cycle(s) "
                          f"found nothing where VISUAL had seen an object: {taken} on the robot")
    if outcome == "succeeded" and wanted is not None:
        end = max((e["t"] for e in events), default=0.0)
        return outcome, f"{taken} of {wanted} object(s) taken in {end:.1f} s"
    return outcome, why


def explored_fraction(events: Sequence[Mapping[str, Any]]) -> float:
    """The room's cells whose certainty reached EXPLORED in the last `model`, of all its cells."""
    model = next((e for e in reversed(events) if e["kind"] == "model"), None)
    if model is None or not model.get("certainty"):
        return 0.0
    data = model["certainty"]
    cell, nx, ny = float(data["cell"]), int(data["nx"]), int(data["ny"])
    grid = np.asarray(data["values"], dtype=float).reshape(ny, nx)
    xmin, xmax, ymin, ymax = run_world(events).bounds
    centres_x, centres_y = (np.arange(nx) + 0.5) * cell, (np.arange(ny) + 0.5) * cell
    room = ((centres_y >= ymin) & (centres_y <= ymax))[:, None] & ((centres_x >= xmin) & (centres_x <= xmax))[None, :]
    return int(np.count_nonzero(room & (grid >= EXPLORED))) / max(1, int(np.count_nonzero(room)))


def objects(events: Sequence[Mapping[str, Any]]) -> tuple[Any, ...]:
    """The room's objects and what became of each (`specc.run.render.LoggedObject`)."""
    return logged_objects(events)


# ---------------------------------------------------------------- the §5.5 properties, from the log


@dataclass(frozen=True)
class Interruption:
    """An exploration move stopped by the take-object cycle, and the detection behind it."""

    move: int  # the EXEC-TRAJ-GOAL request's id
    interrupted_at: float  # it left EXEC for INTER
    by: str  # the take-cycle service whose start interrupted it (Fig 5.6, Table 5.6)
    detected_at: float | None  # the last SEARCH-OBJ that found an object before it (maybe in an
    # earlier take cycle: the cycle takes the nearest object it knows of)
    reply: str | None  # the move's final reply (INT)


@dataclass(frozen=True)
class MissedDetection:
    """An object detected while the take-object cycle waited and an exploration move ran, and the
    move went on to its end instead of being interrupted."""

    detected_at: float
    move: int
    reply: str  # how the move ended


@dataclass(frozen=True)
class DetectionReport:
    interruptions: tuple[Interruption, ...]
    missed: tuple[MissedDetection, ...]


def detection_interruptions(events: Iterable[Mapping[str, Any]]) -> DetectionReport:
    """§5.5, "l'objet A est localisé (t2). Le déplacement est interrompu": from the log, every
    exploration move the take-object cycle interrupted, and every detection that should have
    interrupted one and did not.

    A detection is a SEARCH-OBJ reply counting at least one object. While the take-object cycle
    waits for an object (from (EXECUTION GO) or the end of a take cycle, OPEN-GRIP's reply, to
    the next GET-NEAR-OBJ request), a detection during an exploration move (EXEC-TRAJ-GOAL in
    EXEC) must end that move with INT. While the cycle is busy the detection waits for the
    cycle's end (§5.5: "un nouveau test [...] ne sera fait qu'après la conclusion du cycle
    courant"), and then it is the move running at that time that is interrupted.

    The executive interrupts a move when a conflicting service asks to start (Table 5.6, Fig
    5.6): the interrupting service is the take-cycle service waiting to start at that instant."""
    interruptions: list[Interruption] = []
    missed: list[MissedDetection] = []
    waiting: dict[int, str] = {}  # request id -> service, from its request until it leaves WAIT
    executing: set[int] = set()  # exploration moves in EXEC
    stopping: dict[int, tuple[float, str, float | None]] = {}  # move id -> when, by whom, after which detection
    watched: dict[int, float] = {}  # move id -> the detection it must yield to
    take_waiting = False
    last_detection: float | None = None
    for event in events:
        kind = event["kind"]
        if kind == "fact" and event["fact"] == "(EXECUTION GO)":
            # From GO the cycle waits for its first object; once GO is gone, it waits no more.
            take_waiting = event["change"] == "concluded"
        elif kind == "request":
            waiting[event["id"]] = event["service"]
            if event["service"] == TAKE_CYCLE[0]:
                take_waiting = False
        elif kind == "activity":
            if event["from"] == "WAIT":
                waiting.pop(event["id"], None)
            if event["service"] == EXPLORATION_MOVE:
                move = event["id"]
                if event["to"] == "EXEC":
                    executing.add(move)
                elif event["from"] == "EXEC":
                    executing.discard(move)
                    if event["to"] == "INTER":
                        by = next((s for s in waiting.values() if s in TAKE_CYCLE), "")
                        stopping[move] = (event["t"], by, last_detection)
        elif kind == "reply":
            service, result = event["service"], event["result"]
            waiting.pop(event["id"], None)
            if service == DETECTION and isinstance(result, int) and result >= 1:
                last_detection = event["t"]
                if take_waiting:
                    for move in executing:
                        watched.setdefault(move, event["t"])
            elif service == TAKE_CYCLE[-1]:
                take_waiting = True
            elif service == EXPLORATION_MOVE:
                move = event["id"]
                executing.discard(move)
                stopped = stopping.pop(move, None)
                if stopped is not None and stopped[1]:
                    interruptions.append(Interruption(move, *stopped, str(result)))
                    watched.pop(move, None)
                elif move in watched:
                    missed.append(MissedDetection(watched.pop(move), move, str(result)))
    return DetectionReport(tuple(interruptions), tuple(missed))


@dataclass(frozen=True)
class Overlap:
    """The arm moving for `service` while the robot moved, from `start` to `end`."""

    service: str
    start: float
    end: float


def arm_motion_overlaps(events: Iterable[Mapping[str, Any]], services: Sequence[str] = TAKING) -> list[Overlap]:
    """When the arm moved for one of `services` while the robot moved (true motion, from the
    simulator). §5.1: taking an object requires the robot to stand still, putting it on the
    robot does not ("la prise d'un objet (mais pas la pose) [...] exige l'immobilité du robot"),
    so the default looks at ARM-OBJ only; ARM-BACK during an exploration move is §5.5's
    scenario ("pendant son dépôt sur le robot [...] la tâche d'exploration peut redémarrer")."""
    ordered = list(events)
    robot = motion_stretches(ordered, "robot-motion")
    arm = motion_stretches(ordered, "arm-motion", services)
    overlaps = []
    for service, start, end in arm:
        for _, moving_from, moving_to in robot:
            low, high = max(start, moving_from), min(end, moving_to)
            if low < high:
                overlaps.append(Overlap(service, low, high))
    return overlaps
