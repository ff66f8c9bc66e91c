"""FTplan's planners in their own processes and the planning watchdog (seed 004 §3.2.2.2): real
processes, planners faulty on purpose (tests/ftplan_faulty.py)."""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest

from specc.runtime.ftplan import CostModel, FtPlan, LocalPool, ScriptedExecutor, planners_as_run
from specc.runtime.ftplan.config import FtPlanConfig, PlannerConfig
from specc.runtime.ftplan.planners import (
    Answer,
    PlannerProcess,
    PlannerStartError,
    Watchdog,
    first_answer,
    planner_processes_kept,
    standard_planner,
)
from specc.runtime.planner import Planner
from specc.runtime.planner import model as pm
from tests import ftplan_faulty
from tests.atrv import atrv_models, mutation_1_592

ROOT = Path(__file__).resolve().parent.parent
WATCHDOG = 0.5  # seconds: the planners here answer M1 in about 0.3 s, or never
ANSWER_TIMEOUT = 30.0  # only a broken test waits this long


def faulty(name: str, factory: str) -> PlannerConfig:
    return PlannerConfig(name, "model1", factory=f"tests.ftplan_faulty:{factory}")


@pytest.fixture(scope="module")
def mission() -> tuple[pm.PlanningDomain, pm.Problem]:
    return atrv_models("M1_model1")


@pytest.fixture(scope="module")
def domains(mission: tuple[pm.PlanningDomain, pm.Problem]) -> dict[str, pm.PlanningDomain]:
    return {mission[0].name: mission[0]}


@pytest.fixture()
def problem(mission: tuple[pm.PlanningDomain, pm.Problem]) -> pm.Problem:
    return mission[1]


@pytest.fixture(autouse=True)
def no_planner_left() -> Iterator[None]:
    yield
    left = [p for p in multiprocessing.active_children() if p.name.startswith("ftplan-planner-")]
    assert not left, f"planner processes left behind: {left}"


def charged(answer: Answer, problem: pm.Problem, timing: str = "model", cost: CostModel | None = None) -> float:
    """The mission time FTplan charges for the planning that gave `answer`."""
    config = FtPlanConfig("ftplan", (PlannerConfig("ixtet1", "model1"),))
    ftplan = FtPlan(config, problem, LocalPool({}), ScriptedExecutor(), timing=timing, cost=cost or CostModel())
    return ftplan.charge(answer)


