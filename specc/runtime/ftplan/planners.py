"""FTplan's planners, each in its own OS process, and the planning watchdog (seed 004 §3.1.1,
§3.2.2.2 "Le chien de garde temporel").

A planner that hangs, loops or dies must not take FTplan with it, and FTplan must be able to
stop it at any instant: so every planner runs in a child process of its own, which FTplan kills
and restarts when the watchdog fires (as the prototype kills and relaunches the late IxTeT).

    with PlannerProcess(config, domains) as planner:
        watchdog = Watchdog()
        watchdog.arm(ftplan.watchdog)
        planner.request(problem, now)
        answer = planner.poll(watchdog.remaining())
        if answer is None:            # the watchdog fired: the planner is late
            planner.restart()

What crosses to the child is plain data: the planner's `PlannerConfig` and the planning
domains (`pm.PlanningDomain`, frozen dataclasses; about 10 kB pickled for the rover's Modele1),
sent on its pipe before anything else, then one `pm.Problem` per request; a `PlanResult` comes
back. Passing the domain objects rather
than the name of the generated package to import spares the child any sys.path set-up, and lets
tests and tools plan domains that were never generated. `planning_domains(DOMAINS)` turns a
generated `planner` package's `DOMAINS` into that mapping.

The factory. `PlannerConfig.factory` names, as "module:callable", a callable that the child
calls once at start, as `factory(config, domains)` with `domains` the mapping name ->
`pm.PlanningDomain` given to `PlannerProcess`, and that returns an object with
`plan(problem, now) -> PlanResult` (`SupportsPlan`). A factory that raises leaves the process up,
answering every request with that error, so a bad configuration reads as any other planner
failure; `wait_ready()` reports it at once to whoever wants to know before the mission.

Start method: "forkserver". `fork` is the fastest (a planner ready in 6-10 ms), but FTplan's
process runs threads (the executive, the simulator) and forking a threaded process can deadlock
the child on a lock held by a thread that does not exist in it. "spawn" is safe but starts a
fresh interpreter per planner and imports the planner anew each time: 0.3-0.5 s on every
restart, measured here. "forkserver" forks each planner from a server that has already imported
the planner (`PRELOAD`): as safe (the server runs no thread of ours; numpy's OpenBLAS pool
there handles fork itself), and a planner is ready in about 20 ms once the server is up, which
costs one interpreter start (about 0.4 s) on the first planner of the program. The forkserver
is one per program, shared by every user of that start method; if it is already running, our
preload is not applied and children import the planner themselves (slower, still correct). As
with "spawn", the program's main module is imported again in each child: scripts that start
planners keep their top level under `if __name__ == "__main__":`. What that main module imports
is mostly specc (`specc` itself: its command line imports the whole compiler), so the server
also imports the modules of specc the program has imported by the time it starts: a child's
main module then imports nothing anew, where it took 0.3-0.5 s in each planner's start (each
restart of a planner FTplan gives up on included).

Many missions in one program (a campaign's worker): within `planner_processes_kept()`, a
planner process closed idle is kept for the next PlannerProcess, which builds its own planner
there; the planner's warming up (what it works out once per task, CasADi's solves among it)
then serves the next missions too.

No zombies, no orphans: `kill()` joins what it killed; the processes are daemonic, so
multiprocessing terminates them at interpreter exit; and each child watches its parent (a
thread waiting on the parent's sentinel) and exits at once when FTplan dies, even mid-planning.
"""

from __future__ import annotations

import contextlib
import importlib
import itertools
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from types import ModuleType, TracebackType
from typing import Final, Literal, Protocol

from specc.runtime.ftplan.config import FLAW_ORDERS, HEURISTICS, PlannerConfig
from specc.runtime.planner import Planner, PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner.heuristics import NEWEST_TASK_FIRST, STANDARD
from specc.runtime.planner.plan import Repair

