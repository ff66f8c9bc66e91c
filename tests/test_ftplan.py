"""FTplan's recovery algorithms read against the seed's figures (004 Fig 3.1 successive, Fig 3.2
concurrent), with scripted planners in FTplan's process (`LocalPool`) whose answers are real plans
of mission M1 (Modele1) or scripted faults; the executor carries the plans out in mission time."""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

import pytest

from specc.runtime.ftplan import FtPlan, LocalPool, MissionResult, Outcome, Report, ScriptedExecutor
from specc.runtime.ftplan.component import MISSION_FAILED, MISSION_FAILED_IN_TIME
from specc.runtime.ftplan.config import FtPlanConfig, PlannerConfig
from specc.runtime.ftplan.execution import Execution, nominal
from specc.runtime.planner import Planner, PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Action, GoalOutcome, Plan
from tests.atrv import atrv_models, mutation_1_592

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "generated"))
from atrv.ftplan import rover  # noqa: E402  (the generated package of examples/atrv)

WATCHDOG = rover.CONFIG.watchdog
LATE = 10**6  # partial plans: charged far beyond any watchdog by the cost model


@cache
def mission() -> tuple[pm.PlanningDomain, pm.Problem]:
    return atrv_models("M1_model1")


def config(names: tuple[str, ...], policy: str = "successive") -> FtPlanConfig:
    return replace(rover.CONFIG, planners=tuple(PlannerConfig(n, "model1") for n in names), policy=policy)


@dataclass
class Scripted:
    """A planner answering its requests from a script: `plan` (specc's planner on Modele1),
    `invalid` (Modele1 with mutation 1-592: a plan the analyzer rejects), `late` (a plan charged
    beyond the watchdog), `none` (no plan), `raise`; an extra `nodes` sets the charge."""

    script: list[str]
    nodes: int = 0

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        what = self.script.pop(0)
        domain, _ = mission()
        if what == "raise":
            raise RuntimeError("scripted fault")
        if what == "none":
            return PlanResult(None, reason="scripted: no plan")
        result = Planner(mutation_1_592(domain) if what == "invalid" else domain).plan(problem, now)
        assert result.plan is not None
        return replace(result, nodes=LATE if what == "late" else self.nodes)


@dataclass
class FailingExecutor(ScriptedExecutor):
    """Fails the first action of the executions numbered in `failing` (1, 2, ...)."""

    failing: frozenset[int] = frozenset()
    count: int = 0

    def execute(self, plan: Plan, now: float, report: Callable[[Report], None]) -> Execution:
        self.count += 1
        self.world = broken if self.count in self.failing else nominal
        return super().execute(plan, now, report)


def broken(action: Action, now: float) -> Outcome:
    return Outcome(ended=False, why=f"scripted failure of {action.text()}")


def run(names: tuple[str, ...], scripts: dict[str, list[str]], policy: str = "successive",
        executor: ScriptedExecutor | None = None,
        nodes: dict[str, int] | None = None) -> tuple[MissionResult, LocalPool]:
    _, problem = mission()
    pool = LocalPool({n: Scripted(list(scripts[n]), (nodes or {}).get(n, 0)) for n in names})
    result = FtPlan(config(names, policy), problem, pool, executor or ScriptedExecutor()).run()
    return result, pool


def lines(result: MissionResult) -> list[int]:
    return [line for line, _ in result.trace]


def chosen(result: MissionResult) -> list[str]:
    return [text.removeprefix("choose ") for line, text in result.trace if line == 6]


# ---------------------------------------------------------------- Fig 3.1


