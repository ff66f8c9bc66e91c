"""FTplan's plans carried out on the simulated robot's kernel, in mission time.

`KernelExecutor` is FTplan's `Executor` (`specc.runtime.ftplan.execution`) for any robot: the
actions of a plan start at their dispatch dates, or when the actions the plan orders before them
end; those the plan lets overlap run together on the kernel. Temporal execution control (seed 004
§3.2.2.2, IxTeT's): an action still running at its start plus its planned longest duration has
failed, and is stopped. The first action to fail ends the execution; `safe_state` then stops
whatever still runs and lets the robot come to rest. How one action is carried out is a
subclass's: `BoundExecutor` does it as the system block's `bindings` say,

- `TASK(?a) => goal G(?a)`: the supervisor is given `!(G a)`; the action ends when the goal
  succeeds, fails when it fails (seed 004 §4.1.1: OpenPRS procedures carry out IxTeT's actions);
- `=> service S(?a)`: the executive runs S with those inputs; its success (OK, or whatever its
  output function returns) ends the action, any other reply fails it;
- `=> request module.R(?a)`: the module request itself, as the functional level answers it.

What the log holds: every `action` as it starts and as it ends, fails or is stopped (`status`,
`plan`, `id`, `task`, `args`, `latest_end` at its start, `why`, and how it was carried out:
`goal`, `service` or `request` at its start, and at its end `requests`: the ids of the executive's
requests that carried it out).
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from specc.run.recording import Emit
from specc.runtime import executive as rx
from specc.runtime import functional as rt
from specc.runtime.ftplan.component import MissionFailure
from specc.runtime.ftplan.config import FtPlanConfig, Var
from specc.runtime.ftplan.execution import OVERRUN_TOLERANCE, Execution, Precedences, Report
from specc.runtime.ftplan.facts import FactKey, match, substitute
from specc.runtime.ftplan.state import consequences
from specc.runtime.ftplan.view import View
from specc.runtime.planner.plan import Action, Plan, Value, format_call, format_value
from specc.runtime.planner.validate import normalise, same
from specc.runtime.system import BindingSpec, StateCondition, StateValue

# An action whose plan gives it no finite longest duration is stopped after this long: a faulty
# model's action must not run for ever.
UNBOUNDED_ACTION_LIMIT = 600.0
SETTLE_LIMIT = 5.0  # s the robot is given to come to rest once everything was stopped
STILL_SPEED = 1e-3  # m/s at the wheel rims: slower than this, the robot stands still


@dataclass
class Running:
    """An action under way."""

    plan: int
    action: Action
    started: float
    deadline: float  # its start plus its planned longest duration
    finished: float | None = None  # when it ended or failed
    ok: bool = False
    why: str = ""
    kind: str = ""  # how it is carried out (a subclass's word: goal, service, request...)
    handle: Any = None  # what carries it out
    said: dict[str, Any] = field(default_factory=dict)  # what the log says of how it runs


class HorizonReached(MissionFailure):
    """The run's horizon came before FTplan's mission ended: what ran was stopped, and FTplan's
    mission ends there (it catches this as its mission exception)."""


class KernelExecutor(abc.ABC):
    """The scheduling of a plan's actions on the kernel (see the module's docstring); subclasses
    say how one action is begun, followed, interrupted, and how the robot comes to rest. Nothing
    runs past `horizon` (mission time): the actions under way are stopped there and HorizonReached
    ends FTplan's mission."""

    def __init__(self, kernel: Any, emit: Emit | None = None, horizon: float = math.inf) -> None:
        self.kernel = kernel
        self.emit = emit
        self.horizon = horizon
        self.horizon_reached = False
        self.plans = 0
        self._live: list[Running] = []  # actions under way, also after a failure ended the execution

    # ------------------------------------------------------------ what a subclass provides
    @abc.abstractmethod
    def begin(self, run: Running, plan: Plan) -> None:
        """Start carrying `run.action` out; set `run.finished` (and `run.why`) if it cannot be."""

    @abc.abstractmethod
    def advance(self, run: Running) -> bool:
        """Follow the action: set `finished`, `ok` and `why` when it is over; True then."""

    @abc.abstractmethod
    def interrupt(self, run: Running) -> None:
        """Stop what carries the action out (it has overrun, or the system goes to a safe state)."""

    @abc.abstractmethod
    def wind_down(self, failed: Running) -> None:
        """Wait for what was interrupted to end once `failed` failed (the others go on)."""

    @abc.abstractmethod
    def come_to_rest(self) -> None:
        """Wait for what was interrupted to end and for the robot to stand still (a safe state)."""

    def reports(self, run: Running) -> list[Report]:
        """What FTplan hears when the action is over: its end or its failure."""
        status = "ended" if run.ok else "failed"
        now = run.finished if run.ok and run.finished is not None else self.kernel.now
        return [Report(status, run.action.task, run.action.args, now, run.action.id, "" if run.ok else run.why)]

    # ------------------------------------------------------------ Executor
    def execute(self, plan: Plan, now: float, report: Callable[[Report], None]) -> Execution:
        self.plans += 1
        number = self.plans
        self.catch_up(now)
        self._check_horizon()
        precedences = Precedences(plan)
        waiting = plan.ordered()
        ended_at: dict[str, float] = {}
        while True:
            for run in sorted((r for r in self._live if r.finished is not None), key=lambda r: (r.finished, r.started)):
                self._live.remove(run)
                self._conclude(run, report)
                if not run.ok:
                    return Execution(False, self.kernel.now, run.action.id, run.why)
                assert run.finished is not None
                ended_at[run.action.id] = run.finished
            now = self.kernel.now
            dates = [(date, a) for a in waiting if (date := precedences.start_date(a, ended_at, now)) is not None]
            for date, action in sorted(dates, key=lambda d: (d[0], d[1].dispatch, d[1].id)):
                if date <= now + OVERRUN_TOLERANCE:
                    waiting.remove(action)
                    self._start(number, plan, action, report)
            if not waiting and not self._live:
                return Execution(True, self.kernel.now)
            if any(r.finished is not None for r in self._live):
                continue  # an action that ended as it started (a control request)
            upcoming = [date for date, action in dates if action in waiting]
            if not upcoming and not self._live:  # an ordering no action ends: the plan is malformed
                stuck = ", ".join(a.text() for a in waiting)
                return Execution(False, now, waiting[0].id, f"{stuck} wait for actions that never end")
            self.await_progress(min(upcoming + [r.deadline for r in self._live] + [self.horizon]))
            self._check_horizon()
            for run in self._live:
                if run.finished is None and self.kernel.now >= run.deadline - OVERRUN_TOLERANCE:
                    self._overrun(run)

    def _check_horizon(self) -> None:
        """At the horizon: stop what runs and end FTplan's mission."""
        if self.kernel.now < self.horizon - OVERRUN_TOLERANCE:
            return
        self.horizon_reached = True
        why = f"the run's horizon ({self.horizon:g} s) was reached"
        for run in list(self._live):
            self._live.remove(run)
            if run.finished is None:
                self.interrupt(run)
            self.record(run, "stopped", f"stopped: {why}")
        raise HorizonReached(why, self.kernel.now)

    def safe_state(self, now: float) -> float:
        """Interrupt everything still running for the plan, and wait for the robot to stand and
        what was interrupted to end."""
        self.catch_up(now)
        for run in list(self._live):  # what ran beside the failed action: FTplan hears no more of it
            self._live.remove(run)
            if run.finished is not None:
                self.record(run, "ended" if run.ok else "failed", run.why, run.finished)
            else:
                self.interrupt(run)
                self.record(run, "stopped", "stopped: the system was brought to a safe state")
        self.come_to_rest()
        return self.kernel.now

    def await_progress(self, wake: float) -> None:
        """Run the kernel until an action under way is over, or until `wake` (an action's
        dispatch date or deadline)."""
        self.kernel.run_while(self.nothing_over, wake)

    def nothing_over(self) -> bool:
        """After each kernel event: False once an action under way is over."""
        return not any([self.advance(r) for r in self._live if r.finished is None])

    # ------------------------------------------------------------ one action
    def _start(self, number: int, plan: Plan, action: Action, report: Callable[[Report], None]) -> None:
        now = self.kernel.now
        longest = action.duration[1] if math.isfinite(action.duration[1]) else UNBOUNDED_ACTION_LIMIT
        run = Running(number, action, now, now + longest)
        report(Report("started", action.task, action.args, now, action.id))
        self.begin(run, plan)
        self.event(now, "action", status="started", plan=number, id=action.id, task=action.task,
                   args=list(action.args), latest_end=round(run.deadline, 6), **run.said)
        self._live.append(run)
        if run.finished is None:
            self.advance(run)

    def _overrun(self, run: Running) -> None:
        low, high = run.action.duration
        run.finished = self.kernel.now
        run.why = (f"{run.action.text()} overran its planned duration [{low:.3g}, {high:.3g}] s: still running "
                   f"{self.kernel.now - run.started:.3g} s after it started")
        self.interrupt(run)

    def _conclude(self, run: Running, report: Callable[[Report], None]) -> None:
        if not run.ok:
            self.wind_down(run)
        for said in self.reports(run):
            report(said)
        now = run.finished if run.ok and run.finished is not None else self.kernel.now
        self.record(run, "ended" if run.ok else "failed", run.why, now)

    def record(self, run: Running, outcome: str, why: str, end: float | None = None) -> None:
        end = self.kernel.now if end is None else end
        action = run.action
        self.event(end, "action", status=outcome, plan=run.plan, id=action.id, task=action.task,
                   args=list(action.args), **({"why": why} if why else {}), **self.carried_out_by(run))

    def carried_out_by(self, run: Running) -> dict[str, Any]:
        """What the log says, at the action's end, of what carried it out (a subclass's)."""
        return {}

    def catch_up(self, now: float) -> None:
        """The kernel at mission time `now`: time FTplan spent planning passes for the robot too
        (up to the horizon: the run stops there)."""
        if now > self.kernel.now:
            self.kernel.run_until(min(now, self.horizon))

    def event(self, time_: float, kind: str, **fields: Any) -> None:
        if self.emit is not None:
            self.emit(time_, kind, **fields)