START_METHOD: Final = "forkserver"
# Imported once by the forkserver, so that a planner's process starts without importing them;
# then the modules of specc the program has imported (`forkserver_preload`). Not casadi (0.1-0.2 s):
# the planner imports it only for a task whose duration enclosure is not exact, which no mission
# of the examples has (specc.runtime.planner.numeric.exact_duration).
PRELOAD = ["specc.runtime.planner", "specc.runtime.ftplan.planners"]
KILL_GRACE = 1.0  # seconds a planner has to exit on SIGTERM before it gets SIGKILL


class SupportsPlan(Protocol):
    """What a factory builds: a planner answering one planning request at a time."""

    def plan(self, problem: pm.Problem, now: float) -> PlanResult: ...


PlannerFactory = Callable[[PlannerConfig, Mapping[str, pm.PlanningDomain]], SupportsPlan]


_CLOSED = object()  # what reading a pipe whose other end is closed gives


class PlannerStartError(RuntimeError):
    """The planner's process could not build its planner, or died before saying it had."""


def standard_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Planner:
    """specc's temporal planner on the domain `config` names: the default factory."""
    if config.heuristic is not None and config.heuristic not in HEURISTICS:
        known = ", ".join(sorted(HEURISTICS)) or "none yet: leave the heuristic out"
        raise ValueError(f"planner '{config.name}': specc's planner has no heuristic '{config.heuristic}' "
                         f"(known: {known})")
    if config.flaws is not None and config.flaws not in FLAW_ORDERS:
        raise ValueError(f"planner '{config.name}': specc's planner has no flaw order '{config.flaws}' "
                         f"(known: {', '.join(sorted(FLAW_ORDERS))})")
    if config.domain not in domains:
        raise ValueError(f"planner '{config.name}': no planning domain '{config.domain}' "
                         f"(given: {', '.join(sorted(domains)) or 'none'})")
    return Planner(domains[config.domain], controllability=config.controllability, node_limit=config.node_limit,
                   heuristic=config.heuristic or STANDARD, improve=config.improve,
                   flaws=config.flaws or NEWEST_TASK_FIRST)


def planning_domains(generated: Mapping[str, ModuleType]) -> dict[str, pm.PlanningDomain]:
    """The domains of a generated `planner` package's `DOMAINS` (name -> module with `.DOMAIN`)."""
    return {name: module.DOMAIN for name, module in generated.items()}


def factory_parts(reference: str) -> tuple[str, str]:
    """The module and the (maybe dotted) callable "module:callable" names."""
    module_name, colon, attribute = reference.partition(":")
    if not colon or not module_name or not attribute:
        raise ValueError(f"factory '{reference}' is not 'module:callable'")
    return module_name, attribute


def load_factory(reference: str) -> PlannerFactory:
    """The callable "module:callable" names (the callable may be dotted: "module:Class.build")."""
    module_name, attribute = factory_parts(reference)
    target: object = importlib.import_module(module_name)
    for part in attribute.split("."):
        target = getattr(target, part)
    if not callable(target):
        raise TypeError(f"planner factory '{reference}' is not callable")
    return target  # type: ignore[return-value]


# ---------------------------------------------------------------- the watchdog

