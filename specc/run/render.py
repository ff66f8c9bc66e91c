"""The pictures of a run, drawn from its event log alone (issue #9: `specc run` writes them into
the run's folder, `specc replay RUN` draws them again from the run's JSONL log).

    render_run(read_events("runs/m1w1/events.jsonl"), Path("runs/m1w1"))   # [map.png, timeline.png]

What the log holds decides which pictures a run gets, whatever the robot:

- map.png: the world, the robot's path from start to end (its footprint from mission-start's
  `body`), the world's objects by what became of them (`object-detected`, `object-retrieved`,
  `object-taken`, numbered in the order taken), the photo targets (green once a `photo` of them
  succeeded), where photos were taken, the planned `trajectory`s, the last `model` (its
  certainty cells and observation goal), `mark`s (an extension's: a label at a time on the
  path), where actions failed and where the robot was blocked, and the visibility windows on a
  time strip with the `communication`s and photos done;
- timeline.png: for a run that executed plans (`action` events), a Gantt chart, one row per
  kind of task, each executed action a bar from its start to its end coloured by outcome inside
  the hollow bar of its planned bound (start to `latest_end`); the visibility windows; FTplan's
  events (plan requests, plans, invalid plans, watchdogs, failures, safe states...) as markers,
  and the plans' starts and planner switches as vertical lines. Otherwise one row per executive
  service, each activity a bar from its start (WAIT to INIT) to its end coloured by its reply
  (its wait for the controller thinner before it); the robot's and the arm's motion; the
  objects' events and the alarms;
- state.png, when the log has a `model` with certainty cells: the state at the end as seed 000's
  interface of §5.6 shows it (Fig 5.11, `specc.run.pictures`).

The world comes whole in mission-start's `world_data`. A log cut short (a run that crashed or was
interrupted has no `mission-end`) is drawn as far as it goes. The functions that read the log
(`action_bars`, `service_bars`, `path_of`, `logged_objects`, `motion_stretches`, ...) draw
nothing: tests and other tools can use them alone.
"""

from __future__ import annotations

import dataclasses
import re
import textwrap
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from specc.run import RunError, pictures
from specc.run.events import reply_succeeded
from specc.runtime.body import RobotConfig
from specc.runtime.planner.plan import Value, format_call, format_value
from specc.runtime.sim import Target, Window, World, WorldError, parse_world
from specc.runtime.sim.render import (
    OBJECT_COLOURS,
    Certainty,
    Link,
    Mark,
    Scene,
    Shot,
    map_figure,
    position_at,
    pyplot,
)

Events = Sequence[Mapping[str, Any]]

MAP, TIMELINE, STATE = "map.png", "timeline.png", "state.png"
TITLE_WIDTH = 130  # characters of a title line before it wraps
TITLE_LINES = 3  # lines of a title at most
SHORTEST_AXIS = 1.0  # s: a timeline's time axis spans at least this (a log cut at its start)

# An action's outcome (specc.run.rover's ExecutedAction.outcome; running: the log ends first).
ACTION_COLOURS = {"ended": "#16a34a", "failed": "#dc2626", "stopped": "#f97316", "running": "#9ca3af"}
# FTplan's events worth a marker (`report` repeats the actions, `execute` is drawn as a line, its
# `mission-end` as the run's), on two rows, each kind a little above or below the row's middle so
# that events of one instant (a failure and the safe state it brings) stay apart.
PLANNING, EXECUTION = "FTplan planning", "FTplan execution"
FTPLAN_MARKERS = {  # kind: (row, offset, marker, colour)
    "plan-request": (PLANNING, -0.2, ">", "#6b7280"),
    "plan": (PLANNING, 0.2, "o", "#2563eb"),
    "invalid-plan": (PLANNING, 0.2, "X", "#b91c1c"),
    "watchdog": (PLANNING, 0.2, "v", "#ea580c"),
    "repair-request": (PLANNING, -0.2, "P", "#0d9488"),
    "repaired": (PLANNING, 0.2, "P", "#16a34a"),
    "repair-failed": (PLANNING, 0.2, "P", "#b91c1c"),
    "action-failed": (EXECUTION, -0.2, "X", "#dc2626"),
    "safe-state": (EXECUTION, 0.2, "s", "#f97316"),
    "goal-met": (EXECUTION, 0.0, "^", "#16a34a"),
    "goal-missed": (EXECUTION, 0.0, "v", "#dc2626"),
    "goals-open": (EXECUTION, 0.0, "d", "#ca8a04"),
    "operator": (EXECUTION, 0.0, "d", "#6b7280"),
    "mission-failure": (EXECUTION, -0.2, "*", "#7f1d1d"),
}
PLAN_LINE, SWITCH_LINE = "#9ca3af", "#7c3aed"