class FtplanJournal:
    """A run's log while FTplan runs: FTplan's own events (kind `ftplan`: plan requests, plans,
    watchdogs, failures...) forwarded in mission-time order among everything else logged. FTplan
    notes a plan's execution at the end of its planning time, before the kernel (and its pose
    samples) has caught up with it."""

    def __init__(self, log: Any) -> None:
        self.log = log  # an EventLog
        self.ftplan: Any = None  # the FtPlan whose events are forwarded, once it exists
        self._forwarded = 0
        # Called before each event is logged: what changed unseen (the procedures' facts) is logged
        # first, at its time, whoever logs next (an action's end, a request, a pose sample).
        self.before_each: list[Callable[[], None]] = []

    @property
    def events(self) -> list[dict[str, Any]]:
        events: list[dict[str, Any]] = self.log.events
        return events

    def emit(self, time_: float, kind: str, **fields: Any) -> dict[str, Any]:
        for before in self.before_each:
            before()
        self.catch_up(time_)
        event: dict[str, Any] = self.log.emit(time_, kind, **fields)
        return event

    def catch_up(self, until: float = math.inf) -> None:
        """Forward FTplan's events up to `until`."""
        if self.ftplan is None:
            return
        events = self.ftplan.events
        while self._forwarded < len(events) and events[self._forwarded].time <= until:
            event = events[self._forwarded]
            self.log.emit(event.time, "ftplan", event=event.kind, text=event.text,
                          **({"planner": event.planner} if event.planner else {}))
            self._forwarded += 1


