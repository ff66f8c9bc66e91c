"""The functional level: GenoM-style modules (seed 000 ch. 2) running on the event kernel.

A module's controller receives requests, checks them, starts, interrupts and ends activities
and sends replies; its exec tasks run the activities' codels periodically. Every activity
follows the control graph of Fig. 2.3 (ETHER, INIT, EXEC, INTER, ZOMBIE, nine arcs); inside
EXEC, what each codel returns picks the next codel (Fig. 2.4). Final replies carry a status of
Table 2.1 and a report (the bilan).

The generated package describes each module with the `*Spec` classes below and binds it to
the user's codel functions; nothing here imports the compiler.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import functools
import itertools
import math
import os
import sys
import sysconfig
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import FrameType, ModuleType
from typing import Any, Generic, TypeVar

from specc.runtime.hints import did_you_mean
from specc.runtime.kernel import Kernel, Timer

HISTORY = 1_000  # transitions a module (and messages an executive) remembers

# ---------------------------------------------------------------- the dictionary of Table 2.1


# What a codel may raise and the module survives as a failure of the activity (or an incident):
# any exception, and SystemExit too (`sys.exit()` in a codel is its bug, not the end of the run).
CODE_ERRORS = (Exception, SystemExit)


class Status(enum.StrEnum):
    CS_ERROR = "CS_ERROR"  # the request or a reply could not be transmitted
    WAITING = "WAITING"  # the reply asked for has not arrived yet (report: which one)
    END = "END"  # nominal end, or an intrinsic failure (report: defined by the designer)
    TIMEOUT = "TIMEOUT"  # the client's wait expired (report: intermediate or final)
    INTERRUPTED = "INTERRUPTED"  # report: ABORT, or the name of the conflicting request
    FINAL_ERROR = "FINAL_ERROR"  # extrinsic error (report: its code)
    SERVER_ERROR = "SERVER_ERROR"  # a child activity failed (report: chains the original error)
    ZOMBIE = "ZOMBIE"  # the activity is ZOMBIE (report: identifies the original error)


class State(enum.StrEnum):
    ETHER = "ETHER"
    INIT = "INIT"
    EXEC = "EXEC"
    INTER = "INTER"
    ZOMBIE = "ZOMBIE"


# The nine arcs of Fig. 2.3: (from, event, to). Events marked `x/-` are imposed by the
# controller, `-/x` signified by the activity itself.
ARCS: tuple[tuple[State, str, State], ...] = (
    (State.ETHER, "init/-", State.INIT),
    (State.INIT, "exec/-", State.EXEC),
    (State.INIT, "abort/-", State.ETHER),  # refused by its validation, or interrupted before starting
    (State.EXEC, "-/ended", State.ETHER),
    (State.EXEC, "-/failed", State.ZOMBIE),
    (State.EXEC, "abort/-", State.INTER),
    (State.INTER, "-/ended", State.ETHER),
    (State.INTER, "-/failed", State.ZOMBIE),
    (State.ZOMBIE, "abort/-", State.ETHER),
)
_ARC_SET = {(a, b) for a, _, b in ARCS}

# What a codel may return besides its request's own codel states and fail messages.
ENDED = "ether"
FAILED = "zombie"
INTERMEDIATE_REPORT = "final"  # an intermediate reply says: now waiting for the final one


@dataclass(frozen=True)
class Report:
    """The bilan of a reply: a code, a human detail, and the child's reply it chains to."""

    code: str
    detail: str = ""
    cause: Reply | None = None

    def chain(self) -> list[Reply]:
        """The chained replies, outermost first (SERVER_ERROR -> ... -> the original error)."""
        found: list[Reply] = []
        reply = self.cause
        while reply is not None:
            found.append(reply)
            reply = reply.report.cause
        return found


@dataclass(frozen=True)
class Reply:
    rqst_id: int
    module: str
    request: str
    status: Status
    report: Report
    output: Any = None
    final: bool = True
    time: float = 0.0

    @property
    def ok(self) -> bool:
        return self.status is Status.END and self.report.code == "OK"


ReplySink = Callable[[Reply], None]


# ---------------------------------------------------------------- static description (generated)


@dataclass(frozen=True)
class RequestSpec:
    name: str
    kind: str  # control | exec
    input_type: type | None = None
    output_type: type | None = None
    validate: str | None = None
    codels: Mapping[str, str] = field(default_factory=dict)  # codel state -> function name
    yields: Mapping[str, tuple[str, ...]] = field(default_factory=dict)  # declared next states
    fail: tuple[str, ...] = ()
    incompatible: tuple[str, ...] = ()  # request names, or "all"
    task: str | None = None
    sends: tuple[str, ...] = ()

    def conflicts_with(self, other: RequestSpec) -> bool:
        return ("all" in self.incompatible or other.name in self.incompatible
                or "all" in other.incompatible or self.name in other.incompatible)

    @property
    def first_state(self) -> str:
        return "start" if "start" in self.codels else "exec"


@dataclass(frozen=True)
class ExecTaskSpec:
    name: str
    period: float
    delay: float = 0.0
    priority: int = 0
    init: str | None = None
    permanent: str | None = None


@dataclass(frozen=True)
class PosterSpec:
    name: str
    type: type
    fields: tuple[str, ...] = ()
    update: str = "auto"  # auto | manual
    activity: str | None = None  # request name or codel function whose cycles update it


@dataclass(frozen=True)
class ModuleSpec:
    name: str
    number: int
    codel_module: str
    sdi_type: type
    requests: Mapping[str, RequestSpec]
    tasks: tuple[ExecTaskSpec, ...] = ()
    posters: tuple[PosterSpec, ...] = ()


# ---------------------------------------------------------------- posters


T = TypeVar("T")


@dataclass(frozen=True)
class Snapshot(Generic[T]):
    """A consistent copy of a poster's content and the date it was written."""

    data: T
    date: float


class Poster(Generic[T]):
    """One writer (its module), any number of readers; readers get a private copy."""

    def __init__(self, spec: PosterSpec):
        self.spec = spec
        self._content: tuple[T, float] | None = None  # the data and its date; each reader gets a Snapshot

    def write(self, data: T, date: float) -> None:
        self._content = clone(data), date

    def publish(self, sdi: Any, date: float) -> None:
        """Write the poster's fields copied from the module's SDI (each copied once: the record
        is built from the copies, not copied again whole as `write` would)."""
        spec = self.spec
        self._content = spec.type(**{f: clone(getattr(sdi, f)) for f in spec.fields}), date

    def read(self) -> Snapshot[T] | None:
        if self._content is None:
            return None
        data, date = self._content
        return Snapshot(clone(data), date)


_IMMUTABLE = (int, float, str, bool, type(None), enum.Enum, tuple, frozenset)
_SCALARS = (int, float, str, bool, enum.Enum)  # never None: a field unset now may hold a record later
_COPIERS: dict[type, Callable[[Any], Any]] = {}


