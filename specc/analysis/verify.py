"""`specc verify`: every state the executive can reach, and four properties proved or refuted.

The executive that runs is the real one (`specc.runtime.executive`) deciding with the compiled
controller; only its surroundings are abstract. Modules are models of the functional level
(requests, physical incompatibilities, intermediate replies when an activity starts, final
replies, ZOMBIE, aborts, as in `specc.runtime.functional`), whose validate codels may accept or
refuse each request (a refusal interrupts nothing), whose activities may end, fail or
freeze at any moment, and send once, at any moment, each request their codels send (`sends:`)
that the executive can observe (see `observable_requests`: a sent request whose activity can
reach neither a module the executive uses nor a reflex is left out, and said so);
any pending timeout may expire at any moment; the task level may ask for any service while
fewer than `requests` are outstanding, and interrupt any of them. Time is
abstracted away, so every interleaving is covered.

The exploration is breadth-first over canonical states (activity ids renumbered by age), so
each counterexample is a shortest event sequence. When the state limit stops it, the states it
could not finish expanding count as able to reach anything: a liveness property is refuted only
by states whose every continuation was explored. Properties:

- exclusion: an activity never enters EXEC while a service it has an arc to (must interrupt
  or wait for) is in EXEC;
- one-reply: no request gets two (REPLY ...) facts or leaves without one, and from every state
  the modules and timers alone (plus the interruption the protocol demands of a ZOMBIE) can
  bring every outstanding request to its final reply;
- no-starvation: from every state, a WAIT activity of a service without a start timeout can
  leave WAIT without the task level's help;
- no-error: the executive never enters its general ERROR state (§3.4.2), which in normal
  operation "ne doit jamais se produire";
- settles: the executive handles every event in finitely many cycles (DECISIONS_PER_EVENT at
  most): no reaction loop that would hold the robot at one instant.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

from specc.analysis import kheops as k
from specc.analysis.controller import Controller, executive_controller, mentioned_where
from specc.analysis.incompat import build_graph
from specc.analysis.service_list import executive_spec
from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.runtime import executive as rx
from specc.runtime.functional import Reply, Report, RequestSpec, Status
from specc.runtime.rules import Calls, Decision

PROPERTIES = {
    "exclusion": "no service enters EXEC while one it must wait for or interrupt (its conflicts) is in EXEC",
    "one-reply": "every accepted request ends with exactly one final reply",
    "no-starvation": "a WAIT service without a start timeout can always still start, with no new request",
    "no-error": "the executive never enters its general ERROR state",
    "settles": "every event is handled in finitely many executive cycles, with no reaction loop outside time",
}
# Executive decisions one event may take before its handling counts as a loop: an event takes a
# few (the request, the starts asked again, a reflex or two); a reflex restarting on every reply a
# service its frozen module answers at once takes them without end, and so would the robot.
DECISIONS_PER_EVENT = 10_000
# Requests the executive may send the modules while handling one event: a few (a service's, an
# abort, a reflex's); a reflex requesting again on every reply what a frozen module refuses at once
# sends them without end, and takes no decision for DECISIONS_PER_EVENT to count.
REQUESTS_PER_EVENT = 1_000
# Requests to validate codels one event may make: each may be accepted or refused, and the
# explorer replays the event for every sequence, so a loop through them is cut here, not at
# DECISIONS_PER_EVENT.
CHOICES_PER_EVENT = 32
# Sequences of choices one event is replayed for: an event meets one or two validate codels, so a
# few; a reaction loop through them meets CHOICES_PER_EVENT on every sequence, 2^32 of them. Past
# this many, the event's other sequences are not explored, and the exploration is incomplete (the
# verdicts hold "in the states explored"): nothing is proved, nothing falsely refuted.
SEQUENCES_PER_EVENT = 256


class Unsettled(Exception):
    """The executive's handling of one event went on past DECISIONS_PER_EVENT decisions."""


# ---------------------------------------------------------------- the abstract surroundings


class ModelTimer:
    def __init__(self, action: Callable[[], Any]):
        self.action = action
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class ModelKernel:
    """No clock: a pending timer may expire at any moment."""

    def __init__(self) -> None:
        self.now = 0.0
        self.timers: list[ModelTimer] = []

    def call_later(self, delay: float, action: Callable[[], Any], priority: int = 0) -> ModelTimer:
        timer = ModelTimer(action)
        self.timers.append(timer)
        return timer

    def pending(self) -> list[ModelTimer]:
        self.timers = [t for t in self.timers if not t.cancelled]
        return self.timers


@dataclass(eq=False)
class ModelActivity:
    id: int
    spec: RequestSpec
    sink: Callable[[Reply], None]
    state: str = "INIT"  # INIT EXEC INTER ZOMBIE
    waiting_for: set[int] = field(default_factory=set)
    cause: str = "ABORT"
    sent: frozenset[str] = frozenset()  # the requests (`sends:`) its codels have sent already
    sent_by_codel: bool = False  # it is itself such a request: it counts as an outstanding one
    # The requests it sent that are still there, (module, id): its children, which the module
    # interrupts first when it ends or is interrupted (specc.runtime.functional.Module.finish).
    children: list[tuple[str, int]] = field(default_factory=list)


