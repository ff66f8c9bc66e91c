"""The executive (seed 000 ch. 3): the link between the decision level and the modules.

The task level asks for *services* by name with a unique id (RQST EXEC) and may interrupt them
(RQST INT); the executive turns each into a module request and answers with facts
`(REPLY id result)` and `(WARNING service id type)` (§3.9). Inside, as in Fig 3.2:

- the service description list (`ExecutiveSpec.services`, generated from the spec);
- the activity list: one `Activity` per service request, in a state of Fig 3.3
  (WAIT, INIT, EXEC, INTER, ZOMBIE; ETHER when it leaves the list);
- the request manager (`request`, `interrupt`, the WAIT retries of every cycle, start timeouts);
- the reply manager (intermediate and final replies, ZOMBIE warnings, output functions);
- the resource controller: the generated decision function of the executive's Kheops rules
  (inputs service, event, the groups' previous states; outputs status and the new group
  states; calls changeInterState and sendAbortRequest).

Every input (a task request, a module reply, a timer) runs one *cycle*: the event, then a new
start authorisation for every WAIT activity. Replies that modules send during a cycle queue up
for the next one, so a cycle never re-enters itself. The seed's executive also wakes up
periodically while activities wait (§3.8.2); here nothing a WAIT depends on (the controller
sees only the service, the event and the group states) changes between events, so it need not.

What the controller is told: START for every authorisation asked; for an exec service, INTERM
when its intermediate reply arrives (its group is held from then on), then END, ZOMBIE or ABORT;
for a control service, START then END. An exec activity that ends before its intermediate reply
(refused by its module, interrupted while starting) never held a group and is not reported.

One precaution the seed leaves implicit: a START waits while an activity it conflicts with (an
arc either way of the incompatibility graph) is between its request and its intermediate reply.
The controller only sees groups, which such an activity does not hold yet; without the wait,
both could end up running.

Results of (REPLY id result): OK, or what the service's output function returns; the module's
report code for an intrinsic failure (a REPLY END whose bilan is not OK); INT when interrupted;
TIMEOUT, REFUSED, ZOMBIE (ended after a ZOMBIE and its abort), BAD-SERVICE, or the module's
error status (FINAL_ERROR, SERVER_ERROR, CS_ERROR, TIMEOUT) for REPLY ERROR. An output function
may return any word, a failure's word too, so the result alone cannot tell them apart: the
message's `ok` does (the module ended the request with an OK report). WARNING types:
ZOMBIE (§3.4.1), BAD-ID (RQST INT for an unknown id), ERROR (the executive entered its general
ERROR state, §3.4.2; service EXECUTIVE, id 0).
"""

from __future__ import annotations

import enum
import functools
import itertools
import operator
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from specc.runtime.functional import (
    HISTORY,
    Registry,
    Reply,
    Status,
    build_record,
    check_record,
    check_value,
    where_raised,
)
from specc.runtime.kernel import Timer
from specc.runtime.rules import Decision

# ---------------------------------------------------------------- Fig 3.3


# Executive cycles one instant may take before they count as a reaction loop that would hold the
# robot at that instant for ever: an event takes a few (a request, the starts asked again, a
# reflex or two); the executive then enters its ERROR state, which refuses every request and so
# ends the loop.
CYCLES_PER_INSTANT = 100_000


class Phase(enum.StrEnum):
    ETHER = "ETHER"
    WAIT = "WAIT"
    INIT = "INIT"
    EXEC = "EXEC"
    INTER = "INTER"
    ZOMBIE = "ZOMBIE"


# The activity representation graph of Fig 3.3: (from, what moves it, to).
ARCS: tuple[tuple[Phase, str, Phase], ...] = (
    (Phase.ETHER, "RQST EXEC", Phase.WAIT),
    (Phase.WAIT, "controller OK", Phase.INIT),
    (Phase.WAIT, "RQST INT, start timeout, REFUSE", Phase.ETHER),
    (Phase.INIT, "REPLY INTERM", Phase.EXEC),
    (Phase.INIT, "final reply (control request, refused by the module)", Phase.ETHER),
    (Phase.INIT, "RQST INT, reply timeout", Phase.INTER),
    (Phase.EXEC, "REPLY END, REPLY ERROR", Phase.ETHER),
    (Phase.EXEC, "changeInterState, RQST INT, reply timeout", Phase.INTER),
    (Phase.EXEC, "REPLY ZOMBIE", Phase.ZOMBIE),
    (Phase.INTER, "REPLY INT (or any final reply)", Phase.ETHER),
    (Phase.INTER, "REPLY ZOMBIE", Phase.ZOMBIE),
    (Phase.ZOMBIE, "REPLY ABORT", Phase.ETHER),
)
_ARC_SET = {(a, b) for a, _, b in ARCS}