def test_successive_planning_follows_fig_3_1_and_resets_the_failed_set_on_a_valid_plan() -> None:
    # p1 late -> failed {p1}; p2 plans, its plan is valid (failed emptied, line 14) and fails in
    # execution; p3 late -> failed {p3}; a new round (line 4): p1 is chosen again because the
    # reset forgot its failure; p1 late, p2 late -> failed = every planner: the mission exception.
    result, _ = run(("p1", "p2", "p3"), {"p1": ["late", "late"], "p2": ["plan", "late"], "p3": ["late"]},
                    executor=FailingExecutor(failing=frozenset({1})))
    assert chosen(result) == ["p1", "p2", "p3", "p1", "p2"]
    assert lines(result) == [
        2, 3, 4,
        5, 6, 7, 8, 9, 10, 20, 21,  # p1: the watchdog
        5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15,  # p2: analysed, failed <- {}, executed (and failed)
        5, 6, 7, 8, 9, 10, 20, 21,  # p3: the watchdog
        3, 4,  # candidates exhausted, goals remain: all planners again
        5, 6, 7, 8, 9, 10, 20, 21,  # p1
        5, 6, 7, 8, 9, 10, 20, 21, 23, 24,  # p2: failed = {p1, p2, p3}
    ]
    failed_sets = [text for line, text in result.trace if line in (14, 21)]
    assert failed_sets == ["failed <- p1", "failed <- {}", "failed <- p3", "failed <- p1, p3", "failed <- p1, p2, p3"]
    assert result.failure == MISSION_FAILED_IN_TIME and not result.success
    assert [e.kind for e in result.events].count("action-failed") == 1
    assert any(e.kind == "safe-state" for e in result.events)


def test_successive_planning_switches_planner_after_an_invalid_plan_and_completes() -> None:
    messages: list[str] = []
    _, problem = mission()
    pool = LocalPool({"p1": Scripted(["invalid"]), "p2": Scripted(["plan"])})
    result = FtPlan(config(("p1", "p2")), problem, pool, ScriptedExecutor(), operator=messages.append).run()
    assert lines(result)[:25] == [2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 16, 17, 18,
                                  5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]
    assert result.success and not result.missed and result.failure == ""
    assert len(messages) == 1 and messages[0].startswith("invalid plan from p1") and "PTU_POSITION" in messages[0]


def test_successive_planning_with_every_plan_invalid_raises_the_mission_exception() -> None:
    result, _ = run(("p1", "p2"), {"p1": ["invalid"], "p2": ["invalid"]})
    assert lines(result)[-3:] == [18, 23, 24]
    assert result.failure == MISSION_FAILED_IN_TIME
    assert result.met == [g for g in result.met if g.startswith("AT_ROBOT")]  # it never left home
    assert len(result.missed) == 5


def test_a_crashed_or_planless_planner_counts_as_a_late_one() -> None:
    result, pool = run(("p1", "p2", "p3"), {"p1": ["raise"], "p2": ["none"], "p3": ["plan"]})
    assert chosen(result) == ["p1", "p2", "p3"]
    assert lines(result).count(20) == 2 and result.success
    assert pool.abandoned == ["p1", "p2"]  # killed and restarted
    watchdog = [e.text for e in result.events if e.kind == "watchdog"]
    assert "scripted fault" in watchdog[0] and "no plan" in watchdog[1]


def w2_goal(problem: pm.Problem) -> pm.Assertion:
    """Modele1 M1's goal of communicating in window W2."""
    return next(g for g in problem.assertions if g.goal is not None and getattr(g, "args", ()) == (pm.Sym("W2"),))


@dataclass
class DropsGoal:
    """A planner that silently leaves one goal out of every problem it is given."""

    goal: pm.Assertion

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        kept = replace(problem, assertions=tuple(a for a in problem.assertions if a is not self.goal))
        return Planner(mission()[0]).plan(kept, now)