class Watchdog:
    """The planning watchdog: a budget of planning seconds that runs out.

    Successive planning arms it for each request and disarms it on the answer (Fig 3.1 lines 8,
    12). Concurrent planning arms it once for all the planners and pauses it while FTplan
    analyses a plan, so that the analysis is not charged to the planners (Fig 3.2 lines 4, 10,
    17). The clock is injectable so that tests are deterministic; by default it is monotonic
    wall time, which setting the system clock does not move.
    """

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._budget: float | None = None  # None: disarmed
        self._spent = 0.0  # seconds counted before the current run (pauses stop the count)
        self._running_since: float | None = None  # None: paused (or disarmed)

    def arm(self, seconds: float) -> None:
        if seconds < 0:
            raise ValueError(f"a watchdog is armed for a duration >= 0, not {seconds}")
        self._budget, self._spent, self._running_since = seconds, 0.0, self._clock()

    def pause(self) -> None:
        if self._running_since is not None:
            self._spent += self._clock() - self._running_since
            self._running_since = None

    def resume(self) -> None:
        if self._budget is not None and self._running_since is None:
            self._running_since = self._clock()

    def disarm(self) -> None:
        self._budget, self._spent, self._running_since = None, 0.0, None

    @property
    def armed(self) -> bool:
        return self._budget is not None

    @property
    def paused(self) -> bool:
        return self._budget is not None and self._running_since is None

    def elapsed(self) -> float:
        """Seconds counted since `arm`, pauses excluded."""
        running = 0.0 if self._running_since is None else self._clock() - self._running_since
        return self._spent + running

    def remaining(self) -> float | None:
        """Seconds left before the watchdog fires (0 once it has), None when disarmed: what to
        give `poll` or `first_answer` as their timeout."""
        if self._budget is None:
            return None
        return max(0.0, self._budget - self.elapsed())

    def expired(self) -> bool:
        remaining = self.remaining()
        return remaining is not None and remaining <= 0.0


# ---------------------------------------------------------------- messages

@dataclass(frozen=True)
class _Request:
    id: int
    problem: pm.Problem
    now: float
    repair: Repair | None = None  # a repair request: the plan and its actions still to carry out


@dataclass(frozen=True)
class _Build:
    """Build the planner to serve the requests that follow (the process's first message, and the
    first for each PlannerProcess that takes a kept process)."""

    config: PlannerConfig
    domains: Mapping[str, pm.PlanningDomain]


@dataclass(frozen=True)
class _Started:
    error: str  # "": the planner is built; else why it could not be (every request gets it back)


@dataclass(frozen=True)
class _Reply:
    id: int
    result: PlanResult | None
    error: str  # "Type: message" of what the planner raised ("" when it answered)
    detail: str  # its traceback
    seconds: float  # the planning as the child timed it


Status = Literal["answered", "raised", "crashed"]


@dataclass(frozen=True)
class Answer:
    """How one planning request ended.

    answered: the planner returned a PlanResult (with a plan or with why there is none);
    raised: the planner raised, and `error` / `detail` say what and where;
    crashed: the process died (os._exit, a signal, ...), `exitcode` says how (negative: -signal).
    """

    planner: str
    request: int
    status: Status
    result: PlanResult | None
    seconds: float  # wall time from the request to the answer, as FTplan saw it
    planner_seconds: float = 0.0  # the planning alone, as the child timed it
    error: str = ""
    detail: str = ""
    exitcode: int | None = None

    @property
    def nodes(self) -> int:
        """Partial plans the search expanded: the deterministic measure of planning effort."""
        return self.result.nodes if self.result is not None else 0

    @property
    def failed(self) -> bool:
        return self.status != "answered"


def answer_request(planner: SupportsPlan, problem: pm.Problem, now: float,
                   repair: Repair | None) -> PlanResult:
    """A planning request's answer; with `repair`, a repair request's, which a planner without
    a `repair` method (a factory's own) refuses with a result that says so."""
    if repair is None:
        return planner.plan(problem, now)
    repairing = getattr(planner, "repair", None)
    if repairing is None:
        return PlanResult(None, reason=f"{type(planner).__name__} does not repair plans (it has no `repair` method)")
    result: PlanResult = repairing(problem, now, repair)
    return result


def _exit_description(exitcode: int | None) -> str:
    if exitcode is None:
        return "died"
    if exitcode < 0:
        try:
            return f"killed by signal {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exited with code {exitcode}"


def _describe(error: BaseException) -> str:
    return f"{type(error).__name__}: {error}"


# ---------------------------------------------------------------- the child