# A service's activity, by its reply (specc.runtime.executive): a success whatever word or number
# its output function returns (the reply's `ok` says so, specc.run.events.reply_succeeded); INT
# an interruption; any other reply (TIMEOUT, REFUSED, the module's report code...) a failure.
SERVICE_COLOURS = {"ok": "#16a34a", "interrupted": "#f97316", "failed": "#dc2626", "running": "#9ca3af"}
INTERRUPTED = "INT"
ENDED = ("ETHER",)  # the phase an activity leaves the executive's list for (Fig 3.3)
STARTED = ("WAIT", "INIT")  # the controller let it start
WAIT_COLOUR = "#cbd5e1"
MOTION_COLOUR = "#1d4ed8"
ARM_COLOURS = ("#0891b2", "#a855f7", "#64748b")  # one per arm service, in order of first motion


# ---------------------------------------------------------------- what every run says


def mission_start(events: Events) -> Mapping[str, Any]:
    """The run's `mission-start` event; RunError when the log has none or it lacks the world."""
    start = next((e for e in events if e.get("kind") == "mission-start"), None)
    if start is None:
        raise RunError("the log has no mission-start event: it is not a run's log, or it lost its first line")
    if not isinstance(start.get("world_data"), Mapping):
        raise RunError("the log's mission-start carries no world_data: the run was made by an older specc; "
                       "run it again to draw it")
    return start


def run_world(events: Events) -> World:
    """The world the run took place in, from mission-start (with the visibility windows as the
    seed drew them, when the mission has any)."""
    start = mission_start(events)
    try:
        world = parse_world(start["world_data"], "the log's world_data", str(start.get("world") or "world"))
    except WorldError as error:
        raise RunError(str(error)) from None
    windows = start.get("windows")
    if windows:
        world = dataclasses.replace(world, windows=tuple(Window(str(n), float(a), float(b)) for n, a, b in windows))
    return world


@dataclass(frozen=True)
class RunInfo:
    """What a picture's title says of the run."""

    robot: str
    configuration: str  # an FTplan configuration (Robot1...); "" for none
    mission: str
    world: str
    seed: Any
    outcome: str  # mission-end's, or "" when the log has no end
    why: str
    end: float  # s: the last instant the log reaches
    distance: float | None = None  # m the robot travelled, as mission-end says

    def title(self) -> str:
        who = f"{self.robot} {self.configuration}" if self.configuration else self.robot
        what = f"{self.outcome}: {self.why}" if self.outcome else f"no mission-end: the log stops at {self.end:.1f} s"
        if self.distance is not None:
            what += f", {self.distance:.1f} m travelled"
        # A failure's reason may run to a page (every goal given up, with why): the picture keeps
        # its first lines, the run's report has it whole.
        return textwrap.fill(f"{who}, mission {self.mission}, world {self.world}, seed {self.seed} — {what}",
                             TITLE_WIDTH, max_lines=TITLE_LINES, placeholder=" … (the whole of it: report.json)")


def run_info(events: Events) -> RunInfo:
    start = mission_start(events)
    end = next((e for e in reversed(events) if e.get("kind") == "mission-end"), None)
    return RunInfo(str(start.get("robot", "?")), str(start.get("configuration", "")),
                   str(start.get("mission", "?")), str(start.get("world", "?")), start.get("seed", "?"),
                   str(end.get("outcome", "")) if end else "", str(end.get("why", "")) if end else "",
                   last_time(events), float(end["distance"]) if end and end.get("distance") is not None else None)


def last_time(events: Events) -> float:
    return max((float(e["t"]) for e in events), default=0.0)


def path_of(events: Events) -> np.ndarray:
    """The robot's true path from the `pose` events: rows t, x, y, theta."""
    rows = [(e["t"], e["x"], e["y"], e["theta"]) for e in events if e.get("kind") == "pose"]
    return np.asarray(rows, dtype=float).reshape(-1, 4)