IDLE = "IDLE"
LIVE = (Phase.WAIT, Phase.INIT, Phase.EXEC, Phase.INTER, Phase.ZOMBIE)


class TransitionError(RuntimeError):
    pass


# ---------------------------------------------------------------- static description (generated)


@dataclass(frozen=True)
class ServiceSpec:
    name: str
    module: str
    request: str
    kind: str  # control | exec: the module request's type
    args: Mapping[str, Any] = field(default_factory=dict)  # constant inputs
    takes: tuple[str, ...] = ()  # the inputs the task level gives with each request, in order
    input: str | None = None  # input function, or module.Poster[.field]
    output: str | None = None  # output function
    start_timeout: float | None = None  # s in WAIT before REPLY TIMEOUT
    interm_timeout: float | None = None  # s from the request to its intermediate reply
    final_timeout: float | None = None  # s from the request to its final reply
    conflicts: frozenset[str] = frozenset()  # services it has an arc to, or from
    targets: frozenset[str] = frozenset()  # services it has an arc to (interrupts or waits for)
    group: frozenset[str] = frozenset()  # the services of its group (whose state holds one of them)

    @property
    def control(self) -> bool:
        return self.kind == "control"


@dataclass(frozen=True)
class ReflexSpec:
    """§3.5: on a reply (or intermediate reply, or ZOMBIE warning) of a service or a module
    request, optionally matching its report code, send requests or start or abort services."""

    name: str
    trigger: str  # reply | interm | warning
    source: str  # SERVICE or module.request
    op: str | None = None
    value: Any = None
    actions: tuple[tuple[str, str], ...] = ()  # (request | abort | start, target)

    def matches(self, trigger: str, source: str, code: str) -> bool:
        if trigger != self.trigger or source != self.source:
            return False
        if self.op is None:
            return True
        try:
            return bool(_OPS[self.op](code, self.value))
        except TypeError:  # an ordering between a code and a number: no match
            return False


_OPS: dict[str, Callable[[Any, Any], Any]] = {"==": operator.eq, "!=": operator.ne, "<": operator.lt,
                                               "<=": operator.le, ">": operator.gt, ">=": operator.ge}


@dataclass(frozen=True)
class ParameterSpec:
    name: str
    get: str | None = None  # module.Poster[.field]
    set: str | None = None  # module.request (control)


@dataclass(frozen=True)
class ExecutiveSpec:
    name: str
    services: Mapping[str, ServiceSpec]
    groups: Mapping[str, tuple[str, ...]]  # group state attribute -> its services
    reflexes: tuple[ReflexSpec, ...] = ()
    parameters: Mapping[str, ParameterSpec] = field(default_factory=dict)
    codel_module: str | None = None


# ---------------------------------------------------------------- run time


class Message(NamedTuple):
    """What the executive tells the task level (§3.9)."""

    kind: str  # REPLY | WARNING
    service: str
    id: int
    result: Any  # REPLY: the result; WARNING: the event type
    detail: str = ""
    time: float = 0.0
    ok: bool = False  # REPLY: the service succeeded, whatever its result (see the module's docstring)

    @property
    def fact(self) -> tuple[Any, ...]:
        if self.kind == "REPLY":
            return ("REPLY", self.id, self.result)
        return ("WARNING", self.service, self.id, self.result)


@dataclass(eq=False)
class Activity:
    """An entry of the activity list (§3.3.2)."""

    id: int  # the task level's id
    service: ServiceSpec
    requested: float  # when it entered the list
    state: Phase = Phase.ETHER
    input: Any = None
    module_id: int | None = None  # the module's id for its request
    holds_group: bool = False  # the controller has seen its intermediate reply
    answered: bool = False  # its (REPLY id result) is sent
    abort_sent: bool = False
    timers: list[Timer] = field(default_factory=list)