def exit_with_parent() -> None:
    """End this process as soon as its parent is gone, even in the middle of its work: a planner
    must not outlive FTplan, nor a campaign's experiment process its campaign (nobody would ever
    kill them)."""
    parent = multiprocessing.parent_process()
    if parent is None or parent.sentinel is None:
        return
    sentinel = parent.sentinel

    def watch() -> None:
        wait([sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def _serve(connection: Connection) -> None:
    """The planner's process: build the planner, then answer requests until told to stop; build
    another when told to (a kept process serving its next PlannerProcess). Whatever the planner
    raises is sent back rather than ending the process silently."""
    exit_with_parent()
    # Ctrl-C reaches the whole process group: FTplan, not the terminal, decides when planners stop.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    planner: SupportsPlan | None = None
    startup_error = ""
    domains: Mapping[str, pm.PlanningDomain] = {}
    while True:
        try:
            request = connection.recv()
        except (EOFError, OSError):  # FTplan closed its end, or is gone: nothing more to plan
            return
        if request is None:
            return
        if isinstance(request, _Build):
            config, domains = request.config, _same_objects(request.domains, domains)
            planner, startup_error = None, ""
            try:
                planner = load_factory(config.factory)(config, domains)
            except Exception as error:
                startup_error = f"building planner '{config.name}' with {config.factory} failed: {_describe(error)}"
            try:
                connection.send(_Started(startup_error))
            except OSError:  # FTplan is gone (killed mid-mission): nobody to tell
                return
            continue
        started = time.perf_counter()
        try:
            if planner is None:
                raise PlannerStartError(startup_error)
            result = answer_request(planner, request.problem, request.now, request.repair)
            if not isinstance(result, PlanResult):
                raise TypeError(f"the planner returned a {type(result).__name__}, not a PlanResult")
            reply = _Reply(request.id, result, "", "", time.perf_counter() - started)
        except Exception as error:
            reply = _Reply(request.id, None, _describe(error), traceback.format_exc(), time.perf_counter() - started)
        try:
            connection.send(reply)
        except OSError:  # FTplan is gone (killed mid-mission): nobody to answer
            return
        except Exception as error:  # the result does not pickle: say so rather than die
            connection.send(_Reply(request.id, None, f"the answer could not be sent: {_describe(error)}",
                                   traceback.format_exc(), reply.seconds))


def _same_objects(domains: Mapping[str, pm.PlanningDomain],
                  before: Mapping[str, pm.PlanningDomain]) -> dict[str, pm.PlanningDomain]:
    """`domains`, each one equal to the domain of its name `before` replaced by that one: the
    planner caches what it works out per task by the task's identity, so a kept process planning
    the same domain again (every mission of a campaign but the mutant's) finds it worked out."""
    return {name: before[name] if name in before and before[name] == domain else domain
            for name, domain in domains.items()}


# ---------------------------------------------------------------- the parent's handle

class PlannerProcess:
    """One planner in its own OS process, one request at a time.

    `request` sends a problem without waiting; `poll(timeout)` returns the `Answer` or None when
    the timeout passes first (the caller's watchdog then decides); `kill` stops the process,
    `restart` kills and starts it again (the planner is built anew), `abandon` drops a request
    under way (Fig 3.2 line 13: the planner cannot be interrupted mid-search, so it is
    restarted). Use it as a context manager, or call `close()`; from one thread.
    """

    _ids = itertools.count(1)  # request ids, unique in FTplan's process

    def __init__(self, config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain], *,
                 kill_grace: float = KILL_GRACE) -> None:
        try:
            factory_parts(config.factory)  # a typo is told now, not by the child
        except ValueError as error:
            raise ValueError(f"planner '{config.name}': {error}") from None
        self.config = config
        self.domains = dict(domains)
        self.kill_grace = kill_grace
        self._process: multiprocessing.process.BaseProcess | None = None
        self._connection: Connection | None = None
        self._started = False  # the child said it is ready
        self._startup_error = ""
        self._pending: _Request | None = None
        self._sent_at = 0.0
        self.started_at = 0.0  # perf_counter() at the last start
        self.startup_seconds: float | None = None  # from start to the child's ready message

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def pid(self) -> int | None:
        return self._process.pid if self._process is not None else None

    @property
    def running(self) -> bool:
        return self._process is not None and self._process.is_alive()

    @property
    def busy(self) -> bool:
        """A request is under way (sent, not answered)."""
        return self._pending is not None

    def __repr__(self) -> str:
        return f"PlannerProcess({self.name!r}, pid={self.pid}, busy={self.busy})"

    # ------------------------------------------------------------ life cycle
    def start(self) -> None:
        """Start the process (or take a kept one, see `planner_processes_kept`); does not wait
        for the planner to be built (see `wait_ready`)."""
        if self._process is not None:
            raise RuntimeError(f"planner '{self.name}' is already started (restart() it)")
        self.started_at = time.perf_counter()
        kept = _kept.take() if _kept is not None else None
        process, connection = kept if kept is not None else _launch()
        process.name = f"ftplan-planner-{self.name}"
        try:
            connection.send(_Build(self.config, self.domains))
        except OSError:
            pass  # the process is dead: wait_ready() or poll() report it
        self._process, self._connection = process, connection
        self._started, self._startup_error, self.startup_seconds = False, "", None

    def wait_ready(self, timeout: float | None = None) -> None:
        """Block until the planner is built; raise PlannerStartError if it could not be (bad
        factory, unknown domain or heuristic) or the process died, TimeoutError if it is late."""
        process, connection = self._require_started()
        deadline = None if timeout is None else time.perf_counter() + timeout
        while not self._started:
            if not wait([connection, process.sentinel], _left(deadline)):
                raise TimeoutError(f"planner '{self.name}' not ready within {timeout} s")
            message = self._read(connection)
            if not self._take_started(message) and (message is _CLOSED or not process.is_alive()):
                self._reap(process)
                raise PlannerStartError(f"planner '{self.name}' {_exit_description(process.exitcode)} "
                                        f"before it was ready")
        if self._startup_error:
            raise PlannerStartError(self._startup_error)

    def kill(self) -> None:
        """Stop the process (SIGTERM, then SIGKILL after `kill_grace`) and reap it. Any request
        under way is dropped. Does nothing if the process is not started."""
        process, connection = self._process, self._connection
        self._process, self._connection, self._pending, self._started = None, None, None, False
        if process is not None and connection is not None:
            stop_process(process, connection, self.kill_grace, ask=False)

    def restart(self) -> None:
        self.kill()
        self.start()

    def abandon(self) -> None:
        """Drop the request under way, if any: the planner is restarted to stop its search."""
        if self._pending is not None:
            self.restart()

    def close(self) -> None:
        """Ask the planner to stop, give it `kill_grace` to do so, then kill it; while processes
        are kept (`planner_processes_kept`), keep it instead if it is built and idle."""
        process, connection = self._process, self._connection
        if process is None or connection is None or self._pending is not None or not process.is_alive():
            self.kill()
            return
        # Built, even if nobody waited for it to be (a planner restarted and not asked since).
        kept = _kept is not None and (self._started or self._take_started(self._read(connection)))
        self._process, self._connection, self._started = None, None, False
        if kept:
            assert _kept is not None
            _kept.keep(process, connection)
        else:
            stop_process(process, connection, self.kill_grace, ask=True)

    def __enter__(self) -> PlannerProcess:
        if self._process is None:
            self.start()
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self.close()

    # ------------------------------------------------------------ planning
    def request(self, problem: pm.Problem, now: float = 0.0, repair: Repair | None = None) -> int:
        """Send a planning request (with `repair`, a repair request) and return its id, without
        waiting for the answer."""
        _, connection = self._require_started()
        if self._pending is not None:
            raise RuntimeError(f"planner '{self.name}' is still planning request {self._pending.id}: "
                               f"poll() its answer or abandon() it first")
        request = _Request(next(self._ids), problem, now, repair)
        self._pending, self._sent_at = request, time.perf_counter()
        try:
            connection.send(request)
        except OSError:
            pass  # the process is dead: poll() reports it as crashed
        return request.id

    def poll(self, timeout: float | None = 0.0) -> Answer | None:
        """The answer to the request under way, waiting at most `timeout` seconds for it (None:
        as long as it takes); None if it has not come by then, or if no request is under way."""
        if self._pending is None:
            return None
        process, connection = self._require_started()
        deadline = None if timeout is None else time.perf_counter() + timeout
        while True:
            ready = wait([connection, process.sentinel], _left(deadline))
            if not ready:
                return None
            # A dying child may have written its answer first: read the pipe before the sentinel.
            answer = self._receive(process, connection)
            if answer is not None:
                return answer

    def handles(self) -> list[Connection | int]:
        """What `multiprocessing.connection.wait` may wait on for this planner's next event."""
        if self._process is None or self._connection is None:
            return []
        return [self._connection, self._process.sentinel]

    # ------------------------------------------------------------ internals
    def _require_started(self) -> tuple[multiprocessing.process.BaseProcess, Connection]:
        if self._process is None or self._connection is None:
            raise RuntimeError(f"planner '{self.name}' is not started")
        return self._process, self._connection

    @staticmethod
    def _read(connection: Connection) -> object | None:
        """The child's next message if one is there, None if none is, _CLOSED if the child's end
        of the pipe is closed (it died: its exit code follows on its sentinel)."""
        try:
            return connection.recv() if connection.poll() else None
        except (EOFError, OSError):
            return _CLOSED

    def _take_started(self, message: object | None) -> bool:
        if not isinstance(message, _Started):
            return False
        self._started, self._startup_error = True, message.error
        self.startup_seconds = time.perf_counter() - self.started_at
        return True

    def _receive(self, process: multiprocessing.process.BaseProcess, connection: Connection) -> Answer | None:
        """Consume one event: the child's message, or its death. An Answer when it ends the
        request under way; None for anything else (the ready message, nothing yet)."""
        pending = self._pending
        assert pending is not None
        message = self._read(connection)
        if self._take_started(message):
            return None
        seconds = time.perf_counter() - self._sent_at
        if isinstance(message, _Reply) and message.id == pending.id:
            self._pending = None
            status: Status = "answered" if message.result is not None else "raised"
            return Answer(self.name, pending.id, status, message.result, seconds, message.seconds,
                          message.error, message.detail)
        if message is not _CLOSED and process.is_alive():
            return None
        self._reap(process)
        self._pending = None
        exitcode = process.exitcode
        return Answer(self.name, pending.id, "crashed", None, seconds, error=f"the planner's process "
                      f"{_exit_description(exitcode)}", exitcode=exitcode)

    def _reap(self, process: multiprocessing.process.BaseProcess) -> None:
        """Join a process whose pipe closed, so that it is no zombie and its exit code is known;
        one that closed its pipe and lives on is of no use and is killed."""
        process.join(self.kill_grace)
        if process.is_alive():
            process.kill()
            process.join()


def forkserver_preload() -> list[str]:
    """What the forkserver imports before it forks a planner: PRELOAD, then the modules of specc
    this program has imported, in the order they were (that of sys.modules), so that the child's
    import of the program's main module finds them imported (see the module's docstring)."""
    return PRELOAD + [name for name in list(sys.modules) if name == "specc" or name.startswith("specc.")]


_forkserver_quiet = False


def start_forkserver_quietly() -> None:
    """Start this program's forkserver (with the planner preloaded) with its stderr on /dev/null.
    The forkserver prints a traceback when a client dies in the middle of asking it for a child,
    as a campaign's experiment processes do when the campaign is interrupted; the children it
    forks inherit that stderr too, so only programs whose children report through their pipes
    call this (a campaign and its experiment processes)."""
    global _forkserver_quiet
    if _forkserver_quiet:
        return
    from multiprocessing import forkserver, resource_tracker

    multiprocessing.get_context(START_METHOD).set_forkserver_preload(forkserver_preload())
    resource_tracker.ensure_running()  # before the redirection: its warnings keep the program's stderr
    sys.stderr.flush()
    saved, devnull = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        forkserver.ensure_running()
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    _forkserver_quiet = True


def _launch() -> tuple[multiprocessing.process.BaseProcess, Connection]:
    """A new planner process, waiting for its first `_Build`."""
    context = multiprocessing.get_context(START_METHOD)
    context.set_forkserver_preload(forkserver_preload())
    ours, theirs = context.Pipe(duplex=True)
    process = context.Process(target=_serve, args=(theirs,), name="ftplan-planner", daemon=True)
    try:
        process.start()
    except BaseException:
        ours.close()
        raise
    finally:
        theirs.close()  # the child has its own copy: ours closed, its death reads as EOF here
    return process, ours


def stop_process(process: multiprocessing.process.BaseProcess, connection: Connection, grace: float, *,
                 ask: bool) -> int | None:
    """End a child serving requests on `connection` (a planner's, a campaign's experiment process)
    and reap it: asked to exit first when `ask` (it must be idle: None is its signal to stop),
    then SIGTERM, then SIGKILL, `grace` seconds apart. Its exit code."""
    if ask:
        try:
            connection.send(None)
        except OSError:
            pass  # already gone
        process.join(grace)
    connection.close()
    if process.is_alive():
        process.terminate()
        process.join(grace)
        if process.is_alive():
            process.kill()
    process.join()
    code = process.exitcode
    process.close()
    return code


class _KeptProcesses:
    """Planner processes idle between two PlannerProcesses (`planner_processes_kept`)."""

    def __init__(self) -> None:
        self._idle: list[tuple[multiprocessing.process.BaseProcess, Connection]] = []

    def keep(self, process: multiprocessing.process.BaseProcess, connection: Connection) -> None:
        self._idle.append((process, connection))

    def take(self) -> tuple[multiprocessing.process.BaseProcess, Connection] | None:
        """A kept process still alive with nothing unread on its pipe (else it is of no use)."""
        while self._idle:
            process, connection = self._idle.pop()
            if process.is_alive() and not connection.poll():
                return process, connection
            stop_process(process, connection, KILL_GRACE, ask=False)
        return None

    def close(self) -> None:
        while self._idle:
            stop_process(*self._idle.pop(), KILL_GRACE, ask=True)


_kept: _KeptProcesses | None = None  # processes are kept while planner_processes_kept() runs


@contextlib.contextmanager
def planner_processes_kept() -> Iterator[None]:
    """Within it, a planner process that `PlannerProcess.close` finds built and idle is kept,
    and the next PlannerProcess to start takes it (with its own configuration and domains)
    rather than starting a process: a program running missions one after another (a campaign's
    worker) pays a process start and the planner's warming up (what it works out once per
    task and keeps: about 0.3 s of a mission's first planning) once rather than per mission.
    Isolation holds where FTplan needs it: a planner it gives up on (`kill`, `restart`,
    `abandon`) or that is busy or dead at `close` is still killed, and each PlannerProcess
    builds its planner anew. The processes kept are stopped on leaving; nested, the outermost
    one keeps them. One thread."""
    global _kept
    if _kept is not None:
        yield
        return
    _kept = _KeptProcesses()
    try:
        yield
    finally:
        kept, _kept = _kept, None
        kept.close()


def _left(deadline: float | None) -> float | None:
    return None if deadline is None else max(0.0, deadline - time.perf_counter())


def first_answer(processes: Iterable[PlannerProcess], timeout: float | None) -> tuple[PlannerProcess, Answer] | None:
    """The first answer among the planners with a request under way (concurrent planning), or
    None if none comes within `timeout` seconds (None: wait as long as it takes). Answers already
    there are taken in the order `processes` gives, so a tie goes to the preferred planner."""
    waiting = [p for p in processes if p.busy]
    if not waiting:
        raise ValueError("no planner has a request under way")
    deadline = None if timeout is None else time.perf_counter() + timeout
    while True:
        for process in waiting:
            answer = process.poll(0.0)
            if answer is not None:
                return process, answer
        left = _left(deadline)
        if left is not None and left <= 0.0:
            return None
        wait([handle for p in waiting for handle in p.handles()], left)