def robot_of(events: Events) -> RobotConfig:
    """The robot's body, as mission-start carries it."""
    start = mission_start(events)
    body = start.get("body")
    if not isinstance(body, Mapping):
        raise RunError("the log's mission-start carries no body: the run was made by an older specc; run it again "
                       "to draw it")
    known = {f.name for f in dataclasses.fields(RobotConfig)}
    try:
        return RobotConfig(**{k: v for k, v in body.items() if k in known})
    except TypeError as error:
        raise RunError(f"the log's body cannot be read ({error})") from None


class Span(NamedTuple):
    """A stretch of motion: the service moving it ("" when none is known), from start to end."""

    label: str
    start: float
    end: float


def motion_stretches(events: Events, kind: str, services: Sequence[str] | None = None) -> list[Span]:
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


# ---------------------------------------------------------------- the rover's log


@dataclass(frozen=True)
class ActionBar:
    """An action as it ran, from its `action` events: started, then ended, failed or stopped."""

    plan: int
    id: str
    task: str
    args: tuple[Value, ...]
    start: float
    end: float  # the log's end while it was still running
    outcome: str  # ended | failed | stopped | running
    latest_end: float | None  # its planned bound: start + its longest duration
    why: str = ""
    via: str = ""  # how it was carried out: the goal, service or request its binding made of it

    @property
    def kind(self) -> str:
        """The timeline's row: what carried the action out (the goal's head, the service, the
        module request), so the tasks of two models bound alike share a row; else the task."""
        found = re.match(r"[!?]?\(?\s*([^\s()]+)", self.via)
        return found.group(1) if found else self.task

    def text(self) -> str:
        return format_call(self.task, self.args)


def action_bars(events: Events) -> list[ActionBar]:
    """Every action of the log, in the order started. An action's start and its end share its
    plan number and id (ids restart with each plan)."""
    started: dict[tuple[int, str], Mapping[str, Any]] = {}
    over: dict[tuple[int, str], Mapping[str, Any]] = {}
    for event in events:
        if event.get("kind") == "action":
            key = (int(event["plan"]), str(event["id"]))
            (started if event["status"] == "started" else over)[key] = event
    end = last_time(events)
    bars = []
    for key in started.keys() | over.keys():
        last = over.get(key)
        begun = started.get(key, last)
        assert begun is not None
        latest = begun.get("latest_end")
        said = last or begun
        via = next((str(begun[k]) for k in ("goal", "service", "request") if begun.get(k)), "")
        bars.append(ActionBar(key[0], key[1], str(said["task"]), tuple(said.get("args", ())), float(begun["t"]),
                              float(last["t"]) if last else end, str(last["status"]) if last else "running",
                              float(latest) if latest is not None else None, str(last.get("why", "")) if last else "",
                              via))
    return sorted(bars, key=lambda b: (b.start, b.plan, b.id))


class FtplanMark(NamedTuple):
    time: float
    event: str  # FTplan's kind: plan-request, plan, watchdog...
    planner: str
    text: str


def ftplan_marks(events: Events) -> list[FtplanMark]:
    """FTplan's events worth a marker on the timeline (FTPLAN_MARKERS), in order."""
    return [FtplanMark(float(e["t"]), str(e["event"]), str(e.get("planner", "")), str(e.get("text", "")))
            for e in events if e.get("kind") == "ftplan" and e.get("event") in FTPLAN_MARKERS]


class PlanStart(NamedTuple):
    time: float
    number: int  # from 1, as the actions' `plan`
    planner: str
    switched_from: str  # the planner whose plan ran before, when another one ("" otherwise)


def plan_starts(events: Events) -> list[PlanStart]:
    """When each plan's execution started, by which planner, and where the planner changed (a
    planner switch: FTplan's recovery by another model, seed 004 §3.2.2)."""
    starts: list[PlanStart] = []
    for event in events:
        if event.get("kind") == "ftplan" and event.get("event") == "execute":
            planner = str(event.get("planner", ""))
            before = starts[-1].planner if starts else planner
            starts.append(PlanStart(float(event["t"]), len(starts) + 1, planner, before if before != planner else ""))
    return starts


def shots_of(events: Events) -> tuple[Shot, ...]:
    return tuple(Shot(float(e["t"]), str(e.get("target", "")), bool(e["ok"]), float(e["x"]), float(e["y"]))
                 for e in events if e.get("kind") == "photo")


