"""Where a campaign's experiments run: a local pool of processes (the default), or a Dask
distributed cluster. Both run each experiment the same way, in an `ExperimentProcess`: a child
process of their own that runs experiments one after another and is killed, then replaced, when
one overruns its hard timeout (a mutant may make a planner loop for ever, or a mission never end).
The child is long-lived so that an experiment does not pay an interpreter start and the robot's
imports; it is a separate process so that killing it takes nothing else down.

Every engine takes (experiment, domain) pairs and yields each experiment's `Outcome` as it
finishes, in whatever order they finish."""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from multiprocessing.connection import Connection
from typing import Any, Protocol

from specc.campaign.experiments import Experiment, Outcome, Setting, run_experiment
from specc.run import RunError
from specc.runtime.ftplan import planner_processes_kept
from specc.runtime.ftplan.planners import exit_with_parent, start_forkserver_quietly, stop_process
from specc.runtime.planner import model as pm

# forkserver: the parent may run threads (the progress display, the local engine's own), which
# fork must not copy; the experiment process then starts its planners from a forkserver of its own.
START_METHOD = "forkserver"
KILL_GRACE = 2.0  # seconds a timed-out experiment's process has to exit on SIGTERM

Task = tuple[Experiment, pm.PlanningDomain | None]


def _serve(connection: Connection, setting: Setting) -> None:
    """The experiment process: run what the parent sends until it sends None or goes away."""
    start_forkserver_quietly()  # killed mid-way through a planner's start, we leave no traceback behind
    exit_with_parent()  # a killed campaign takes its experiment processes (and their planners) along

    # Planner processes go from one experiment to the next (each builds its planner anew from
    # its own domains): a mission's planners then start warm instead of paying a process start.
    with planner_processes_kept():
        while True:
            try:
                task = connection.recv()
            except EOFError:
                return
            if task is None:
                return
            experiment, domain = task
            connection.send(run_experiment(experiment, domain, setting))


class ExperimentProcess:
    """A child process running one experiment at a time, with a hard timeout per experiment."""

    def __init__(self, setting: Setting, timeout: float) -> None:
        self.setting, self.timeout = setting, timeout
        self.context: Any = multiprocessing.get_context(START_METHOD)
        self.process: Any = None
        self.connection: Connection | None = None

    def _start(self) -> None:
        parent_end, child_end = self.context.Pipe()
        # Not daemonic: the experiment starts planner processes of its own, which a daemonic
        # process may not; it watches its parent instead (_serve).
        self.process = self.context.Process(target=_serve, args=(child_end, self.setting), daemon=False,
                                            name="specc-experiment")
        self.process.start()
        child_end.close()
        self.connection = parent_end

    def run(self, experiment: Experiment, domain: pm.PlanningDomain | None) -> Outcome:
        if self.process is None or not self.process.is_alive():
            self._start()
        assert self.connection is not None
        self.connection.send((experiment, domain))
        if self.connection.poll(self.timeout):
            try:
                outcome: Outcome = self.connection.recv()
                return outcome
            except (EOFError, OSError):
                code = self._stop()
                return Outcome(experiment, "crashed", None, 0.0,
                               f"the experiment's process died (exit code {code})")
        self._stop()
        return Outcome(experiment, "timeout", None, self.timeout,
                       f"overran its hard timeout of {self.timeout:g} s and was killed")

    def _stop(self, ask: bool = False) -> int | None:
        process, connection = self.process, self.connection
        self.process, self.connection = None, None
        if process is None or connection is None:
            return None
        return stop_process(process, connection, KILL_GRACE, ask=ask)

    def close(self) -> None:
        self._stop(ask=self.process is not None and self.process.is_alive())

    def abort(self) -> None:
        """Kill the process now, from another thread than the one running an experiment in it:
        that thread sees the pipe close and returns (a campaign interrupted mid-experiment)."""
        process = self.process
        if process is not None and process.is_alive():
            process.kill()


class Engine(Protocol):
    workers: int

    def run(self, tasks: Iterable[Task]) -> Iterator[Outcome]: ...

    def describe(self) -> str: ...