class Choices:
    """The choices made inside one event, which the explorer enumerates: a step is replayed
    once for each sequence of options (`given` sets the first ones, every later one takes its
    first option), as a request a validate codel may accept or refuse is met deep inside the
    executive's handling of an event, not between events."""

    def __init__(self, given: tuple[int, ...] = ()):
        self.given = given
        self.made: list[int] = []
        self.options: list[int] = []  # how many options each choice made had
        self.said: list[str] = []  # the options taken other than the first, for the trace

    def choose(self, options: Sequence[str]) -> int:
        position = len(self.made)
        if position >= CHOICES_PER_EVENT:
            raise Unsettled(f"the executive's handling of this event sent {CHOICES_PER_EVENT} requests to validate "
                            f"codels (the last: {options[1].split(' refused')[0]}) with no time passing: a reaction "
                            "loop while they refuse, as a reflex starting again on every refusal makes")
        picked = self.given[position] if position < len(self.given) else 0
        self.made.append(picked)
        self.options.append(len(options))
        if picked:
            self.said.append(options[picked])
        return picked

    def description(self) -> str:
        """The options taken other than the first, a run of the same one said once with its count."""
        runs = [(said, len(list(group))) for said, group in itertools.groupby(self.said)]
        return "; ".join(said if count == 1 else f"{said}, {count} times" for said, count in runs)

    def others(self) -> Iterator[tuple[int, ...]]:
        """The sequences that depart from this one at a choice after those it was given."""
        for position in range(len(self.given), len(self.made)):
            for option in range(1, self.options[position]):
                yield (*self.made[:position], option)


class ModelModule:
    """A module as its clients see it: what `specc.runtime.functional.Module` does on a request
    or an abort, with the activities' own endings left to the explorer."""

    def __init__(self, name: str, requests: Mapping[str, RequestSpec], registry: ModelRegistry,
                 codes: tuple[str, ...] = ()):
        self.name = name
        self.codes = codes  # the report codes reflexes look for: activities may end with them too
        self.requests = requests
        self.registry = registry
        self.spec = SimpleNamespace(requests=requests)  # what the executive reads (no request takes an input)
        self.activities: dict[int, ModelActivity] = {}
        self.zombies: set[int] = set()
        self.reply_listeners: list[Callable[[Reply], None]] = []

    def emit(self, sink: Callable[[Reply], None], reply: Reply) -> None:
        sink(reply)  # as specc.runtime.functional.Module.emit: the client, then the reflexes
        for listener in self.reply_listeners:
            listener(reply)

    def reply(self, rqst_id: int, request: str, status: Status, code: str = "OK", final: bool = True) -> Reply:
        return Reply(rqst_id, self.name, request, status, Report(code), None, final)

    def submit(self, request: str, input_: Any, sink: Callable[[Reply], None], parent: Any = None) -> int:
        self.registry.submitted += 1
        if self.registry.submitted > REQUESTS_PER_EVENT:
            raise Unsettled(f"the executive's handling of this event sent {REQUESTS_PER_EVENT:,} requests to the "
                            f"modules (the last: {self.name}.{request}) with no time passing: a reaction loop, as "
                            "a reflex starting or requesting again, on every reply, what a frozen module refuses "
                            "at once")
        rqst_id = self.registry.new_id()
        spec = self.requests.get(request)
        if spec is None:
            self.emit(sink, self.reply(rqst_id, request, Status.CS_ERROR, "UNKNOWN_REQUEST"))
            return rqst_id
        if spec.kind == "control":
            refusal = self.validated(spec)
            if refusal is not None:
                self.emit(sink, self.reply(rqst_id, request, Status.FINAL_ERROR, refusal))
                return rqst_id
            for other in list(self.activities.values()):
                if other.state in ("INIT", "EXEC") and spec.conflicts_with(other.spec):
                    self.interrupt(other, request)
            self.emit(sink, self.reply(rqst_id, request, Status.END))
            return rqst_id
        if self.zombies:
            self.emit(sink, self.reply(rqst_id, request, Status.ZOMBIE, "MODULE_FROZEN"))
            return rqst_id
        refusal = self.validated(spec)
        if refusal is not None:  # before it interrupts anything, as the runtime's validate
            self.emit(sink, self.reply(rqst_id, request, Status.FINAL_ERROR, refusal))
            return rqst_id
        activity = ModelActivity(rqst_id, spec, sink)
        conflicting = [o for o in self.activities.values()
                       if o.state in ("INIT", "EXEC", "INTER") and spec.conflicts_with(o.spec)]
        activity.waiting_for = {o.id for o in conflicting}
        self.activities[rqst_id] = activity
        for other in conflicting:
            if other.state != "INTER":
                self.interrupt(other, request)
        self.try_start(activity)
        return rqst_id

    def validated(self, spec: RequestSpec) -> str | None:
        """A request with a validate codel is accepted or refused, which the explorer chooses:
        None when accepted, else the code it is refused with. The codes are those the request
        may fail with (`fail:`, any when it says none) that a reflex looks for, and one other."""
        if spec.validate is None:
            return None
        others = sorted(set(spec.fail) - set(self.codes)) if spec.fail else ["FAILED"]
        codes = list(dict.fromkeys([*others[:1], *(c for c in self.codes if not spec.fail or c in spec.fail)]))
        options = ["accepted", *(f"{self.name}.{spec.name} refused by its validate codel with {c}" for c in codes)]
        picked = self.registry.choices.choose(options)
        return codes[picked - 1] if picked else None

    def abort(self, target: int, sink: Callable[[Reply], None] | None = None) -> int:
        rqst_id = self.registry.new_id()
        activity = self.activities.get(target)
        if activity is not None:
            self.interrupt(activity, "ABORT")
        if sink is not None:
            status, code = (Status.END, "OK") if activity is not None else (Status.FINAL_ERROR, "UNKNOWN_ACTIVITY")
            self.emit(sink, self.reply(rqst_id, "abort", status, code))
        return rqst_id

    def interrupt(self, activity: ModelActivity, cause: str) -> None:
        if activity.state != "INTER":  # an activity already being interrupted keeps its first cause
            activity.cause = cause
        if activity.state == "INIT":
            self.finish(activity, Status.INTERRUPTED, cause)
        elif activity.state == "EXEC":
            activity.state = "INTER"
            self.interrupt_children(activity)
        elif activity.state == "ZOMBIE":
            del self.activities[activity.id]
            self.zombies.discard(activity.id)

    def try_start(self, activity: ModelActivity) -> None:
        if activity.state != "INIT" or activity.waiting_for:
            return
        if self.zombies:
            self.finish(activity, Status.ZOMBIE, "MODULE_FROZEN")
            return
        activity.state = "EXEC"
        self.emit(activity.sink, self.reply(activity.id, activity.spec.name, Status.WAITING, "final", final=False))

    def interrupt_children(self, activity: ModelActivity) -> None:
        """The runtime interrupts a parent's running children when it ends or is interrupted: a
        child does not go on, and send, once its parent is over. (Its final reply, which the
        runtime holds until the children have ended, is not held here: the executive may hear
        it a little sooner than on the robot.)"""
        for module, ident in activity.children:
            receiver = self.registry.modules.get(module)
            child = receiver.activities.get(ident) if receiver is not None else None
            if receiver is not None and child is not None and child.state in ("INIT", "EXEC"):
                receiver.interrupt(child, "ABORT")

    def finish(self, activity: ModelActivity, status: Status, code: str) -> None:
        self.interrupt_children(activity)
        if status is Status.ZOMBIE and code != "MODULE_FROZEN":
            activity.state = "ZOMBIE"
            self.zombies.add(activity.id)
        else:
            del self.activities[activity.id]
        self.emit(activity.sink, self.reply(activity.id, activity.spec.name, status, code))
        for other in list(self.activities.values()):
            if activity.id in other.waiting_for:
                other.waiting_for.discard(activity.id)
                self.try_start(other)

    def send(self, activity: ModelActivity, target: str) -> None:
        """A codel of the activity sends `target` (`module.request`) to another module, once."""
        activity.sent = activity.sent | {target}
        module, _, request = target.partition(".")
        receiver = self.registry.modules.get(module)
        if receiver is not None:
            ident = receiver.submit(request, None, _ignore)
            if ident in receiver.activities:
                receiver.activities[ident].sent_by_codel = True
                activity.children.append((module, ident))

    def endings(self, activity: ModelActivity) -> list[tuple[str, Callable[[], None]]]:
        """What the activity itself may do next."""
        # What its codels may still send: while it runs, and while its `inter` codel runs.
        sends = [(f"sends {target}", functools.partial(self.send, activity, target))
                 for target in activity.spec.sends if target not in activity.sent]
        if activity.state == "EXEC":
            reported = [(f"ends with {code}", functools.partial(self.finish, activity, Status.END, code))
                        for code in self.codes]
            return [("ends", functools.partial(self.finish, activity, Status.END, "OK")), *reported, *sends,
                    ("fails", functools.partial(self.finish, activity, Status.FINAL_ERROR, "FAILED")),
                    ("goes ZOMBIE", functools.partial(self.finish, activity, Status.ZOMBIE, "ZOMBIE"))]
        if activity.state == "INTER":
            return [("is interrupted", functools.partial(self.finish, activity, Status.INTERRUPTED, activity.cause)),
                    *(sends if "inter" in activity.spec.codels else []),
                    ("goes ZOMBIE", functools.partial(self.finish, activity, Status.ZOMBIE, "ZOMBIE"))]
        return []