def links_of(events: Events) -> tuple[Link, ...]:
    return tuple(Link(float(e.get("start", e["t"])), float(e["t"]), bool(e["ok"]))
                 for e in events if e.get("kind") == "communication")


# ---------------------------------------------------------------- the executive's, the objects', the model's


@dataclass(frozen=True)
class LoggedObject:
    """One of the world's objects and what the log says became of it (times in simulated s)."""

    index: int  # in mission-start's `objects` (the world's, with what the run drew)
    x: float  # where it really is
    y: float
    detected_at: float | None = None  # `object-detected`: a sensor first saw it
    retrieved_at: float | None = None  # `object-retrieved`: the robot went for it
    taken_at: float | None = None  # `object-taken`: it is on the robot

    @property
    def state(self) -> str:
        """taken, retrieved (not taken yet), detected, or undetected."""
        if self.taken_at is not None:
            return "taken"
        if self.retrieved_at is not None:
            return "retrieved"
        return "detected" if self.detected_at is not None else "undetected"


def logged_objects(events: Events) -> tuple[LoggedObject, ...]:
    """The world's objects (mission-start's `objects`, else the world's) and when each was
    detected, retrieved and taken; a retrieval of no object (`object` null) is none's."""
    start = mission_start(events)
    placed = start.get("objects")
    if placed is None:
        placed = run_world(events).objects
    when: dict[str, dict[int, float]] = {"object-detected": {}, "object-retrieved": {}, "object-taken": {}}
    for event in events:
        seen = when.get(str(event.get("kind")))
        if seen is not None and event.get("object") is not None:
            seen.setdefault(int(event["object"]), float(event["t"]))
    return tuple(LoggedObject(k, float(x), float(y), when["object-detected"].get(k),
                              when["object-retrieved"].get(k), when["object-taken"].get(k))
                 for k, (x, y) in enumerate(placed))


def taken_order(events: Events) -> tuple[int, ...]:
    """The objects taken, in the order taken."""
    return tuple(int(e["object"]) for e in events if e.get("kind") == "object-taken" and e.get("object") is not None)


@dataclass(frozen=True)
class ServiceBar:
    """One activity of the executive: requested, started (left WAIT for INIT), ended (left the
    list), with its reply."""

    service: str
    id: int
    requested: float
    started: float | None  # None: it never left WAIT (a start timeout, an interruption, a refusal)
    ended: float  # the log's end while it was still under way
    result: Any  # the reply's result; None without a reply
    outcome: str  # ok | interrupted | failed | running


def reply_outcome(reply: Mapping[str, Any]) -> str:
    """ok, interrupted or failed: what a `reply` event says of its activity."""
    if reply_succeeded(reply):
        return "ok"
    return "interrupted" if reply.get("result") == INTERRUPTED else "failed"


def service_bars(events: Events) -> list[ServiceBar]:
    """Every activity the task level asked the executive for, in the order requested."""
    requested: dict[int, tuple[str, float]] = {}
    started: dict[int, float] = {}
    ended: dict[int, float] = {}
    replies: dict[int, Mapping[str, Any]] = {}
    for event in events:
        kind = event.get("kind")
        if kind == "request":
            requested[int(event["id"])] = (str(event["service"]), float(event["t"]))
        elif kind == "activity":
            ident = int(event["id"])
            if (event["from"], event["to"]) == STARTED:
                started[ident] = float(event["t"])
            if event["to"] in ENDED:
                ended[ident] = float(event["t"])
        elif kind == "reply":
            replies[int(event["id"])] = event
    end = last_time(events)
    bars = []
    for ident, (service, at) in requested.items():
        reply = replies.get(ident)
        outcome = reply_outcome(reply) if reply is not None else "failed" if ident in ended else "running"
        bars.append(ServiceBar(service, ident, at, started.get(ident), ended.get(ident, end),
                               reply.get("result") if reply is not None else None, outcome))
    return bars


def last_model(events: Events) -> tuple[Certainty | None, tuple[float, float] | None]:
    """The last `model` event's certainty grid and observation goal (a robot's extension writes one
    at the end, Fig 5.11); nothing when the log has none."""
    model = next((e for e in reversed(events) if e.get("kind") == "model"), None)
    if model is None:
        return None, None
    data, goal = model.get("certainty"), model.get("goal")
    certainty = Certainty(float(data["cell"]), int(data["nx"]), int(data["ny"]), tuple(data["values"])) \
        if data else None
    return certainty, (float(goal[0]), float(goal[1])) if goal else None


