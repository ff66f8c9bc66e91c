"""The planner: a problem (an initial partial plan) in, a plan or the reason there is none out.

Goals are kept by priority, as IxTeT does: a goal that cannot be met even alone is dropped at
once; then the planner looks for a plan meeting every remaining goal; when that fails within its
budget, it adds the goals one at a time, highest priority first, and drops each goal that cannot
join those already kept. Every search is bounded by a number of partial plans (not by wall time,
so that a run is deterministic), so the planner never searches forever on an impossible goal set.
"""

from __future__ import annotations

import functools
import itertools
import math
import random
import re
import time
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TypeVar

from specc.runtime.planner import model as pm
from specc.runtime.planner import waypoints as wp
from specc.runtime.planner.heuristics import (
    FLAW_ORDERS,
    HEURISTICS,
    LEAST_ROOM,
    NEWEST_TASK_FIRST,
    OLDEST_TASK_FIRST,
    STANDARD,
)
from specc.runtime.planner.numeric import domain_of, exact_duration
from specc.runtime.planner.plan import Action, GoalOutcome, Link, Plan, PlanResult, Repair
from specc.runtime.planner.reachable import Reach, impossible_goal, reach, valued
from specc.runtime.planner.search import (
    CONTROLLABILITIES,
    EPS,
    PSEUDO,
    STRONG,
    TOLERANCE,
    Assertion,
    Bindings,
    Context,
    DeadEnd,
    Instance,
    Limits,
    Node,
    Term,
    Threat,
    differences,
    is_temporal,
    is_var,
    producers_of,
    restoring_events,
    same_value,
    task_constraints,
    translate,
)
from specc.runtime.stn import STN, Inconsistent

INF = math.inf
IMPROVEMENT = 0.5  # s: a plan must end this much earlier to count as better (not a rounding's worth)
REORDER_TRIAL = 400  # partial plans at most for one goal order tried by the improvement (Setup.reorder)
# Partial plans at most for searching a plan again without its round trips (`round_trips`), after
# the first plan and whatever the improvement's budget.
ROUND_TRIP_TRIAL = 300
WAYPOINT_TRIAL = 300  # partial plans at most for one move split at one waypoint (Setup.waypoints)


class NodeLimitReached(Exception):
    """The planning expanded more partial plans than its node limit allows: `nodes` of them."""

    def __init__(self, nodes: int) -> None:
        super().__init__(nodes)
        self.nodes = nodes


class PlanningInputError(ValueError):
    """The problem cannot be planned as written (a contingent instant without bounds, a
    constraint the planner does not handle): one clear message, no plan."""


@dataclass(frozen=True)
class Goal:
    """A goal of the problem as the search pursues it."""

    index: int  # position among the problem's assertions
    hold: pm.Hold | pm.Event
    priority: float

    @property
    def text(self) -> str:
        a = self.hold
        args = f"({', '.join(pm.describe(x) for x in a.args)})"
        value = pm.describe(a.value) if isinstance(a, pm.Hold) else pm.describe(a.after)
        return f"{a.attribute}{args} = {value} (line {a.line}, priority {self.priority:g})"


def holds_apart(first: Goal, second: Goal) -> bool:
    """Two goals holding one attribute (the same constant arguments) at other constant values over
    the same interval: no plan meets both."""
    a, b = first.hold, second.hold
    constant = (pm.Num, pm.Sym)
    return (isinstance(a, pm.Hold) and isinstance(b, pm.Hold) and (a.attribute, a.args, a.start, a.end)
            == (b.attribute, b.args, b.start, b.end) and a.value != b.value
            and all(isinstance(x, constant) for x in (*a.args, a.value, b.value)))


@dataclass
class Attempt:
    """One search: the plan found (or none), the partial plans expanded, whether every branch was
    tried, and its dead ends."""

    node: Node | None
    nodes: int
    exhausted: bool  # the whole search space was explored
    failures: Counter[str] = field(default_factory=Counter)




def forget_caches() -> None:
    """Drop what the plannings of this process worked out and keep for the next ones (tasks'
    durations and constraints by binding, the validator's checks): a planning after it does a
    first planning's work. A comparison of one planning with another planner's (`make bench`)
    starts from here."""
    from specc.runtime.planner import numeric, search, validate

    for table in (numeric._READERS, numeric._DURATIONS, numeric._TASK_CONSTRAINTS, search._TASK_CONSTRAINTS):
        table.clear()
    numeric.exact_duration.cache_clear()
    validate.check_task.cache_clear()


