"""FTplan, the fault-tolerant planning component of seed 004 (ch. 3).

It sits between the supervisor and several planners with diversified models or heuristics and
tolerates design faults in planning knowledge with four detection mechanisms:

- the planning watchdog (a late, crashed or plan-less planner: killed and restarted);
- the plan analyzer (constraints written apart from the models, checked before execution);
- action-failure detection (from the execution reports);
- on-line goal verification (FTplan's own state, after each report and when a plan ends);

and two recovery policies, written line for line after the seed's algorithms: successive
planning (Fig 3.1) and concurrent planning (Fig 3.2). Every step taken is recorded in `trace`
with the figure's line number, so that a run can be read against the figure.

Mission time and planning. Planning wall time is charged to mission time. By default the charge
is deterministic: a cost model on the partial plans the planner expanded (`CostModel`), and the
watchdog judges that charge, so that a run depends on its seed only; concurrent planning then
lets the plan of the lowest charge count as the first found. With `timing="wall"` the measured
wall time is charged, the watchdog is a wall-clock one, and the first plan to arrive wins. In
both modes a planner silent for `wall_limit` wall seconds is killed: that is how a hung one ends.
`arrivals` is where the watchdog is judged, for both policies.

Two departures from the figures, both where they are silent:
- a planner that answers "no plan" or crashes is killed and restarted as a late one (§3.2.2.2:
  "si la planification prend trop de temps ou si aucune solution n'a été trouvée, FTplan tue le
  processus IxTeT en échec, le relance, puis bascule sur un autre modèle"); Fig 3.1 counts it as
  a late one (lines 20-21), Fig 3.2, where the watchdog's expiry ends the mission, as an invalid
  plan (lines 16-20);
- the loops of Fig 3.1/3.2 end when goals remain after a round in which every planner gave a
  valid plan, carried out to its end, that met no goal (they all leave those goals aside): the
  remaining goals are reported missed instead of replanning until their deadlines pass.
  Concurrent planning runs one plan per round: a planner whose last plan met no goal sits out
  the next rounds until a plan meets one. A round with a failure goes on as the figures say;
  its failures cost mission time, so the goals' deadlines end it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Generator, Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Protocol

from specc.runtime.ftplan.analyzer import Violation, analyse
from specc.runtime.ftplan.config import FtPlanConfig, PlannerConfig
from specc.runtime.ftplan.execution import Execution, Executor, Report
from specc.runtime.ftplan.planners import Answer, Watchdog
from specc.runtime.ftplan.state import Goal, Running, SystemState, consequences, fact_list
from specc.runtime.ftplan.view import View, same_fact
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import Plan, Repair, format_call
from specc.runtime.planner.replan import replanning_problem

MISSION_FAILED_IN_TIME = "mission failure: no valid plan found in time"  # Fig 3.1 line 24, Fig 3.2 line 24
MISSION_FAILED = "mission failure: no valid plan found"  # Fig 3.2 line 20


class MissionFailure(Exception):
    """The mission exception: the redundant planners are exhausted. `at`: the mission time it
    came at, when the execution layer raised it (the run's horizon), later than FTplan's own."""

    def __init__(self, why: str, at: float | None = None):
        super().__init__(why)
        self.at = at


# ---------------------------------------------------------------- planners, as FTplan sees them


class PlannerPool(Protocol):
    """The planners, each in its own process (`pools.ProcessPool`) or in this one (`pools.LocalPool`)."""

    names: tuple[str, ...]

    def request(self, name: str, problem: pm.Problem, now: float, repair: Repair | None = None) -> None:
        """Send a planning request (envoyer(demande_plan) à k); returns at once. With `repair`, a
        request to repair the plan under way (`Planner.repair`)."""
        ...

    def next_answer(self, names: Collection[str], wall_timeout: float) -> Answer | None:
        """The first answer of one of `names` (requested and not yet answered) within
        `wall_timeout` wall seconds; None when none came."""
        ...

    def abandon(self, name: str) -> None:
        """Kill the planner and start it again: its planning under way, if any, is dropped (Fig 3.2
        line 13), and a planner judged failed starts afresh (§3.2.2.2)."""
        ...


@dataclass(frozen=True)
class CostModel:
    """Deterministic charge of a planning to mission time: IxTeT's cycle is of the order of two
    seconds (§3.2.2.2); a partial plan costs a little more."""

    base: float = 2.0  # seconds per planning
    per_node: float = 0.01  # seconds per partial plan expanded

    def seconds(self, answer: Answer) -> float:
        return self.charge(answer.nodes)

    def charge(self, nodes: int) -> float:
        return self.base + self.per_node * nodes

    def nodes_within(self, seconds: float) -> int:
        """The most partial plans a planning may expand and still be charged at most `seconds`."""
        nodes = max(0, math.floor((seconds - self.base) / self.per_node))
        while self.charge(nodes + 1) <= seconds:  # the division's rounding, either way
            nodes += 1
        while nodes > 0 and self.charge(nodes) > seconds:
            nodes -= 1
        return nodes


# Under the cost model a planner stops by itself once its answer would be late (`planners_as_run`):
# the wall-clock kill is then for a planner that hangs, and must not catch a slow machine.
HUNG_PLANNER_SECONDS = 60.0


def planners_as_run(config: FtPlanConfig, timing: str, cost: CostModel | None = None) -> tuple[PlannerConfig, ...]:
    """`config`'s planners as FTplan runs them. Under the cost model (`timing="model"`) each stops
    once it has expanded more partial plans than the watchdog pays for: its answer would be late
    whatever it found, and where it stops does not depend on the machine's speed, so a run
    depends on its seed only. With the wall clock, the watchdog stops them."""
    if timing != "model":
        return config.planners
    limit = (cost or CostModel()).nodes_within(config.watchdog)
    return tuple(replace(planner, node_limit=limit) for planner in config.planners)


# ---------------------------------------------------------------- results


@dataclass(frozen=True)
class Event:
    """One entry of FTplan's log: what happened at which mission time."""

    time: float
    kind: str  # plan-request, plan, watchdog, invalid-plan, execute, report, action-failed, goal-met,
    # goals-open, goal-missed, safe-state, operator, mission-failure, mission-end
    text: str
    planner: str = ""


@dataclass
class MissionResult:
    met: list[str]
    missed: dict[str, str]  # goal -> why
    failure: str  # the mission exception's message, "" when none was raised
    now: float  # mission time at the end
    plannings: int  # planning requests sent (repairs apart)
    rounds: int  # planning rounds: a request (Fig 3.1 line 9), or one to every planner at once (Fig 3.2 line 5)
    planner_failures: int  # watchdog expiries, crashes, plan-less answers, invalid plans
    events: list[Event]
    trace: list[tuple[int, str]]  # (line of Fig 3.1 / 3.2, what happened)
    repairs: int = 0  # plan repairs asked after an action failure (`repair: on` planners)
    repaired: int = 0  # of them, those that gave a plan carried out

    @property
    def replannings(self) -> int:
        """Planning rounds after the first (seed 004 §4.1.4's R; model switches count too)."""
        return max(0, self.rounds - 1)

    @property
    def success(self) -> bool:
        return not self.failure and not self.missed


# ---------------------------------------------------------------- the component


@dataclass
class FtPlan:
    config: FtPlanConfig
    problem: pm.Problem  # the mission, in the vocabulary of FTplan's state rules
    pool: PlannerPool
    executor: Executor
    analyzer: bool = True  # the plan analyzer on (the seed's prototype had none)
    timing: str = "model"  # model | wall
    cost: CostModel = field(default_factory=CostModel)
    wall_limit: float | None = None  # wall seconds before a silent planner is killed (default: the watchdog)
    policy: str | None = None  # overrides the block's policy (the Robot1/2c configuration)
    operator: Callable[[str], None] | None = None  # messages to the operator
    # Each planner's own statement of the mission, when it is not `problem` (a planner with
    # another vocabulary: `config.for_mission`, `view.View`).
    problems: Mapping[str, pm.Problem] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.timing not in ("model", "wall"):
            raise ValueError(f"timing is 'model' or 'wall', not '{self.timing}'")
        policy = self.policy or self.config.policy
        if policy not in ("successive", "concurrent"):
            raise ValueError(f"policy is 'successive' or 'concurrent', not '{policy}'")
        self.policy = policy
        self.state = SystemState.from_problem(self.problem)
        self.views = {p.name: View(p.view) for p in self.config.planners if p.view}
        missing = [k for k in self.views if k not in self.problems]
        if missing:
            raise ValueError(f"planner(s) {', '.join(missing)} speak another vocabulary than FTplan's state: "
                             "give their own problems (`problems=`)")
        # Each planner's own problem (one in another vocabulary, or the same mission written for
        # another domain, its goals on other lines) as a ledger: its goals, to tell which are
        # still FTplan's, and its timepoints' dates.
        self.planner_ledgers = {k: SystemState.from_problem(own) for k, own in self.problems.items()
                                if k in self.views or own is not self.problem}
        self.now = 0.0
        self.events: list[Event] = []
        self.trace: list[tuple[int, str]] = []
        self.plannings = 0
        self.rounds = 0
        self.planner_failures = 0
        self.dropped_by: dict[str, str] = {}  # planner -> the goals its last plan dropped, with why
        self.repairs = 0
        self.repaired = 0

    # ------------------------------------------------------------ entry point
    def run(self) -> MissionResult:
        failure = ""
        try:
            if self.policy == "successive":
                self.successive()
            else:
                self.concurrent()
        except MissionFailure as error:
            failure = str(error)
            self.now = max(self.now, error.at if error.at is not None else self.now)
            self.log("mission-failure", failure)
            self.tell_operator(failure)
            self.now = self.executor.safe_state(self.now)
        self.state.check_goals(self.now, mission_over=True)
        for goal in self.state.goals:
            if goal.line in self.state.missed:
                self.log("goal-missed", f"{goal.text()}: {self.state.missed[goal.line]}")
        self.log("mission-end", f"{len(self.state.met)} of {len(self.state.goals)} goals met")
        by_line = {g.line: g.text() for g in self.state.goals}
        return MissionResult(
            met=[by_line[line] for line in sorted(self.state.met)],
            missed={by_line[line]: why for line, why in sorted(self.state.missed.items())},
            failure=failure, now=self.now, plannings=self.plannings, rounds=self.rounds,
            planner_failures=self.planner_failures,
            events=self.events, trace=self.trace, repairs=self.repairs, repaired=self.repaired)

    # ------------------------------------------------------------ Fig 3.1
    def successive(self) -> None:
        planners = [p.name for p in self.config.planners]
        failed: set[str] = set()
        self.step(2, "failed <- {}")
        while self.objectives():
            self.step(3, "goals remain")
            candidates = list(planners)
            self.step(4, f"candidates <- {', '.join(candidates)}")
            outcomes: list[str] = []  # of this round: met, idle (nothing met), failed
            while candidates and self.objectives():
                self.step(5, "candidates and goals remain")
                # Some candidate is not in `failed`: the set is emptied by every valid plan, so
                # when it held every candidate left, it would hold all planners (line 23 caught that).
                k = next(k for k in candidates if k not in failed)
                self.step(6, f"choose {k}")
                candidates.remove(k)
                self.step(7, f"candidates <- {', '.join(candidates) or '{}'}")
                self.step(8, f"arm the watchdog ({self.config.watchdog:g} s)")
                self.request(k)
                self.rounds += 1
                self.step(9, f"request a plan from {k}")
                self.step(10, "wait for the plan or the watchdog")
                arrivals = self.arrivals([k])
                answer = next(arrivals, None)
                arrivals.close()
                # None: the watchdog fired, and killed the planner then: no later.
                self.now += self.config.watchdog if answer is None else self.charge(answer)
                plan = None if answer is None else self.plan_of(answer)
                if plan is not None:
                    self.step(11, f"plan found by {k}")
                    self.step(12, "disarm the watchdog")
                    violations = self.analyse(k, plan)
                    if not violations:
                        self.step(13, "analysis OK")
                        failed.clear()
                        self.step(14, "failed <- {}")
                        self.step(15, f"{k} executes its plan")
                        outcomes.append(self.execute(k, plan))
                    else:
                        outcomes.append("failed")
                        self.step(16, "analysis found errors")
                        self.step(17, f"tell the operator: invalid plan from {k}")
                        failed.add(k)
                        self.step(18, f"failed <- {', '.join(sorted(failed))}")
                else:
                    outcomes.append("failed")
                    self.step(20, f"watchdog: no plan from {k}")
                    failed.add(k)
                    self.step(21, f"failed <- {', '.join(sorted(failed))}")
                if failed >= set(planners):
                    self.step(23, "every planner failed in a row")
                    self.step(24, MISSION_FAILED_IN_TIME)
                    raise MissionFailure(MISSION_FAILED_IN_TIME)
            if outcomes and set(outcomes) == {"idle"} and self.objectives():
                self.give_up(self.left_aside(planners))
                return

    # ------------------------------------------------------------ Fig 3.2
    def concurrent(self) -> None:
        planners = [p.name for p in self.config.planners]
        # Planners whose last valid plan ran to its end and met no goal: asking them again would
        # give the same plan, which the fastest of them would win every time.
        idle: list[str] = []
        while self.objectives():
            self.step(2, "goals remain")
            candidates = [k for k in planners if k not in idle]
            self.step(3, f"candidates <- {', '.join(candidates)}"
                      + (f" (not {', '.join(idle)}: its last plan met no goal)" if idle else ""))
            self.step(4, f"arm the watchdog ({self.config.watchdog:g} s)")
            first = self.plannings == 0
            for k in candidates:
                self.request(k, self.planning_problem(k, first))
            self.rounds += 1
            self.step(5, f"request a plan from {', '.join(candidates)}")
            started = self.now
            arrivals = self.arrivals(candidates)
            outcome = ""
            while candidates:
                self.step(6, "candidates remain")
                answer = next(arrivals, None)
                if answer is None:
                    self.now = max(self.now, started + self.config.watchdog)
                    self.step(23, "the watchdog expired")
                    self.step(24, MISSION_FAILED_IN_TIME)
                    raise MissionFailure(MISSION_FAILED_IN_TIME)
                k = answer.planner
                self.now = max(self.now, started + self.charge(answer))
                self.step(8, f"answer from {k}")
                candidates.remove(k)
                self.step(9, f"candidates <- {', '.join(candidates) or '{}'}")
                self.step(10, "pause the watchdog")
                plan = self.plan_of(answer)
                if plan is not None and not self.analyse(k, plan):
                    self.step(11, f"analysis of {k}'s plan OK")
                    self.step(12, "disarm the watchdog")
                    arrivals.close()
                    for other in candidates:
                        self.pool.abandon(other)
                    self.step(13, f"abandon planning: {', '.join(candidates) or 'none left'}")
                    candidates = []
                    self.step(14, "candidates <- {}")
                    self.step(15, f"{k} executes its plan")
                    outcome = self.execute(k, plan)
                else:
                    self.step(16, f"no valid plan from {k}")
                    self.step(17, "resume the watchdog")
                    if plan is None:  # the analyzer told the operator of an invalid plan, not of this
                        self.tell_operator(f"no plan from {k}")
                    self.step(18, f"tell the operator: invalid plan from {k}")
                    if not candidates:
                        self.step(19, "no candidate left")
                        self.step(20, MISSION_FAILED)
                        raise MissionFailure(MISSION_FAILED)
            if outcome == "idle":
                idle.append(k)
            elif outcome == "met":
                idle.clear()
            if len(idle) == len(planners) and self.objectives():
                self.give_up(self.left_aside(planners))
                return

    def arrivals(self, candidates: list[str]) -> Generator[Answer, None, None]:
        """The answers of the planners just asked, in the order they count as found, while the
        watchdog lets them (Fig 3.1 line 20, Fig 3.2 line 23): a planner silent or late is killed
        and restarted, and the answers end there.

        Model timing: every answer is collected within `wall_limit` wall seconds of the requests,
        then given in the order of its charge (ties: the candidates' order) up to the first one
        charged beyond the watchdog. Wall timing: as they arrive, on a wall-clock watchdog that is
        paused while the consumer analyses one (between two `next`, Fig 3.2 lines 10 and 17)."""
        order, waiting = list(candidates), list(candidates)
        expiry = self.now + self.config.watchdog  # the mission time the watchdog fires at
        watchdog = Watchdog()
        if self.timing == "model":
            watchdog.arm(self.wall_seconds())
            collected = []
            while waiting:
                answer = self.pool.next_answer(waiting, watchdog.remaining() or 0.0)
                if answer is None:
                    self.silent(waiting, self.wall_seconds(), expiry)
                    break
                waiting.remove(answer.planner)
                collected.append(answer)
            collected.sort(key=lambda a: (self.charge(a), order.index(a.planner)))
            for rank, answer in enumerate(collected):
                if self.charge(answer) > self.config.watchdog:
                    for late in collected[rank:]:
                        self.planner_failed(late.planner, f"{late.planner} planned for {self.charge(late):.3g} s, "
                                            f"beyond the {self.config.watchdog:g} s watchdog", expiry)
                    return
                yield answer
            return
        budget = min(self.wall_seconds(), self.config.watchdog)
        watchdog.arm(budget)
        while waiting:
            answer = self.pool.next_answer(waiting, watchdog.remaining() or 0.0)
            if answer is None:
                self.silent(waiting, budget, expiry)
                return
            waiting.remove(answer.planner)
            watchdog.pause()
            yield answer
            watchdog.resume()

    def silent(self, names: list[str], seconds: float, expiry: float) -> None:
        for k in names:
            self.planner_failed(k, f"{k} did not answer within {seconds:g} s", expiry)

    # ------------------------------------------------------------ the mechanisms
    def objectives(self) -> bool:
        """Goals remain (Fig 3.1 lines 3 and 5, Fig 3.2 line 2): on-line goal verification."""
        self.state.check_goals(self.now)
        return bool(self.state.pending())

    def planning_problem(self, k: str, first: bool) -> pm.Problem:
        """What FTplan sends k: its own facts, the goals still open, the mission time (§3.2.2.3),
        in k's vocabulary. The mission's first planning sends k's statement of the mission."""
        own = self.problems.get(k, self.problem)
        if first:
            return own
        view = self.views.get(k)
        if k not in self.planner_ledgers:  # FTplan's own problem
            return replanning_problem(own, fact_list(self.state.facts), [g.line for g in self.state.open_goals()],
                                      self.now, self.state.dates)
        facts = self.state.facts if view is None else view.read(self.state.facts)
        return replanning_problem(own, fact_list(facts), self.open_planner_goals(k, view), self.now,
                                  self.planner_ledgers[k].dates)

    def open_planner_goals(self, k: str, view: View | None) -> list[int]:
        """The lines of k's goals (in k's own problem) standing for a goal FTplan still has open:
        through k's view, those whose correspondences give an open goal's fact; in FTplan's own
        vocabulary, k's goal paired with FTplan's goal of the same fact (the n-th of a fact with
        the n-th: two goals `AT() = DOCK` stay two). A goal nothing pairs is kept."""
        if view is None:
            return [line for line, partner in self._paired_goals(k) if partner is None or self.state.is_open(partner)]
        open_facts = [(g.key, g.value) for g in self.state.open_goals()]
        lines = []
        for goal in self.planner_ledgers[k].goals:
            stands_for = view.state_facts_of(goal.key, goal.value)
            if not stands_for or any(same_fact(f, o) for f in stands_for for o in open_facts):
                lines.append(goal.line)
        return lines

    def _paired_goals(self, k: str) -> list[tuple[int, Goal | None]]:
        """Each goal line of k's own problem with FTplan's goal of the same fact, in the order
        both problems list them (None: FTplan has no such goal)."""
        unpaired = list(self.state.goals)
        pairs: list[tuple[int, Goal | None]] = []
        for goal in self.planner_ledgers[k].goals:
            partner = next((g for g in unpaired if same_fact((g.key, g.value), (goal.key, goal.value))), None)
            if partner is not None:
                unpaired.remove(partner)
            pairs.append((goal.line, partner))
        return pairs

    def request(self, k: str, problem: pm.Problem | None = None) -> None:
        problem = problem or self.planning_problem(k, self.plannings == 0)
        self.plannings += 1
        goals = ", ".join(g.text() for g in self.state.open_goals())
        self.log("plan-request", f"{k} asked to plan at {self.now:g} s for: {goals}", k)
        self.pool.request(k, problem, self.now)

    def charge(self, answer: Answer) -> float:
        return self.cost.seconds(answer) if self.timing == "model" else answer.seconds

    def plan_of(self, answer: Answer) -> Plan | None:
        """The answer's plan, or None when the planner crashed or found no plan: counted as a late
        one, killed and restarted (§3.2.2.2)."""
        k, result = answer.planner, answer.result
        if result is None:
            self.planner_failed(k, f"{k} {answer.status}: {answer.error or answer.detail or 'no reason given'}")
            return None
        if result.plan is None:
            self.planner_failed(k, f"{k} found no plan: {result.reason}")
            return None
        dropped = "; ".join(f"{g.description}: {g.reason}" for g in result.dropped)
        self.dropped_by[k] = dropped
        improved = "".join(f"; {note}" for note in result.notes if note.startswith("improvement"))
        self.log("plan", f"{k}: {len(result.plan.actions)} actions" + (f", dropped {dropped}" if dropped else "")
                 + improved, k)
        return result.plan

    def planner_failed(self, k: str, why: str, at: float | None = None) -> None:
        """The watchdog's detection (and what counts as one): the planner is killed and restarted."""
        self.pool.abandon(k)
        self.planner_failures += 1
        self.log("watchdog", f"{why}: killed, restarted", k, at)

    def analyse(self, k: str, plan: Plan) -> list[Violation]:
        if not self.analyzer:
            return []
        violations = analyse(plan, self.config, self.state, self.problem, self.views.get(k))
        if violations:
            self.planner_failures += 1
            text = f"invalid plan from {k}: " + "; ".join(v.message for v in violations)
            self.log("invalid-plan", text, k)
            self.tell_operator(text)
        return violations

    def execute(self, k: str, plan: Plan) -> str:
        """k.executer(plan): blocking; FTplan's state follows the reports, the goals are checked
        after each. `failed` (an action failed), `met` (it ended and met some goal) or
        `idle` (it ended, meeting none). A planner with `repair: on` repairs its plan after an
        action failure, and the repaired plan is carried out in its stead (`repair`): FTplan's
        recovery starts only when the repair fails, as IxTeT-eXeC tells FTplan of a failure only
        after its own repair failed (seed 004 §3.2.2.3)."""
        met_before = self.progress()
        self.log("execute", f"{k}'s plan of {len(plan.actions)} actions starts", k)
        ended: set[str] = set()  # ids of the current plan's actions that ended

        def report(r: Report) -> None:
            if r.kind == "started":  # what its end will change is uncertain until then (`SystemState.changing`)
                for key, _ in consequences(self.config.state_rules, "ended", r.name, r.args, self.views.get(k)):
                    self.state.changing[key] = Running(r.action, r.name, r.args)
            elif r.kind in ("ended", "failed"):
                self.state.changing = {key: by for key, by in self.state.changing.items() if by.action != r.action}
            self.state.report(self.config.state_rules, r.kind, r.name, r.args, self.views.get(k))
            self.log("report", f"{r.kind} {format_call(r.name, r.args)}"
                     + (f": {r.why}" if r.why else ""), k, r.time)
            if r.kind == "ended":
                ended.add(r.action)
            # After every report that may change a fact (a failure too): a goal is met when it
            # comes true, by its deadline (`SystemState.check_goals`).
            for goal in self.state.check_goals(r.time):
                self.log("goal-met", goal.text(), k, r.time)

        while True:
            outcome: Execution = self.executor.execute(plan, self.now, report)
            self.now = outcome.now
            if outcome.completed:
                break
            self.log("action-failed", f"{outcome.why} (action {outcome.failed_action})", k)
            self.now = self.executor.safe_state(self.now)
            self.log("safe-state", "running activities stopped before recovery", k)
            self.stopped_as_failed(k)
            repaired = self.repair(k, plan, ended, outcome.failed_action)
            if repaired is None:
                return "failed"
            plan = repaired
            ended = set()
            self.log("execute", f"{k}'s repaired plan of {len(plan.actions)} actions starts", k)
        self.state.check_goals(self.now)
        left = ", ".join(g.text() for g in self.state.pending())
        if left:
            self.log("goals-open", f"{k}'s plan ended with goals open: {left}", k)
        return "met" if self.progress() > met_before else "idle"

    def progress(self) -> int:
        """How many goals are met, or reached and holding (a final goal, such as an item left at
        its station until the end, is met only when the mission ends: reaching it is progress
        all the same, and the plan that did so is not one that met nothing)."""
        return len(self.state.met) + len(self.state.reached)

    def repair(self, k: str, plan: Plan, ended: Collection[str], failed: str) -> Plan | None:
        """Plan repair (seed 004 §3.2.1, IxTeT-eXeC's): k, if its block says `repair: on`, is sent
        the present (the replanning problem FTplan would send) and its plan's actions still to
        carry out, the failed one left out; it keeps what still fits and plans only what the
        failure broke. The repaired plan, once the analyzer accepts it, is carried out; None (a
        repair refused, found wanting, late or invalid) leaves the recovery to the policy.

        A repair is charged to mission time as a planning is, and judged by the same watchdog; it
        is neither a replanning nor a planning round (seed 004 §4.2.1.2 counts R without them).
        One departure: the system is brought to a safe state first, as for a replanning, where
        IxTeT-eXeC kept the rest of the plan running while it repaired."""
        if not next((p.repair for p in self.config.planners if p.name == k), False):
            return None
        kept = tuple(a.id for a in plan.ordered() if a.id not in ended and a.id != failed)
        self.repairs += 1
        self.log("repair-request", f"{k} asked to repair its plan at {self.now:g} s ({len(kept)} action(s) still "
                 "to carry out)", k)
        self.pool.request(k, self.planning_problem(k, False), self.now, Repair(plan, kept))
        arrivals = self.arrivals([k])
        answer = next(arrivals, None)
        arrivals.close()
        self.now += self.config.watchdog if answer is None else self.charge(answer)
        if answer is None:
            return None  # the watchdog judged it (`arrivals`)
        if answer.result is not None and answer.result.plan is None:
            self.log("repair-failed", f"{k}: {answer.result.reason}", k)
            return None
        repaired = self.plan_of(answer)
        if repaired is None or self.analyse(k, repaired):
            return None
        self.repaired += 1
        said = answer.result.notes if answer.result is not None else ()
        self.log("repaired", f"{k}: {'; '.join(n for n in said if n.startswith('repaired')) or 'plan repaired'}", k)
        return repaired

    def stopped_as_failed(self, k: str) -> None:
        """The actions the safe state stopped on their way (beside the one that failed) left the
        world as a failure does: their `on failed` rules say what FTplan now believes, and nothing
        is still changing (the next plan's actions have ids of their own to track)."""
        for running in dict.fromkeys(self.state.changing.values()):
            self.state.report(self.config.state_rules, "failed", running.name, running.args, self.views.get(k))
            self.log("report", f"stopped {running.text()}: counted as failed (brought to the safe state)", k)
        self.state.changing.clear()

    def left_aside(self, planners: Iterable[str]) -> str:
        """Why the goals are given up when every planner's plan leaves them aside: what each plan
        dropped, and why (a search budget too small, a deadline that cannot be met...), not only
        that it did."""
        said = [f"{k}: {self.dropped_by[k]}" for k in planners if self.dropped_by.get(k)]
        return "every planner's plan left them aside" + (f" ({'; '.join(said)})" if said else "")

    def give_up(self, why: str) -> None:
        # Only the goals still calling for action: a final goal that holds now (the robot is home)
        # is met when the mission ends (`run`), not abandoned.
        for goal in self.state.pending():
            self.state.missed[goal.line] = why
        self.tell_operator(f"remaining goals abandoned: {why}")

    # ------------------------------------------------------------ bookkeeping
    def wall_seconds(self) -> float:
        return self.wall_limit if self.wall_limit is not None else self.config.watchdog

    def step(self, line: int, text: str) -> None:
        self.trace.append((line, text))

    def log(self, kind: str, text: str, planner: str = "", at: float | None = None) -> None:
        self.events.append(Event(self.now if at is None else at, kind, text, planner))

    def tell_operator(self, text: str) -> None:
        self.log("operator", text)
        if self.operator is not None:
            self.operator(text)