def clone(value: Any) -> Any:
    """A deep copy of poster data (records, lists, scalars), several times faster than
    `copy.deepcopy`, whose memo bookkeeping dominated a simulated robot's step: each record
    type gets a copier made once, which knows which of its fields need copying."""
    copier = _COPIERS.get(type(value))
    if copier is None:
        copier = _COPIERS[type(value)] = _copier(value)
    return copier(value)


def _copier(value: Any) -> Callable[[Any], Any]:
    if isinstance(value, _IMMUTABLE):
        return _same
    if isinstance(value, list):
        return _copy_list
    if not dataclasses.is_dataclass(value) or isinstance(value, type):
        return copy.deepcopy
    kind = type(value)
    names = tuple(f.name for f in dataclasses.fields(value))
    # A field holding a scalar now holds one of the same type always (the spec types them).
    shared = tuple(n for n in names if isinstance(getattr(value, n), _SCALARS))
    deep = tuple(n for n in names if n not in shared)

    def copy_record(record: Any) -> Any:
        copied = object.__new__(kind)
        state = copied.__dict__
        source = record.__dict__
        for name in shared:
            state[name] = source[name]
        for name in deep:
            state[name] = clone(source[name])
        return copied

    return copy_record


def _same(value: Any) -> Any:
    return value


def _copy_list(value: list[Any]) -> list[Any]:
    if not value or isinstance(value[0], _IMMUTABLE):  # a spec's arrays hold one type
        return value.copy()
    return [clone(v) for v in value]


@dataclass(frozen=True)
class ActivityInfo:
    rqst_id: int
    request: str
    state: State
    codel_state: str
    started: float


# ---------------------------------------------------------------- activities


class Activity:
    __slots__ = ("id", "spec", "module", "input", "output", "state", "codel_state", "sink", "parent",
                 "children", "started", "cause", "waiting_for", "pending_final", "pending_state", "fail_report",
                 "task")

    def __init__(self, rqst_id: int, spec: RequestSpec, module: Module, input_: Any, sink: ReplySink,
                 parent: Activity | None, now: float):
        self.id = rqst_id
        self.spec = spec
        self.module = module
        self.input = input_
        self.output = spec.output_type() if spec.output_type is not None else None
        self.state = State.ETHER
        self.codel_state = ""
        self.sink = sink
        self.parent = parent
        self.children: list[Activity] = []
        self.started = now
        self.cause = ""  # why it was interrupted: ABORT, or the conflicting request's name
        self.waiting_for: set[int] = set()  # activities that must end before it may start
        self.pending_final: Reply | None = None  # held until every child has ended
        self.pending_state = State.ETHER  # where it goes once they have
        self.fail_report: Report | None = None  # an intrinsic failure going through the end codel
        self.task: TaskRunner | None = None

    @property
    def live_children(self) -> list[Activity]:
        """Children still running; a ZOMBIE child has sent its final reply, so it is over here."""
        return [c for c in self.children if c.state in (State.INIT, State.EXEC, State.INTER)]

    def __getattr__(self, name: str) -> Any:
        # Codels read inputs and write outputs as `request.<field>` (GenoM's request record).
        get = object.__getattribute__
        for slot in ("input", "output"):
            record = get(self, slot)
            if record is not None and hasattr(record, name):
                return getattr(record, name)
        raise AttributeError(f"request '{get(self, 'spec').name}' has no input or output '{name}'")

    def __setattr__(self, name: str, value: Any) -> None:
        if name in Activity.__slots__:
            object.__setattr__(self, name, value)
            return
        output = object.__getattribute__(self, "output")
        if output is not None and hasattr(output, name):
            setattr(output, name, value)
            return
        raise AttributeError(f"request '{self.spec.name}' has no output '{name}'")


class EnumFieldError(ValueError):
    """A codel left an enum field of its module's SDI holding what is not one of the enum's values."""


class CodelMissing(LookupError):
    """The codels a module was given have no function of a name its spec gives a codel."""


class TransitionError(RuntimeError):
    """An arc that Fig. 2.3 does not have: a bug in the runtime, never a user error."""


@functools.cache
def _single_field(poster_type: type) -> str | None:
    """The name of a poster type's only field, None when it has several."""
    names = [f.name for f in dataclasses.fields(poster_type)]
    return names[0] if len(names) == 1 else None


class InternalData:
    """Base of each module's generated SDI: what codels reach besides their own data. The SDI
    has slots: a codel assigning a field the spec does not declare (`sdi.maxSped = ...`) raises
    AttributeError, reported as the codel's error, instead of silently adding a field."""

    __slots__ = ("_module",)

    def read_poster(self, name: str) -> Any:
        """Another module's poster content (`"module.Poster"`), or None if it has none yet.

        A poster exporting a single field gives that field's value directly."""
        module: Module | None = getattr(self, "_module", None)
        if module is None:
            return None
        snapshot = module.registry.read_poster(name)
        if snapshot is None:
            return None
        data = snapshot.data
        poster_type: type = type(data)
        single = _single_field(poster_type)
        return getattr(data, single) if single is not None else data

    def write_poster(self, name: str) -> None:
        """Update one of this module's `update: manual` posters from the SDI now."""
        module: Module | None = getattr(self, "_module", None)
        assert module is not None
        if name not in module.posters:
            raise LookupError(f"module '{module.name}' has no poster '{name}' "
                              f"(its posters: {', '.join(module.posters) or 'none'})")
        module.update_poster(name)

    @property
    def hardware(self) -> Any:
        """The robot's devices when a simulator (`specc.runtime.sim.Simulation`) or a driver is
        attached to the registry, else None (codels then fall back on their own models)."""
        module: Module | None = getattr(self, "_module", None)
        if module is None:
            return None
        registry = module.registry
        return registry.hardware_for[module.name] if registry.hardware_for is not None else registry.hardware

    def send_request(self, name: str, **inputs: Any) -> RequestHandle:
        """Send `"module.request"` from the running codel: the new activity is its child."""
        module: Module | None = getattr(self, "_module", None)
        assert module is not None
        return module.registry.send_from_codel(name, inputs)


@dataclass
class RequestHandle:
    """What a codel gets back from `send_request`: the child's id and its replies so far."""

    id: int
    interm: Reply | None = None
    final: Reply | None = None

    def receive(self, reply: Reply) -> None:
        if reply.final:
            self.final = reply
        else:
            self.interm = reply


# ---------------------------------------------------------------- exec tasks