class Planner:
    def __init__(self, domain: pm.PlanningDomain, *, nodes: int = 300, goal_nodes: int = 300,
                 exact: bool = True, limits: Limits | None = None, controllability: str = STRONG,
                 node_limit: int | None = None, heuristic: str = STANDARD, improve: int = 0,
                 flaws: str = NEWEST_TASK_FIRST) -> None:
        if controllability not in CONTROLLABILITIES:
            raise ValueError(f"controllability '{controllability}': choose {' or '.join(CONTROLLABILITIES)}")
        if heuristic not in HEURISTICS:
            raise ValueError(f"heuristic '{heuristic}': choose {' or '.join(sorted(HEURISTICS))}")
        if flaws not in FLAW_ORDERS:
            raise ValueError(f"flaw order '{flaws}': choose {' or '.join(FLAW_ORDERS)}")
        self.heuristic = heuristic  # the order of the orderings a choice offers (HEURISTICS)
        self.flaws = flaws  # which task's open conditions come first (FLAW_ORDERS)
        self.domain = domain
        self.controllability = controllability  # what the plans must hold against (search.py's doc)
        self.nodes = nodes  # budget of the search for every goal at once
        self.goal_nodes = goal_nodes  # budget of each smaller search
        self.exact = exact  # exact durations by CasADi (else the interval enclosures)
        self.limits = limits or Limits()
        # Partial plans one planning may expand in all before it gives up: FTplan sets it to what
        # its watchdog pays for, so that a planning stops where its answer would be late anyway,
        # at the same count on any machine. Below it, the search is the same as without.
        self.node_limit = node_limit
        # Partial plans spent improving the first plan (anytime, `_improve`); 0: the first plan.
        self.improve = improve

    # ------------------------------------------------------------ entry point
    def plan(self, problem: pm.Problem, now: float = 0.0) -> PlanResult:
        started = time.perf_counter()
        try:
            setup = Setup(self.domain, problem, now, self.limits, self.controllability, self.heuristic, self.flaws)
        except PlanningInputError as error:
            return PlanResult(None, reason=str(error), seconds=time.perf_counter() - started)
        try:
            return self._plan(setup, started)
        except NodeLimitReached as reached:
            return PlanResult(None, reason=f"no plan within the limit of {self.node_limit} partial plans",
                              nodes=reached.nodes, seconds=time.perf_counter() - started)

    def _plan(self, setup: Setup, started: float) -> PlanResult:
        """`plan` once the problem is set up; NodeLimitReached past the node limit."""
        goals = setup.goals
        total = 0
        outcomes: dict[int, GoalOutcome] = {}

        def attempt(active: Iterable[Goal], budget: int, discrepancies: bool = True) -> Attempt:
            nonlocal total
            allowance = None if self.node_limit is None else self.node_limit - total
            result = setup.search(list(active), budget, discrepancies, allowance)
            total += result.nodes
            if self.node_limit is not None and total > self.node_limit:
                raise NodeLimitReached(total)
            return result

        base = attempt([], self.goal_nodes)
        if base.node is None:
            why = "no plan satisfies the problem's required assertions and constraints"
            return PlanResult(None, tuple(GoalOutcome(g.text, g.priority, g.hold.line, False, why) for g in goals),
                              reason=f"{why}: {explain(base)}", nodes=total,
                              seconds=time.perf_counter() - started)
        candidates: list[Goal] = []
        alone: dict[int, Attempt] = {}  # each goal's search alone: the first of those below, if it comes to them
        reached = reach(self.domain, setup.problem)  # a goal no task can ever reach needs no search to drop
        for goal in goals:
            impossible, tried = why_impossible(reached, goal, setup.problem,
                                               functools.partial(attempt, [goal], self.goal_nodes))
            if tried is not None:
                alone[goal.index] = tried
            if impossible is not None:
                outcomes[goal.index] = GoalOutcome(goal.text, goal.priority, goal.hold.line, False, impossible)
            else:
                candidates.append(goal)
        # Every goal at once, depth first: when the heuristic leads there, the plan comes in a few
        # hundred partial plans; when not, the goals are added one by one below.
        best = attempt(candidates, self.nodes, discrepancies=False) if candidates else base
        kept = list(candidates) if best.node is not None else []
        if best.node is None:
            # Highest priority first; within a priority, in the order the problem lists them.
            best = base
            for goal in sorted(candidates, key=lambda g: (-g.priority, g.index)):
                clash = next((k for k in kept if holds_apart(k, goal)), None)
                if clash is not None:  # no search tells it better, nor a larger budget
                    h = goal.hold
                    assert isinstance(h, pm.Hold)
                    why = (f"cannot be met together with {clash.text}: both hold {h.attribute}"
                           f"({', '.join(pm.describe(x) for x in h.args)}) from {h.start} to {h.end}, with "
                           "other values, and an attribute has one value at a time")
                    outcomes[goal.index] = GoalOutcome(goal.text, goal.priority, goal.hold.line, False, why,
                                                       for_others=True)
                    continue
                # The first goal alone was searched already, with the same budget: the same search.
                tried = alone[goal.index] if not kept else attempt(kept + [goal], self.goal_nodes)
                if tried.node is not None:
                    kept.append(goal)
                    best = tried
                else:
                    # "Cannot" only when every partial plan failed; a search that ran out of its
                    # budget proves nothing (`explain` says it ran out).
                    together = "cannot be met" if tried.exhausted else "was not planned"
                    why = (f"{together} together with the goals kept before it ({', '.join(g.text for g in kept)})"
                           if kept else "not met alone either (no goal was kept before it)")
                    why += f": {explain(tried)}{dates_said(goal, setup.problem, tried)}"
                    outcomes[goal.index] = GoalOutcome(goal.text, goal.priority, goal.hold.line, False, why,
                                                       for_others=bool(kept))  # planned alone, or tried
        assert best.node is not None
        # Not an improvement (which FTplan's planners leave at 0): a plan that puts an object down
        # only to pick it up again is one no robot should carry out.
        allowance = ROUND_TRIP_TRIAL if self.node_limit is None else min(ROUND_TRIP_TRIAL, self.node_limit - total)
        straight, spent = setup.without_round_trips(kept, best.node, allowance)
        total += spent
        plan, notes = setup.extract(straight, self.exact)
        if self.improve:
            budget = self.improve if self.node_limit is None else min(self.improve, self.node_limit - total)
            plan, notes, kept, spent = self._improve(setup, straight, plan, notes, kept, candidates, budget)
            total += spent
        for goal in kept:
            outcomes[goal.index] = GoalOutcome(goal.text, goal.priority, goal.hold.line, True)
        plan = replace(plan, goals=tuple(g.hold.line for g in kept))
        ordered = tuple(outcomes[g.index] for g in goals)
        return PlanResult(plan, ordered, nodes=total, seconds=time.perf_counter() - started, notes=notes)

    def _improve(self, setup: Setup, node: Node, plan: Plan, notes: tuple[str, ...], kept: list[Goal],
                 candidates: list[Goal], budget: int) -> tuple[Plan, tuple[str, ...], list[Goal], int]:
        """Anytime improvement of a first plan within `budget` partial plans (#25: the time the
        watchdog leaves, under FTplan's cost model): first the goals it dropped that are not
        impossible alone, highest priority first, each tried again with the budget left (more
        priority-weighted goals kept is the better plan); then the worst-case makespan: by
        waypoints in the first plan's idle times (`Setup.waypoints`: a move split so that the robot
        goes part of the way while it would wait), by branch and bound near the first plan's
        choices (`Setup.improve`), by other orders of taking the goals up (`Setup.reorder`:
        another tour of the photos), then by other orders each with its waypoints. A plan
        replaces the first only when it keeps every goal it kept and ends earlier at worst
        (`Plan.makespan`, the measure the plans are compared by), so the result is never worse.
        Returns the plan, its notes, the goals kept and the partial plans spent."""
        spent = 0
        gained: list[str] = []
        for goal in sorted((g for g in candidates if g not in kept), key=lambda g: (-g.priority, g.index)):
            if spent >= budget:
                break
            # Other tours first, with half of what is left (they need no more when the mission's
            # end is what drops the goal), then the search in the heuristic's order.
            with_goal, used = setup.tour_in_time(kept + [goal], node, (budget - spent + 1) // 2)
            spent += used
            if with_goal is None and spent < budget:
                tried = setup.search(kept + [goal], budget - spent)
                spent += tried.nodes
                with_goal = tried.node
            if with_goal is not None:
                kept, node = kept + [goal], with_goal
                plan, notes = setup.extract(node, self.exact)
                gained.append(goal.text)
        first = plan.makespan
        bound = node.worst_end()
        best = node
        # A twentieth kept for merging back the waypoints the best plan drives through.
        reserve = (budget - spent) // 20
        budget -= reserve
        ways: list[str] = []
        # Each phase has a share of the budget still left (1/4, 1/6, 1/2, all the rest) and
        # leaves what it does not spend to the next: waypoints in the first plan's idle times
        # (they seldom need their share), branch and bound near the heuristic's choices, other
        # orders of taking the goals up, then other orders each with its own waypoints (a tour
        # that waits more may end sooner once the robot goes on during the waits: M3's best).
        phases: tuple[tuple[str, Callable[[list[Goal], float, int], tuple[list[Node], int]], int], ...] = (
            ("waypoints", lambda active, limit, share: setup.waypoints(active, node, limit, share), 4),
            ("branch and bound", setup.improve, 6),
            ("other goal orders", functools.partial(setup.reorder, trial=order_trial(node)), 2),
            ("other goal orders with waypoints",
             functools.partial(setup.reorder, waypoints=True, trial=order_trial(node)), 1))
        for name, search, share in phases:
            found, used = search(kept, bound, (budget - spent) // share) if spent < budget else ([], 0)
            spent += used
            for better in reversed(found):  # the best by the search's measure first
                candidate, candidate_notes = setup.extract(better, self.exact)
                if candidate.makespan < plan.makespan - 1e-6:
                    plan, notes, best = candidate, candidate_notes, better
                    bound = min(bound, better.worst_end())
                    ways.append(name)
                    break
        budget += reserve
        merged, used = setup.merge_drive_throughs(kept, best, budget - spent)
        spent += used
        if merged is not best:
            candidate, candidate_notes = setup.extract(merged, self.exact)
            if candidate.makespan < plan.makespan + 1e-6:
                plan, notes = candidate, candidate_notes
        said = ([f"goal(s) kept by the improvement: {'; '.join(gained)}"] if gained else []) + (
            [f"worst-case makespan improved from {first:.1f} s to {plan.makespan:.1f} s ({', '.join(ways)})"]
            if plan.makespan < first - 1e-6 else [])
        note = f"improvement: {spent} partial plan(s); " + ("; ".join(said) or "no better plan found")
        return plan, (*notes, note), kept, spent

    def impossible_goals(self, problem: pm.Problem, now: float = 0.0) -> dict[int, str]:
        """The source lines of the goals that cannot be met even alone (every partial plan of the
        goal's own search failed), with why: the goals `plan` drops first, found without planning
        the others (`specc export` leaves them out)."""
        try:
            setup = Setup(self.domain, problem, now, self.limits, self.controllability, self.heuristic, self.flaws)
        except PlanningInputError:
            return {}
        found = {}
        reached = reach(self.domain, setup.problem)
        for goal in setup.goals:
            why, _ = why_impossible(reached, goal, problem, functools.partial(setup.search, [goal], self.goal_nodes))
            if why is not None:
                found[goal.hold.line] = why
        return found

    # ------------------------------------------------------------ plan repair
    def repair(self, problem: pm.Problem, now: float, repair: Repair) -> PlanResult:
        """IxTeT's plan repair (seed 004 §3.2.1, after Lemai-Chenevier 2004: "il essaie de réparer
        le plan en ne replanifiant que les objectifs ou les contraintes mis en échec"). The plan
        under way failed; `problem` is the replanning problem of the present (its facts, the goals
        still open, `now`) and `repair` the plan with its actions still to carry out. The search starts
        from those actions, each put back with its arguments (one that no longer fits the present is
        left out, as IxTeT backtracks over the actions that became impossible), and resolves only
        the flaws the failure left: the conditions a failed action no longer gives, the present's
        facts, the threats and conflicts they bring; the kept actions keep the order and the causal
        links the plan gave them. A repair meets every goal the plan met that is still open; when
        none is found within the planner's budget, the result has no plan and the caller replans
        from scratch (FTplan, `component.FtPlan.execute`)."""
        started = time.perf_counter()
        try:
            setup = Setup(self.domain, problem, now, self.limits, self.controllability, self.heuristic, self.flaws)
        except PlanningInputError as error:
            return PlanResult(None, reason=str(error), seconds=time.perf_counter() - started)
        # The goals the plan met (all, when it does not say): one it left aside stays so.
        active = [g for g in setup.goals if g.hold.line in repair.plan.goals or not repair.plan.goals]
        aside = "left aside by the plan repaired"
        attempt = setup.search(active, self.nodes, True, self.node_limit, repair)
        if attempt.node is None:
            why = f"no repair of the plan: {explain(attempt)}"
            dropped = tuple(GoalOutcome(g.text, g.priority, g.hold.line, False, why if g in active else aside)
                            for g in setup.goals)
            return PlanResult(None, dropped, reason=why, nodes=attempt.nodes, seconds=time.perf_counter() - started)
        plan, notes = setup.extract(attempt.node, self.exact)
        plan = replace(plan, goals=tuple(g.hold.line for g in active))
        still = sum(1 for a in plan.actions if a.id in setup.kept_ids)
        note = (f"repaired: {still} of the {len(repair.kept)} action(s) still to carry out kept, "
                f"{len(plan.actions) - still} inserted")
        outcomes = tuple(GoalOutcome(g.text, g.priority, g.hold.line, g in active, "" if g in active else aside)
                         for g in setup.goals)
        return PlanResult(plan, outcomes, nodes=attempt.nodes, seconds=time.perf_counter() - started,
                          notes=(*notes, note))


def order_trial(plan: Node) -> int:
    """The partial plans a depth-first search led by one order of the goals may take: an order
    that leads to a plan needs about one to five per action of a plan like `plan` (the rover's
    missions: 2.9-5.2), and one that fails spends the whole trial, which should not be wasted."""
    return min(REORDER_TRIAL, 20 + 6 * len(plan.instances))


class _Enough(Exception):
    """`Setup.reorder`'s caller has what it looked for."""


def _sooner(late: tuple[float, float], than: tuple[float, float]) -> bool:
    """Is a plan of `late` (`Setup._lateness`) better than one of `than`? An earlier worst-case
    end, or the same one with its goals met sooner."""
    return late[0] < than[0] - 1e-6 or (late[0] < than[0] + 1e-6 and late[1] < than[1] - 1e-6)


def _push(stack: list[tuple[Node, Resolver | None, int]], node: Node, choice: list[Resolver], used: int,
          allowed: float) -> bool:
    """The children of `node`, pushed so that the heuristic's first choice is popped first, each
    with the discrepancies it costs (any but the first: one more); those beyond `allowed` are left
    out for this pass: True then. A pass revisits the last one's: the stack never holds the tree."""
    cut = False
    for rank in range(len(choice) - 1, -1, -1):
        cost = used + (1 if rank else 0)
        if cost > allowed:
            cut = True
            continue
        stack.append((node, choice[rank], cost))
    return cut


def why_impossible(reached: Reach | None, goal: Goal, problem: pm.Problem,
                   search_alone: Callable[[], Attempt]) -> tuple[str | None, Attempt | None]:
    """Why no plan can meet `goal`, or None: no task ever reaches its value (`reached`, the
    relaxed reachability; None when not judged), which needs no search; else the goal's own
    search (`search_alone`) failed everywhere. And that search, when it was made."""
    never = impossible_goal(reached, goal.hold) if reached is not None else None
    if never is not None:
        return never, None
    alone = search_alone()
    return impossible_alone(alone, goal, problem), alone


def impossible_alone(alone: Attempt, goal: Goal, problem: pm.Problem) -> str | None:
    """Why a goal searched for alone is impossible (its whole search space failed), else None."""
    if alone.node is not None or not alone.exhausted:
        return None
    return f"impossible even alone: {explain(alone)}{dates_said(goal, problem, alone)}"


def dates_said(goal: Goal, problem: pm.Problem, attempt: Attempt) -> str:
    """The problem's constraints on the goal's dates (a deadline), and when the search failed
    for time (`attempt`'s contradictions between timepoints), the mission's latest end: what the
    search's own words do not name, and what a goal dropped for time is dropped for."""
    dated = set(pm.assertion_timepoints(goal.hold)) - {problem.start, problem.end}
    own = [f"{_constraint_text(c)} (line {c.line})" for c in problem.constraints
           if c.line and pm.timepoints_of(c) & dated]
    said = f"; the goal's dates: {', '.join(own)}" if own else ""
    latest = pm.latest_end(problem)
    if math.isfinite(latest) and any(TIMED_OUT in why for why in attempt.failures):
        lines = sorted({c.line for c in pm.end_bounds(problem)
                        if c.line and isinstance(c.domain, pm.Interval) and c.domain.high == latest})
        said += f"; the mission ends by {latest:g} s at the latest" + (
            f" (line {', '.join(map(str, lines))})" if lines else "")
    return said


# What a dead end says when the plan's dates cannot all hold (search.Node.require).
TIMED_OUT = "contradicts"


def nature_conflict(constraints: list[tuple[pm.Constraint, list[tuple[str, str, float, float]]]]) -> str | None:
    """Why the problem's constraints on nature's instants (each with its difference pieces) cannot
    all hold, naming a smallest set of them that cannot, or None when they can."""

    def consistent(chosen: list[tuple[pm.Constraint, list[tuple[str, str, float, float]]]]) -> bool:
        network = STN()
        try:
            for _, pieces in chosen:
                for first, second, low, high in pieces:
                    network.add(first, second, low, high)
        except Inconsistent:
            return False
        return True

    if consistent(constraints):
        return None
    # The first prefix that cannot hold, then each of its constraints left out when the rest still
    # cannot: what remains is a conflict where every constraint counts.
    end = next(k for k in range(1, len(constraints) + 1) if not consistent(constraints[:k]))
    conflict = constraints[:end]
    for item in list(conflict[:-1]):
        trial = [x for x in conflict if x is not item]
        if not consistent(trial):
            conflict = trial
    said = [f"{_constraint_text(c)} (line {c.line})" if c.line else _constraint_text(c) for c, _ in conflict]
    listed = said[0] if len(said) == 1 else f"{', '.join(said[:-1])} and {said[-1]}"
    return f"the problem's constraints on nature's instants cannot all hold: {listed}"


def _constraint_text(c: pm.Constraint) -> str:
    if isinstance(c, pm.Member) and isinstance(c.domain, pm.Interval):
        return f"{pm.describe(c.expr)} in [{c.domain.low:g}, {c.domain.high:g}]"
    if isinstance(c, pm.Relation):
        return f"{pm.describe(c.left)} {c.op} {pm.describe(c.right)}"
    return "a constraint"


def explain(attempt: Attempt) -> str:
    if attempt.node is not None:
        return "planned"
    scope = "every partial plan failed" if attempt.exhausted else (
        f"no plan within {attempt.nodes} partial plans (a larger search budget may find one)")
    if not attempt.failures:
        return scope
    common = ", ".join(why for why, _ in attempt.failures.most_common(2))
    return f"{scope}; most often: {common}"


def _source(a: pm.Assertion) -> str:
    """Where an assertion comes from: its line, or the fact a replanning was given (line 0)."""
    if a.line:
        return f"line {a.line}"
    value = a.after if isinstance(a, pm.Event) else a.value if isinstance(a, pm.Hold) else a.amount
    return f"fact {pm.subject(a)}({', '.join(pm.describe(x) for x in a.args)}) = {pm.describe(value)}"


def _owner(owner: str) -> str:
    """An assertion's owner as a sentence names it: a task (`MOVE#3`), or the problem."""
    return "the problem" if owner == "problem" else owner


def _generic(message: str) -> str:
    """A dead end's message without instance numbers, so that alike failures count together."""
    return re.sub(r"#\d+", "", message)


# ---------------------------------------------------------------- one problem


class Setup:
    """A problem made ready to plan: its goals, the contingent instants and the constraints."""

    def __init__(self, domain: pm.PlanningDomain, problem: pm.Problem, now: float, limits: Limits,
                 controllability: str = STRONG, heuristic: str = STANDARD, flaws: str = NEWEST_TASK_FIRST) -> None:
        self.heuristic = heuristic
        self.limits, self.controllability, self.flaws = limits, controllability, flaws
        if problem.domain != domain.name:
            raise PlanningInputError(f"problem '{problem.name}' is written for domain '{problem.domain}', "
                                     f"not '{domain.name}'")
        self.domain = domain
        self.problem = problem
        self.now = now
        self.origin = problem.start
        self.goals = [Goal(i, a, a.goal.priority) for i, a in enumerate(problem.assertions)
                      if isinstance(a, (pm.Hold, pm.Event)) and a.goal is not None]
        known = {x.name for x in domain.attributes} | {r.name for r in domain.resources}
        for a in problem.assertions:
            if isinstance(a, pm.Event) and a.kind == "" and a.goal is None:
                continue
            if pm.subject(a) not in known:
                raise PlanningInputError(f"{_source(a)}: unknown attribute '{pm.subject(a)}' in problem "
                                         f"'{problem.name}'")
            terms = a.args + ((a.value,) if isinstance(a, pm.Hold) else (a.before, a.after)
                              if isinstance(a, pm.Event) else (a.amount,))
            if any(isinstance(t, (pm.Op, pm.Time)) for t in terms):
                raise PlanningInputError(f"{_source(a)}: assertions take values and variables, not expressions")
            declared = domain.attribute(pm.subject(a))
            # An explained event's former value is history: only what it sets must be a value.
            values: tuple[pm.Expr, ...] = (a.value,) if isinstance(a, pm.Hold) else () if not isinstance(
                a, pm.Event) else (a.after,) if a.kind == "explained" else (a.before, a.after)
            for value in values:
                if (declared is not None and isinstance(declared.values, pm.Symbols) and isinstance(value, pm.Sym)
                        and value.name not in declared.values.values):
                    raise PlanningInputError(
                        f"{_source(a)}: '{value.name}' is not a value of {declared.name} "
                        f"({', '.join(declared.values.values)}), in problem '{problem.name}'")
                # A symbol where numbers are meant would only fail deep in the search, as if the
                # goals were out of reach.
                if (declared is not None and isinstance(declared.values, pm.Interval)
                        and isinstance(value, pm.Sym)):
                    raise PlanningInputError(
                        f"{_source(a)}: '{value.name}' is not a value of {declared.name}, whose values are numbers "
                        f"in [{declared.values.low:g}, {declared.values.high:g}], in problem '{problem.name}'")
            if isinstance(a, pm.Use) and isinstance(a.amount, pm.Sym):
                raise PlanningInputError(f"{_source(a)}: '{a.amount.name}' is not an amount of {a.resource}: "
                                         f"a resource is used by a number, in problem '{problem.name}'")
        for task in domain.tasks:  # a task the search could not insert is refused here, once
            for temporal in task_constraints(task).temporal:
                try:
                    differences(temporal, str, self.origin)
                except ValueError as error:
                    raise PlanningInputError(
                        f"task {task.name}, line {temporal.line}: {error}: the planner takes temporal constraints that "
                        "bound the difference of two timepoints (or a timepoint's date)") from None
        # Nature's instants: the times of contingent events, bounded from the origin.
        self.contingent = sorted({a.time for a in problem.assertions
                                  if isinstance(a, pm.Event) and a.kind == "contingent" and a.time != self.origin})
        bounds: dict[str, tuple[float, float]] = {p: (-INF, INF) for p in self.contingent}
        self.requirements: list[tuple[str, str, float, float]] = []
        self.nature_before: set[tuple[str, str]] = set()
        natures = set(self.contingent) | {self.origin}
        on_nature: list[tuple[pm.Constraint, list[tuple[str, str, float, float]]]] = []
        for c in problem.constraints:
            if isinstance(c, pm.Implies) or not is_temporal(c):
                if isinstance(c, pm.Member) and isinstance(c.expr, pm.Var):
                    continue  # a variable's domain
                raise PlanningInputError(f"line {c.line}: only temporal constraints and variable domains are "
                                         "planned in a problem")
            try:
                pieces = differences(c, origin=self.origin)
            except ValueError as error:
                raise PlanningInputError(f"line {c.line}: {error}") from None
            if any({first, second} <= natures for first, second, _, _ in pieces):
                on_nature.append((c, pieces))
            for first, second, low, high in pieces:
                nature = {first, second} <= natures
                if nature and first == self.origin and second in bounds:
                    old = bounds[second]
                    bounds[second] = (max(old[0], low), min(old[1], high))
                elif not nature:
                    self.requirements.append((first, second, low, high))
                elif low > 0:
                    self.nature_before.add((first, second))
                elif high < 0:
                    self.nature_before.add((second, first))
                # Constraints among nature's instants alone describe nature: nothing to plan.
        for point, (low, high) in bounds.items():
            if not (math.isfinite(low) and math.isfinite(high)):
                raise PlanningInputError(f"contingent instant '{point}' needs bounds from {self.origin} "
                                         f"(e.g. `({point} - {self.origin}) in [a, b];`)")
        self.bounds = bounds
        # The planner trusts what the problem says of nature's instants (their bounds, and the
        # orders in `nature_before`), and the validator judges a plan on the realisations that
        # keep it: when no realisation can, any plan would pass for a nature that cannot be, so
        # the problem's constraints are contradictory and no plan is made (problem_root).
        self.nature_conflict = nature_conflict(on_nature)
        # A goal's own timepoints (used by no other assertion) leave with it.
        used_by: dict[str, set[int]] = {}
        for i, a in enumerate(problem.assertions):
            for point in pm.assertion_timepoints(a):
                used_by.setdefault(point, set()).add(i)
        for point in problem.timepoints:
            if point not in used_by and point not in bounds:
                used_by[point] = set()  # no assertion uses it (a goal left out of a replanning)
        goal_indexes = {g.index for g in self.goals}
        self.owned = {point: owners for point, owners in used_by.items()
                      if owners <= goal_indexes and point not in (self.origin, problem.end)}
        self.kept_ids: set[str] = set()  # a repair's instances put back from the plan it repairs
        self._roots: dict[frozenset[int], Node] = {}  # problem_root's, by the indexes of the active goals
        self.context = Context(problem.end, self.origin, now, limits, {r.name: r.capacity for r in domain.resources},
                               producers_of(domain), self.nature_before, controllability,
                               flaws == OLDEST_TASK_FIRST, restoring=restoring_events(domain))

    def for_problem(self, problem: pm.Problem) -> Setup:
        """Another problem made ready with this one's domain, date and settings."""
        return Setup(self.domain, problem, self.now, self.limits, self.controllability, self.heuristic, self.flaws)

    def root(self, active: list[Goal], repair: Repair | None = None) -> Node:
        node = self.problem_root(active)
        if repair is None:
            return node
        # A repair's actions still to carry out, each with the arguments it had; an action that
        # no longer fits (its arguments, duration or window refused by the present) is left out,
        # and so is an order between two of them that no longer can hold.
        def put_back(node: Node, action: Action) -> tuple[Action, Instance] | None:
            """The action inserted into `node` with its arguments, and its instance (None: its
            task is gone); DeadEnd when it no longer fits."""
            task = self.domain.task(action.task)
            if task is None:
                return None
            instance = node.insert(task)
            changed: list[str] = []
            for local, value in zip(task.params, action.args, strict=True):
                changed += node.bindings.unify(instance.var(local), value)
            node.bound(changed)
            return action, instance

        node, put = each_that_fits(node, repair.actions, put_back)
        points: dict[str, str] = {}  # the repaired plan's timepoints -> the new instances'
        for action, instance in filter(None, put):
            self.kept_ids.add(instance.id)
            points |= {action.start: instance.start, action.end: instance.end}
        for first, second, low in repair.orderings:
            if first in points and second in points and node.allows(points[first], points[second], low):
                node.require(points[first], points[second], low)
        # The causal links between two kept actions hold again: only the needs the failure (or the
        # present's facts) left without a producer are open. Links are read back by their
        # descriptions (`_where`), which the same assertion of the same action gives again.
        renamed = {action.id: new_id for action in repair.actions
                   if (new_id := points.get(action.start, "").rsplit(".", 1)[0])}
        renamed["problem"] = "problem"  # its goals, and the facts that still hold
        described = {f"{old}: {a.text(node.bindings)}": a for old, new in renamed.items()
                     for a in node.assertions if a.owner == new}
        links = [(producer.id, consumer.id) for link in repair.plan.links
                 if (producer := described.get(link.producer)) is not None
                 and (consumer := described.get(link.consumer)) is not None]

        def relink(node: Node, link: tuple[int, int]) -> None:
            producer, consumer = link
            if consumer in node.open:
                node.link(node.assertions[producer], node.assertions[consumer])

        node, _ = each_that_fits(node, links, relink)
        return node

    def problem_root(self, active: list[Goal]) -> Node:
        """The partial plan the search starts from: the problem's assertions, its active goals
        and their constraints. Made once per set of goals (the improvement searches the same
        goals again and again, under other goal orders), then copied: a search changes its root."""
        if self.nature_conflict is not None:
            raise DeadEnd(self.nature_conflict)
        key = frozenset(g.index for g in active)
        made = self._roots.get(key)
        if made is None:
            made = self._roots[key] = self._problem_root(active)
        node = made.copy()
        node.ctx = self.context  # the goal order of the moment (`reorder`); the rest is the same
        return node

    def _problem_root(self, active: list[Goal]) -> Node:
        node = Node(self.context)
        problem = self.problem
        active_indexes = {g.index for g in active}
        dropped_points = {p for p, owners in self.owned.items() if not owners & active_indexes}
        node.require("origin", self.origin, 0.0, 0.0)
        node.require(self.origin, problem.end, max(0.0, self.now))
        for point, (low, high) in self.bounds.items():
            node.make_contingent(point, self.origin, low, high, instant=True)
        for point in problem.timepoints:
            if point not in self.bounds and point not in dropped_points:
                node.require(self.origin, point, 0.0)
                node.require(point, problem.end, 0.0)
        for first, second, low, high in self.requirements:
            if first in dropped_points or second in dropped_points:
                continue
            node.require(first, second, low, high)
        for var in problem.variables:
            node.bindings.declare(var, None)
        for c in problem.constraints:
            if isinstance(c, pm.Member) and isinstance(c.expr, pm.Var):
                node.bindings.restrict(c.expr.name, domain_of(c.domain))

        for i, a in enumerate(problem.assertions):
            if a.goal is not None and i not in active_indexes:
                continue
            node.add_written(a, str, str, "problem")
            if isinstance(a, pm.Hold):
                node.require(a.start, a.end, 0.0)
        return node

    # ------------------------------------------------------------ search
    def search(self, active: list[Goal], budget: int, discrepancies: bool = True,
               allowance: int | None = None, repair: Repair | None = None) -> Attempt:
        """A plan for the `active` goals within `budget` partial plans, or none; the search stops
        as soon as it has expanded more than `allowance` (the planning's node limit). A repair
        starts from the actions of the plan it repairs."""
        failures: Counter[str] = Counter()
        try:
            root = self.root(active, repair)
        except DeadEnd as error:
            failures[_generic(str(error))] += 1
            return Attempt(None, 1, True, failures)
        # With `discrepancies`: a short depth-first dive (a twentieth of the budget), enough when
        # the heuristic is right; then limited discrepancy search: plans departing from the
        # heuristic at one choice, then two... so that a wrong early choice costs one
        # discrepancy, not the exhaustion of everything below it (depth-first search's
        # thrashing). Without: depth-first search alone, whose local backtracking suits a
        # problem the heuristic leads through.
        nodes = 0
        for allowed in itertools.chain((INF,), itertools.count(1)):
            dive = allowed == INF and discrepancies
            limit = budget // 20 if dive else budget
            nodes, end, found = self._pass(root, allowed, nodes, limit if allowance is None else min(limit, allowance),
                                           failures=failures)
            if end == "plan":
                return Attempt(found[0], nodes, False, failures)
            if end == "limit" and nodes > limit:
                if dive:
                    continue  # the dive is over: discrepancies now
                return Attempt(None, nodes - 1, False, failures)
            if end == "limit":  # the planning's node limit
                return Attempt(None, nodes, False, failures)
            if end == "done":
                return Attempt(None, nodes, True, failures)
        raise AssertionError("unreachable")

    def improve(self, active: list[Goal], bound: float, budget: int) -> tuple[list[Node], int]:
        """Plans for the `active` goals whose worst-case makespan (`Node.worst_end`) beats `bound`,
        each better than the one before, within `budget` partial plans; and the partial plans
        expanded. Branch and bound over limited discrepancy search: the passes depart from the
        heuristic at no choice, then one, then two..., so the plans nearest the heuristic's come
        first; a partial plan that can no longer beat the best so far is cut."""
        found: list[Node] = []
        nodes = 0
        try:
            root = self.root(active)
        except DeadEnd:
            return found, 1
        for allowed in itertools.count(0):
            nodes, end, better = self._pass(root, allowed, nodes, budget, bound=bound)
            found += better
            bound = better[-1].worst_end() if better else bound
            if end == "limit":
                return found, nodes - 1
            if end == "done":
                return found, nodes
        raise AssertionError("unreachable")

    def _pass(self, root: Node, allowed: float, nodes: int, limit: int, bound: float | None = None,
              failures: Counter[str] | None = None) -> tuple[int, str, list[Node]]:
        """One depth-first pass from `root` departing from the heuristic at `allowed` choices at
        most, counting on from `nodes` partial plans up to `limit`. Without `bound` it stops at
        the first plan; with it, branch and bound: it goes on, each plan found beating the one
        before by IMPROVEMENT. Returns the count, how the pass ended ("plan"; "limit"; "cut": a
        branch was left out for lack of discrepancies; "done": every branch was tried) and the
        plans found; each dead end counts in `failures`."""
        found: list[Node] = []
        stack: list[tuple[Node, Resolver | None, int]] = [(root, None, 0)]
        cut = False
        while stack:
            node, resolver, used = stack.pop()
            if resolver is not None:
                node = node.copy()
            nodes += 1
            if nodes > limit:
                return nodes, "limit", found
            try:
                choice = self._expand(node, resolver, INF if bound is None else bound - IMPROVEMENT)
            except DeadEnd as error:
                if failures is not None:
                    failures[_generic(str(error))] += 1
                continue
            if choice is None:
                found.append(node)
                if bound is None:
                    return nodes, "plan", found
                bound = node.worst_end()
                continue
            cut = _push(stack, node, choice, used, allowed) or cut
        return nodes, "cut" if cut else "done", found

    def reorder(self, active: list[Goal], bound: float, budget: int, waypoints: bool = False,
                enough: Callable[[list[int], Node, int], tuple[bool, int]] | None = None,
                trial: int = REORDER_TRIAL) -> tuple[list[Node], int]:
        """Plans for the `active` goals whose worst-case makespan beats `bound`, each better than
        the one before, found by taking the goals up in other orders within `budget` partial
        plans. The search plans first for the goal that may come earliest; among goals that may
        all come as early (the photos of a tour), the order it takes them up in is the order of
        the tour. An iterated local search over that order: first improvement over every segment
        reversed (2-opt), then every goal moved elsewhere, each order searched depth first within
        `trial` partial plans; at a local optimum, a seeded random reversal of the current
        order and on from there (the same problem gives the same plans). With `waypoints`, each
        order's plan is measured once its waits are used (`waypoints`, within REORDER_TRIAL more).
        With `enough`, asked of each better order with its plan (and the partial plans it may still spend),
        answering whether to stop and the partial plans it spent, the search stops when it says so."""
        found: list[Node] = []
        try:
            root = self.root(active)
        except DeadEnd:
            return found, 1
        # The goals that may all come as early, in the order the search takes them up when no
        # order is given (the lower priority first: the photos before the communications).
        ties: dict[float, list[tuple[float, int]]] = {}
        for a in root.assertions:
            if a.owner == "problem" and a.goal is not None:
                ties.setdefault(round(root.bounds("origin", a.start)[0], 6), []).append((a.goal.priority, a.line))
        largest: list[tuple[float, int]] = max(ties.values(), key=len) if ties else []
        tour = [line for _, line in sorted(largest)]
        if len(tour) < 2:
            return found, 1
        context = self.context
        chance = random.Random(len(tour))
        nodes = 1

        def makespan(order: list[int]) -> float:
            """The worst-case makespan of the plan the order leads to (inf: none within the trial)."""
            nonlocal nodes, bound
            self.context = replace(context, goal_order={line: rank for rank, line in enumerate(order)})
            # Depth first without a bound: a bound makes it thrash far from where the order leads.
            tried = self.search(active, min(trial, budget - nodes), discrepancies=False)
            nodes += tried.nodes
            if tried.node is None:
                return INF
            ways, used = self.waypoints(active, tried.node, INF, min(REORDER_TRIAL, max(0, budget - nodes))) if (
                waypoints) else ([], 0)
            nodes += used
            best = ways[-1] if ways else tried.node
            end = best.worst_end()
            if end < bound - IMPROVEMENT:
                found.append(best)
                bound = end
                if enough is not None:
                    stop, used = enough(order, best, max(0, budget - nodes))
                    nodes += used
                    if stop:
                        raise _Enough
            return end

        def neighbours(order: list[int]) -> Iterator[list[int]]:
            for i, j in itertools.combinations(range(len(order)), 2):
                yield order[:i] + order[i:j + 1][::-1] + order[j + 1:]
            for i, j in itertools.permutations(range(len(order)), 2):
                if abs(i - j) > 1:  # an adjacent move is a reversal of two
                    moved = order[:]
                    moved.insert(j, moved.pop(i))
                    yield moved

        try:
            current, value = tour, bound
            while nodes < budget:
                for order in neighbours(current):
                    if nodes >= budget:
                        break
                    end = makespan(order)
                    if end < value - IMPROVEMENT:
                        current, value = order, end
                        break
                else:  # a local optimum: start again from a random reversal of it
                    i, j = sorted(chance.sample(range(len(current)), 2))
                    current = current[:i] + current[i:j + 1][::-1] + current[j + 1:]
                    value = makespan(current)
        except _Enough:
            pass
        finally:
            self.context = context
        return found, nodes

    def tour_in_time(self, active: list[Goal], node: Node, budget: int) -> tuple[Node | None, int]:
        """A plan for the `active` goals, which the search in the heuristic's order of taking them
        up did not find, when the mission's latest end is what keeps it from them: `reorder`'s
        local search over the orders, on the problem with that end lifted (where an order too
        slow for the mission still has a plan and a makespan, so the search can walk towards
        faster tours), until a plan found there takes the end back: the problem's plan. None if
        no tour does within `budget`; and the partial plans spent. `node`, a plan for some of the
        goals, sizes each order's trial (`order_trial`)."""
        latest = pm.latest_end(self.problem)
        if latest == INF:
            return None, 0
        in_time: list[Node] = []

        def ends_in_time(order: list[int], plan: Node, left: int) -> tuple[bool, int]:
            bounded = plan.copy()
            try:
                bounded.require(self.origin, self.problem.end, -INF, latest)
            except DeadEnd:
                return False, 0
            in_time.append(bounded)
            return True, 0

        lifted = self.for_problem(pm.without_latest_end(self.problem))
        _, spent = lifted.reorder(active, INF, budget, enough=ends_in_time, trial=order_trial(node))
        return (in_time[0] if in_time else None), spent

    def waypoints(self, active: list[Goal], node: Node, bound: float, budget: int) -> tuple[list[Node], int]:
        """Plans for the `active` goals made from `node`'s by splitting its moves at waypoints
        (`waypoints`: where the robot waits, it goes part of the way to its next place), each
        better than the one before, within `budget` partial plans; and the partial plans spent.
        Better (`_sooner`): a shorter worst-case makespan, or the same one with the goals met
        sooner (the sum of their dates: the time a wait saves comes out at the end only once the
        waits after it are used too); the last plan's makespan beats `bound` or it is not
        returned. First improvement: a split that makes the plan better is kept, and the moves
        are looked at again."""
        found: list[Node] = []
        nodes = 0
        while self.movers and nodes < budget:
            better, used = self._split_one_move(active, node, budget - nodes)
            nodes += used
            if better is None:
                break
            node = better
            found.append(node)
        return ([found[-1]] if found and found[-1].worst_end() < bound - IMPROVEMENT else []), nodes

    def without_round_trips(self, active: list[Goal], node: Node, budget: int) -> tuple[Node, int]:
        """`node`'s plan without the pairs of actions the second of which only undoes the first
        (`round_trips`: an object put down and picked up again, nothing else using it
        meanwhile), searched as a repair of the plan within `budget` partial plans, when the
        repaired plan has fewer actions and ends no later at worst; and the partial plans spent.
        A depth-first search reaches such plans when a need's other producers lie down a
        longer path: each round trip it inserts needs another before it, until one links."""
        pairs = round_trips(node)
        if not pairs or budget <= 0:
            return node, 0
        plan, _ = self.extract(node, exact=False)
        dropped = {ident for pair in pairs for ident in pair}
        tried = self.search(active, budget, True, None,
                            Repair(plan, tuple(a.id for a in plan.actions if a.id not in dropped)))
        better = tried.node
        if (better is None or len(better.instances) >= len(node.instances)
                or better.worst_end() > node.worst_end() + TOLERANCE):
            return node, tried.nodes
        return better, tried.nodes

    def merge_drive_throughs(self, active: list[Goal], node: Node, budget: int) -> tuple[Node, int]:
        """`node`'s plan with each waypoint the robot drives through without stopping merged
        back into one move (`waypoints.drive_throughs`), where the plan is no worse for it: a
        split may have led the search to a better plan in which its waypoint serves nothing,
        and the plan should not keep a bend no one needs. The partial plans spent too."""
        nodes = 0
        current = self._lateness(active, node)
        merging = True
        while merging and nodes < budget:
            merging = False
            plan, _ = self.extract(node, exact=False)
            for first, second, mover in wp.drive_throughs(plan, self.movers):
                tried = self.search(active, min(WAYPOINT_TRIAL, budget - nodes), True, None,
                                    wp.merge(plan, first, second, mover))
                nodes += tried.nodes
                if tried.node is not None and not _sooner(current, late := self._lateness(active, tried.node)):
                    node, current, merging = tried.node, late, True  # no worse
                    break
                if nodes >= budget:
                    break
        return node, nodes

    def _split_one_move(self, active: list[Goal], node: Node, budget: int) -> tuple[Node | None, int]:
        """The first plan better than `node`'s made by splitting one of its moves at a waypoint,
        or None; and the partial plans spent. The moves in the order they are dispatched, each after an idle time
        only, its waypoints farthest first, a first leg too slow for the idle time not searched."""
        plan, _ = self.extract(node, exact=False)
        current = self._lateness(active, node)
        reached = {name: wp.places(plan, mover) for name, mover in self.movers.items()}
        nodes = 0
        for move in plan.ordered():
            mover = self.movers.get(move.task)
            idle = wp.idle_time(plan, move) if mover is not None else 0.0
            if mover is None or idle <= EPS:
                continue
            for point in wp.candidates(move, mover, reached[move.task]):
                if not wp.first_leg_fits(move, mover, point, idle):
                    continue
                if nodes >= budget:
                    return None, nodes
                tried = self.search(active, min(WAYPOINT_TRIAL, budget - nodes), True, None,
                                    wp.split(plan, move, mover, point))
                nodes += tried.nodes
                if tried.node is not None and _sooner(self._lateness(active, tried.node), current):
                    return tried.node, nodes
        return None, nodes

    @staticmethod
    def _lateness(active: list[Goal], node: Node) -> tuple[float, float]:
        """A plan's worst-case makespan, and the sum of the earliest dates its goals are met at."""
        met = sum(node.bounds("origin", point)[0] for g in active for point in pm.assertion_timepoints(g.hold))
        return node.worst_end(), met

    @functools.cached_property
    def movers(self) -> dict[str, wp.Mover]:
        return wp.movers(self.domain)

    def _expand(self, node: Node, resolver: Resolver | None, beyond: float = INF) -> list[Resolver] | None:
        """`resolver` applied to `node` (a copy of its parent), then the resolvers of its next flaw,
        in the heuristic's order (None: the partial plan is a plan). DeadEnd when it has no
        completion, or (branch and bound) when its worst-case makespan already reaches `beyond`."""
        if resolver is not None:
            resolver.apply(node)
        if beyond < INF and node.worst_end() >= beyond:
            raise DeadEnd("no better plan below")
        choice = select(node)
        if choice is not None and self.heuristic == LEAST_ROOM and all(r.kind == "order" for r in choice):
            choice = choice[::-1]
        return choice

    # ------------------------------------------------------------ output
    def extract(self, node: Node, exact: bool) -> tuple[Plan, tuple[str, ...]]:
        notes: list[str] = []
        durations = dict(node.durations)
        if exact:
            for instance_id, spec in node.durations.items():
                if not spec.contingent:
                    continue
                instance = node.instances[instance_id]
                key = tuple(sorted((local, value) for local in instance.task.params + instance.task.variables
                                   if (value := node.bindings.value(instance.var(local))) is not None))
                tight = exact_duration(instance.task, key)
                if tight is not None and spec.low - 1e-6 <= tight[0] <= tight[1] <= spec.high + 1e-6:
                    # A duration only nature decides may be a little wider than the solver's optimum.
                    durations[instance_id] = replace(spec, low=max(spec.low, tight[0] - 1e-6),
                                                     high=min(spec.high, tight[1] + 1e-6))
        # Nature's timepoints: the problem's contingent instants and the contingent actions' ends.
        instants = {point: (self.origin, low, high) for point, (low, high) in self.bounds.items()}
        ends = {}
        for instance_id, spec in durations.items():
            instance = node.instances[instance_id]
            if spec.contingent:
                ends[instance.end] = (instance.start, spec.low, spec.high)
        if self.context.controllability == PSEUDO:
            network, note = pseudo_network(node, ends, instants)
        else:
            network, note = strong_network(node, ends | instants)
        if note:
            notes.append(note)
        links = ends | instants
        # (The controllable durations are among node.original: the search required them.) The
        # network's constraints are differences of dates, so its earliest schedule puts every
        # date at its least at once: it is the earliest completion, which no solver improves
        # (a linear program over the same rows found it to the last digit on M1-M4: it went).
        schedule = network.earliest_schedule()
        schedule.pop("origin", None)
        schedule = {name: max(0.0, date) if abs(date) < 1e-6 else date for name, date in schedule.items()}
        uncontrolled, assumed = {}, {}
        for point, (anchor, low, high) in links.items():
            uncontrolled[point] = (schedule[anchor] + low, schedule[anchor] + high)
            if point in network.index:  # a pseudo-controllable plan's instant, at the date it assumes
                assumed[point] = schedule[point]
            schedule.pop(point, None)
        actions = []
        for instance in sorted(node.instances.values(), key=lambda i: int(i.id.split("#")[1])):
            task = instance.task
            spec = durations[instance.id]
            args = tuple(_chosen(node.bindings.value(instance.var(p))) for p in task.params)
            # Every local variable the plan pins (a symbol, or a number such as `?b2 =. ?b - 1`
            # once ?b is chosen): the validator evaluates the assertions that use it.
            values = tuple((v, value) for v in task.variables
                           if (value := node.bindings.value(instance.var(v))) is not None)
            actions.append(Action(instance.id, task.name, args, instance.start, instance.end,
                                  schedule[instance.start], (spec.low, spec.high), spec.contingent,
                                  task.preemptible, network.window(instance.start), values))
        names = {i.start: i.id for i in node.instances.values()} | {i.end: i.id for i in node.instances.values()}
        orderings = sorted({(a, b, low) for a, b, low, _ in node.original
                            if low > -INF and a in names and b in names and names[a] != names[b]})
        causal = tuple(Link(_where(node.assertions[k.producer], node), _where(node.assertions[k.consumer], node),
                           node.assertions[k.consumer].attribute,
                           _chosen(node.bindings.value(node.assertions[k.producer].value)))
                      for k in node.links if node.assertions[k.producer].owner != node.assertions[k.consumer].owner)
        bindings = {v: _some_value(node.bindings, v) for v in self.problem.variables}
        free = tuple(v for v in self.problem.variables if node.bindings.value(v) is None)
        plan = Plan(self.domain.name, self.problem.name, tuple(actions), tuple(orderings), causal, schedule,
                    uncontrolled, bindings, self.context.controllability, self.now, assumed, free=free)
        return plan, tuple(notes)


def round_trips(node: Node) -> list[tuple[str, str]]:
    """The pairs (first, second) of the plan's task instances where the second only undoes the
    first: each event of the second gives back, on the same attribute instance, the value an event
    of the first changed, linked from it, and nothing but the second needs what the first gives
    (an object put down, then picked up again from where it was put, the gripper emptied and
    filled again)."""
    resolve = node.bindings.resolve
    events: dict[str, list[Assertion]] = {}
    for a in node.assertions:
        if a.kind == "event" and a.owner != "problem":
            events.setdefault(a.owner, []).append(a)
    linked = {(link.producer, link.consumer) for link in node.links}
    needers: dict[str, set[str]] = {}  # task instance -> the others its events give a value to
    for link in node.links:
        producer, consumer = node.assertions[link.producer], node.assertions[link.consumer]
        if producer.owner != consumer.owner:
            needers.setdefault(producer.owner, set()).add(consumer.owner)

    def undoes(later: Assertion, earlier: Assertion) -> bool:
        return (later.attribute == earlier.attribute and (earlier.id, later.id) in linked
                and [resolve(x) for x in later.args] == [resolve(x) for x in earlier.args]
                and later.before is not None and earlier.before is not None
                and resolve(later.before) == resolve(earlier.value) and resolve(later.value) == resolve(earlier.before))

    found: list[tuple[str, str]] = []
    paired: set[str] = set()
    for first, changes in events.items():
        users = needers.get(first, set())
        if len(users) != 1:
            continue
        (second,) = users
        undoing = events.get(second, [])
        if (len(undoing) == len(changes) and second not in paired
                and all(any(undoes(later, earlier) for earlier in changes) for later in undoing)):
            found.append((first, second))
            paired.update((first, second))
    return found


def _chosen(value: Term | None) -> float | str:
    if value is None:
        return "?"
    return value


def _some_value(bindings: Bindings, var: str) -> float | str:
    """The variable's value, or one its domain allows when no assertion of the plan uses it (the
    initial facts of a dropped goal)."""
    value = bindings.value(var)
    if value is not None:
        return value
    domain = bindings.domain[bindings.root(var)]
    if isinstance(domain, frozenset):
        return min(domain)
    if isinstance(domain, tuple):
        return min(max(0.0, domain[0]), domain[1])
    return 0.0


def _where(a: Assertion, node: Node) -> str:
    return f"{a.owner}: {a.text(node.bindings)}"


Links = dict[str, tuple[str, float, float]]  # nature's timepoint -> (the point it hangs from, low, high)


def _add(network: STN, a: str, b: str, low: float, high: float) -> None:
    try:
        network.add(a, b, low, high)
    except Inconsistent:  # rounding only: the search's network, with its tolerance, took it
        low, high = low - 1e-6 if low > -INF else -INF, high + 1e-6 if high < INF else INF
        network.add(a, b, low, high)


def translated_network(node: Node, anchors: Links) -> STN:
    """The plan's timepoints but those hanging from another (`anchors`), every requirement
    rewritten on the points they hang from, for nature's worst offsets."""
    network = STN()
    for name in node.stn.names:
        if name not in anchors:
            network.point(name)
    for a, b, low, high in node.original:
        pa, pb, new_low, new_high = translate(anchors, a, b, low, high)
        if pa != pb:
            _add(network, pa, pb, new_low, new_high)
    return network


def strong_network(node: Node, links: Links) -> tuple[STN, str]:
    """The plan's own timepoints, every requirement rewritten for nature's worst case."""
    return translated_network(node, links), ""


def pseudo_network(node: Node, ends: Links, instants: Links) -> tuple[STN, str]:
    """The plan's own timepoints and the problem's contingent instants, every requirement
    rewritten for the contingent durations' worst case, and each instant at its latest date: the
    executive cannot see a window open, so it waits until the window surely is. The plan carries
    these dates (`assumed`)."""
    network = translated_network(node, ends)
    latest = network.copy()
    try:
        for point, (anchor, _, high) in sorted(instants.items()):
            _add(latest, anchor, point, high, high)
        return latest, ""
    except Inconsistent:
        for point, (anchor, low, high) in sorted(instants.items()):
            _add(network, anchor, point, low, high)
        return network, ("nature's instants at their latest do not fit the plan together: the dispatch "
                         "assumes the earliest dates of them that fit")


# ---------------------------------------------------------------- resolvers and flaw choice


@dataclass(frozen=True)
class Resolver:
    """One way to resolve a flaw: a link, an insertion, an ordering, a separation or a binding."""

    kind: str  # link | insert | order | apart | bind
    need: int = -1
    producer: int = -1
    task: pm.Task | None = None
    index: int = -1
    first: str = ""
    second: str = ""
    gap: float = 0.0
    terms: tuple[Term, Term] = ("", "")

    def apply(self, node: Node) -> None:
        if self.kind == "link":
            node.link(node.assertions[self.producer], node.assertions[self.need])
        elif self.kind == "insert":
            assert self.task is not None
            own_from = len(node.assertions)  # the instance's assertions follow, one for each of the task's
            node.insert(self.task)
            # By position: two calls of one macro give a task events alike down to their line.
            node.link(node.assertions[own_from + self.index], node.assertions[self.need])
        elif self.kind == "order":
            node.require(self.first, self.second, self.gap)
        elif self.kind == "apart":
            node.bindings.keep_apart(*self.terms)
        elif self.kind == "bind":
            node.bound(node.bindings.unify(*self.terms))


T = TypeVar("T")
R = TypeVar("R")


def each_that_fits(node: Node, items: Sequence[T], put: Callable[[Node, T], R]) -> tuple[Node, list[R]]:
    """A copy of `node` with `put` of each item, leaving out those that raise DeadEnd (each tried
    on the node the ones before it left), and what `put` gave for those kept. Most often all of
    them fit: they are put in one copy, the very node one copy per item would give."""
    try:
        trial = node.copy()
        return trial, [put(trial, item) for item in items]
    except DeadEnd:
        pass
    kept = []
    for item in items:
        trial = node.copy()
        try:
            kept.append(put(trial, item))
        except DeadEnd:
            continue
        node = trial
    return node, kept


def select(node: Node) -> list[Resolver] | None:
    """The resolvers of the flaw to solve next (forced ones are applied on the way), or None
    when the plan has no flaw left: it is a solution."""
    while True:
        best: list[Resolver] | None = None
        chosen: Threat | None = None
        fewest = INF
        forced = False
        # Each threat is read as it comes, so a forced resolver applied here counts for the next.
        for threat in node.threats():
            if threat.before and threat.after:
                count = 2  # not forced; the apart resolvers it may have are only listed if it is chosen
            else:
                resolvers = threat_resolvers(node, threat)
                if not resolvers:
                    producer = node.assertions[threat.link.producer]
                    consumer = node.assertions[threat.link.consumer]
                    event = threat.event
                    raise DeadEnd(f"{event.text(node.bindings)} of {_owner(event.owner)} may come while "
                                  f"{_owner(consumer.owner)} needs the {consumer.attribute} value "
                                  f"{_owner(producer.owner)} gives it")
                if len(resolvers) == 1:
                    # Constraints only tighten: a threat with one resolver left keeps just that one.
                    resolvers[0].apply(node)
                    forced = True
                    continue
                count = len(resolvers)
            if count < fewest:
                fewest, chosen = count, threat
        if forced:
            continue
        if chosen is not None:
            best = threat_resolvers(node, chosen)
        for a, b in node.resource_conflicts():
            resolvers = [r for r in (Resolver("order", first=a.end, second=b.start),
                                     Resolver("order", first=b.end, second=a.start))
                         if node.allows(r.first, r.second, 0.0)]
            if not resolvers:
                raise DeadEnd(f"{a.owner} and {b.owner} need more {a.attribute} than there is")
            if len(resolvers) == 1:
                resolvers[0].apply(node)
                forced = True
                break
            if best is None or len(resolvers) < len(best):
                best = resolvers
        if forced:
            continue
        if best is not None:
            return best
        picked = pick_need(node)
        if picked is None:
            return unbound(node)
        need, resolvers = picked
        if not resolvers:
            raise DeadEnd(f"nothing can give {need.text(node.bindings)} to {need.owner}")
        if len(resolvers) == 1:
            resolvers[0].apply(node)
            continue
        return resolvers


def threat_resolvers(node: Node, threat: Threat) -> list[Resolver]:
    """The ways to keep the threat's event off the link: the orders still possible, as
    Node.threats read them (an order that already holds leaves no threat), then keeping arguments
    apart."""
    producer, consumer = node.assertions[threat.link.producer], node.assertions[threat.link.consumer]
    event = threat.event
    gap = EPS if consumer.kind == "event" else 0.0
    options = []
    if threat.before:
        options.append(Resolver("order", first=event.start, second=producer.start, gap=EPS))
    if threat.after:
        options.append(Resolver("order", first=consumer.end, second=event.start, gap=gap))
    # The order leaving the most room first.
    options.sort(key=lambda r: -(node.bounds(r.first, r.second)[1] - r.gap))
    for x, y in zip(event.args, consumer.args, strict=False):
        rx, ry = node.bindings.resolve(x), node.bindings.resolve(y)
        if (is_var(rx) or is_var(ry)) and rx != ry and node.bindings.possibly_equal(x, y):
            options.append(Resolver("apart", terms=(x, y)))
    return options


def pick_need(node: Node) -> tuple[Assertion, list[Resolver]] | None:
    """The open condition to solve next, with its resolvers: the newest task's first (to bind its
    arguments early; the oldest task's with OLDEST_TASK_FIRST), the one with the fewest resolvers
    among them (a pan-tilt unit's tilt that only a new pan-tilt move gives goes before its pan,
    which the same move should give too); then the problem's required assertions; then its goals,
    those that may come earliest first."""
    if not node.open:
        return None
    mine = [node.assertions[i] for i in node.open if node.assertions[i].owner != "problem"]
    if mine:
        # Tasks come in the order they are numbered, each with its assertions: the newest task's
        # assertions are the last ones.
        first = min if node.ctx.oldest_task_first else max
        owner = first(mine, key=lambda a: a.id).owner
        # Counted first, ranked only for the need chosen.
        best: tuple[Assertion, list[Assertion], list[tuple[pm.Task, int]]] | None = None
        for need in sorted((a for a in mine if a.owner == owner), key=lambda a: a.id):
            existing, insertions = node.producers(need), node.insertions(need)
            count = len(existing) + len(insertions)
            if best is None or count < len(best[1]) + len(best[2]):
                best = (need, existing, insertions)
            if count <= 1:
                break
        assert best is not None
        return best[0], need_resolvers(node, *best)

    ranks = node.ctx.goal_order

    def order(a: Assertion) -> tuple[float, float, int, float, int]:
        if a.goal is None:
            return (0.0, 0.0, 0, 0.0, a.id)
        return (1.0, node.bounds("origin", a.start)[0], ranks.get(a.line, 0), a.goal.priority, a.id)
    need = min((node.assertions[i] for i in node.open), key=order)
    return need, need_resolvers(node, need, node.producers(need), node.insertions(need))


def need_resolvers(node: Node, need: Assertion, existing: list[Assertion],
                   insertions: list[tuple[pm.Task, int]]) -> list[Resolver]:
    """The need's resolvers, ranked, from its producers and the tasks that could give it. A task
    that gives the value back (`Context.restoring`: a probe lowered and raised again, a move
    from STILL to STILL) comes last: it needs the value itself at its start, so the link its own need would take
    serves the need as well, and inserted first it only adds an action (a probe of a plot the plan
    has no goal for, whose free coordinates the insertion binds to where the robot is)."""
    restoring = node.ctx.restoring
    # A task whose change the needing task's own change undoes (an object put down, for the pick
    # up that needs it there, from the hand the pick up puts it back in): the two are a round
    # trip, which only pays when nothing else gives the value; tried first, each round trip
    # needs another, and the plan fills with put-downs and pick-ups until the search gives up.
    undone = node.bindings.value(need.value) if need.kind == "event" else None
    round_trips = {(task.name, index) for task, index in insertions
                   if isinstance(event := task.assertions[index], pm.Event) and isinstance(event.before, pm.Sym)
                   and undone is not None and event.before.name == undone}
    inserts = [Resolver("insert", need=need.id, task=task, index=index) for task, index in insertions
               if (task.name, index) not in restoring and (task.name, index) not in round_trips]
    restorers = [Resolver("insert", need=need.id, task=task, index=index) for task, index in insertions
                 if (task.name, index) in restoring or (task.name, index) in round_trips]
    if not existing:
        return inserts + restorers
    siblings = {node.assertions[k.producer].owner for k in node.links
                if node.assertions[k.consumer].owner == need.owner and need.owner != "problem"} - {"problem"}
    changers = node.changers(need)
    givable: dict[int, bool] = {}  # open need -> may an event give it with the plan's bindings (asked once)

    def risky(producer: Assertion) -> bool:
        """Does the link leave the plan worse off than a new task would? With the arguments the
        link binds: an event may change the value between the producer and the need (a link to a
        value set long ago, the pan-tilt unit STRAIGHT at the start, often may, and a new task
        giving it afresh is the better bet), or another need could then be given by no event of
        the plan although it could before (a robot to look at a place, linked to the dock where it
        stands, binds the place to the dock, where the object it is to pick up is not: a move
        there, then the look, is the better bet; a search trying the link first sinks into
        putting the object down at the dock, which needs it picked up first...)."""
        pairs = [*zip(producer.args, need.args, strict=False), (producer.value, need.wanted)]
        resolve = node.bindings.resolve
        linked, bound = node.bindings, set[str]()
        if any(resolve(a) != resolve(b) for a, b in pairs):  # else the link binds nothing: no copy
            linked = node.bindings.copy()
            try:
                bound = {v for a, b in pairs for v in linked.unify(a, b)}
            except DeadEnd:
                return False  # the link fails when applied, and is counted there
        possibly_equal = linked.possibly_equal
        if any(e.id != producer.id and all(possibly_equal(x, y) for x, y in zip(e.args, need.args, strict=False))
               and not node.surely_before(e.start, producer.start, EPS) for e in changers):
            return True
        for i in node.open if bound else ():
            other = node.assertions[i]
            if i == need.id or not any(t in bound for t in (*other.args, other.wanted)):
                continue
            if i not in givable:
                givable[i] = bool(node.producers(other))
            if givable[i] and not node.producers(other, linked) and not _one_task_gives(node, other, linked):
                return True
        return False

    ranked = sorted((risky(e), e.owner not in siblings, -node.bounds("origin", e.start)[0], -e.id, e.id)
                    for e in existing)
    links = [(r[0], Resolver("link", need=need.id, producer=r[-1])) for r in ranked]
    # Safe links first, then new tasks, then links something may undo, then tasks giving it back.
    return [r for risky, r in links if not risky] + inserts + [r for risky, r in links if risky] + restorers


def _one_task_gives(node: Node, need: Assertion, bindings: Bindings) -> bool:
    """Could one new task give `need` (with `bindings`), each of the task's own needs given by an
    event of the plan that may come before `need`? A move to where the robot must stand can (it
    drives from wherever the robot is); putting an object down where it must be cannot when the
    plan picks it up only later (the put-down needs it in hand first): a link leaving a need to
    such a task sends the search a long way."""
    wanted = [bindings.resolve(t) for t in (*need.args, need.wanted)]
    for task, index in node.ctx.producers.get(need.attribute, []):
        gives = task.assertions[index]
        assert isinstance(gives, pm.Event)
        known: dict[str, Term] = {}  # the task's variables the need's values fix
        fits = True
        for expr, term in zip((*gives.args, gives.after), wanted, strict=True):
            if is_var(term):
                continue
            if isinstance(expr, pm.Var):
                fits = fits and same_value(known.setdefault(expr.name, term), term)
            elif (constant := valued(expr)) is not None:
                fits = fits and same_value(constant, term)
        if fits and all(_given_before(node, a, known, need, bindings) for a in task.assertions
                        if not isinstance(a, pm.Use)):
            return True
    return False


def _given_before(node: Node, need: pm.Hold | pm.Event, known: Mapping[str, Term], before: Assertion,
                  bindings: Bindings) -> bool:
    """Could an event of the plan that may come before the assertion `before` give a new task's
    `need`, its variables valued as `known` says (the others free)?"""
    terms = [valued(x, known) for x in (*need.args, need.before if isinstance(need, pm.Event) else need.value)]
    possibly_equal = bindings.possibly_equal
    return any(event_id != before.id and node.allows(e.start, before.start, 0.0)
               and all(t is None or possibly_equal(x, t) for x, t in zip((*e.args, e.value), terms, strict=False))
               for event_id in node.events.get(need.attribute, ()) for e in (node.assertions[event_id],))


def unbound(node: Node) -> list[Resolver] | None:
    """A parameter still free once every condition is met gets a value from its domain."""
    for instance in node.instances.values():
        for local in instance.task.params:
            var = instance.var(local)
            if node.bindings.value(var) is not None:
                continue
            domain = node.bindings.domain[node.bindings.root(var)]
            values: list[Term]
            if isinstance(domain, frozenset):
                values = sorted(domain)
            elif isinstance(domain, tuple):
                values = []
                for v in (0.0, domain[0], domain[1]):
                    if domain[0] <= v <= domain[1] and abs(v) < INF:
                        values.append(v)
                        break
            else:
                values = []
            if not values:
                raise DeadEnd(f"{var} has no value to take")
            return [Resolver("bind", terms=(var, v)) for v in values]
    # A task whose duration its parameters leave open (Modele2's distance symbol ?D when a
    # distance table says nothing of a place) takes a value for its free symbolic variables:
    # a plan has no action of unbounded duration.
    for instance in node.instances.values():
        if instance.id in node.durations:
            continue
        for local in instance.task.variables:
            var = instance.var(local)
            domain = node.bindings.domain[node.bindings.root(var)]
            if node.bindings.value(var) is None and isinstance(domain, frozenset):
                return [Resolver("bind", terms=(var, v)) for v in sorted(domain)]
        raise DeadEnd(f"{instance.id}'s duration is not bounded by its task's constraints")
    return None