def _ignore(reply: Reply) -> None:
    """Where a sent request's replies go: its sender's codels, which the model leaves free."""


class ModelModules(dict[str, ModelModule]):
    """The registry's modules, each made when first looked up: a state names few of them, and
    the exploration makes a registry for every transition."""

    def __init__(self, make: Callable[[str], ModelModule], names: Mapping[str, Any]):
        super().__init__()
        self._make = make
        self._names = names

    def __missing__(self, name: str) -> ModelModule:
        if name not in self._names:
            raise KeyError(name)
        module = self[name] = self._make(name)
        return module

    def get(self, name: str, default: Any = None) -> Any:  # type: ignore[override]
        return self[name] if name in self._names else default

    def __contains__(self, name: object) -> bool:  # every module of the model is there, made or not
        return name in self._names


class ModelRegistry:
    def __init__(self, modules: Mapping[str, Mapping[str, RequestSpec]], codes: tuple[str, ...] = ()):
        self.kernel = ModelKernel()
        self._ids = itertools.count(1)
        self.submitted = 0  # requests sent to its modules: a world is made for one event (see Unsettled)
        self.choices = Choices()
        self.modules = ModelModules(lambda name: ModelModule(name, modules[name], self, codes), modules)

    def new_id(self) -> int:
        return next(self._ids)

    def read_poster(self, name: str) -> None:
        return None


# ---------------------------------------------------------------- the explored world


def decision_function(compiled: k.Compiled) -> Callable[..., Decision]:
    """The compiled decision graph as the runtime calls it (the generated code unrolls the same graph).
    A decision depends on its inputs alone, and the exploration asks the same ones again and
    again: each is worked out once (the executive only reads a decision)."""
    known: dict[tuple[Any, ...], tuple[Decision, tuple[tuple[str, tuple[Any, ...]], ...]]] = {}

    def decide(inputs: Mapping[str, Any], calls: Calls) -> Decision:
        key = tuple(inputs.items())
        found = known.get(key)
        if found is None:
            outcome = k.evaluate(compiled, inputs)
            found = known[key] = (Decision(outcome.outputs, tuple(outcome.inconsistent), tuple(outcome.incomplete),
                                           outcome.impossible), tuple(outcome.calls))
        decision, made = found
        for function, args in made:
            calls(function, args)
        return decision

    return decide


@dataclass
class World:
    executive: rx.Executive
    registry: ModelRegistry
    next_id: int = 1
    problems: list[tuple[str, str]] = field(default_factory=list)  # (property, what) seen in the last step


@dataclass(frozen=True)
class Event:
    label: str
    helped: bool  # needs the task level (a new request, or interrupting what is not a ZOMBIE)
    run: Callable[[World], None]


@dataclass
class Violation:
    property: str
    message: str
    trace: list[str]