class TaskRunner:
    """An exec task: every period, the permanent codel, then one codel of each activity."""

    def __init__(self, module: Module, spec: ExecTaskSpec):
        self.module = module
        self.spec = spec
        self.activities: list[Activity] = []
        self.timer: Timer | None = None
        self.slot = -1  # k of the pending tick, or of the last one when none is pending (-1: none yet)
        self.initialised = False
        self.cycles = 0

    @property
    def permanent(self) -> bool:
        """Does the task wake every period even without activities? Only with a permanent
        codel: an init codel runs once, as the module starts, and an idle task sleeps."""
        return self.spec.permanent is not None

    def start(self) -> None:
        # The init codel runs as the module starts, before it serves any request: a control
        # request answered at t = 0 must not be undone by an init codel run at the first tick.
        self.initialise()
        if self.permanent:
            self.schedule()

    def initialise(self) -> None:
        if not self.initialised and self.spec.init is not None:
            if self.module.call_permanent(self.spec.init, "init", self.spec.name):
                self.module.cycle_done(self.spec.init)
        self.initialised = True

    def schedule(self) -> None:
        """Next tick on the grid delay + k * period: now at the earliest, never twice an instant."""
        if self.timer is not None:
            return
        # Never twice a slot: a tick rescheduling itself is in its own.
        spec = self.spec
        self._schedule_slot(max(math.ceil((self.module.kernel.now - spec.delay) / spec.period - 1e-9), self.slot + 1))

    def _schedule_slot(self, k: int) -> None:
        self.slot = k
        spec = self.spec
        # Rounded to the nanosecond: 3 x 0.1 s and 1 x 0.3 s are one instant, so priority orders them.
        self.timer = self.module.kernel.call_at(round(spec.delay + k * spec.period, 9), self.tick, spec.priority)

    def tick(self) -> None:
        self.timer = None
        module = self.module
        self.cycles += 1
        if not self.initialised:
            self.initialise()
        permanent = self.spec.permanent
        if permanent is not None:
            if module.call_permanent(permanent, task=self.spec.name):
                module.cycle_done(permanent)
        if self.activities:
            for activity in list(self.activities):
                module.step(activity)
        if (permanent is not None or self.activities) and self.timer is None:
            # The next slot: this tick is on slot `self.slot`, so `schedule` would find no earlier one.
            self._schedule_slot(self.slot + 1)


# ---------------------------------------------------------------- the module and its controller