class Context:
    """What input and output functions see: executive variables, posters, the world file."""

    def __init__(self, registry: Registry, world: str | None):
        self.vars: dict[str, Any] = {}
        self.world = world
        self._registry = registry

    def read_poster(self, name: str) -> Any:
        """The data of poster `module.Poster` (None before its first write)."""
        snapshot = self._registry.read_poster(name)
        return snapshot.data if snapshot is not None else None


class Executive:
    def __init__(self, spec: ExecutiveSpec, decide: Callable[..., Decision], registry: Registry,
                 codels: Any = None, world: str | None = None, measure: bool = False):
        self.spec = spec
        self.decide = decide
        self.registry = registry
        self.kernel = registry.kernel
        self.codels = codels
        self.context = Context(registry, world)
        self.activities: dict[int, Activity] = {}  # the activity list, by task-level id
        self.groups: dict[str, str] = dict.fromkeys(spec.groups, IDLE)  # the controller's state
        self.zombies: dict[str, list[Activity]] = {}  # module -> its ZOMBIE activities: requests refused
        self.error: str | None = None  # the general ERROR state (§3.4.2): why
        self.messages: deque[Message] = deque(maxlen=HISTORY)  # the latest ones; listeners get them all
        self.listeners: list[Callable[[Message], None]] = []
        self.observers: list[Callable[[Activity, Phase, Phase], None]] = []
        # Told of each reflex that fires (§3.5), with the report code it fired on: the run's log.
        self.reflex_listeners: list[Callable[[ReflexSpec, str], None]] = []
        self.reflex_replies: list[Reply] = []  # replies to requests sent by reflexes
        self.incidents: list[str] = []  # exceptions raised by listeners and observers
        # With `measure`: each cycle's duration, without the time modules spend handling what it
        # sends them (in-process here, they are other processes on the robot).
        self.cycle_durations: list[float] | None = [] if measure else None
        self._in_modules = 0.0
        self._inbox: deque[tuple[Callable[..., None], tuple[Any, ...]]] = deque()
        self._busy = False
        self._looping = False  # the cycle limit stopped a reaction loop at this instant: reflexes are off
        self._internal_ids = itertools.count(-1, -1)
        self._highest_id = 0  # of the ids task-level clients gave their requests (see `fresh_id`)
        missing = sorted({s.module for s in spec.services.values() if s.module not in registry.modules})
        if missing:  # else each request would fail later with a KeyError of the module's name
            raise ValueError(f"executive '{spec.name}': its services run requests of module(s) "
                             f"{', '.join(missing)}, which the registry does not have: create the modules on it "
                             "first (the package's `modules.create_all(registry)`)")
        for name in {r.source.partition(".")[0] for r in spec.reflexes if "." in r.source}:
            module = registry.modules.get(name)
            if module is not None:
                module.reply_listeners.append(self._module_reply_seen)

    # ------------------------------------------------------------ the task level's interface
    def request(self, service: str, ident: int | None = None, inputs: tuple[Any, ...] = ()) -> int:
        """RQST EXEC: ask for `service`, giving the inputs it takes; its (REPLY id result) comes
        later. Returns the id: `ident`, or one the executive picks (negative: never a task level's).
        TypeError, before anything is sent, when `inputs` is not a tuple or list of values in the
        order the service `takes` them."""
        if not isinstance(inputs, (tuple, list)):
            spec = self.spec.services.get(service)
            takes = spec.takes if spec is not None else ()
            example = ("()" if not takes else f"({inputs!r},)" if len(takes) == 1
                       else "(" + ", ".join(f"{k + 1}.0" for k in range(len(takes))) + ")")
            order = f" ({', '.join(takes)})" if takes else ""
            raise TypeError(f"inputs of {service}: give a tuple of values in the order the service takes them{order}, "
                            f"e.g. {example}, not {type(inputs).__name__} {inputs!r}")
        ident = next(self._internal_ids) if ident is None else ident
        self._highest_id = max(self._highest_id, ident)
        self._post(self._on_request, service, ident, tuple(inputs))
        return ident

    def fresh_id(self) -> int:
        """An id no task-level client has given a request yet: two clients of one executive (a
        program's own requests and a supervisor's) that each counted from 1 would each take the
        other's replies for their own."""
        self._highest_id += 1
        return self._highest_id

    def interrupt(self, ident: int) -> None:
        """RQST INT: the client no longer wants service `ident` (no reply of its own, §3.4.1)."""
        self._post(self._on_interrupt, ident)

    def get_param(self, name: str) -> Any:
        """GET-PARAM: the value of a parameter (None before the poster's first write)."""
        parameter = self._parameter(name)
        if parameter.get is None:
            raise LookupError(f"parameter '{name}' cannot be read (it has no 'get:')")
        return self._read_path(parameter.get)

    def set_param(self, name: str, value: Any) -> str:
        """SET-PARAM: write a parameter through its control request; OK or the error code."""
        parameter = self._parameter(name)
        if parameter.set is None:
            raise LookupError(f"parameter '{name}' cannot be written (it has no 'set:')")
        module_name, _, request = parameter.set.partition(".")
        module = self.registry.modules[module_name]
        spec = module.spec.requests[request]
        replies: list[Reply] = []
        if self.error is not None or self.zombies.get(module_name):
            return "REFUSED"
        self._post(self._interrupted_by, module_name, request)
        module.submit(request, _as_input(spec.input_type, value, parameter.set), replies.append)
        reply = replies[-1] if replies else None
        if reply is None or not reply.final:
            return "ERROR"
        return "OK" if reply.ok else reply.report.code

    def _parameter(self, name: str) -> ParameterSpec:
        parameter = self.spec.parameters.get(name)
        if parameter is None:
            known = ", ".join(sorted(self.spec.parameters)) or "none"
            raise LookupError(f"executive '{self.spec.name}' has no parameter '{name}' (it has: {known})")
        return parameter

    # ------------------------------------------------------------ cycles
    def _post(self, handler: Callable[..., None], *args: Any) -> None:
        self._inbox.append((handler, args))
        if self._busy:
            return
        self._busy = True
        cycles = 0
        try:
            while self._inbox:
                cycles += 1
                if cycles == CYCLES_PER_INSTANT:
                    self._fatal(f"{CYCLES_PER_INSTANT:,} cycles at {self.kernel.now:g} s with no time passing: a "
                                "reaction loop (a reflex starting a service again on every reply its module gives "
                                "at once?); `specc verify` shows how (its `settles` property)")
                    self._looping = True
                started = time.perf_counter()
                self._in_modules = 0.0
                handler, args = self._inbox.popleft()
                handler(*args)
                self._retry_waiting()
                if self.cycle_durations is not None:
                    self.cycle_durations.append(time.perf_counter() - started - self._in_modules)
        finally:
            self._busy = self._looping = False

    def _retry_waiting(self) -> None:
        """§3.3.3: a WAIT activity asks again for its start at every cycle."""
        for activity in [a for a in self.activities.values() if a.state is Phase.WAIT]:
            if activity.state is Phase.WAIT:
                self._try_start(activity)

    # ------------------------------------------------------------ the request manager
    def _on_request(self, name: str, ident: int, inputs: tuple[Any, ...] = ()) -> None:
        service = self.spec.services.get(name)
        if service is None:
            self._tell("REPLY", name, ident, "BAD-SERVICE", f"the executive offers no service '{name}'")
            return
        if ident in self.activities:  # a REPLY would be a second final reply for the live request
            self._tell("WARNING", name, ident, "BAD-ID", f"id {ident} is already in use: request ignored")
            return
        activity = Activity(ident, service, self.kernel.now)
        self.activities[ident] = activity
        self._move(activity, Phase.WAIT)
        if len(inputs) != len(service.takes):
            taken = ", ".join(service.takes) or "no input"
            self._end(activity, "BAD-INPUT", f"{name} takes {taken} from the task level; {len(inputs)} given")
            return
        problem = _taken_problem(self.registry.modules[service.module].spec.requests[service.request].input_type,
                                 service.takes, inputs)
        if problem:  # the task level's mistake, as a wrong count of inputs is
            self._end(activity, "BAD-INPUT", f"{name}'s input {problem}")
            return
        try:
            activity.input = self._input(service, inputs)
        except Exception as exc:  # the user's input function: report it, keep running
            self._end(activity, "ERROR", f"input of {name}: {type(exc).__name__}: {exc}{where_raised(exc)}")
            return
        if service.start_timeout is not None:
            activity.timers.append(self.kernel.call_later(
                service.start_timeout, functools.partial(self._post, self._on_timeout, activity, "start")))

    def _input(self, service: ServiceSpec, inputs: tuple[Any, ...] = ()) -> Any:
        """The request's input: the constant args, completed by the input function or poster,
        then by the inputs the task level gave (`takes`)."""
        module = self.registry.modules[service.module]
        input_type = module.spec.requests[service.request].input_type
        values: dict[str, Any] = dict(service.args)
        if service.input is not None:
            if "." in service.input:
                found = self._read_path(service.input)
            else:
                found = getattr(self.codels, service.input)(self.context)
            if input_type is not None and isinstance(found, input_type):
                if not inputs:
                    return found
                found = vars(found)  # a record the task level's inputs complete
            values.update(_input_fields(input_type, found, service.input))
        values.update(zip(service.takes, inputs, strict=True))
        if input_type is None:
            return None
        built = build_record(input_type, values)
        problem = check_record(built, input_type)
        if problem:
            raise TypeError(problem)
        return built

    def _read_path(self, path: str) -> Any:
        module, _, rest = path.partition(".")
        poster, _, fields = rest.partition(".")
        value = self.context.read_poster(f"{module}.{poster}")
        for part in fields.split(".") if fields and value is not None else ():
            value = getattr(value, part)
        return value

    def _try_start(self, activity: Activity) -> None:
        service = activity.service
        if self.error is not None:
            self._end(activity, "REFUSED", f"the executive is in its ERROR state: {self.error}")
            return
        zombies = self.zombies.get(service.module)
        if zombies:
            self._end(activity, "REFUSED", f"module {service.module} is frozen by ZOMBIE service "
                                           f"{zombies[0].service.name} (id {zombies[0].id}): interrupt it first")
            return
        for other in self.activities.values():
            if other is activity or other.service.control:
                continue
            if other.state is Phase.INIT and other.service.name in service.conflicts:
                return  # a conflicting activity is about to hold its group: ask again next cycle
            if other.state in (Phase.INIT, Phase.EXEC, Phase.INTER) and other.service.name in service.group \
                    and other.service.name not in service.targets:
                # Its group's state names one running service: a mate the rules would not interrupt
                # (two instances of a service that does not exclude itself) must end first.
                return
        status = self._control(service.name, "START")
        if status == "OK":
            self._move(activity, Phase.INIT)
            self._send(activity)
        elif status == "REFUSE":
            self._end(activity, "REFUSED", "refused by the resource controller")
        elif status == "ERROR":
            self._fatal(f"the controller answered ERROR to the start of {service.name}")
        # WAIT (or an ERROR state just entered): stays in the list

    def _send(self, activity: Activity) -> None:
        service = activity.service
        module = self.registry.modules[service.module]
        for timeout, which in ((service.interm_timeout, "interm"), (service.final_timeout, "final")):
            if timeout is not None and not (which == "interm" and service.control):
                activity.timers.append(self.kernel.call_later(
                    timeout, functools.partial(self._post, self._on_timeout, activity, which)))
        # Replies the module sends before `submit` returns queue up for the next cycle.
        activity.module_id = self._to_module(module.submit, service.request, activity.input,
                                             functools.partial(self._post, self._on_reply, activity))

    def _to_module(self, call: Callable[..., Any], *args: Any) -> Any:
        if self.cycle_durations is None:
            return call(*args)
        started = time.perf_counter()
        try:
            return call(*args)
        finally:
            self._in_modules += time.perf_counter() - started

    def _on_interrupt(self, ident: int) -> None:
        activity = self.activities.get(ident)
        if activity is None:
            self._tell("WARNING", "INT", ident, "BAD-ID", f"no service with id {ident} to interrupt")
            return
        if activity.state is Phase.WAIT:
            self._end(activity, "INT", "interrupted before it started")
        else:
            self._abort(activity)

    def _abort(self, activity: Activity) -> None:
        """Interrupt a running activity: the controller hears it (ABORT), then the module does."""
        if activity.state is Phase.EXEC and activity.holds_group and self.error is None:
            if self._control(activity.service.name, "ABORT") == "ERROR":
                self._fatal(f"the controller refused the interruption of {activity.service.name}")
        if activity.state in (Phase.INIT, Phase.EXEC) and not activity.service.control:
            self._move(activity, Phase.INTER)
        self._send_abort(activity)

    def _send_abort(self, activity: Activity) -> None:
        if activity.abort_sent or activity.module_id is None or activity.service.control:
            return
        activity.abort_sent = True
        module = self.registry.modules[activity.service.module]
        self._to_module(module.abort, activity.module_id, functools.partial(self._post, self._on_abort_reply, activity))

    def _on_timeout(self, activity: Activity, which: str) -> None:
        if activity.state is Phase.ETHER or activity.answered:
            return
        if which == "start":
            if activity.state is Phase.WAIT:
                self._end(activity, "TIMEOUT", "not allowed to start in time")
            return
        if which == "interm" and activity.state is not Phase.INIT:
            return
        if activity.state is Phase.ZOMBIE:
            return  # it already answered with a WARNING; the task level decides
        # The client hears TIMEOUT now; the activity stays listed until its module lets it go.
        self._answer(activity, "TIMEOUT", f"no {'intermediate' if which == 'interm' else 'final'} reply in time")
        self._abort(activity)

    # ------------------------------------------------------------ the reply manager
    def _on_reply(self, activity: Activity, reply: Reply) -> None:
        if activity.state is Phase.ETHER:
            self._fatal(f"reply {reply.status} for {activity.service.name} (id {activity.id}), which has ended")
            return
        service = activity.service
        if not reply.final:
            if activity.state is Phase.INIT:
                self._move(activity, Phase.EXEC)
            elif activity.state is not Phase.INTER:
                self._fatal(f"intermediate reply for {service.name} (id {activity.id}) in {activity.state}")
                return
            if not service.control and self.error is None:
                activity.holds_group = True
                if self._control(service.name, "INTERM") == "ERROR":
                    self._fatal(f"the controller rejected the intermediate reply of {service.name}")
            self._reflexes("interm", service.name, reply)
            return
        if reply.status is Status.ZOMBIE and reply.report.code != "MODULE_FROZEN":
            self._move(activity, Phase.ZOMBIE)
            self.zombies.setdefault(service.module, []).append(activity)
            activity.abort_sent = False  # an abort sent before it froze is spent: a new one releases it
            if activity.holds_group and self.error is None and self._control(service.name, "ZOMBIE") == "ERROR":
                self._fatal(f"the controller rejected the ZOMBIE of {service.name}")
            if activity.answered:  # its client gave up (TIMEOUT): release the module on its behalf
                self._send_abort(activity)
            else:
                self._tell("WARNING", service.name, activity.id, "ZOMBIE", reply.report.detail)
            self._reflexes("warning", service.name, reply)
            return
        if reply.status is Status.INTERRUPTED and activity.state is not Phase.INTER:
            # §3.4.2: an interruption nobody decided
            self._fatal(f"{service.name} (id {activity.id}) was interrupted ({reply.report.code}) "
                        f"while {activity.state}, not INTER")
        self._release(activity)
        self._end(activity, *self._result(activity, reply))
        self._reflexes("reply", service.name, reply)

    def _release(self, activity: Activity) -> None:
        """The controller hears that the activity ended (END), if it ever held a group."""
        service = activity.service
        if self.error is None and (activity.holds_group or service.control):
            if self._control(service.name, "END") == "ERROR":
                self._fatal(f"the controller rejected the end of {service.name}")

    def _result(self, activity: Activity, reply: Reply) -> tuple[Any, str, bool]:
        """The result of (REPLY id result), its detail, and whether the service succeeded."""
        if reply.status is Status.END:
            if reply.report.code != "OK":
                return reply.report.code, reply.report.detail, False
            output = activity.service.output
            if output is None:
                return "OK", "", True
            try:
                return getattr(self.codels, output)(self.context, reply.output), "", True
            except Exception as exc:  # the user's output function
                return "ERROR", f"output of {activity.service.name}: {type(exc).__name__}: {exc}", False
        if reply.status is Status.INTERRUPTED:
            return "INT", reply.report.code, False
        if reply.status is Status.ZOMBIE:  # refused because its module is frozen
            return "REFUSED", reply.report.detail, False
        return reply.status.value, f"{reply.report.code}: {reply.report.detail}".strip(": "), False

    def _on_abort_reply(self, activity: Activity, reply: Reply) -> None:
        """REPLY ABORT: only news for a ZOMBIE, whose module it unfreezes (§3.4.1)."""
        if activity.state is not Phase.ZOMBIE or reply.status is not Status.END:
            return
        self._forget_zombie(activity)
        self._release(activity)
        self._end(activity, "ZOMBIE", "ended after ZOMBIE and its interruption")

    def _module_reply_seen(self, reply: Reply) -> None:
        if reply.request == "abort":
            return
        frozen = reply.status is Status.ZOMBIE and reply.report.code != "MODULE_FROZEN"
        trigger = "warning" if frozen else "reply" if reply.final else "interm"
        self._post(self._reflexes, trigger, f"{reply.module}.{reply.request}", reply)

    # ------------------------------------------------------------ the resource controller
    def _control(self, service: str, event: str) -> str:
        """One decision of the resource controller; its calls act on the activity list."""
        if self.error is not None:
            return "ERROR"
        inputs: dict[str, Any] = {"service": service, "event": event}
        for attribute, value in self.groups.items():
            inputs["@" + attribute] = value
        calls: list[tuple[str, tuple[Any, ...]]] = []
        decision = self.decide(inputs, lambda function, args: calls.append((function, args)))
        status = decision.outputs.get("status")
        if not decision.ok or status is None:
            what = decision.impossible or ", ".join(decision.inconsistent or decision.incomplete)
            self._fatal(f"the controller cannot decide {event} of {service}: {what}")
            return "ERROR"
        for attribute in self.groups:
            self.groups[attribute] = decision.outputs[attribute]
        for function, args in calls:
            targets = [a for a in self.activities.values() if a.service.name == args[0] and a.holds_group
                       and a.state in (Phase.EXEC, Phase.INTER)] if args else []
            for target in targets:
                if function == "changeInterState" and target.state is Phase.EXEC:
                    self._move(target, Phase.INTER)
                elif function == "sendAbortRequest":
                    self._send_abort(target)
        return str(status)

    def _fatal(self, reason: str) -> None:
        """§3.4.2: the general ERROR state; every request is refused, running activities are
        interrupted so the system can be reviewed."""
        if self.error is not None:
            return
        if self.groups:  # the controller's state, which most reasons depend on
            reason += f" (groups: {', '.join(f'{k}={v}' for k, v in self.groups.items())})"
        self.error = reason
        self._tell("WARNING", "EXECUTIVE", 0, "ERROR", reason)
        for activity in list(self.activities.values()):
            if activity.state is Phase.WAIT:
                self._end(activity, "REFUSED", f"the executive is in its ERROR state: {reason}")
            elif activity.state in (Phase.INIT, Phase.EXEC):
                self._abort(activity)

    # ------------------------------------------------------------ reflexes (§3.5)
    def _reflexes(self, trigger: str, source: str, reply: Reply) -> None:
        if self._looping:
            # The cycle limit caught a reaction loop at this instant (a reflex requesting again
            # what a frozen module refuses at once): no reflex fires until the instant is over,
            # or it would go on without end past the ERROR the limit brought.
            return
        for reflex in self.spec.reflexes:
            if reflex.matches(trigger, source, reply.report.code):
                for listener in self.reflex_listeners:
                    self._guarded(listener, reflex, reply.report.code)
                for verb, target in reflex.actions:
                    self._reflex_action(verb, target)

    def _interrupted_by(self, module_name: str, request: str) -> None:
        """The executive is about to send `request` itself: the activities of that module it
        excludes will be interrupted by the module, which the executive decides here (INTER)."""
        requests = self.registry.modules[module_name].spec.requests
        sent = requests.get(request)
        for activity in list(self.activities.values()):
            service = activity.service
            if service.module != module_name or service.control or activity.state not in (Phase.INIT, Phase.EXEC):
                continue
            own = requests.get(service.request)
            if sent is not None and own is not None and sent.conflicts_with(own):
                if activity.state is Phase.EXEC and activity.holds_group and self.error is None:
                    self._control(service.name, "ABORT")
                self._move(activity, Phase.INTER)

    def _reflex_action(self, verb: str, target: str) -> None:
        if verb == "request":
            module_name, _, request = target.partition(".")
            self._interrupted_by(module_name, request)
            self._to_module(self.registry.modules[module_name].submit, request, None, self.reflex_replies.append)
        elif verb == "start":
            self._on_request(target, next(self._internal_ids))
        else:
            for activity in [a for a in self.activities.values() if a.service.name == target]:
                self._on_interrupt(activity.id)

    # ------------------------------------------------------------ bookkeeping
    def _move(self, activity: Activity, target: Phase) -> None:
        source = activity.state
        if source is target:
            return
        if (source, target) not in _ARC_SET:
            raise TransitionError(f"{activity.service.name} (id {activity.id}): no arc {source} -> {target}")
        activity.state = target
        for observer in self.observers:
            self._guarded(observer, activity, source, target)

    def _answer(self, activity: Activity, result: Any, detail: str = "", ok: bool = False) -> None:
        if not activity.answered:
            activity.answered = True
            self._tell("REPLY", activity.service.name, activity.id, result, detail, ok)

    def _end(self, activity: Activity, result: Any, detail: str = "", ok: bool = False) -> None:
        """The activity leaves the list (ETHER); the client hears its result unless it already has."""
        self._answer(activity, result, detail, ok)
        for timer in activity.timers:
            timer.cancel()
        self._move(activity, Phase.ETHER)
        self.activities.pop(activity.id, None)
        self._forget_zombie(activity)

    def _forget_zombie(self, activity: Activity) -> None:
        zombies = self.zombies.get(activity.service.module)
        if zombies and activity in zombies:
            zombies.remove(activity)
            if not zombies:
                del self.zombies[activity.service.module]

    def _tell(self, kind: str, service: str, ident: int, result: Any, detail: str = "", ok: bool = False) -> None:
        message = Message(kind, service, ident, result, detail, self.kernel.now, ok)
        self.messages.append(message)
        for listener in self.listeners:
            self._guarded(listener, message)

    def _guarded(self, callback: Callable[..., Any], *args: Any) -> None:
        """A listener's or observer's bug is recorded, not allowed to leave the lists half updated."""
        try:
            callback(*args)
        except Exception as exc:
            self.incidents.append(f"{getattr(callback, '__name__', callback)!s}: {type(exc).__name__}: {exc}")