@pytest.mark.parametrize("policy", ["successive", "concurrent"])
def test_goals_a_plan_leaves_open_are_planned_again_by_the_next_planner(policy: str) -> None:
    # p1's plan meets every goal but COMMUNICATION(W2) (a planner that silently drops it); the
    # goal check at the plan's end finds it open. Successive planning gives it to p2 (line 5).
    # Concurrent planning asks both again, and p1, the fastest, wins with a plan that meets
    # nothing; p1 is then left out of the next round, so p2's plan runs.
    _, problem = mission()
    w2 = w2_goal(problem)
    requests: list[pm.Problem] = []

    @dataclass
    class Recording:
        def plan(self, problem: pm.Problem, now: float) -> PlanResult:
            requests.append(problem)
            return Planner(mission()[0]).plan(problem, now)

    result = FtPlan(config(("p1", "p2"), policy), problem, LocalPool({"p1": DropsGoal(w2), "p2": Recording()}),
                    ScriptedExecutor()).run()
    assert result.success, result.missed
    assert any(e.kind == "goals-open" and "COMMUNICATION(W2)" in e.text for e in result.events)
    if policy == "successive":
        assert chosen(result) == ["p1", "p2"]
        goals = {a.line for a in requests[0].assertions if a.goal is not None}
        assert w2.line in goals and len(goals) == 3  # W2, and the return home (X and Y) still to hold
    else:
        executed = [e.planner for e in result.events if e.kind == "execute"]
        assert executed[0] == "p1" and executed[-1] == "p2" and "p2" not in executed[:-1]
        assert any("(not p1: its last plan met no goal)" in text for line, text in result.trace if line == 3)


@pytest.mark.parametrize("policy", ["successive", "concurrent"])
def test_goals_abandoned_when_every_plan_leaves_them_aside_spare_the_final_goals_that_hold(policy: str) -> None:
    # Both planners drop COMMUNICATION(W2): FTplan gives it up. The robot is home by then, so the
    # final goals of being home (X and Y) hold: they are met when the mission ends, not abandoned.
    _, problem = mission()
    w2 = w2_goal(problem)
    result = FtPlan(config(("p1", "p2"), policy), problem, LocalPool({"p1": DropsGoal(w2), "p2": DropsGoal(w2)}),
                    ScriptedExecutor()).run()
    goals = [g for g in problem.assertions if g.goal is not None]
    assert list(result.missed) == [next(text for text in result.missed if "COMMUNICATION(W2)" in text)]
    assert len(result.met) == len(goals) - 1 and any("AT_ROBOT_X" in text for text in result.met)
    assert any(e.kind == "operator" and "abandoned" in e.text for e in result.events)



HOME = ("AT_ROBOT_X", "AT_ROBOT_Y")


@dataclass
class MoreGoalsEachTime:
    """A planner that plans, at its k-th request, for the first k goals of the mission but the
    return home (those of them its problem still has) and for the return home: each of its plans
    leaves the others open."""

    asked: int = 0

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        self.asked += 1
        first = sorted(a.line for a in mission()[1].assertions if a.goal is not None and a.attribute not in HOME)
        kept = replace(problem, assertions=tuple(a for a in problem.assertions if a.goal is None
                                                 or a.attribute in HOME or a.line in first[:self.asked]))
        return Planner(mission()[0]).plan(kept, now)


def test_a_plan_that_reached_goals_held_to_the_end_is_progress_and_the_rest_are_planned_again() -> None:
    """M1's photos kept to the mission's end (as an item left at its station is): a photo taken
    is met only when the mission ends. A plan that took one has not "met nothing": the one planner
    is asked again for the rest, as many times as it takes, instead of FTplan giving them up after
    its first plan."""
    _, problem = mission()
    photos_kept = replace(problem, assertions=tuple(
        replace(a, end=problem.end) if a.goal is not None and a.attribute == "PICTURE" else a  # type: ignore[call-arg]
        for a in problem.assertions))
    result = FtPlan(config(("p1",)), photos_kept, LocalPool({"p1": MoreGoalsEachTime()}), ScriptedExecutor()).run()
    goals = [g for g in photos_kept.assertions if g.goal is not None]
    assert result.success and len(result.met) == len(goals), result.missed
    assert result.plannings == len(goals) - len(HOME)  # one per goal but the return home


@dataclass
class DropsGoalSaying(DropsGoal):
    """A planner that leaves one goal out and says why, as a planner whose search ran out does."""

    def plan(self, problem: pm.Problem, now: float) -> PlanResult:
        result = super().plan(problem, now)
        said = GoalOutcome("COMMUNICATION(W2) = DONE", 3, self.goal.line, False,
                           "no plan within 300 partial plans (a larger search budget may find one)")
        return replace(result, goals=(*result.goals, said))