@dataclass
class Verification:
    executive: str
    requests: int
    states: int
    transitions: int
    complete: bool  # False when the state limit (`limited`) or the choices' limit (`cut`) left states out
    violations: dict[str, Violation]
    left_out: tuple[str, ...] = ()  # the sends the model leaves out ("module.request sends module.request")
    parts: tuple[tuple[str, ...], ...] = ()  # the independent parts explored one by one (services), if several
    # Conflicts declared by one side only: (source, policy, target), the target starting beside a
    # running source unhindered; exclusion, which reads the arcs as written, allows it.
    one_way: tuple[tuple[str, str, str], ...] = ()
    limited: bool = False  # the state limit stopped the exploration
    unexplored: tuple[tuple[str, ...], ...] = ()  # the parts the state limit kept from being explored
    cut: tuple[str, ...] = ()  # events not replayed for every sequence of choices (SEQUENCES_PER_EVENT)
    # Exec services that entered EXEC in no state of a complete exploration: each request of them
    # ends before it runs (refused, timed out, kept waiting), which no property forbids.
    never_started: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.complete and not self.violations


class Explorer:
    def __init__(self, spec: rx.ExecutiveSpec, decide: Callable[..., Decision],
                 modules: Mapping[str, Mapping[str, RequestSpec]], arcs: set[tuple[str, str]], requests: int,
                 parts: Sequence[tuple[str, ...]] = ()):
        self.spec = dataclasses.replace(spec, services={
            name: dataclasses.replace(s, args={}, input=None, output=None) for name, s in spec.services.items()})
        self.decisions = 0  # the decisions taken for the event being stepped (see Unsettled)
        self.decide = self._watched(decide)
        # Services that share nothing (see `independent_parts`) are explored part by part: the
        # executive's states are then the products of the parts' states, which are not listed.
        self.parts = tuple(parts) if len(parts) > 1 else ()
        self.asked: frozenset[str] | None = None  # the services the task level may ask for (None: all)
        self.parts_interact = False  # a decision a part's exploration met ties it to the others
        self._declared = modules
        self._model(observable_requests(spec, modules, listened=False))
        # Leaving out the requests whose replies only run a cycle (those of a module a reflex
        # listens to), and exploring parts apart, both hold when a start authorisation pass
        # changes nothing right after a cycle: every transition checks it (`step`).
        self.check_passes = bool(self.parts) or observable_requests(spec, modules) != self._observable
        self.passes_matter = False
        self.arcs = arcs
        # (running, started): a service entered EXEC while the other was in EXEC, in some state explored.
        self.together: set[tuple[str, str]] = set()
        self.started: set[str] = set()  # the services that entered EXEC in some state explored
        self.requests = requests
        # The report codes reflexes look for: module activities may end with them too.
        self.codes = tuple(sorted({str(r.value) for r in self.spec.reflexes if r.op is not None} - {"OK"}))

    # -- states: a world is rebuilt from its canonical key before each step (cheaper than copying it)
    def initial(self) -> World:
        registry = ModelRegistry(self.modules, self.codes)
        executive = rx.Executive(self.spec, self.decide, registry)  # type: ignore[arg-type]
        world = World(executive, registry)
        executive.observers.append(functools.partial(_check_exclusion, world, self.arcs, self.together, self.started))
        return world

    def key(self, world: World) -> Key:
        """The world's state, canonical: activities numbered by age, module activities by owner."""
        executive = world.executive
        ordered = list(executive.activities.values())  # in the order they were listed: by age
        ranks = {a.id: rank for rank, a in enumerate(ordered)}
        owners = {(a.service.module, a.module_id): rank for rank, a in enumerate(ordered)}
        timers: dict[int, list[str]] = {}
        for timer in world.registry.kernel.pending():
            activity, which = _timer_parts(timer)
            if isinstance(activity, rx.Activity) and activity.id in ranks:
                timers.setdefault(ranks[activity.id], []).append(which)
        def by_owner(name: str, module: ModelModule) -> list[ModelActivity]:
            return sorted(module.activities.values(), key=lambda a: (owners.get((name, a.id), len(ordered)), a.id))

        listed = [(name, by_owner(name, module)) for name, module in sorted(world.registry.modules.items())
                  if module.activities]
        place = {(name, a.id): i for name, entries in listed for i, a in enumerate(entries)}
        modules = []
        for name, entries in listed:
            modules.append((name, tuple((owners.get((name, a.id), -1), a.spec.name, a.state, a.cause,
                                         tuple(sorted(place[name, w] for w in a.waiting_for if (name, w) in place)),
                                         tuple(sorted(a.sent)), a.sent_by_codel,
                                         # in the order they were sent: the order they are interrupted in
                                         tuple((child[0], place[child]) for child in a.children if child in place))
                                        for a in entries)))
        activities = tuple((a.service.name, a.state, a.holds_group, a.answered, a.abort_sent,
                            tuple(sorted(timers.get(rank, ()))))
                           for rank, a in enumerate(ordered))
        zombies = tuple(sorted((module, ranks[a.id]) for module, listed in executive.zombies.items()
                               for a in listed))
        return (activities, tuple(modules), tuple(executive.groups.values()), zombies, executive.error is not None)

    def world(self, key: Key) -> World:
        activities, modules, groups, zombies, error = key
        world = self.initial()
        executive, registry = world.executive, world.registry
        made = []
        for rank, (service, state, holds, answered, abort_sent, timers) in enumerate(activities):
            activity = rx.Activity(rank + 1, self.spec.services[service], 0.0, state, None,
                                   None, holds, answered, abort_sent)
            for which in timers:
                activity.timers.append(registry.kernel.call_later(  # type: ignore[arg-type]
                    0.0, functools.partial(executive._post, executive._on_timeout, activity, which)))
            executive.activities[activity.id] = activity
            made.append(activity)
        built_in: dict[str, list[ModelActivity]] = {}
        for name, entries in modules:
            module = registry.modules[name]
            built = built_in[name] = []
            for owner, request, state, cause, _, sent, sent_by_codel, _ in entries:
                owned = made[owner] if owner >= 0 else None
                sink = (functools.partial(executive._post, executive._on_reply, owned) if owned is not None
                        else executive.reflex_replies.append)
                entry = ModelActivity(registry.new_id(), module.requests[request], sink, state, set(), cause,
                                      frozenset(sent), sent_by_codel)
                module.activities[entry.id] = entry
                if state == "ZOMBIE":
                    module.zombies.add(entry.id)
                if owned is not None:
                    owned.module_id = entry.id
                built.append(entry)
            for entry, (_, _, _, _, waiting, _, _, _) in zip(built, entries, strict=True):
                entry.waiting_for = {built[i].id for i in waiting}
        for name, entries in modules:  # the children, once every module's entries are there
            for entry, (*_, children) in zip(built_in[name], entries, strict=True):
                entry.children = [(module, built_in[module][i].id) for module, i in children]
        for activity in made:
            if activity.module_id is None and activity.state is not rx.Phase.WAIT:
                activity.module_id = registry.new_id()  # its module has forgotten it
        executive.groups = dict(zip(self.spec.groups, groups, strict=True))
        for module, rank in zombies:
            executive.zombies.setdefault(module, []).append(made[rank])
        executive.error = "ERROR" if error else None
        world.next_id = len(made) + 1
        return world

    def events(self, world: World) -> list[Event]:
        executive = world.executive
        found: list[Event] = []
        # A request a codel sent is outstanding too: the bound keeps the state space finite.
        sent = sum(a.sent_by_codel for module in world.registry.modules.values() for a in module.activities.values())
        if len(executive.activities) + sent < self.requests:
            for service in self.spec.services:
                if self.asked is None or service in self.asked:
                    found.append(Event(f"task: RQST EXEC {service}", True, functools.partial(_request, service)))
        for activity in executive.activities.values():
            zombie = activity.state is rx.Phase.ZOMBIE
            found.append(Event(f"task: RQST INT of {activity.service.name}{' (ZOMBIE)' if zombie else ''}",
                               not zombie, functools.partial(_interrupt, activity.id)))
        for name, module in world.registry.modules.items():
            for entry in list(module.activities.values()):
                for verb, _ in module.endings(entry):
                    found.append(Event(f"{name}: {entry.spec.name} {verb}", False,
                                       functools.partial(_module_event, name, entry.id, verb)))
        for index, timer in enumerate(world.registry.kernel.pending()):
            found.append(Event(f"timer: {_timer_label(timer)}", False, functools.partial(_fire, index)))
        return found

    def step(self, world: World, event: Event) -> World:
        """Run one event in a world just rebuilt from its key, note what went wrong. An event names
        activities, module entries and timers by id or position, which every rebuild of one key
        gives alike: the events listed once for a state serve each of its transitions."""
        executive = world.executive
        before = {a.id: a.answered for a in executive.activities.values()}
        fresh = world.next_id
        self.decisions = 0
        try:
            event.run(world)
        except Unsettled as exc:
            world.problems.append(("settles", str(exc)))
            return world
        except Exception as exc:  # the runtime itself failed: a finding, not a crash of the verifier
            world.problems.append(("no-error", f"the executive raised {type(exc).__name__}: {exc}"))
            return world
        replied: set[int] = set()
        for message in executive.messages:
            if message.kind == "WARNING" and message.result == "ERROR":
                world.problems.append(("no-error", f"ERROR state: {message.detail}"))
            if message.kind != "REPLY":
                continue
            if message.id in replied or before.get(message.id, False) or (
                    message.id not in before and message.id != fresh and message.id > 0):
                world.problems.append(("one-reply", f"a second (REPLY ...) for {message.service}"))
            replied.add(message.id)
        for ident, answered in before.items():
            if ident not in executive.activities and not answered and ident not in replied:
                world.problems.append(("one-reply", f"request {ident} left the activity list without a reply"))
        return world

    def check_pass(self, world: World, reached: Key) -> None:
        """With `check_passes`: one more start authorisation pass on `world` (whose key is
        `reached`, just stepped), noting whether it changes a state (`passes_matter`)."""
        executive = world.executive
        # A pass only asks again for the starts of WAIT activities: with none, it changes nothing.
        if (self.check_passes and not self.passes_matter and executive.error is None
                and any(a.state is rx.Phase.WAIT for a in executive.activities.values())):
            self.decisions = world.registry.submitted = 0  # the pass is an event of its own
            try:
                executive._post(_nothing)  # a cycle with no event
            except Unsettled:  # the pass itself loops: every cycle counts, as when it changes a state
                self.passes_matter = True
                return
            if self.key(world) != reached:
                self.passes_matter = True

    # -- the search
    def _model(self, observable: set[str]) -> None:
        """Model the modules sending only the requests in `observable`."""
        modules = self._declared
        self._observable = observable
        self.left_out = tuple(sorted(f"{module}.{name} sends {target}" for module, requests_ in modules.items()
                                     for name, request in requests_.items() if f"{module}.{name}" in observable
                                     for target in request.sends if target not in observable))
        self.modules = {module: {name: dataclasses.replace(request, sends=tuple(
                            t for t in request.sends if t in observable)) for name, request in requests_.items()}
                        for module, requests_ in modules.items()}

    def _watched(self, decide: Callable[..., Decision]) -> Callable[..., Decision]:
        """`decide`, noting, while a part is explored, a decision that ties it to another part:
        one changing the state of a group outside the part or naming a service outside it in a
        call (what `independent_parts` rules out, checked again), or a START not granted that
        changes a group's state (WAIT activities ask again after every event of any part, and
        such a decision would make that pass depend on how often it runs)."""

        def watched(inputs: Mapping[str, Any], calls: Calls) -> Decision:
            self.decisions += 1
            if self.decisions > DECISIONS_PER_EVENT:
                raise Unsettled(f"the executive's handling of this event went on for {DECISIONS_PER_EVENT:,} "
                                f"decisions (the last: {inputs.get('event')} of {inputs.get('service')}) with no "
                                "time passing: a reaction loop, as a reflex starting on every reply a service its "
                                "module answers at once (a frozen module, a conflict) makes")
            asked = self.asked
            if asked is None:
                return decide(inputs, calls)

            def checked(function: str, args: tuple[Any, ...]) -> None:
                if args and args[0] in self.spec.services and args[0] not in asked:
                    self.parts_interact = True
                calls(function, args)

            decision = decide(inputs, checked)
            waiting = inputs.get("event") == "START" and decision.outputs.get("status") != "OK"
            for group, members in self.spec.groups.items():
                if decision.outputs.get(group) != inputs.get("@" + group) and (
                        waiting or not asked.issuperset(members)):
                    self.parts_interact = True
            return decision

        return watched

    def explore(self, limit: int = 200_000, progress: Callable[[int], None] | None = None) -> Verification:
        """Every state, part by part when the services split into independent parts: a property
        fails in the whole executive exactly when it fails in a part (the others idle), with a
        trace as short (where two parts refute it as soon, the whole's search may show the
        other's). The parts are explored as one whole when one of them enters the
        general ERROR state (which reaches every part) or a decision ties them (`_watched`); and
        the whole with every request a reflex's module replies to when a start authorisation
        pass right after a transition changed a state (`step`): then every cycle counts."""
        result = self._explore_parts(limit, progress)
        if self.passes_matter:  # a pass changed something: every cycle counts, explore the whole
            self._model(observable_requests(self.spec, self._declared))
            self.parts, self.check_passes = (), False
            return self._explore(limit, progress)
        return result

    def _explore_parts(self, limit: int, progress: Callable[[int], None] | None) -> Verification:
        if self.parts:
            results: list[Verification] = []
            for part in self.parts:
                explored = sum(r.states for r in results)
                self.asked = frozenset(part)
                try:
                    results.append(self._explore(limit - explored, _offset(progress, explored)))
                finally:
                    self.asked = None
                if self.passes_matter:
                    return results[-1]  # `explore` starts again with every request kept
                if self.parts_interact or "no-error" in results[-1].violations:
                    return self._explore(limit, progress)
                if results[-1].limited:
                    break  # the state limit: the parts left are not explored either
            violations: dict[str, Violation] = {}
            for result in results:  # the shortest trace of any part, as the whole's exploration finds first
                for prop, violation in result.violations.items():
                    if prop not in violations or len(violation.trace) < len(violations[prop].trace):
                        violations[prop] = violation
            return Verification(self.spec.name, self.requests, sum(r.states for r in results),
                                sum(r.transitions for r in results), all(r.complete for r in results)
                                and len(results) == len(self.parts), violations, self.left_out, self.parts,
                                limited=any(r.limited for r in results), unexplored=self.parts[len(results):],
                                cut=tuple(label for r in results for label in r.cut))
        return self._explore(limit, progress)

    def _explore(self, limit: int, progress: Callable[[int], None] | None) -> Verification:
        start = self.key(self.initial())
        keys = {start: 0}
        states = [start]
        parents: list[tuple[int, str] | None] = [None]
        edges: list[list[tuple[int, bool]]] = [[]]
        violations: dict[str, Violation] = {}
        queue = deque([0])
        transitions = 0
        complete, limited = True, False
        unfinished: set[int] = set()  # states with a successor the limit kept out
        cut: list[str] = []  # events whose sequences of choices were not all replayed (SEQUENCES_PER_EVENT)
        while queue:
            index = queue.popleft()
            key = states[index]
            first = self.world(key)
            listed: World | None = first  # stepped by the first event; the others rebuild the key
            for event in self.events(first):
                choices: list[tuple[int, ...]] = [()]  # each sequence of choices inside the event is a transition
                replays = 0
                while choices:
                    if replays == SEQUENCES_PER_EVENT:
                        cut.append(event.label)
                        complete = False
                        unfinished.add(index)
                        break
                    replays += 1
                    world = listed or self.world(key)
                    listed = None
                    world.registry.choices = made = Choices(choices.pop())
                    after = self.step(world, event)
                    choices += made.others()
                    label = f"{event.label} ({made.description()})" if made.said else event.label
                    transitions += 1
                    for prop, message in after.problems:
                        if prop not in violations:
                            violations[prop] = Violation(prop, message, self.trace(parents, index) + [label])
                    if any(prop == "settles" for prop, _ in after.problems):
                        continue  # the event never ends: no state comes after it
                    reached = self.key(after)
                    self.check_pass(after, reached)
                    target = keys.get(reached)
                    if target is None:
                        if len(states) >= limit:
                            complete, limited = False, True
                            unfinished.add(index)
                            continue
                        target = len(states)
                        keys[reached] = target
                        states.append(reached)
                        parents.append((index, label))
                        edges.append([])
                        queue.append(target)
                    edges[index].append((target, event.helped))
            if progress is not None and index % 1000 == 0:
                progress(len(states))
        self.liveness(states, edges, parents, violations, unfinished)
        return Verification(self.spec.name, self.requests, len(states), transitions, complete, violations,
                            self.left_out, limited=limited, cut=tuple(cut))

    def liveness(self, states: list[Key], edges: list[list[tuple[int, bool]]],
                 parents: list[tuple[int, str] | None], violations: dict[str, Violation],
                 unfinished: AbstractSet[int] = frozenset()) -> None:
        """One-reply's and no-starvation's "from every state, without the task level": a state
        from which no goal state can be reached refutes them. A state the limit kept from being
        expanded fully (`unfinished`) may reach one through what was not explored: it counts as
        reaching it, so that what is refuted is refuted by states explored to the end."""
        untimed = {name for name, s in self.spec.services.items() if s.start_timeout is None}
        goals: dict[str, Callable[[Key], bool]] = {
            "one-reply": lambda key: not key[0],
            "no-starvation": lambda key: not any(a[1] == "WAIT" and a[0] in untimed for a in key[0]),
        }
        backwards: list[list[int]] = [[] for _ in states]
        for source, targets in enumerate(edges):
            for target, helped in targets:
                if not helped:
                    backwards[target].append(source)
        for prop, goal in goals.items():
            if prop in violations:
                continue
            reached = {i for i, key in enumerate(states) if goal(key)} | unfinished
            queue = deque(reached)
            while queue:
                for source in backwards[queue.popleft()]:
                    if source not in reached:
                        reached.add(source)
                        queue.append(source)
            stuck = next((i for i in range(len(states)) if i not in reached), None)
            if stuck is not None:
                waiting = ", ".join(f"{a[0]} in {a[1]}" for a in states[stuck][0])
                message = (f"stuck with {waiting}: only new requests could end them" if prop == "one-reply"
                           else f"a WAIT without start timeout can never start: {waiting}")
                violations[prop] = Violation(prop, message, self.trace(parents, stuck))

    @staticmethod
    def trace(parents: list[tuple[int, str] | None], index: int) -> list[str]:
        labels: list[str] = []
        step = parents[index]
        while step is not None:
            labels.append(step[1])
            step = parents[step[0]]
        return labels[::-1]