def run_ftplan(setup: Any, executor: KernelExecutor, journal: FtplanJournal, timing: str) -> tuple[Any, Any]:
    """FTplan on the mission `setup` (specc.runtime.ftplan.MissionSetup) with its configuration's
    planners, each in its own process, `executor` carrying its plans out; then the safe state
    (nothing runs past the plan's end). The FtPlan and its MissionResult."""
    from specc.runtime.ftplan import HUNG_PLANNER_SECONDS, FtPlan, ProcessPool, planners_as_run

    with ProcessPool(planners_as_run(setup.config, timing), setup.domains) as pool:
        ftplan = FtPlan(setup.config, setup.problem, pool, executor, timing=timing, problems=setup.problems,
                        wall_limit=HUNG_PLANNER_SECONDS if timing == "model" else None)
        journal.ftplan = ftplan
        result = ftplan.run()
    journal.catch_up()
    executor.safe_state(result.now)  # the robot idles to the mission's last instant
    return ftplan, result


@dataclass(frozen=True)
class Call:
    """What a binding makes of one action: the goal, service or request and its arguments."""

    kind: str
    target: str
    args: tuple[Value, ...]

    def text(self) -> str:
        args = " ".join(format_value(a) for a in self.args)
        if self.kind == "goal":
            return f"!({self.target}{' ' + args if args else ''})"
        return format_call(self.target, self.args)