class Module:
    def __init__(self, spec: ModuleSpec, registry: Registry, codels: ModuleType | Any):
        self.spec = spec
        self.registry = registry
        self.kernel = registry.kernel
        self.name = spec.name
        self.codels = codels
        self.sdi = spec.sdi_type()
        # The SDI's enum fields, with the values a codel may set each to (a member, or its name
        # or value as text): checked after every codel, since the SDI takes any assignment.
        self._enum_fields = [(f.name, type(value), {m.name for m in type(value)} | {m.value for m in type(value)})
                             for f in dataclasses.fields(self.sdi)
                             if isinstance(value := getattr(self.sdi, f.name), enum.Enum)]
        self.sdi._module = self
        self.activities: dict[int, Activity] = {}  # every activity not in ETHER
        self.posters = {p.name: Poster[Any](p) for p in spec.posters}
        self.tasks = {t.name: TaskRunner(self, t) for t in spec.tasks}
        self.zombies: dict[int, Activity] = {}  # any of them freezes the module (§2.2)
        # (id, from, to), the latest HISTORY of them, for tests and logs: a robot runs for hours.
        self.transitions: deque[tuple[int, State, State]] = deque(maxlen=HISTORY)
        self.observers: list[Callable[[Module, Activity, State, State], None]] = []
        self.reply_listeners: list[ReplySink] = []  # see every reply the module sends (reflexes, logs)
        self._functions: dict[str, Callable[..., Any]] = {}
        # Permanent codels raising on every cycle, by (exec task, codel): the first raise's date and the
        # raises in a row. A robot lives on with one for hours; its incidents say the first, then the
        # count (`_raised`).
        self._raising: dict[tuple[str, str], tuple[float, int]] = {}
        # A poster's activity is a request, or a codel (of a request or an exec task) whose cycles update it.
        self._auto_posters: dict[str, list[Poster[Any]]] = {}
        for poster_spec in spec.posters:
            if poster_spec.update == "auto" and poster_spec.activity is not None:
                self._auto_posters.setdefault(poster_spec.activity, []).append(self.posters[poster_spec.name])

    @property
    def zombie(self) -> Activity | None:
        """The oldest activity in ZOMBIE, if any: the module is frozen until every one is aborted."""
        return next(iter(self.zombies.values()), None)

    def start(self) -> None:
        for runner in self.tasks.values():
            runner.start()
        # As GenoM creates its posters when the module starts, every poster exists from then on,
        # holding the initialised SDI: a client reading one before its first update gets that,
        # not "no poster" (PILO's start codel has AVOID read pilo.Setpoint at once).
        for name in self.posters:
            self.update_poster(name)

    # -- codel binding
    def function(self, name: str) -> Callable[..., Any]:
        found = self._functions.get(name)
        if found is None:
            found = getattr(self.codels, name, None)
            if not callable(found):
                given = getattr(self.codels, "__name__", None) if isinstance(self.codels, ModuleType) else None
                where = given or f"the codels given to module '{self.name}' ({type(self.codels).__name__})"
                raise CodelMissing(f"codel '{name}' is not defined in {where}" if found is None else
                                   f"codel '{name}' of {where} is a {type(found).__name__}, not a function")
            if self._enum_fields:
                found = functools.partial(self._enum_checked, found)
            self._functions[name] = found
        return found

    def _enum_checked(self, codel: Callable[..., Any], *args: Any) -> Any:
        """`codel(*args)`, then ValueError (the codel's error) if it left an enum field of the SDI
        holding what is not one of its values (`sdi.state = "MOVNG"`); the field keeps the value it
        had, so that the module's other codels go on with a value of the type. A name it was given
        (`sdi.state = "MOVING"`) becomes the member, so that every codel after it reads a member
        (which the generated `enum.StrEnum` also makes equal to its name)."""
        sdi = self.sdi
        before = [getattr(sdi, field_name) for field_name, _, _ in self._enum_fields]
        result = codel(*args)
        for (field_name, enum_type, allowed), kept in zip(self._enum_fields, before, strict=True):
            value = getattr(sdi, field_name)
            if isinstance(value, enum_type):
                continue
            if isinstance(value, str) and value in allowed:
                setattr(sdi, field_name, enum_type[value] if value in enum_type.__members__ else enum_type(value))
                continue
            setattr(sdi, field_name, kept)
            code = getattr(codel, "__code__", None)
            place = f" (in {code.co_name}, {_shown(code.co_filename)}:{code.co_firstlineno})" if code is not None \
                else ""
            raise EnumFieldError(f"the SDI's field '{field_name}' was left holding {value!r}{place}, not a value "
                                 f"of {enum_type.__name__} ({', '.join(m.name for m in enum_type)})"
                                 f"{did_you_mean(str(value), [m.name for m in enum_type])}")
        return result

    # -- requests
    def submit(self, request: str, input_: Any, sink: ReplySink, parent: Activity | None = None) -> int:
        """Receive a request; every outcome is a reply through `sink` (now or later)."""
        rqst_id = self.registry.new_id()
        spec = self.spec.requests.get(request)
        if spec is None:
            self.refuse(self.reply(rqst_id, request, Status.CS_ERROR, Report(
                "UNKNOWN_REQUEST", f"module '{self.name}' has no request '{request}'")), sink, parent)
            return rqst_id
        problem = check_record(input_, spec.input_type)
        if problem:
            self.refuse(self.reply(rqst_id, request, Status.FINAL_ERROR, Report("BAD_INPUT", problem)), sink,
                        parent if spec.kind == "exec" else None)
            return rqst_id
        if spec.kind == "control":
            self.run_control(rqst_id, spec, input_, sink)
            return rqst_id
        if self.zombies:
            self.refuse(self.frozen_reply(rqst_id, request), sink, parent)
            return rqst_id
        activity = Activity(rqst_id, spec, self, input_, sink, parent, self.kernel.now)
        if parent is not None:
            parent.children.append(activity)
        self.move(activity, State.INIT)
        self.activities[rqst_id] = activity
        if spec.validate is not None:
            outcome = self.call_codel(activity, spec, spec.validate)
            if outcome is not None:
                self.move(activity, State.ETHER)
                del self.activities[rqst_id]
                self.deliver(activity, self.reply(rqst_id, request, Status.FINAL_ERROR, outcome))
                return rqst_id
        # Wait for every conflicting activity before interrupting any: one that gives way at once
        # (in INIT) must not let the newcomer start while another is still to leave INTER.
        conflicting = [other for other in self.activities.values()
                       if other is not activity and other.state in (State.INIT, State.EXEC, State.INTER)
                       and spec.conflicts_with(other.spec) and not is_ancestor(other, activity)]
        for other in conflicting:
            activity.waiting_for.add(other.id)
        for other in conflicting:
            if other.state is not State.INTER:
                self.interrupt(other, spec.name)
        self.try_start(activity)
        return rqst_id

    def frozen_reply(self, rqst_id: int, request: str) -> Reply:
        zombie = next(iter(self.zombies.values()))
        return self.reply(rqst_id, request, Status.ZOMBIE, Report(
            "MODULE_FROZEN", f"activity {zombie.id} ({zombie.spec.name}) is ZOMBIE; abort it first"))

    def refuse(self, reply: Reply, sink: ReplySink, parent: Activity | None) -> None:
        """A request refused before it became an activity; sent from a codel, it ends its parent."""
        self.emit(sink, reply)
        if parent is not None:
            child_failed(parent, reply, activated=False)

    def emit(self, sink: ReplySink, reply: Reply) -> None:
        # The client first, then who watches (the executive's reflexes): a reflex on a module's
        # reply acts on what the executive made of that reply (a ZOMBIE it has recorded), not before.
        sink(reply)
        for listener in self.reply_listeners:
            listener(reply)

    def run_control(self, rqst_id: int, spec: RequestSpec, input_: Any, sink: ReplySink) -> None:
        """A control request takes no time: its validate codel runs and the final reply goes now."""
        output = spec.output_type() if spec.output_type is not None else None
        outcome: Report | None = None
        if spec.validate is not None:
            record = ControlRecord(spec, input_, output)
            outcome = self.call_codel(record, spec, spec.validate)
            if record.written():
                problem = record.flush()
                if problem:
                    outcome = Report("CODEL_ERROR", f"codel '{spec.validate}': {problem}")
        if outcome is None:
            # A control request interrupts the activities it is incompatible with (Table 3.1, mod2f3).
            for other in list(self.activities.values()):
                if other.state in (State.INIT, State.EXEC) and spec.conflicts_with(other.spec):
                    self.interrupt(other, spec.name)
        # Its one cycle is over: the auto posters of this activity show what its codel wrote,
        # before the client hears the reply; not after a refusal or a codel that raised (half
        # written: its posters keep their last date, as a permanent codel's do).
        if outcome is None:
            self.cycle_done(spec.name)
        status = Status.END if outcome is None else Status.FINAL_ERROR
        self.emit(sink, self.reply(rqst_id, spec.name, status, outcome or Report("OK"), output))

    def abort(self, target: int, sink: ReplySink | None = None) -> int:
        """The module's abort control request (modAbortRqstSend)."""
        rqst_id = self.registry.new_id()
        activity = self.activities.get(target)
        if activity is None:
            report, status = Report("UNKNOWN_ACTIVITY", f"no activity {target} in module '{self.name}'"), \
                Status.FINAL_ERROR
        else:
            self.interrupt(activity, "ABORT")
            report, status = Report("OK"), Status.END
        if sink is not None:
            self.emit(sink, self.reply(rqst_id, "abort", status, report))
        return rqst_id

    def interrupt(self, activity: Activity, cause: str) -> None:
        if activity.state is State.INIT:
            activity.cause = cause
            self.finish(activity, State.ETHER, Status.INTERRUPTED, Report(cause))
        elif activity.state is State.EXEC:
            activity.cause = cause
            self.move(activity, State.INTER)
            for child in activity.live_children:
                child.module.interrupt(child, "ABORT")
        elif activity.state is State.ZOMBIE:
            self.move(activity, State.ETHER)
            self.forget(activity)
            self.zombies.pop(activity.id, None)

    def try_start(self, activity: Activity) -> None:
        if activity.state is not State.INIT or activity.waiting_for:
            return
        if self.zombies:  # what it waited for went ZOMBIE: the module is frozen, it may not start
            self.finish(activity, State.ETHER, Status.ZOMBIE, self.frozen_reply(activity.id, activity.spec.name).report)
            return
        self.move(activity, State.EXEC)
        activity.codel_state = activity.spec.first_state
        runner = self.tasks.get(activity.spec.task or "")
        if runner is None:
            self.finish(activity, State.ETHER, Status.FINAL_ERROR,
                        Report("NO_EXEC_TASK", f"request '{activity.spec.name}' has no exec task to run in"))
            return
        activity.task = runner
        runner.activities.append(activity)
        self.emit(activity.sink, self.reply(activity.id, activity.spec.name, Status.WAITING,
                                            Report(INTERMEDIATE_REPORT), final=False))
        runner.schedule()

    # -- running codels
    def step(self, activity: Activity) -> None:
        """One codel of `activity`, then the transition its result asks for."""
        if activity.pending_final is not None:
            return  # done; waiting for its children to end
        if activity.state is State.INTER:
            self.step_inter(activity)
            return
        if activity.state is not State.EXEC:
            return
        spec = activity.spec
        name = spec.codels.get(activity.codel_state)
        if name is None:  # e.g. `end` requested without an end codel: the activity is over
            self.end(activity, activity.fail_report or Report("OK"))
            return
        result = self.run_codel(activity, name)
        if result is None:
            return
        self.cycle_done(spec.name)
        self.cycle_done(name)
        if activity.state is not State.EXEC or activity.pending_final is not None:
            return  # ended or interrupted while its codel ran (a child refused, a control request): moot
        if result == ENDED:
            self.end(activity, activity.fail_report or Report("OK"))
        elif result == FAILED:
            self.fail(activity, Report("ZOMBIE", f"codel '{name}' failed"))
        elif result in spec.fail:
            if activity.codel_state != "end" and "end" in spec.codels:
                activity.fail_report = Report(result)
                activity.codel_state = "end"
            else:
                self.end(activity, Report(result))
        elif result == "end" and activity.codel_state == "end":
            self.end(activity, activity.fail_report or Report("OK"))
        elif result in spec.codels or result == "end":
            declared = spec.yields.get(activity.codel_state)
            if declared and result not in declared:
                self.extrinsic(activity, "UNDECLARED_STATE",
                               f"codel '{name}' returned '{result}', not one of its declared {declared}")
            else:
                activity.codel_state = result
        else:
            self.extrinsic(activity, "UNDECLARED_STATE",
                           f"codel '{name}' returned {result!r}: not a codel state of '{spec.name}' "
                           f"({', '.join(sorted(spec.codels))}), 'end', 'ether', 'zombie' or a fail message "
                           f"({', '.join(spec.fail) or 'none declared'})")

    def step_inter(self, activity: Activity) -> None:
        name = activity.spec.codels.get("inter")
        result = ENDED if name is None else self.run_codel(activity, name)
        if result is None or activity.state is not State.INTER or activity.pending_final is not None:
            return
        if result == FAILED:
            self.fail(activity, Report("ZOMBIE", f"inter codel '{name}' failed"))
        elif result != "inter":  # `inter` asks for one more cycle of the interruption codel
            self.finish(activity, State.ETHER, Status.INTERRUPTED, Report(activity.cause or "ABORT"))

    def run_codel(self, activity: Activity, name: str) -> str | None:
        """The codel's result, or None when it raised (the activity is then already ended)."""
        try:
            result = self.call_with_parent(activity, self.function(name), self.sdi, activity)
        except CODE_ERRORS as exc:  # a codel's bug is the activity's extrinsic error, not the runtime's
            self.extrinsic(activity, "CODEL_ERROR", f"codel '{name}' raised {self.explain(exc)}")
            return None
        if not isinstance(result, str):
            self.extrinsic(activity, "UNDECLARED_STATE", f"codel '{name}' returned {result!r}, not a state name")
            return None
        return result

    def call_codel(self, record: Any, spec: RequestSpec, name: str) -> Report | None:
        """A validate codel: None to accept, else the report refusing the request."""
        registry = self.registry
        running = registry.current
        if running is not None:  # a request it sends is nobody's child, not a child of the codel that sent ours
            registry.current = None
        try:
            result = self.function(name)(self.sdi, record)
        except CODE_ERRORS as exc:
            return Report("CODEL_ERROR", f"codel '{name}' raised {self.explain(exc)}")
        finally:
            if running is not None:
                registry.current = running
        if result in (None, "end", "ok", "OK", ENDED, "exec"):
            return None
        if isinstance(result, str) and result in spec.fail:
            return Report(result)
        return Report("UNDECLARED_STATE", f"validate codel '{name}' returned {result!r}: accept with 'end', "
                      f"refuse with a fail message ({', '.join(spec.fail) or 'none declared'})")

    def explain(self, exc: BaseException) -> str:
        """A codel's exception as the activity's report gives it; a field the SDI does not declare
        is named with the fields it has."""
        missing = f"'{type(self.sdi).__name__}' object has no attribute '"
        text = str(exc)
        # Python names the attribute of a failed read (exc.name), not of a failed assignment.
        if isinstance(exc, EnumFieldError):  # raised once the codel returned: it names the codel's place
            return f"ValueError: {text}"
        if isinstance(exc, CodelMissing):  # raised by specc looking the codel up: no place of the user's
            return text
        if isinstance(exc, AttributeError) and text.startswith(missing) and text.endswith("'"):
            name = text[len(missing):-1]
            fields = [f.name for f in dataclasses.fields(self.sdi)]
            return (f"AttributeError: module {self.name}'s SDI has no field '{name}'{did_you_mean(name, fields)} "
                    f"(its fields: {', '.join(fields) or 'none'}; declare it in the module's internal_data)"
                    f"{where_raised(exc)}")
        return f"{type(exc).__name__}: {text}{where_raised(exc)}"

    def call_with_parent(self, activity: Activity, function: Callable[..., Any], *args: Any) -> Any:
        previous = self.registry.current
        self.registry.current = activity
        try:
            return function(*args)
        finally:
            self.registry.current = previous

    def call_permanent(self, name: str, kind: str = "permanent", task: str = "") -> bool:
        """Run a permanent (or init) codel; False when it raised (an incident): then the posters
        named after it keep their last date, so that no reader takes stale data for fresh."""
        try:
            self.function(name)(self.sdi)
        except CODE_ERRORS as exc:
            self._raised(name, kind, self.explain(exc), task)
            return False
        streak = self._raising.pop((task, name), None) if self._raising else None  # a dict lookup less a cycle
        if streak is not None and streak[1] > 1:
            self.registry.incidents.append(f"{self.kernel.now:.3f} {self.name}: {kind} codel '{name}' ran again "
                                           f"after raising {streak[1]:,} times in a row since {streak[0]:.3f} s")
        return True

    def _raised(self, name: str, kind: str, said: str, task: str = "") -> None:
        """An incident for the first raise of a streak, then one at its 10th, 100th, 1,000th... raise:
        a codel raising on every cycle of a long run fills no log."""
        now = self.kernel.now
        first, count = self._raising.get((task, name), (now, 0))
        count += 1
        self._raising[task, name] = (first, count)
        if count == 1:
            self.registry.incidents.append(f"{now:.3f} {self.name}: {kind} codel '{name}' raised {said}")
        elif _power_of_ten(count):
            self.registry.incidents.append(f"{now:.3f} {self.name}: {kind} codel '{name}' has raised {count:,} times "
                                           f"in a row since {first:.3f} s (said again at 10, 100, 1,000... "
                                           f"times), the last: {said}")

    # -- endings
    def end(self, activity: Activity, report: Report) -> None:
        """The activity's success; an output its codels left holding what its type does not
        (`request.travelled = "far"` for a double) is their error instead, as an input would be."""
        if activity.output is not None:
            as_declared(activity.output)
            problem = check_record(activity.output, activity.spec.output_type)
            if problem:
                self.extrinsic(activity, "CODEL_ERROR", f"the output of {activity.spec.name}: {problem}")
                return
        self.finish(activity, State.ETHER, Status.END, report)

    def extrinsic(self, activity: Activity, code: str, detail: str) -> None:
        self.finish(activity, State.ETHER, Status.FINAL_ERROR, Report(code, detail))

    def fail(self, activity: Activity, report: Report) -> None:
        self.finish(activity, State.ZOMBIE, Status.ZOMBIE, Report(report.code, report.detail or
                                                                  f"activity {activity.id}"))

    def finish(self, activity: Activity, target: State, status: Status, report: Report) -> None:
        """End an activity: children first (the parent ends only when they have), then the reply."""
        if activity.pending_final is not None or activity.state is State.ETHER or activity.state is State.ZOMBIE:
            return  # already ended: one final reply only
        reply = self.reply(activity.id, activity.spec.name, status, report, activity.output)
        live = activity.live_children
        if live:
            activity.pending_final = reply
            activity.pending_state = target
            for child in live:
                if child.state in (State.INIT, State.EXEC):
                    child.module.interrupt(child, "ABORT")
            return
        self.complete(activity, target, reply)

    def complete(self, activity: Activity, target: State, reply: Reply) -> None:
        if activity.state is State.INIT and target is State.ZOMBIE:
            target = State.ETHER
        self.move(activity, target)
        if activity.task is not None and activity in activity.task.activities:
            activity.task.activities.remove(activity)
        if target is State.ZOMBIE:
            self.zombies[activity.id] = activity
        else:
            self.forget(activity)
        self.deliver(activity, reply)
        for other in list(self.activities.values()):
            if activity.id in other.waiting_for:
                other.waiting_for.discard(activity.id)
                self.try_start(other)

    def forget(self, activity: Activity) -> None:
        self.activities.pop(activity.id, None)

    def deliver(self, activity: Activity, reply: Reply) -> None:
        self.emit(activity.sink, reply)
        parent = activity.parent
        if parent is None:
            return
        if parent.pending_final is not None and not parent.live_children:
            parent.module.complete(parent, parent.pending_state, parent.pending_final)
        else:
            child_failed(parent, reply, activated=activity.codel_state != "")

    def move(self, activity: Activity, target: State) -> None:
        source = activity.state
        if source is target:
            return
        if (source, target) not in _ARC_SET:
            raise TransitionError(f"{self.name}: no arc {source.value} -> {target.value} (activity {activity.id})")
        activity.state = target
        self.transitions.append((activity.id, source, target))
        for observer in self.observers:
            observer(self, activity, source, target)

    def reply(self, rqst_id: int, request: str, status: Status, report: Report, output: Any = None,
              final: bool = True) -> Reply:
        return Reply(rqst_id, self.name, request, status, report, output, final, self.kernel.now)

    # -- posters
    def cycle_done(self, activity_name: str) -> None:
        """A cycle of a request or of a codel ended: update the auto posters named after it."""
        posters = self._auto_posters.get(activity_name)
        if posters:
            for poster in posters:
                poster.publish(self.sdi, self.kernel.now)

    def update_poster(self, name: str) -> None:
        self.posters[name].publish(self.sdi, self.kernel.now)

    def control_poster(self) -> Snapshot[tuple[ActivityInfo, ...]]:
        """The standard control poster: every activity, its state and when it started."""
        return Snapshot(tuple(ActivityInfo(a.id, a.spec.name, a.state, a.codel_state, a.started)
                              for a in sorted(self.activities.values(), key=lambda a: a.id)), self.kernel.now)