def trajectories(events: Events) -> tuple[tuple[tuple[float, float], ...], ...]:
    """The `trajectory` events' points (the paths a planning module computed), in order."""
    return tuple(tuple((float(x), float(y)) for x, y in e["points"]) for e in events if e.get("kind") == "trajectory")


def marks_of(events: Events, path: np.ndarray, world: World) -> tuple[Mark, ...]:
    """Where things happened on the path: actions that failed, the robot blocked, and each
    label of the `mark` events (an extension's: {label, at})."""
    placed: dict[str, list[tuple[float, float]]] = {}
    for bar in action_bars(events):
        if bar.outcome == "failed":
            placed.setdefault("action failed", []).append(position_at(path, world, bar.end))
    for event in events:
        if event.get("kind") == "mark":
            placed.setdefault(str(event["label"]), []).append(position_at(path, world, float(event["at"])))
        elif event.get("kind") == "alarm" and event.get("what") == "blocked":
            placed.setdefault("blocked", []).append(position_at(path, world, float(event["t"])))
    return tuple(Mark(label, tuple(points), "P" if label == "blocked" else "X") for label, points in placed.items())


def scene_of(events: Events) -> Scene:
    """The map of a run, from its log: whatever of it the log holds."""
    start = mission_start(events)
    world = run_world(events)
    path = path_of(events)
    objects = logged_objects(events)
    certainty, goal = last_model(events)
    targets = tuple(Target(str(n), float(x), float(y)) for n, x, y in start["targets"]) \
        if start.get("targets") is not None else world.targets
    return Scene(world, robot_of(events), path, objects=tuple((o.x, o.y) for o in objects),
                 object_states=tuple(o.state for o in objects), taken_order=taken_order(events),
                 targets=targets, shots=shots_of(events), links=links_of(events), planned=trajectories(events),
                 certainty=certainty, goal=goal, marks=marks_of(events, path, world), now=last_time(events))


# ---------------------------------------------------------------- the pictures


def render_run(events: Events, folder: Path) -> list[Path]:
    """Draw the run's pictures into `folder` from its events alone; returns the files written.
    RunError (one line) when the log cannot be drawn."""
    run_world(events)  # a log that cannot be drawn fails before any file is written
    robot_of(events)
    drawers: tuple[tuple[str, Callable[[Events, Path], Path]], ...] = ((MAP, draw_map), (TIMELINE, draw_timeline))
    if last_model(events)[0] is not None:
        drawers += ((STATE, draw_state),)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RunError(f"{folder}: cannot make the run's folder ({error.strerror or error})") from None
    try:
        return [draw(events, folder / name) for name, draw in drawers]
    except RunError:
        raise
    except (KeyError, IndexError, TypeError, ValueError) as error:  # a log edited or written by hand
        raise RunError(f"the log cannot be drawn: an event lacks a field or has one of the wrong type "
                       f"({type(error).__name__}: {error})") from None


def draw_map(events: Events, path: str | Path) -> Path:
    """The run's map (see the module's docstring) as a PNG at `path`."""
    figure = map_figure(scene_of(events), run_info(events).title())
    try:
        return pictures.save(figure, path)
    finally:
        pyplot().close(figure)


def draw_state(events: Events, path: str | Path) -> Path:
    """The state at the end (Fig 5.11) as a PNG at `path`."""
    return pictures.write_state(scene_of(events), path, run_info(events).title())


def draw_timeline(events: Events, path: str | Path) -> Path:
    """The plan's actions when the run executed plans, else the executive's services."""
    if any(e.get("kind") == "action" for e in events):
        return draw_rover_timeline(events, path)
    return draw_service_timeline(events, path)