def bound_call(binding: BindingSpec, action: Action, after: Callable[[], Mapping[FactKey, Value]]) -> Call:
    """The call `binding` makes of `action`; `after()` gives FTplan's state changes when the action
    ends (for `ATTR(...)` arguments). ValueError when the action's arguments do not fit."""
    found = match(binding.args, action.args)
    if found is None:
        raise ValueError(f"{action.text()} does not match the binding of {binding.task}"
                         f"({', '.join(_term_text(a) for a in binding.args)})")
    if binding.where is not None:
        found = _where(binding.where, found, action, after())
    values: list[Value] = []
    for arg in binding.target_args:
        if isinstance(arg, StateValue):
            key = (arg.attribute, tuple(substitute(a, found) for a in arg.args))
            changes = after()
            if key not in changes:
                raise ValueError(f"FTplan's state rules do not say what {arg.attribute}"
                                 f"({', '.join(format_value(v) for v in key[1])}) becomes when {action.text()} ends")
            values.append(changes[key])
        else:
            values.append(substitute(arg, found))
    return Call(binding.kind, binding.target, tuple(values))


def _where(condition: StateCondition, found: Mapping[str, Value], action: Action,
           changes: Mapping[FactKey, Value]) -> dict[str, Value]:
    """`found` extended by the first state change at the action's end that reads
    `condition` (in the state rules' order); ValueError when none does."""
    for (attribute, args), value in changes.items():
        if attribute != condition.attribute or not same(normalise(value), normalise(substitute(condition.value,
                                                                                                 found))):
            continue
        extended = match(condition.args, args, dict(found))
        if extended is not None:
            return extended
    pattern = ", ".join(_term_text(a) for a in condition.args)
    raise ValueError(f"FTplan's state rules make no {condition.attribute}({pattern}) "
                     f"{_term_text(condition.value)} when {action.text()} ends")


def _term_text(term: Any) -> str:
    return term.name if isinstance(term, Var) else format_value(term)