Key = tuple[Any, ...]


def _nothing() -> None:
    """The event of a cycle that only asks again for the start of every WAIT activity."""


def _offset(progress: Callable[[int], None] | None, before: int) -> Callable[[int], None] | None:
    """`progress`, told the states of the parts explored before too."""
    if progress is None:
        return None
    report = progress
    return lambda states: report(before + states)


def _request(service: str, world: World) -> None:
    # The inputs the task level gives (`takes:`): the abstract modules read no input, but a
    # request given fewer than its service takes would be refused before it ever ran.
    takes = world.executive.spec.services[service].takes
    world.executive.request(service, world.next_id, (None,) * len(takes))


def _interrupt(ident: int, world: World) -> None:
    world.executive.interrupt(ident)


def _module_event(module_name: str, ident: int, verb: str, world: World) -> None:
    module = world.registry.modules[module_name]
    activity = module.activities[ident]
    dict(module.endings(activity))[verb]()


def _fire(index: int, world: World) -> None:
    timer = world.registry.kernel.pending()[index]
    timer.cancelled = True
    timer.action()


def _timer_parts(timer: ModelTimer) -> tuple[Any, str]:
    action = timer.action
    if isinstance(action, functools.partial) and len(action.args) == 3:  # _post(_on_timeout, activity, which)
        return action.args[1], action.args[2]
    return None, repr(action)


