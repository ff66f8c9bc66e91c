"""What Hilare's hunt log tells on its own: the objects and what became of them, and the properties
of seed 000 §5.5 (a detection interrupts the exploration move; the robot stands still while the
arm takes an object).

`specc.run.hunt` runs the hunt and `specc.run.render` draws it; both read the log through this
module, which imports neither, so the runner can draw its run and the pictures can name the
hunt's objects and motions.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

# The services of the take-object cycle, in TakeObject's order (procedures.spec).
TAKE_CYCLE = ("GET-NEAR-OBJ", "CALC-OBJ", "CALC-TRAJ-OBJ", "EXEC-TRAJ-OBJ", "ARM-OBJ", "CLOSE-GRIP", "ARM-BACK",
              "OPEN-GRIP")
EXPLORATION_MOVE = "EXEC-TRAJ-GOAL"
DETECTION = "SEARCH-OBJ"  # its result is the number of objects the image showed (§5.3)
TAKING = ("ARM-OBJ",)  # §5.1: "la prise d'un objet (mais pas la pose) exige l'immobilité du robot"


# ---------------------------------------------------------------- the room's objects


@dataclass(frozen=True)
class HuntObject:
    """One of the room's objects and what became of it (times in simulated seconds)."""

    index: int  # in the simulator's list
    x: float  # where it really is
    y: float
    detected_at: float | None = None  # the camera first saw it
    retrieved_at: float | None = None  # GET-NEAR-OBJ handed it to the take-object cycle
    taken_at: float | None = None  # its take cycle ended with it on the robot

    @property
    def state(self) -> str:
        """taken, retrieved (its take cycle did not end), detected, or undetected."""
        if self.taken_at is not None:
            return "taken"
        if self.retrieved_at is not None:
            return "retrieved"
        return "detected" if self.detected_at is not None else "undetected"


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


class Span(NamedTuple):
    """A stretch of motion: the arm's service ("" for the robot), from start to end."""

    label: str
    start: float
    end: float


def motion_stretches(events: Iterable[Mapping[str, Any]], kind: str,
                     services: Sequence[str] | None = None) -> list[Span]:
    """Each stretch of `kind` events (`robot-motion`, `arm-motion`) from moving to still, for
    `services` only when given; a stretch still open at the end of the log ends with its last
    event."""
    stretches: list[Span] = []
    opened: tuple[str, float] | None = None
    last = 0.0
    for event in events:
        last = event["t"]
        if event["kind"] != kind:
            continue
        service = str(event.get("service") or "")
        if event["moving"] and opened is None:
            opened = (service, event["t"])
        elif not event["moving"] and opened is not None:
            stretches.append(Span(opened[0], opened[1], event["t"]))
            opened = None
    if opened is not None:
        stretches.append(Span(opened[0], opened[1], last))
    if services is None:
        return stretches
    return [s for s in stretches if s.label in services]