@pytest.mark.parametrize("policy", ["successive", "concurrent"])
def test_goals_given_up_say_why_each_planner_dropped_them(policy: str) -> None:
    """"Every planner's plan left them aside" says what each plan dropped and why (a search that
    ran out, not a choice), in the operator's message and in the goals missed."""
    _, problem = mission()
    w2 = w2_goal(problem)
    result = FtPlan(config(("p1", "p2"), policy), problem,
                    LocalPool({"p1": DropsGoalSaying(w2), "p2": DropsGoalSaying(w2)}), ScriptedExecutor()).run()
    (why,) = result.missed.values()
    assert why.startswith("every planner's plan left them aside (p1: COMMUNICATION(W2) = DONE: no plan within 300")
    assert "; p2: COMMUNICATION(W2) = DONE: no plan within 300 partial plans" in why
    assert any(e.kind == "operator" and "no plan within 300" in e.text for e in result.events)


# ---------------------------------------------------------------- Fig 3.2


def test_concurrent_planning_follows_fig_3_2_first_valid_plan_wins() -> None:
    # In model timing the charge orders the answers: p1 (10 partial plans) comes first with an
    # invalid plan, p2 (20) second with a valid one: p3 (30) is abandoned, p2's plan executed.
    result, pool = run(("p1", "p2", "p3"), {"p1": ["invalid"], "p2": ["plan"], "p3": ["plan"]},
                       policy="concurrent", nodes={"p1": 10, "p2": 20, "p3": 30})
    assert lines(result)[:21] == [2, 3, 4, 5,
                                  6, 8, 9, 10, 16, 17, 18,  # p1's plan rejected, the watchdog resumed
                                  6, 8, 9, 10, 11, 12, 13, 14, 15,  # p2's accepted, the others abandoned
                                  ]
    assert [text for line, text in result.trace if line == 8] == ["answer from p1", "answer from p2"]
    assert pool.abandoned == ["p3"]
    assert result.success and result.plannings == 3


def test_concurrent_planning_with_every_plan_invalid_raises_the_mission_exception() -> None:
    result, _ = run(("p1", "p2"), {"p1": ["invalid"], "p2": ["invalid"]}, policy="concurrent")
    assert lines(result)[-4:] == [17, 18, 19, 20]
    assert result.failure == MISSION_FAILED


def test_concurrent_planning_past_the_watchdog_raises_the_mission_exception_in_time() -> None:
    result, _ = run(("p1", "p2"), {"p1": ["late"], "p2": ["late"]}, policy="concurrent")
    assert lines(result)[-3:] == [6, 23, 24]
    assert result.failure == MISSION_FAILED_IN_TIME
    assert result.now == pytest.approx(WATCHDOG)


def test_model_timing_makes_a_mission_reproducible() -> None:
    first, _ = run(("p1", "p2"), {"p1": ["invalid"], "p2": ["plan"]})
    second, _ = run(("p1", "p2"), {"p1": ["invalid"], "p2": ["plan"]})
    assert first.events == second.events and first.now == second.now


def test_mutation_1_592_goes_unseen_without_the_analyzer_and_is_refused_with_it() -> None:
    # Robot1 of the seed with mutation 1-592 (§4.2.2.3): no mechanism FTplan had could see it,
    # the photos are "taken" with the camera looking ahead. With the analyzer, the plan is
    # refused before execution and the mission exception says no valid plan exists.
    _, problem = mission()
    unseen = FtPlan(config(("p1",)), problem, LocalPool({"p1": Scripted(["invalid"])}), ScriptedExecutor(),
                    analyzer=False).run()
    assert unseen.success and any(e.kind == "execute" for e in unseen.events)
    refused = FtPlan(config(("p1",)), problem, LocalPool({"p1": Scripted(["invalid"])}), ScriptedExecutor()).run()
    assert not any(e.kind == "execute" for e in refused.events)
    assert refused.failure == MISSION_FAILED_IN_TIME
    assert any(e.kind == "invalid-plan" and "PTU_POSITION" in e.text for e in refused.events)