def gone(pid: int) -> bool:
    """The process no longer runs (a zombie nobody reaps, outside our reach, counts as gone)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return True
    return state == "Z"


def wait_gone(pid: int, seconds: float = 5.0) -> bool:
    deadline = time.monotonic() + seconds
    while not gone(pid):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.05)
    return True


# ---------------------------------------------------------------- the watchdog

class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_watchdog_counts_down_and_pauses_while_a_plan_is_analysed() -> None:
    clock = FakeClock()
    watchdog = Watchdog(clock)
    assert not watchdog.armed and watchdog.remaining() is None and not watchdog.expired()
    watchdog.arm(10.0)
    clock.now += 4.0
    assert watchdog.remaining() == 6.0
    watchdog.pause()  # Fig 3.2 line 10: the analysis of a plan is not planning time
    clock.now += 100.0
    assert watchdog.paused and watchdog.remaining() == 6.0 and not watchdog.expired()
    watchdog.resume()  # line 17: the plan was invalid, the other planners go on
    clock.now += 5.0
    assert watchdog.elapsed() == 9.0 and watchdog.remaining() == 1.0 and not watchdog.expired()
    clock.now += 1.0
    assert watchdog.expired() and watchdog.remaining() == 0.0
    watchdog.arm(2.0)  # re-arming starts afresh
    assert watchdog.remaining() == 2.0 and not watchdog.paused
    watchdog.disarm()
    clock.now += 50.0
    assert not watchdog.expired() and watchdog.remaining() is None
    watchdog.resume()  # a disarmed watchdog stays disarmed
    assert not watchdog.armed
    with pytest.raises(ValueError, match=">= 0"):
        watchdog.arm(-1.0)


def test_watchdog_runs_on_wall_time_by_default() -> None:
    watchdog = Watchdog()
    watchdog.arm(0.05)
    assert not watchdog.expired()
    time.sleep(0.06)
    assert watchdog.expired()


# ---------------------------------------------------------------- the standard planner

def test_standard_planner_refuses_an_unknown_heuristic_or_domain(domains: dict[str, pm.PlanningDomain]) -> None:
    assert isinstance(standard_planner(PlannerConfig("ixtet1", "model1"), domains), Planner)
    with pytest.raises(ValueError, match="planner 'ixtet1': specc's planner has no heuristic 'astar'"):
        standard_planner(PlannerConfig("ixtet1", "model1", heuristic="astar"), domains)
    with pytest.raises(ValueError, match="no planning domain 'model9' \\(given: model1\\)"):
        standard_planner(PlannerConfig("ixtet1", "model9"), domains)


def test_standard_planner_in_its_process_plans_as_in_process(
        mission: tuple[pm.PlanningDomain, pm.Problem], domains: dict[str, pm.PlanningDomain]) -> None:
    domain, problem = mission
    expected = Planner(domain).plan(problem, now=0.0)
    with PlannerProcess(PlannerConfig("ixtet1", "model1"), domains) as planner:
        planner.wait_ready(ANSWER_TIMEOUT)
        assert planner.running and planner.pid != os.getpid() and planner.startup_seconds is not None
        request = planner.request(problem, 0.0)
        assert planner.busy
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and not planner.busy
        assert (answer.planner, answer.request, answer.status, answer.failed) == ("ixtet1", request, "answered", False)
        assert answer.result is not None and expected.plan is not None
        assert answer.result.plan == expected.plan
        assert answer.result.goals == expected.goals and answer.nodes == expected.nodes > 0
        # Time accounting: the wall time FTplan saw covers the planning the child timed.
        assert answer.seconds >= answer.planner_seconds > 0
        assert charged(answer, problem, timing="wall") == answer.seconds
        assert charged(answer, problem, cost=CostModel(base=0.0, per_node=0.01)) == pytest.approx(0.01 * expected.nodes)
        assert planner.poll(0.0) is None  # nothing under way any more
    assert not planner.running and planner.pid is None


def test_a_node_limit_stops_the_planning_once_passed_and_changes_nothing_below_it(
        mission: tuple[pm.PlanningDomain, pm.Problem]) -> None:
    domain, problem = mission
    free = Planner(domain).plan(problem, now=0.0)
    assert free.plan is not None and free.nodes > 2
    enough = Planner(domain, node_limit=free.nodes).plan(problem, now=0.0)
    assert enough.plan == free.plan and enough.goals == free.goals and enough.nodes == free.nodes
    # One partial plan short: it stops on the one that passes the limit, the last one it needed.
    short = Planner(domain, node_limit=free.nodes - 1).plan(problem, now=0.0)
    assert short.plan is None and short.nodes == free.nodes
    assert f"limit of {free.nodes - 1} partial plans" in short.reason


def test_under_the_cost_model_planners_stop_where_the_watchdog_would_find_them_late(
        mission: tuple[pm.PlanningDomain, pm.Problem], domains: dict[str, pm.PlanningDomain]) -> None:
    cost = CostModel()
    assert cost.nodes_within(10.0) == 800 and cost.charge(800) <= 10.0 < cost.charge(801)
    assert CostModel(base=2.0, per_node=0.3).nodes_within(10.0) == 26  # 9.8 s; 27 would be 10.1 s
    assert cost.nodes_within(1.0) == 0
    config = FtPlanConfig("ftplan", (PlannerConfig("ixtet1", "model1"), PlannerConfig("ixtet2", "model1")),
                          watchdog=3.0)
    assert [p.node_limit for p in planners_as_run(config, "model")] == [100, 100]
    assert planners_as_run(config, "wall") == config.planners  # the wall-clock watchdog stops them
    # The limit reaches the planner in its own process: a late answer, whatever the machine's speed.
    domain, problem = mission
    needed = Planner(domain).plan(problem, now=0.0).nodes
    limited = replace(PlannerConfig("ixtet1", "model1"), node_limit=needed - 1)
    with PlannerProcess(limited, domains) as planner:
        planner.request(problem, 0.0)
        answer = planner.poll(ANSWER_TIMEOUT)
    assert answer is not None and answer.result is not None
    assert answer.result.plan is None and answer.nodes == needed
    assert charged(answer, problem, cost=CostModel(base=0.0, per_node=1.0)) > needed - 1


def test_a_bad_configuration_is_reported_at_start_and_on_every_request(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with pytest.raises(ValueError, match="not 'module:callable'"):
        PlannerProcess(PlannerConfig("ixtet1", "model1", factory="nowhere"), domains)
    with PlannerProcess(PlannerConfig("ixtet1", "model1", heuristic="astar"), domains) as planner:
        with pytest.raises(PlannerStartError, match="no heuristic 'astar'"):
            planner.wait_ready(ANSWER_TIMEOUT)
    with PlannerProcess(faulty("broken", "failing_factory"), domains) as planner:
        planner.request(problem)
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and answer.status == "raised"
        assert "building planner 'broken' with tests.ftplan_faulty:failing_factory failed" in answer.error
        assert "model files cannot be read" in answer.error
        assert planner.running  # a planner that cannot plan still answers: it is FTplan's to replace


# ---------------------------------------------------------------- faults

def test_a_hanging_planner_is_caught_by_the_watchdog_killed_and_restarted(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    watchdog = Watchdog()
    with PlannerProcess(faulty("hangs", "hanging_at_start_planner"), domains) as planner:
        planner.wait_ready(ANSWER_TIMEOUT)
        watchdog.arm(WATCHDOG)
        planner.request(problem, now=0.0)
        with pytest.raises(RuntimeError, match="still planning"):
            planner.request(problem, now=0.0)
        assert planner.poll(watchdog.remaining()) is None
        assert watchdog.expired()
        hung = planner.pid
        assert hung is not None
        planner.restart()
        assert gone(hung), "the hung planner still runs"
        assert hung not in [p.pid for p in multiprocessing.active_children()]
        assert planner.pid != hung and not planner.busy
        # The restarted planner answers a replanning from a later state.
        watchdog.arm(ANSWER_TIMEOUT)
        planner.request(problem, now=1.0)
        answer = planner.poll(watchdog.remaining())
        assert answer is not None and answer.status == "answered"
        assert answer.result is not None and answer.result.ok and answer.nodes > 0
        watchdog.disarm()


def test_abandon_restarts_a_planner_only_if_it_is_planning(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with PlannerProcess(faulty("hangs", "hanging_planner"), domains) as planner:
        idle = planner.pid
        planner.abandon()
        assert planner.pid == idle
        planner.request(problem)
        planner.abandon()  # Fig 3.2 line 13
        assert planner.pid != idle and not planner.busy and wait_gone(idle or 0)


def test_a_crashing_planner_is_reported_with_its_exit_code_and_restarts(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with PlannerProcess(faulty("crashes", "crashing_planner"), domains) as planner:
        planner.request(problem)
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and answer.status == "crashed" and answer.failed
        assert answer.exitcode == ftplan_faulty.CRASH_EXIT_CODE
        assert answer.error == f"the planner's process exited with code {ftplan_faulty.CRASH_EXIT_CODE}"
        assert answer.result is None and answer.nodes == 0 and not planner.busy
        crashed = planner.pid
        assert not planner.running and crashed is not None and gone(crashed)
        planner.restart()
        planner.wait_ready(ANSWER_TIMEOUT)
        assert planner.running and planner.pid != crashed


def test_a_segfault_is_reported_as_a_crash(domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with PlannerProcess(faulty("segfaults", "segfaulting_planner"), domains) as planner:
        planner.request(problem)
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and answer.status == "crashed"
        assert answer.exitcode == -signal.SIGSEGV
        assert answer.error == "the planner's process killed by signal SIGSEGV"


def test_an_exception_in_the_planner_is_reported_and_the_process_lives_on(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with PlannerProcess(faulty("raises", "raising_planner"), domains) as planner:
        for _ in range(2):
            planner.request(problem)
            answer = planner.poll(ANSWER_TIMEOUT)
            assert answer is not None and answer.status == "raised" and answer.exitcode is None
            assert answer.error == f"RuntimeError: {ftplan_faulty.RAISED_MESSAGE}"
            assert "ftplan_faulty.py" in answer.detail and "raise RuntimeError" in answer.detail
            assert planner.running


def test_a_valid_looking_plan_of_another_problem_is_an_answer(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    """The process layer cannot tell a wrong plan: that is the analyzer's and the goal checks' job."""
    with PlannerProcess(faulty("goalless", "goalless_planner"), domains) as planner:
        planner.request(problem)
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and answer.status == "answered"
        assert answer.result is not None and answer.result.plan is not None
        assert answer.result.plan.problem != problem.name and answer.result.goals == ()


def test_a_mutated_model_plans_in_its_process(
        mission: tuple[pm.PlanningDomain, pm.Problem], domains: dict[str, pm.PlanningDomain]) -> None:
    domain, problem = mission
    expected = Planner(mutation_1_592(domain)).plan(problem)
    with PlannerProcess(faulty("mutant", "mutation_1_592_planner"), domains) as planner:
        planner.request(problem)
        answer = planner.poll(ANSWER_TIMEOUT)
        assert answer is not None and answer.status == "answered" and answer.result is not None
        assert answer.result.plan is not None and answer.result.plan == expected.plan


# ---------------------------------------------------------------- concurrent planning

def test_first_answer_is_the_fastest_planners(domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    slow = PlannerProcess(faulty("slow", "slow_planner"), domains)
    fast = PlannerProcess(PlannerConfig("fast", "model1"), domains)
    hangs = PlannerProcess(faulty("hangs", "hanging_planner"), domains)
    with slow, fast, hangs:
        with pytest.raises(ValueError, match="no planner has a request under way"):
            first_answer([slow, fast, hangs], 0.0)
        watchdog = Watchdog()
        watchdog.arm(ftplan_faulty.SLOW_SECONDS + 3.0)
        for planner in (slow, fast, hangs):  # the slow one first: order must not decide
            planner.request(problem)
        first = first_answer([slow, fast, hangs], watchdog.remaining())
        assert first is not None and first[0] is fast and first[1].status == "answered"
        watchdog.pause()  # the plan is analysed (found invalid, say), then the others go on
        watchdog.resume()
        second = first_answer([slow, fast, hangs], watchdog.remaining())
        assert second is not None and second[0] is slow and second[1].seconds >= ftplan_faulty.SLOW_SECONDS
        assert second[1].result is not None and second[1].result.plan == first[1].result.plan  # type: ignore[union-attr]
        assert first_answer([slow, fast, hangs], 0.2) is None  # only the hanging one is left
        assert hangs.busy
        pids = [p.pid for p in (slow, fast, hangs)]
    assert all(pid is not None and gone(pid) for pid in pids)


# ---------------------------------------------------------------- processes kept from one mission to the next

def test_kept_processes_serve_the_next_planners_each_built_anew(
        mission: tuple[pm.PlanningDomain, pm.Problem], domains: dict[str, pm.PlanningDomain]) -> None:
    domain, problem = mission
    expected = Planner(domain).plan(problem, now=0.0)
    with planner_processes_kept():
        with PlannerProcess(PlannerConfig("ixtet1", "model1"), domains) as first:
            first.wait_ready(ANSWER_TIMEOUT)
            pid = first.pid
        assert pid is not None and not gone(pid) and first.pid is None  # kept, idle
        # The next planner takes it with its own configuration, a bad one included ...
        with PlannerProcess(PlannerConfig("other", "model1", heuristic="astar"), domains) as second:
            assert second.pid == pid
            with pytest.raises(PlannerStartError, match="planner 'other': .* no heuristic 'astar'"):
                second.wait_ready(ANSWER_TIMEOUT)
        # ... and the one after it plans as a planner in a process of its own does.
        with PlannerProcess(PlannerConfig("third", "model1"), domains) as third:
            assert third.pid == pid
            third.request(problem, 0.0)
            answer = third.poll(ANSWER_TIMEOUT)
            assert answer is not None and answer.status == "answered" and answer.planner == "third"
            assert answer.result is not None and answer.result.plan == expected.plan
        assert [p.pid for p in multiprocessing.active_children()] == [pid]
    assert wait_gone(pid) and multiprocessing.active_children() == []


def test_kept_processes_never_keep_a_planner_ftplan_gave_up_on(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with planner_processes_kept():
        with PlannerProcess(faulty("hangs", "hanging_planner"), domains) as planner:
            planner.wait_ready(ANSWER_TIMEOUT)
            hung = planner.pid
            planner.request(problem)
            planner.abandon()  # killed, and a process started for it again
            assert hung is not None and wait_gone(hung) and planner.pid != hung
            busy = planner.pid
            planner.request(problem)
        assert busy is not None and wait_gone(busy)  # busy when closed: killed, not kept
        with PlannerProcess(faulty("crashes", "crashing_planner"), domains) as crashing:
            crashing.request(problem)
            answer = crashing.poll(ANSWER_TIMEOUT)
            assert answer is not None and answer.status == "crashed"
        assert multiprocessing.active_children() == []


# ---------------------------------------------------------------- no process left behind

def test_kill_leaves_no_process_behind(domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    planner = PlannerProcess(faulty("hangs", "hanging_planner"), domains, kill_grace=0.2)
    planner.start()
    planner.request(problem)
    assert planner.poll(0.1) is None
    pid = planner.pid
    assert pid is not None and pid in [p.pid for p in multiprocessing.active_children()]
    planner.kill()
    assert gone(pid) and pid not in [p.pid for p in multiprocessing.active_children()]
    planner.kill()  # twice is harmless
    planner.close()


def test_a_planner_dies_with_an_exception_in_the_with_block(
        domains: dict[str, pm.PlanningDomain], problem: pm.Problem) -> None:
    with pytest.raises(KeyError), PlannerProcess(faulty("hangs", "hanging_planner"), domains) as planner:
        planner.request(problem)
        pid = planner.pid
        raise KeyError("FTplan failed")
    assert pid is not None and gone(pid)


@pytest.mark.parametrize("ending", ["returns", "os._exit"])
def test_a_planner_does_not_outlive_ftplan(ending: str, tmp_path: Path) -> None:
    """FTplan ends (normally, or abruptly: no cleanup at all) while a planner hangs: the planner
    goes too, and no orphan is left."""
    end = "os._exit(0)" if ending == "os._exit" else "pass"
    script = textwrap.dedent(f"""
        import os, sys, time
        sys.path.insert(0, "generated")
        from atrv.planner import PROBLEMS
        from specc.runtime.ftplan.config import PlannerConfig
        from specc.runtime.ftplan.planners import PlannerProcess
        if __name__ == "__main__":
            config = PlannerConfig("hangs", "model1", factory="tests.ftplan_faulty:hanging_planner")
            planner = PlannerProcess(config, {{}})
            planner.start()
            planner.wait_ready(30)
            planner.request(PROBLEMS["M1_model1"].PROBLEMS["M1_model1"])
            time.sleep(0.2)  # the planner is in its endless planning, deaf to its pipe
            print(planner.pid, flush=True)
            {end}
    """)
    # Files, not pipes: a planner that outlived FTplan would hold a pipe open and hang the run.
    out, err = tmp_path / "out", tmp_path / "err"
    with out.open("w") as stdout, err.open("w") as stderr:
        done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, stdout=stdout, stderr=stderr, timeout=60)
    assert done.returncode == 0, err.read_text()
    pid = int(out.read_text().split()[0])
    if not wait_gone(pid):
        os.kill(pid, signal.SIGKILL)
        pytest.fail(f"planner {pid} outlived FTplan")