class LocalEngine:
    """`workers` experiment processes on this machine, each fed by a thread of ours."""

    def __init__(self, setting: Setting, workers: int, timeout: float) -> None:
        if workers < 1:
            raise RunError(f"--workers {workers}: give at least 1")
        self.setting, self.workers, self.timeout = setting, workers, timeout

    def describe(self) -> str:
        return f"local pool of {self.workers} process(es)"

    def run(self, tasks: Iterable[Task]) -> Iterator[Outcome]:
        start_forkserver_quietly()  # interrupted mid-way through an experiment process's start: no traceback
        idle: list[ExperimentProcess] = [ExperimentProcess(self.setting, self.timeout) for _ in range(self.workers)]
        everyone = list(idle)
        lock = threading.Lock()

        def one(task: Task) -> Outcome:
            with lock:
                process = idle.pop()
            try:
                return process.run(*task)
            finally:
                with lock:
                    idle.append(process)

        pending = iter(tasks)
        running: set[Future[Outcome]] = set()
        pool = ThreadPoolExecutor(self.workers, thread_name_prefix="specc-campaign")
        finished = False
        try:
            # Never more submitted than there are processes: an interrupted campaign leaves no
            # queue behind it, and each result is recorded as soon as it exists.
            for task in pending:
                running.add(pool.submit(one, task))
                if len(running) < self.workers:
                    continue
                ended, running = _some_finished(running)
                yield from ended
            while running:
                ended, running = _some_finished(running)
                yield from ended
            finished = True
        finally:
            if not finished:  # interrupted (Ctrl-C, an error recording a result): stop at once
                for future in running:
                    future.cancel()
                for process in everyone:
                    process.abort()  # a busy one's experiment is not recorded: it runs again on resuming
            pool.shutdown(wait=True, cancel_futures=True)
            for process in everyone:
                process.close()


def _some_finished(running: set[Future[Outcome]]) -> tuple[list[Outcome], set[Future[Outcome]]]:
    done, still = wait(running, return_when=FIRST_COMPLETED)
    return [future.result() for future in done], set(still)


# ---------------------------------------------------------------- Dask distributed

_worker_processes = threading.local()  # in a Dask worker: its experiment process, one per thread


def run_in_worker(experiment: Experiment, domain: pm.PlanningDomain | None, setting: Setting,
                  timeout: float) -> Outcome:
    """A Dask task: the experiment in this worker's experiment process (started at its first task)."""
    process = getattr(_worker_processes, "process", None)
    if process is None or (process.setting, process.timeout) != (setting, timeout):
        if process is not None:
            process.close()
        process = _worker_processes.process = ExperimentProcess(setting, timeout)
    result: Outcome = process.run(experiment, domain)
    return result


class DaskEngine:
    """The campaign on Dask distributed: `address` names a running scheduler (tcp://host:8786),
    or "local" starts a cluster of `workers` processes here. The workers must see the compiled
    package and the robot's folder at the same paths as this machine (a shared file system)."""

    def __init__(self, setting: Setting, address: str, workers: int, timeout: float) -> None:
        if address != "local":  # said at once, not when the first experiment is sent
            try:
                from distributed.comm.addressing import parse_address, parse_host_port

                parse_host_port(parse_address(address)[1])
            except ImportError as error:
                raise RunError(f"--scheduler needs dask.distributed ({error})") from None
            except ValueError as error:
                raise RunError(f"--scheduler {address}: {error}; give tcp://HOST:PORT or local") from None
        self.setting, self.address, self.timeout = setting, address, timeout
        self.workers = workers
        self.client: Any = None
        self.cluster: Any = None

    def describe(self) -> str:
        where = f"a local Dask cluster of {self.workers} worker(s)" if self.address == "local" else self.address
        return f"Dask distributed ({where})"

    def _connect(self) -> Any:
        try:
            import dask
            from distributed import Client, LocalCluster
        except ImportError as error:
            raise RunError(f"--scheduler needs dask.distributed ({error})") from None
        # Each experiment starts planner processes, which a daemonic worker process may not.
        dask.config.set({"distributed.worker.daemon": False})
        try:
            if self.address == "local":
                self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                            dashboard_address=None)
                return Client(self.cluster)
            client = Client(self.address, timeout=10)
        except (OSError, TimeoutError, ValueError) as error:  # ValueError: not an address (no port...)
            raise RunError(f"cannot reach the Dask scheduler at {self.address}: {error}; give tcp://HOST:PORT "
                           "or local") from None
        self.workers = max(1, sum(client.nthreads().values()))
        return client

    def run(self, tasks: Iterable[Task]) -> Iterator[Outcome]:
        self.client = self._connect()
        from distributed import as_completed

        futures = []
        try:
            for experiment, domain in tasks:
                futures.append(self.client.submit(run_in_worker, experiment, domain, self.setting, self.timeout,
                                                  key=f"experiment-{experiment.key}", pure=False))
            for future in as_completed(futures):
                yield future.result()
        finally:
            for future in futures:
                future.cancel()
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()