def draw_rover_timeline(events: Events, path: str | Path) -> Path:
    """The Gantt chart of the plans' actions (see the module's docstring) as a PNG at `path`."""
    bars = action_bars(events)
    kinds = list(dict.fromkeys(bar.kind for bar in bars))
    windows = run_world(events).windows
    rows = [PLANNING, EXECUTION, *(["windows"] if windows else []), *kinds]
    row = {name: k for k, name in enumerate(rows)}
    end = max([last_time(events), SHORTEST_AXIS] + [b.latest_end or 0.0 for b in bars] + [w.end for w in windows])
    plt = pyplot()
    from matplotlib.patches import Patch

    figure, ax = plt.subplots(figsize=(14.0, 2.2 + 0.55 * len(rows)), dpi=110)
    try:
        seconds_per_char = end / 200  # about 200 characters of 6-point text across the axes
        for bar in bars:
            y = row[bar.kind]
            if bar.latest_end is not None and bar.latest_end > bar.start:
                ax.barh(y, bar.latest_end - bar.start, left=bar.start, height=0.8, fill=False, ec="#6b7280", lw=0.8,
                        ls="--", zorder=2)
            width = max(bar.end - bar.start, end * 0.002)  # an instantaneous action stays visible
            ax.barh(y, width, left=bar.start, height=0.5, color=ACTION_COLOURS.get(bar.outcome, "#9ca3af"),
                    ec="#111827", lw=0.4, zorder=3)
            label = ", ".join(format_value(a) for a in bar.args)
            if label and len(label) * seconds_per_char < width:
                ax.text(bar.start + seconds_per_char, y, label, va="center", fontsize=6, clip_on=True, zorder=4)
        for window in windows:
            ax.barh(row["windows"], window.end - window.start, left=window.start, height=0.6, color="#bfdbfe",
                    ec="#1d4ed8", zorder=2)
            ax.text((window.start + window.end) / 2, row["windows"], window.name, ha="center", va="center",
                    fontsize=7, zorder=4)
        marks = ftplan_marks(events)
        for event, (name, offset, marker, colour) in FTPLAN_MARKERS.items():
            times = [m.time for m in marks if m.event == event]
            if times:
                ax.plot(times, [row[name] + offset] * len(times), marker=marker, ls="", ms=6, color=colour,
                        label=event, zorder=5)
        for start in plan_starts(events):
            switch = bool(start.switched_from)
            ax.axvline(start.time, color=SWITCH_LINE if switch else PLAN_LINE, lw=1.2 if switch else 0.8,
                       ls="-" if switch else ":", zorder=1)
            text = f"plan {start.number}: {start.switched_from} → {start.planner}" if switch \
                else f"plan {start.number} ({start.planner})"
            ax.text(start.time, -0.6, text, rotation=90, ha="right", va="bottom", fontsize=6,
                    color=SWITCH_LINE if switch else "#4b5563")
        keys = [Patch(color=colour, label=f"action {outcome}") for outcome, colour in ACTION_COLOURS.items()]
        keys.append(Patch(fill=False, ec="#6b7280", ls="--", label="planned bound (start to latest end)"))
        ax.plot([], [], color=PLAN_LINE, ls=":", label="a plan starts")
        ax.plot([], [], color=SWITCH_LINE, label="planner switch")
        _finish_timeline(ax, events, rows, keys, top=-1.6, right=end * 1.02, xlabel="mission time (s)")
        return pictures.save(figure, path)
    finally:
        plt.close(figure)