def test_a_planner_s_own_problem_gets_its_goals_that_stand_for_ftplan_s_open_ones() -> None:
    """In FTplan's vocabulary, each goal of the planner's problem pairs with FTplan's goal of the same
    fact, in order: of two `AT() = DOCK`, the one met leaves its partner alone; a goal FTplan's problem
    does not have is kept."""
    import math
    from types import SimpleNamespace

    from specc.runtime.ftplan.state import Goal, SystemState

    def goal(line: int, attribute: str, value: str) -> Goal:
        return Goal(line, attribute, (), value, 1.0, math.inf, False)

    state = SystemState({}, (goal(10, "AT", "DOCK"), goal(11, "CART", "C"), goal(12, "AT", "DOCK")), {})
    state.met.add(10)
    own = SystemState({}, (goal(50, "AT", "DOCK"), goal(51, "CART", "C"), goal(52, "AT", "DOCK"),
                           goal(53, "LIGHT", "ON")), {})
    component = SimpleNamespace(state=state, planner_ledgers={"careful": own})
    component._paired_goals = lambda k: FtPlan._paired_goals(component, k)  # type: ignore[arg-type]
    assert FtPlan.open_planner_goals(component, "careful", None) == [51, 52, 53]  # type: ignore[arg-type]
    state.met.add(11)
    assert FtPlan.open_planner_goals(component, "careful", None) == [52, 53]  # type: ignore[arg-type]


def test_an_action_the_safe_state_stopped_counts_as_failed_and_changes_nothing_more() -> None:
    # A pan-tilt move runs beside a move that failed: the safe state stops it on its way. FTplan's
    # `on failed` rule for it applies (the unit is somewhere: OTHER_POSITION), and nothing is left
    # "changing" to be mistaken, at the mission's end, for an action stopped by the horizon.
    from specc.runtime.ftplan.state import Running

    _, problem = mission()
    ftplan = FtPlan(config(("p1",)), problem, LocalPool({"p1": Scripted([])}), ScriptedExecutor())
    ftplan.state.changing[("PTU_POSITION", ())] = Running("MOVE_PAN_TILT_UNIT#4", "MOVE_PAN_TILT_UNIT",
                                                         (0.0, -30.0))
    ftplan.stopped_as_failed("p1")
    assert ftplan.state.changing == {} and ftplan.state.facts[("PTU_POSITION", ())] == "OTHER_POSITION"
    assert ftplan.events[-1].text.startswith("stopped MOVE_PAN_TILT_UNIT(0, -30): counted as failed")


def test_a_final_goal_met_by_its_deadline_is_met_when_the_mission_ends_after_it() -> None:
    """`hold(CHECKED(CP1): YES, (t1, t_end))` with `t1` by 100 s: checked at 63 s and still checked
    when the mission ends at 300 s is met; one that comes true after 100 s, or comes true in time
    but stops holding and comes back late, is missed, and says why."""
    from specc.runtime.ftplan.state import Goal, SystemState

    def mission(*changes: tuple[float, str]) -> SystemState:
        goal = Goal(66, "CHECKED", ("CP1",), "YES", 3.0, 100.0, True)
        state = SystemState({("CHECKED", ("CP1",)): "NO"}, (goal,), {})
        for now, value in changes:
            state.facts[("CHECKED", ("CP1",))] = value
            state.check_goals(now)
        state.check_goals(300.0, mission_over=True)
        return state

    assert mission((63.5, "YES"), (131.5, "YES")).met == {66}
    late = mission((120.0, "YES"))
    assert late.met == set() and late.missed[66] == "its deadline 100 s had passed when it came true"
    lost = mission((63.5, "YES"), (80.0, "NO"), (150.0, "YES"))
    assert lost.met == set() and "deadline 100 s" in lost.missed[66]
