"""Planner factories faulty on purpose, for FTplan's tests: each is named in a PlannerConfig as
"tests.ftplan_faulty:NAME" and built inside the planner's own process; and the rover's models,
with the seed's mutation 1-592. The module is imported by every planner process that uses one of
its factories: it imports nothing heavy at its top (no pytest, no spec loading)."""

from __future__ import annotations

import ctypes
import os
import time
from collections.abc import Mapping
from dataclasses import replace

from specc.runtime.ftplan.config import PlannerConfig
from specc.runtime.ftplan.planners import SupportsPlan, standard_planner
from specc.runtime.planner import PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner.replan import replanning_problem
from tests.atrv import mutation_1_592, optimistic_speed

SLOW_SECONDS = 1.0
CRASH_EXIT_CODE = 3
RAISED_MESSAGE = "injected fault: the planner's inference failed"


class Hanging:
    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        while True:
            time.sleep(3600)


class HangingAtStart:
    """specc's planner, except that it hangs on the mission's first planning (now == 0): a fault
    that a restart and a replanning from a later state get past."""

    def __init__(self, planner: SupportsPlan) -> None:
        self.planner = planner

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        if now == 0.0:
            Hanging().plan(problem, now)
        return self.planner.plan(problem, now)


class Crashing:
    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        os._exit(CRASH_EXIT_CODE)


class Segfaulting:
    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        ctypes.string_at(0)  # reads address 0: SIGSEGV
        raise AssertionError("unreachable")


class Raising:
    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        raise RuntimeError(RAISED_MESSAGE)


class Slow:
    """specc's planner, answering SLOW_SECONDS late."""

    def __init__(self, planner: SupportsPlan) -> None:
        self.planner = planner

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        time.sleep(SLOW_SECONDS)
        return self.planner.plan(problem, now)


class Goalless:
    """Plans the problem without its goals: a valid-looking plan of another problem, that meets
    none of the mission's goals (only the plan analyzer or the goal checks can tell)."""

    def __init__(self, planner: SupportsPlan) -> None:
        self.planner = planner

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        return self.planner.plan(replanning_problem(problem, (), (), now), now)


def hanging_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Hanging:
    return Hanging()


def hanging_at_start_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> HangingAtStart:
    return HangingAtStart(standard_planner(config, domains))


def crashing_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Crashing:
    return Crashing()


def segfaulting_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Segfaulting:
    return Segfaulting()


def raising_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Raising:
    return Raising()


def slow_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Slow:
    return Slow(standard_planner(config, domains))


def goalless_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> Goalless:
    return Goalless(standard_planner(config, domains))


def mutation_1_592_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> SupportsPlan:
    """specc's planner on the configured domain with mutation 1-592: valid-looking, wrong plans."""
    return standard_planner(config, {**domains, config.domain: mutation_1_592(domains[config.domain])})


def failing_factory(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> SupportsPlan:
    raise OSError("injected fault: the planner's model files cannot be read")


def optimistic_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> SupportsPlan:
    """specc's planner on a Modele1 ten times too fast: its moves overrun their planned durations."""
    return standard_planner(config, {**domains, config.domain: optimistic_speed(domains[config.domain])})


class SilentlyDropping:
    """Plans without the communication goals and says nothing: the plan claims to keep every
    goal, and only the goal check when it ends finds them open."""

    def __init__(self, planner: SupportsPlan) -> None:
        self.planner = planner

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        kept = replace(problem, assertions=tuple(a for a in problem.assertions
                                                 if a.goal is None or getattr(a, "attribute", "") != "COMMUNICATION"))
        result = self.planner.plan(kept, now)
        return replace(result, goals=tuple(g for g in result.goals if g.kept))


def silently_dropping_planner(config: PlannerConfig, domains: Mapping[str, pm.PlanningDomain]) -> SilentlyDropping:
    return SilentlyDropping(standard_planner(config, domains))