def draw_service_timeline(events: Events, path: str | Path) -> Path:
    """The chart of the executive's services and the motions (see the module's docstring) as a
    PNG at `path`."""
    bars = service_bars(events)
    services = list(dict.fromkeys(bar.service for bar in bars))
    motions, objects, alarms, reflexes = "robot motion", "objects", "alarms", "reflexes"
    arm = motion_stretches(events, "arm-motion")
    fired = [e for e in events if e.get("kind") == "reflex"]
    rows = [*services, motions, *(["arm motion"] if arm else []), objects, *([reflexes] if fired else []), alarms]
    row = {name: k for k, name in enumerate(rows)}
    end = max(last_time(events), SHORTEST_AXIS)
    plt = pyplot()
    from matplotlib.patches import Patch

    figure, ax = plt.subplots(figsize=(15.0, 2.0 + 0.3 * len(rows)), dpi=110)
    try:
        for service in services:
            mine = [b for b in bars if b.service == service]
            waits = [(b.requested, (b.started if b.started is not None else b.ended) - b.requested) for b in mine]
            ax.broken_barh(waits, (row[service] - 0.12, 0.24), color=WAIT_COLOUR, zorder=2)
            for outcome, colour in SERVICE_COLOURS.items():
                spans = [(b.started, max(b.ended - b.started, end * 0.0005)) for b in mine
                         if b.started is not None and b.outcome == outcome]
                if spans:
                    ax.broken_barh(spans, (row[service] - 0.3, 0.6), color=colour, zorder=3)
            # An activity that never started failed or was interrupted while it waited.
            for b in mine:
                if b.started is None and b.outcome != "ok":
                    ax.plot(b.ended, row[service], marker="x", ms=5, color=SERVICE_COLOURS[b.outcome], zorder=4)
        robot = motion_stretches(events, "robot-motion")
        ax.broken_barh([(s.start, s.end - s.start) for s in robot], (row[motions] - 0.3, 0.6), color=MOTION_COLOUR)
        arm_services = dict.fromkeys(s.label for s in arm)
        colours = {label: ARM_COLOURS[k % len(ARM_COLOURS)] for k, label in enumerate(arm_services)}
        for label, colour in colours.items():
            ax.broken_barh([(s.start, s.end - s.start) for s in arm if s.label == label],
                           (row["arm motion"] - 0.3, 0.6), color=colour, label=f"arm moving for {label or '?'}")
        for kind, colour, label in (("object-detected", OBJECT_COLOURS["detected"], "object detected"),
                                    ("object-retrieved", OBJECT_COLOURS["retrieved"], "object retrieved"),
                                    ("object-taken", OBJECT_COLOURS["taken"], "object taken")):
            times = [e["t"] for e in events if e.get("kind") == kind]
            if times:
                ax.plot(times, [row[objects]] * len(times), marker="o", ls="", ms=6, mfc=colour, mec="#111827",
                        mew=0.5, label=label, zorder=5)
        for reflex in fired:  # the executive's own reactions (§3.5): what it did without the task level
            ax.plot(reflex["t"], row[reflexes], marker="v", ms=7, color="#7c3aed", zorder=5)
            ax.annotate(str(reflex.get("reflex") or reflex.get("on", "")), (reflex["t"], row[reflexes]),
                        textcoords="offset points", xytext=(4, 4), fontsize=6, color="#7c3aed")
        for alarm in (e for e in events if e.get("kind") == "alarm"):
            ax.plot(alarm["t"], row[alarms], marker="X", ms=8, color="#dc2626", zorder=5)
            ax.annotate(str(alarm.get("what", "")), (alarm["t"], row[alarms]), textcoords="offset points",
                        xytext=(4, 4), fontsize=6, color="#dc2626")
        keys = [Patch(color=colour, label=f"activity {outcome}") for outcome, colour in SERVICE_COLOURS.items()]
        keys += [Patch(color=WAIT_COLOUR, label="waiting to start"), Patch(color=MOTION_COLOUR, label="robot moving")]
        ax.plot([], [], marker="x", ls="", color=SERVICE_COLOURS["failed"], label="ended before it started")
        _finish_timeline(ax, events, rows, keys, top=-0.6, right=end * 1.01, xlabel="simulated time (s)",
                         fontsize=7)
        return pictures.save(figure, path)
    finally:
        plt.close(figure)


def _finish_timeline(ax: Any, events: Events, rows: Sequence[str], keys: list[Any], *, top: float, right: float,
                     xlabel: str, fontsize: float | None = None) -> None:
    """What both timelines share: the end line, one row per name top down, the title, the legend."""
    _end_line(ax, events)
    ax.set_yticks(range(len(rows)), rows, fontsize=fontsize)
    ax.set_ylim(len(rows) - 0.4, top)
    ax.set_xlim(0, right)
    ax.set_xlabel(xlabel)
    ax.grid(axis="x", alpha=0.3)
    ax.set_title(run_info(events).title(), fontsize=9)
    ax.legend(handles=keys + ax.get_legend_handles_labels()[0], loc="upper left", bbox_to_anchor=(1.01, 1.0),
              fontsize=7, framealpha=0.9)


def _end_line(ax: Any, events: Events) -> None:
    """The mission's end, or where the log stops when it has none."""
    end = next((e for e in reversed(events) if e.get("kind") == "mission-end"), None)
    if end is not None:
        ax.axvline(end["t"], color="#111827", lw=1.0, ls="--", label="mission end", zorder=1)
    else:
        ax.axvline(last_time(events), color="#dc2626", lw=1.0, ls="--", label="the log stops (no mission-end)",
                   zorder=1)