class ControlRecord:
    """What a control request's validate codel sees as `request`: its inputs and outputs.

    What the codel writes lands in the record's own dict (no `__setattr__` hook on the control
    path) and is moved into the output record by `flush` once the codel has returned."""

    def __init__(self, spec: RequestSpec, input_: Any, output: Any):
        self._spec = spec
        self._input = input_
        self._output = output

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        for record in (self._input, self._output):
            if record is not None and hasattr(record, name):
                return getattr(record, name)
        raise AttributeError(f"request '{self._spec.name}' has no input or output '{name}'")

    def written(self) -> bool:
        return len(self.__dict__) > 3

    def flush(self) -> str:
        """Move what the codel wrote into the output record; '' or what it wrote that is no output."""
        output = self._output
        for name in [n for n in self.__dict__ if n not in ("_spec", "_input", "_output")]:
            value = self.__dict__.pop(name)
            if output is None or not hasattr(output, name):
                return f"request '{self._spec.name}' has no output '{name}'"
            setattr(output, name, value)
        return ""


def _power_of_ten(count: int) -> bool:
    while count % 10 == 0:
        count //= 10
    return count == 1


def child_failed(parent: Activity, reply: Reply, activated: bool) -> None:
    """A child's error ends its running parent: SERVER_ERROR when the child ran, FINAL_ERROR
    (Table 2.1: "non activation d'activité fille") when it never started; both chain the reply."""
    if reply.status is Status.END or reply.status is Status.INTERRUPTED or parent.state is not State.EXEC:
        return
    if activated:
        status, code = Status.SERVER_ERROR, "CHILD_ERROR"
    else:
        status, code = Status.FINAL_ERROR, "CHILD_NOT_ACTIVATED"
    parent.module.finish(parent, State.ETHER, status, Report(
        code, f"{reply.module}.{reply.request} ended {reply.status.value}", cause=reply))


