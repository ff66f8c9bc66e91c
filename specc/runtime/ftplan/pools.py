"""The planners FTplan drives, behind one interface (`component.PlannerPool`):

- `ProcessPool`: each planner in its own OS process (`planners.PlannerProcess`), killed and
  restarted when FTplan gives up on it: the independence FTplan needs (seed 004 §3.2.2.1);
- `LocalPool`: the planners in FTplan's process, each request answered at once. Nothing can
  stop a planner that hangs there: it serves scripted tests of the recovery algorithms and
  tools that plan without fault tolerance.
"""

from __future__ import annotations

import contextlib
import time
import traceback
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

from specc.runtime.ftplan.config import PlannerConfig
from specc.runtime.ftplan.planners import (
    Answer,
    PlannerProcess,
    PlannerStartError,
    SupportsPlan,
    answer_request,
    first_answer,
)
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Repair

READY_TIMEOUT = 60.0  # wall seconds a planner may take to start


class ProcessPool:
    def __init__(self, planners: Collection[PlannerConfig], domains: Mapping[str, pm.PlanningDomain],
                 ready_timeout: float = READY_TIMEOUT) -> None:
        self.processes = {config.name: PlannerProcess(config, domains) for config in planners}
        self.names = tuple(self.processes)
        for process in self.processes.values():
            process.start()
        # FTplan launches its planners before the mission (§3.2.2.2), so that their start-up is
        # not counted in the first planning's time. A planner that cannot be built (or is slow to)
        # still answers every request with why (or late): FTplan sees that as any other planner
        # failure, so it is not told here.
        for process in self.processes.values():
            with contextlib.suppress(PlannerStartError, TimeoutError):
                process.wait_ready(ready_timeout)

    def request(self, name: str, problem: pm.Problem, now: float, repair: Repair | None = None) -> None:
        self.processes[name].request(problem, now, repair)

    def next_answer(self, names: Collection[str], wall_timeout: float) -> Answer | None:
        waiting = [self.processes[n] for n in names if self.processes[n].busy]
        if not waiting:
            return None
        found = first_answer(waiting, wall_timeout)
        return None if found is None else found[1]

    def abandon(self, name: str) -> None:
        # Whether it is planning, crashed, or answered without a plan: a planner FTplan gives up
        # on is killed and relaunched (§3.2.2.2), so that it starts the next request afresh.
        self.processes[name].restart()

    def close(self) -> None:
        for process in self.processes.values():
            process.close()

    def __enter__(self) -> ProcessPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass
class LocalPool:
    planners: Mapping[str, SupportsPlan]
    abandoned: list[str] = field(default_factory=list)  # planners FTplan gave up on, in order

    def __post_init__(self) -> None:
        self.names = tuple(self.planners)
        self._answers: dict[str, Answer] = {}
        self._requests = 0

    def request(self, name: str, problem: pm.Problem, now: float, repair: Repair | None = None) -> None:
        self._requests += 1
        started = time.perf_counter()
        try:
            result = answer_request(self.planners[name], problem, now, repair)
        except Exception as error:  # a planner's fault is an answer, as in its own process
            self._answers[name] = Answer(name, self._requests, "raised", None, time.perf_counter() - started,
                                         error=f"{type(error).__name__}: {error}",
                                         detail=traceback.format_exc(limit=3))
            return
        seconds = time.perf_counter() - started
        self._answers[name] = Answer(name, self._requests, "answered", result, seconds, seconds)

    def next_answer(self, names: Collection[str], wall_timeout: float) -> Answer | None:
        for name in names:  # in the order asked: the preferred planner first
            if name in self._answers:
                return self._answers.pop(name)
        return None

    def abandon(self, name: str) -> None:
        self._answers.pop(name, None)
        self.abandoned.append(name)

    def close(self) -> None:
        self._answers.clear()