def _taken_problem(input_type: Any, takes: Sequence[str], inputs: Sequence[Any]) -> str:
    """What is wrong with the values the task level gave for the inputs a service `takes` (their
    types, as the request declares them), '' when nothing is."""
    kinds = {f[0]: f for f in getattr(input_type, "__specc_fields__", ())}
    for name, value in zip(takes, inputs, strict=True):
        if name in kinds:
            _, kind, size = kinds[name]
            problem = check_value(build_record(kind, value), kind, size)
            if problem:
                return f"{name}: {problem}"
    return ""


def _input_fields(input_type: Any, value: Any, origin: str) -> Mapping[str, Any]:
    """The request input fields `value` gives: a mapping of them, or the value of the only one."""
    if isinstance(value, Mapping):
        return value
    fields: tuple[Any, ...] = tuple(getattr(input_type, "__specc_fields__", ()))
    if len(fields) == 1:
        return {fields[0][0]: value}
    raise TypeError(f"'{origin}' gave {type(value).__name__}; give a dict of the request's inputs")


def _as_input(input_type: Any, value: Any, origin: str) -> Any:
    if input_type is None or isinstance(value, input_type):
        return value
    try:
        return build_record(input_type, _input_fields(input_type, value, origin))
    except TypeError:
        return value  # the module refuses it with BAD_INPUT, which SET-PARAM returns


def load_codels(spec: ExecutiveSpec, codels: Any = None) -> Any:
    """The module of input and output functions: the one given, else the one the spec names."""
    if codels is not None or spec.codel_module is None:
        return codels
    from specc.runtime.functional import import_user_module

    return import_user_module(spec.codel_module, f"executive '{spec.name}'", "its functions", "pass `codels=`")