def is_ancestor(candidate: Activity, activity: Activity) -> bool:
    parent = activity.parent
    while parent is not None:
        if parent is candidate:
            return True
        parent = parent.parent
    return False


# ---------------------------------------------------------------- type checking of records

_PRIMITIVES: dict[str, tuple[type, ...]] = {"float": (float, int), "int": (int,), "bool": (bool,), "str": (str,)}


def check_record(value: Any, expected: type | None) -> str:
    """'' when `value` fits the generated record type `expected`, else what is wrong."""
    if expected is None:
        return "" if value is None else "this request takes no input"
    if not isinstance(value, expected):
        return f"expected {expected.__name__}, got {type(value).__name__}"
    for f in getattr(expected, "__specc_fields__", ()):
        problem = check_value(getattr(value, f[0]), f[1], f[2])
        if problem:
            return f"{f[0]}: {problem}"
    return ""


def as_declared(record: Any) -> None:
    """What a codel wrote into `record` made what its type says, as its clients read it: a whole
    number in a `double`/`float` field (`= 3`) the float, an enum's name (`= "OBSTACLE"`) its
    member (nested records and lists too). What fits no such reading is left for `check_record`."""
    for name, kind, size in getattr(record, "__specc_fields__", ()):
        value = getattr(record, name)
        if size is not None and isinstance(value, list):
            value[:] = [_declared(v, kind) for v in value]
        else:
            setattr(record, name, _declared(value, kind))


def _declared(value: Any, kind: Any) -> Any:
    if kind == "float" and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        return kind.__members__.get(value, value) if isinstance(value, str) else value
    if not isinstance(kind, str):
        as_declared(value)
    return value