class BoundExecutor(KernelExecutor):
    """Each action carried out as the system's bindings say (see the module's docstring)."""

    def __init__(self, kernel: Any, bindings: Mapping[str, BindingSpec], registry: rt.Registry,
                 executive: rx.Executive | None, supervisor: Any, robot: Any, config: FtPlanConfig,
                 emit: Emit | None = None, horizon: float = math.inf) -> None:
        super().__init__(kernel, emit, horizon)
        self.bindings = bindings
        self.config = config  # FTplan's on the mission: its state rules and its planners' views
        self.registry = registry
        self.executive = executive
        self.supervisor = supervisor
        self.robot = robot  # the simulated body: the wheels' speeds say when it stands still
        self._replies: dict[int, rx.Message] = {}  # the executive's replies to our requests, by id
        self._stopping: list[Running] = []  # interrupted, not yet over
        if executive is not None:
            executive.listeners.append(self._message)

    def _message(self, message: rx.Message) -> None:
        if message.kind == "REPLY":
            self._replies[message.id] = message

    # ------------------------------------------------------------ carrying an action out
    def begin(self, run: Running, plan: Plan) -> None:
        action = run.action
        binding = self.bindings.get(action.task)
        try:
            if binding is None:
                raise ValueError(f"the system binds no way to carry out task {action.task}")
            call = bound_call(binding, action, lambda: self.effects(plan, action))
        except ValueError as error:
            run.finished, run.why = run.started, f"{action.text()} cannot be carried out: {error}"
            return
        run.kind = call.kind
        run.said[call.kind] = call.text()
        if call.kind == "goal":
            run.handle = self.supervisor.post(call.text())
        elif call.kind == "service":
            assert self.executive is not None  # the checks: a service binding needs an executive
            run.handle = self.executive.request(call.target, None, call.args)
        else:
            module, _, request = call.target.partition(".")
            run.handle = _ModuleCall(self.registry.modules[module], request, call.args)

    def advance(self, run: Running) -> bool:
        if run.finished is not None:
            return True
        kind = run.kind
        if kind == "goal":
            status = run.handle.status
            if status == "running":
                return False
            run.ok = status == "succeeded"
            run.why = "" if run.ok else f"{run.action.text()} failed: {run.said['goal']} {status}" \
                                        f"{self._refused(run.handle.requests)}"
        elif kind == "service":
            reply = self._replies.pop(run.handle, None)
            if reply is None:
                return False
            run.ok = reply.ok
            detail = f" ({reply.detail})" if reply.detail else ""
            run.why = "" if run.ok else f"{run.action.text()} failed: {run.said['service']} answered " \
                                        f"{reply.result}{detail}"
        else:
            reply = run.handle.reply
            if reply is None:
                return False
            run.ok = reply.ok
            detail = f" ({reply.report.detail})" if reply.report.detail else ""
            run.why = "" if run.ok else f"{run.action.text()} failed: {run.said['request']} -> " \
                                        f"{reply.status.value} {reply.report.code}{detail}"
        run.finished = self.kernel.now
        return True

    def carried_out_by(self, run: Running) -> dict[str, Any]:
        """The executive's request ids that carried the action out: those its goal's procedures
        asked for, or its service's (the log's `request` events with those ids name the module
        request each ran)."""
        if run.kind == "goal" and run.handle is not None:
            return {"requests": list(run.handle.requests)}
        if run.kind == "service" and run.handle is not None:
            return {"requests": [run.handle]}
        return {}

    def _refused(self, requests: Iterable[int]) -> str:
        """The last failure the services a goal's procedures asked for replied: most likely what
        they failed on."""
        replies = [self._replies[i] for i in requests if i in self._replies and not self._replies[i].ok]
        if not replies:
            return ""
        reply = replies[-1]
        detail = f" ({reply.detail})" if reply.detail else ""
        return f" ({reply.service} answered {reply.result}{detail})"

    def effects(self, plan: Plan, action: Action) -> dict[FactKey, Value]:
        """What FTplan's state becomes when the action ends, in FTplan's vocabulary (through the
        view of the planner whose model made the plan)."""
        planner = next((p for p in self.config.planners if p.domain == plan.domain), None)
        view = View(planner.view) if planner is not None and planner.view else None
        return dict(consequences(self.config.state_rules, "ended", action.task, action.args, view))

    def reports(self, run: Running) -> list[Report]:
        """The binding's report (posters read now), then the action's end or failure."""
        said = super().reports(run)
        binding = self.bindings.get(run.action.task)
        if binding is not None and binding.report is not None:
            try:
                values = tuple(self._read(path) for path in binding.report.paths)
            except (ValueError, AttributeError) as error:  # FTplan goes on without it; the log says so
                self.event(self.kernel.now, "alarm", what="report", detail=f"{binding.report.name}: {error}")
            else:
                said.insert(0, Report("report", binding.report.name, values, said[0].time, run.action.id))
        return said

    def _read(self, path: str) -> Value:
        """A poster's field, `module.Poster.field.subfield` (a number or a word)."""
        module, poster, *fields = path.split(".")
        snapshot = self.registry.read_poster(f"{module}.{poster}")
        if snapshot is None:
            raise ValueError(f"poster {module}.{poster} has not been written yet: nothing to report")
        value: Any = snapshot.data
        for name in fields:
            value = getattr(value, name)
        return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else str(value)

    def interrupt(self, run: Running) -> None:
        if run.kind == "goal":
            self.supervisor.abandon(run.handle, run.why or "stopped")  # it interrupts the services it asked for
        elif run.kind == "service" and self.executive is not None:
            self.executive.interrupt(run.handle)
        elif run.kind == "request":
            run.handle.abort()
        self._stopping.append(run)

    def _still_running(self, run: Running) -> bool:
        """What carries `run` out has not ended yet (after it was interrupted)."""
        live = self.executive.activities if self.executive is not None else {}
        if run.kind == "goal":
            return any(ident in live for ident in run.handle.requests)
        if run.kind == "service":
            return run.handle in live
        if run.kind == "request":
            return bool(run.handle.reply is None)
        return False

    def wind_down(self, failed: Running) -> None:
        """What was interrupted ends and the robot comes to rest before FTplan hears of the failure
        (a report then says where the robot stands), unless other actions still run: they go on."""
        others = any(r.finished is None for r in self._live)
        busy = (lambda: any(self._still_running(r) for r in self._stopping)) if others else self._busy
        self.kernel.run_while(busy, self.kernel.now + SETTLE_LIMIT)
        self._stopping = [r for r in self._stopping if self._still_running(r)]

    def come_to_rest(self) -> None:
        self.kernel.run_while(self._busy, self.kernel.now + SETTLE_LIMIT)
        self._stopping.clear()

    def _busy(self) -> bool:
        moving = abs(self.robot.left_speed) + abs(self.robot.right_speed) > STILL_SPEED
        return moving or any(self._still_running(r) for r in self._stopping)


class _ModuleCall:
    """A module request sent for an action, and its final reply when it comes."""

    def __init__(self, module: rt.Module, request: str, args: tuple[Value, ...]) -> None:
        self.module = module
        spec = module.spec.requests[request]
        fields = [f[0] for f in getattr(spec.input_type, "__specc_fields__", ())]
        value = rt.build_record(spec.input_type, dict(zip(fields, args, strict=True))) \
            if spec.input_type is not None else None
        self.reply: rt.Reply | None = None
        self.id = module.submit(request, value, self._replied)

    def _replied(self, reply: rt.Reply) -> None:
        if reply.final:
            self.reply = reply

    def abort(self) -> None:
        if self.reply is None:
            self.module.abort(self.id)