def _timer_label(timer: ModelTimer) -> str:
    activity, which = _timer_parts(timer)
    if isinstance(activity, rx.Activity):
        return f"{which} timeout of {activity.service.name} (id {activity.id})"
    return which


def _check_exclusion(world: World, arcs: set[tuple[str, str]], together: set[tuple[str, str]], started: set[str],
                     activity: rx.Activity, source: rx.Phase, target: rx.Phase) -> None:
    if target is not rx.Phase.EXEC:
        return
    started.add(activity.service.name)
    for other in world.executive.activities.values():
        if other is activity or other.state is not rx.Phase.EXEC:
            continue
        together.add((other.service.name, activity.service.name))
        if (activity.service.name, other.service.name) in arcs:
            world.problems.append(("exclusion", f"{activity.service.name} (id {activity.id}) entered EXEC while "
                                                f"{other.service.name} (id {other.id}), which it must interrupt "
                                                "or wait for, is in EXEC"))


# ---------------------------------------------------------------- from a spec


def observable_requests(spec: rx.ExecutiveSpec, modules: Mapping[str, Mapping[str, RequestSpec]],
                        listened: bool = True) -> set[str]:
    """The module requests ("module.request") whose activities can change what the executive
    sees: a cone of influence. What can run at all: the services' requests, what a running
    request's codels send, and what a reflex whose source can run requests. Of those, the
    executive observes its services' requests, the reflexes' sources and, with `listened`,
    every request of a module a reflex takes as its source (it hears all their replies); then
    every request of a module where it observes one (they conflict, wait for each other, freeze
    the module), and every request that sends one it observes. The others, however they end,
    fail, freeze or send, leave every executive state as it is: the model need not send them."""

    def sends(request: str) -> tuple[str, ...]:
        module, _, name = request.partition(".")
        found = modules.get(module, {}).get(name)
        return found.sends if found is not None else ()

    def requested_by_reflexes(source: str) -> list[str]:
        return [target for reflex in spec.reflexes if reflex.source == source
                for verb, target in reflex.actions if verb == "request"]

    services = {f"{s.module}.{s.request}" for s in spec.services.values()}
    # A service's replies can come whenever the task level asks for it: its reflexes can run.
    pending = sorted(services) + [t for service in spec.services for t in requested_by_reflexes(service)]
    live: set[str] = set()
    while pending:
        request = pending.pop()
        if request not in live:
            live.add(request)
            pending.extend(sends(request))
            pending.extend(requested_by_reflexes(request))
    # The executive listens to every module a reflex names as its source: any reply of any of
    # its requests runs an executive cycle (a new start authorisation for every WAIT activity),
    # whether or not the reflex matches it. Without `listened`, those replies are taken to change
    # nothing (which the explorer then checks: `passes_matter`).
    heard = {r.source.partition(".")[0] for r in spec.reflexes if "." in r.source} if listened else set()
    observable = services | {r.source for r in spec.reflexes if r.source in live} | {
        r for r in live if r.partition(".")[0] in heard}
    while True:
        seen = {request.partition(".")[0] for request in observable}
        grown = observable | {r for r in live if r.partition(".")[0] in seen or any(t in observable for t in sends(r))}
        if grown == observable:
            return observable
        observable = grown