def build_record(kind: Any, value: Any) -> Any:
    """A generated record (or enum, or list of them) from plain data: mappings become records,
    names become enum members; what does not fit is left for `check_record` to report."""
    if isinstance(kind, type) and issubclass(kind, enum.Enum) and isinstance(value, str):
        return kind.__members__.get(value, value)
    fields = getattr(kind, "__specc_fields__", None)
    if fields is None or not isinstance(value, Mapping):
        return value
    known = {f[0]: f for f in fields}
    built = {}
    for name, item in value.items():
        spec = known.get(name)
        if spec is None:
            built[name] = item
        elif spec[2] is not None and isinstance(item, list):
            built[name] = [build_record(spec[1], x) for x in item]
        else:
            built[name] = build_record(spec[1], item)
    try:
        return kind(**built)
    except TypeError:
        return value


def check_value(value: Any, kind: Any, size: int | None) -> str:
    if size is not None:
        if not isinstance(value, list) or len(value) != size:
            return f"expected a list of {size}"
        for item in value:
            problem = check_value(item, kind, None)
            if problem:
                return problem
        return ""
    if isinstance(kind, str):
        allowed = _PRIMITIVES[kind]
        if isinstance(value, bool) and bool not in allowed:
            return f"expected {kind}, got bool"
        return "" if isinstance(value, allowed) else f"expected {kind}, got {type(value).__name__}"
    if isinstance(kind, type) and issubclass(kind, enum.Enum) and not isinstance(value, kind):
        names = [member.name for member in kind]
        return (f"{value!r} is not a {kind.__name__} ({', '.join(names)})"
                f"{did_you_mean(str(value), names)}")
    return check_record(value, kind)


# ---------------------------------------------------------------- the robot's modules together


class Registry:
    """The modules of one robot on one kernel: request ids, posters by name, activity trees."""

    def __init__(self, kernel: Kernel | None = None):
        self.kernel = kernel or Kernel()
        self.modules: dict[str, Module] = {}
        self.current: Activity | None = None  # the activity whose codel is running
        self.incidents: list[str] = []
        self.hardware: Any = None  # the devices codels drive (`sdi.hardware`): a simulation, a driver
        self.hardware_for: Any = None  # module -> its own view of them, when the system grants devices
        self._ids = itertools.count(1)

    def new_id(self) -> int:
        return next(self._ids)

    def add(self, spec: ModuleSpec, codels: Any) -> Module:
        if spec.name in self.modules:  # two of one module would both run on the kernel, one unreachable
            raise ValueError(f"module '{spec.name}' is already on this registry: create the modules once (a "
                             "fresh rt.Registry() starts over)")
        module = Module(spec, self, codels)
        self.modules[spec.name] = module
        module.start()
        return module

    def read_poster(self, name: str) -> Snapshot[Any] | None:
        module_name, _, poster_name = name.partition(".")
        module = self.modules.get(module_name)
        poster = module.posters.get(poster_name) if module is not None else None
        return poster.read() if poster is not None else None

    def send_from_codel(self, name: str, inputs: Mapping[str, Any]) -> RequestHandle:
        module_name, _, request = name.partition(".")
        handle = RequestHandle(0)
        parent = self.current
        module = self.modules.get(module_name)
        if module is None:
            self.refused(handle, parent, Reply(self.new_id(), module_name, request, Status.CS_ERROR,
                                               Report("UNKNOWN_MODULE", f"no module '{module_name}'"),
                                               time=self.kernel.now))
            return handle
        spec = module.spec.requests.get(request)
        input_: Any = None
        if spec is not None:
            problem = ""
            if spec.input_type is not None:
                input_ = build_record(spec.input_type, dict(inputs))
                problem = check_record(input_, spec.input_type)
            elif inputs:
                problem = f"request '{name}' takes no input (given: {', '.join(inputs)})"
            if problem:
                self.refused(handle, parent if spec.kind == "exec" else None, Reply(
                    self.new_id(), module_name, request, Status.FINAL_ERROR, Report("BAD_INPUT", problem),
                    time=self.kernel.now))
                return handle
        handle.id = module.submit(request, input_, handle.receive, parent)
        return handle

    @staticmethod
    def refused(handle: RequestHandle, parent: Activity | None, reply: Reply) -> None:
        handle.id = reply.rqst_id
        handle.receive(reply)
        if parent is not None:
            child_failed(parent, reply, activated=False)


# ---------------------------------------------------------------- the client (modFuncRqstSend / ReplyRcv)


@dataclass
class _Exchange:
    request: str
    interm: Reply | None = None
    final: Reply | None = None
    timers: list[Timer] = field(default_factory=list)


DEFAULT_WAIT = 3600.0  # s of simulated time a blocking wait gives up after, when no timeout is set