def independent_parts(controller: Controller, spec: rx.ExecutiveSpec,
                      modules: Mapping[str, Mapping[str, RequestSpec]]) -> list[tuple[str, ...]]:
    """The services split into parts that share nothing the executive or the modules act on:
    two services are in one part when their requests are in one module (conflicts, a ZOMBIE
    freezing it), when an arc or a group joins them, when a decision for one reads, decides or
    names (changeInterState, sendAbortRequest) what concerns the other (its group's state, the
    service itself), when a request one runs sends (observably) to the other's module, and when
    a reflex on one acts on the other. A call whose argument the analysis cannot name joins
    everything. In spec order."""
    parent: dict[str, str] = {}

    def find(node: str) -> str:
        while parent.setdefault(node, node) != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    def union(a: str, b: str) -> None:
        parent[find(a)] = find(b)

    def node_of(name: str) -> str:
        """A service, else the module of a `module.request`."""
        return f"service {name}" if name in spec.services else f"module {name.partition('.')[0]}"

    everything = "everything"
    for name, service in spec.services.items():
        union(f"service {name}", f"module {service.module}")
        for other in service.conflicts | service.group:
            union(f"service {name}", f"service {other}")
    for attribute, members in spec.groups.items():
        for member in members:
            union(f"group {attribute}", f"service {member}")
    memory = k.initial_memory(controller.base)
    for name, (base, _) in controller.parts().items():
        memory["service"] = frozenset({name})
        touched: set[str] = set()
        for rule in base.rules:
            touched |= mentioned_where(rule, memory)
            for action in rule.actions:
                if not isinstance(action, k.Call):
                    continue
                for arg in action.args:
                    named = arg.attributes()
                    if not named:
                        union(f"service {name}", node_of(str(arg.evaluate({}))))
                    elif any(a.lstrip("@") not in spec.groups for a in named):
                        union(f"service {name}", everything)
        for attribute in touched:
            if attribute.lstrip("@") in spec.groups:
                union(f"service {name}", f"group {attribute.lstrip('@')}")
    observable = observable_requests(spec, modules)
    for module, requests in modules.items():
        for request_name, request in requests.items():
            if f"{module}.{request_name}" in observable:
                for target in request.sends:
                    if target in observable:
                        union(f"module {module}", node_of(target))
    for reflex in spec.reflexes:
        for _, target in reflex.actions:
            union(node_of(reflex.source), node_of(target))
    parts: dict[str, list[str]] = {}
    for name in spec.services:
        parts.setdefault(find(f"service {name}"), []).append(name)
    return [tuple(services) for services in parts.values()]


def explorer_for(program: m.Program, executive: m.Executive, requests: int = 2) -> Explorer:
    controller = executive_controller(program, executive)
    compiled = controller.compile()
    spec = executive_spec(program, controller)
    modules = {name: {r.name: RequestSpec(r.name, r.kind or "exec",
                                          validate=r.validate.text if r.validate is not None else None,
                                          codels={c.state: c.function for c in r.codels},
                                          fail=tuple(x.text for x in r.fail),
                                          incompatible=tuple(x.text for x in r.incompatible_with),
                                          sends=tuple(x.text for x in r.sends))
                      for r in declared.values()}
               for name, declared in symbols_of(program).requests.items()}
    arcs = {(a.source, a.target) for a in controller.graph.arcs}
    return Explorer(spec, decision_function(compiled), modules, arcs, requests,
                    independent_parts(controller, spec, modules))


def verify(program: m.Program, executive: m.Executive, requests: int = 2, limit: int = 200_000,
           progress: Callable[[int], None] | None = None) -> Verification:
    explorer = explorer_for(program, executive, requests)
    graph = build_graph(program, executive)
    arcs = {(a.source, a.target): a.policy for a in graph.arcs}
    result = explorer.explore(limit, progress)
    # A control service takes no time: no arc ends at one, so an arc from one is one-way by
    # nature, not by an entry left out. Of the others, those the exploration saw the target of
    # start while the source ran: the controller's own rules may keep them apart all the same.
    one_way = tuple(sorted((source, policy, target) for (source, target), policy in arcs.items()
                           if source != target and (target, source) not in arcs
                           and source not in graph.control and target not in graph.control
                           and (source, target) in explorer.together))
    never = tuple(name for name, service in explorer.spec.services.items()
                  if not service.control and name not in explorer.started) if result.complete else ()
    return dataclasses.replace(result, one_way=one_way, never_started=never)


def describe(result: Verification) -> Iterator[str]:
    for prop, text in PROPERTIES.items():
        violation = result.violations.get(prop)
        if violation is None:
            verdict = "holds" if result.complete else "holds in the states explored"
            yield f"{prop}: {verdict} - {text}"
            continue
        yield f"{prop}: REFUTED - {text}"
        yield f"  {violation.message}"
        for number, label in enumerate(violation.trace, start=1):
            yield f"  {number:3}. {label}"
    if result.parts:
        yield (f"explored as {len(result.parts)} independent parts (no event of one changes what another does; "
               f"the states counted are theirs, not their products): "
               + " | ".join(", ".join(part) for part in result.parts))
    if result.left_out:
        yield (f"left out of the model, as nothing the requests they send do can reach the executive: "
               f"{'; '.join(result.left_out)}")
    if result.one_way:
        verbs = {"wait": "waits for", "interrupt": "interrupts"}
        said = "; ".join(f"{target} starts while {source} runs ({source} {verbs[policy]} {target}, {target} does "
                         f"not name {source})" for source, policy, target in result.one_way)
        yield (f"conflicts declared one way only, which the states explored show running together (exclusion "
               f"reads them as written): {said}; for two services never to run together, give each a conflict "
               "with the other")
    if result.never_started:
        yield (f"never started, in any state explored: {', '.join(result.never_started)} (every request of it ends "
               "before it runs: refused, timed out or kept waiting); a service no request can run is worth a look")
    if result.limited:
        skipped = (f"; parts not explored at all: {' | '.join(', '.join(part) for part in result.unexplored)}"
                   if result.unexplored else "")
        yield (f"INCOMPLETE: the state limit stopped the exploration at {result.states:,} states (raise "
               f"--max-states){skipped}: what holds, holds only in the states explored")
    if result.cut:
        events = list(dict.fromkeys(result.cut))
        yield (f"INCOMPLETE: {len(events)} event(s) met so many requests to validate codels that not every way "
               f"they may answer was explored ({SEQUENCES_PER_EVENT} at most), the first: {events[0]}: a reaction "
               "loop through them, if `settles` is refuted")