class ModuleClient:
    """Send requests to one module and receive their replies (seed 000 §2.5)."""

    def __init__(self, module: Module):
        self.module = module
        self.kernel = module.kernel
        self._exchanges: dict[int, _Exchange] = {}
        # Told of each request's final reply as it comes (a TIMEOUT the client gives itself too):
        # what a caller waiting on several requests at once needs instead of polling `reply`.
        self.final_listeners: list[ReplySink] = []

    def send(self, request: str, input_: Any = None, *, interm_timeout: float | None = None,
             final_timeout: float | None = None) -> int:
        """modFuncRqstSend: the request's id; its replies arrive through the kernel."""
        if input_ is not None:  # `client.setMode("FAST")`: an enum's name is its member, as in a codel's writes
            as_declared(input_)  # (the executive's and codels' requests are built so already)
        exchange = _Exchange(request)
        receive = self._receiver(exchange)
        rqst_id = self.module.submit(request, input_, receive)
        self._exchanges[rqst_id] = exchange
        for timeout, which in ((interm_timeout, "interm"), (final_timeout, "final")):
            if timeout is not None and exchange.final is None:
                exchange.timers.append(self.kernel.call_later(timeout, functools.partial(self._expire, rqst_id, which)))
        return rqst_id

    def _receiver(self, exchange: _Exchange) -> ReplySink:
        def receive(reply: Reply) -> None:
            if exchange.final is not None:
                return  # the client already gave up (TIMEOUT)
            if reply.final:
                for timer in exchange.timers:
                    timer.cancel()
                self._finished(exchange, reply)
            else:
                exchange.interm = reply
        return receive

    def _expire(self, rqst_id: int, which: str) -> None:
        exchange = self._exchanges[rqst_id]
        if exchange.final is not None or (which == "interm" and exchange.interm is not None):
            return
        self._finished(exchange, Reply(rqst_id, self.module.name, exchange.request, Status.TIMEOUT, Report(
            which, f"no {'intermediate' if which == 'interm' else 'final'} reply in time"), time=self.kernel.now))

    def _finished(self, exchange: _Exchange, reply: Reply) -> None:
        exchange.final = reply
        for listener in self.final_listeners:
            listener(reply)

    def reply(self, rqst_id: int) -> Reply:
        """modFuncReplyRcv without waiting: the final reply, or WAITING (report: which one)."""
        exchange = self._exchanges.get(rqst_id)
        if exchange is None:
            return Reply(rqst_id, self.module.name, "?", Status.CS_ERROR, Report("UNKNOWN_ID"),
                         time=self.kernel.now)
        if exchange.final is not None:
            return exchange.final
        which = "final" if exchange.interm is not None else "interm"
        return Reply(rqst_id, self.module.name, exchange.request, Status.WAITING, Report(which), final=False,
                     time=self.kernel.now)

    def interm(self, rqst_id: int, timeout: float | None = None) -> Reply:
        """Wait for the intermediate reply (or the final one, if the request ended first)."""
        exchange = self._exchanges.get(rqst_id)
        if exchange is None:
            return self.reply(rqst_id)
        done = self._wait(lambda: exchange.interm is None and exchange.final is None, timeout)
        if not done and exchange.interm is None and exchange.final is None:
            # The client gave up, not the module: the request goes on, its final reply is still to come.
            return Reply(rqst_id, self.module.name, exchange.request, Status.TIMEOUT,
                         Report("interm", "gave up waiting"), final=False, time=self.kernel.now)
        return exchange.interm or self.reply(rqst_id)

    def final(self, rqst_id: int, timeout: float | None = None) -> Reply:
        """Wait for the final reply; TIMEOUT (report 'final') if `timeout` expires first."""
        exchange = self._exchanges.get(rqst_id)
        if exchange is None:
            return self.reply(rqst_id)
        done = self._wait(lambda: exchange.final is None, timeout)
        if not done and exchange.final is None:
            # The client gave up, not the module: the request goes on, its final reply is still to come.
            return Reply(rqst_id, self.module.name, exchange.request, Status.TIMEOUT,
                         Report("final", "gave up waiting"), final=False, time=self.kernel.now)
        return self.reply(rqst_id)

    def _wait(self, pending: Callable[[], bool], timeout: float | None) -> bool:
        deadline = self.kernel.now + (DEFAULT_WAIT if timeout is None else timeout)
        return self.kernel.run_while(pending, deadline)

    def abort(self, rqst_id: int) -> Reply:
        """modAbortRqstSend + modAbortReplyRcv: interrupt an activity of this module."""
        box: list[Reply] = []
        self.module.abort(rqst_id, box.append)
        return box[0]

    def call(self, request: str, input_: Any = None, timeout: float | None = None) -> Reply:
        """Send and wait for the final reply."""
        return self.final(self.send(request, input_), timeout)

    def control_poster(self) -> Snapshot[tuple[ActivityInfo, ...]]:
        """The module's control poster: its activities, their states and start dates."""
        return self.module.control_poster()

    def poster(self, name: str) -> Snapshot[Any] | None:
        """The poster's latest content and date; None before its first write."""
        poster = self.module.posters.get(name)
        if poster is None:
            raise LookupError(f"module '{self.module.name}' has no poster '{name}' "
                              f"(its posters: {', '.join(self.module.posters) or 'none'})")
        return poster.read()


def load_codels(spec: ModuleSpec, codels: Any = None) -> Any:
    """The user's codel module: the one given (an object, or a module's dotted name), else imported
    by the name the spec declares."""
    if isinstance(codels, str):
        return import_user_module(codels, f"module '{spec.name}'", "its codels", "pass `codels=`")
    if codels is not None:
        return codels
    if not spec.codel_module:  # a module naming no codel function needs no codel module (checked)
        import types

        return types.SimpleNamespace()
    return import_user_module(spec.codel_module, f"module '{spec.name}'", "its codels", "pass `codels=`")


def import_user_module(dotted: str, owner: str, what: str, instead: str) -> Any:
    """The user's Python module `dotted` (`owner`'s `what`: "module 'arm'", "its codels"). When it
    cannot be found: ImportError saying to put its folder on sys.path (or `instead`); when it is
    found but its import fails (an import inside it, a typo at its top level): ImportError with
    the reason and the file and line where it failed."""
    import importlib

    try:
        return importlib.import_module(dotted)
    except ModuleNotFoundError as exc:
        if exc.name is not None and (dotted == exc.name or dotted.startswith(exc.name + ".")):
            raise ImportError(f"{owner}: cannot import {what} '{dotted}' ({exc}); put the folder holding them on "
                              f"sys.path, or {instead}") from exc
        raise ImportError(f"{owner}: {what} '{dotted}' import what cannot be found: {exc}{where_raised(exc)}") from exc
    except Exception as exc:  # the file itself, run as Python imports it
        raise ImportError(f"{owner}: importing {what} '{dotted}' failed: {type(exc).__name__}: {exc}"
                          f"{where_raised(exc)}") from exc


def where_raised(exc: BaseException) -> str:
    """` (file:line)`: the last place of the user's code the exception went through (a codel's
    line, not specc's device that refused its misspelt name, nor the import machinery's frozen
    frames); specc's own last place when none is the user's; empty when there is none."""
    import traceback

    frames = [f for f in traceback.extract_tb(exc.__traceback__) if not f.filename.startswith("<")]
    if isinstance(exc, SyntaxError) and exc.filename:
        return f" ({_shown(exc.filename)}:{exc.lineno})"
    users = [f for f in frames if not os.path.abspath(f.filename).startswith(_NOT_THE_USERS)]
    shown = (users or frames)[-1:]
    return f" ({_shown(shown[0].filename)}:{shown[0].lineno})" if shown else ""


_SPECC_FOLDER = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep  # specc/, with its separator
# Frames never the user's mistake: specc's own, and Python's library (pathlib refusing the None a
# user's function passed it is to be shown at the user's line).
_NOT_THE_USERS = (_SPECC_FOLDER,
                  *{os.path.abspath(sysconfig.get_paths()[k]) + os.sep for k in ("stdlib", "platstdlib")})


def where_running(frame: FrameType | None) -> str:
    """` (in FUNCTION, file:line)`: the innermost place of the user's code a live `frame` stands
    in (a codel stuck in a loop when a run is stopped), neither specc's nor Python's own nor an
    installed library's; empty when there is none."""
    installed = tuple(os.path.abspath(p) + os.sep for p in {sys.prefix, sys.base_prefix, sys.exec_prefix})
    while frame is not None:
        name = frame.f_code.co_filename
        path = os.path.abspath(name)
        if not name.startswith("<") and not path.startswith(_SPECC_FOLDER) and not path.startswith(installed):
            return f" (in {frame.f_code.co_name}, {_shown(path)}:{frame.f_lineno})"
        frame = frame.f_back
    return ""


def _shown(path: str) -> str:
    """A file as a message names it: relative to the working folder when it is below it."""
    relative = os.path.relpath(path) if os.path.isabs(path) else path
    return path if relative.startswith("..") else relative
