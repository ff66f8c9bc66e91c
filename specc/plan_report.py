"""`specc plan`: find the problem the user means, plan it, check the plan with the independent
validator and print it all."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from rich.console import Console
from rich.table import Table

from specc.analysis.planning import domain_block, domain_model, problem_model
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.runtime.planner import Planner, PlanResult
from specc.runtime.planner import model as pm
from specc.runtime.planner.plan import format_value
from specc.runtime.planner.replan import Fact, checked_facts, replanning_problem
from specc.runtime.planner.validate import validate


@dataclass
class Outcome:
    """A planning problem solved for `specc plan`, and what the validator says of the plan."""

    domain: pm.PlanningDomain
    problem: pm.Problem
    result: PlanResult
    violations: list[str]

    @property
    def useful(self) -> bool:
        """Is there a plan, meeting some goal when the problem has any? A plan dropping every goal
        does nothing: the problem is unsolvable as it stands; nor does one with no action that
        drops a goal for itself (those it keeps held without it). One with no action that drops
        goals only because they exclude the goals it keeps is the planner's answer."""
        goals, plan = self.result.goals, self.result.plan
        if plan is None:
            return False
        if not plan.actions and any(not g.kept and not g.for_others for g in goals):
            return False
        return not goals or any(g.kept for g in goals)


def choose_problem(program: m.Program, name: str, domain: str | None) -> m.Problem:
    problems = [p for p in program.items if isinstance(p, m.Problem)]
    if domain is not None:
        domains = sorted({p.domain.text for p in problems})
        problems = [p for p in problems if p.domain.text.startswith(domain)]  # model2 takes model2_M1
        if not problems:
            raise ValueError(f"no domain '{domain}' has a problem{did_you_mean(domain, domains)} (domains with "
                             f"problems: {', '.join(domains) or 'none'})")
    found = [p for p in problems if p.name == name] or [p for p in problems if p.name.startswith(name)]
    if len(found) == 1:
        return found[0]
    if not found:
        known = ", ".join(sorted(p.name for p in problems)) or "none"
        where = f" for domain '{domain}'" if domain else ""
        raise ValueError(f"no problem '{name}'{where} (problems: {known})")
    names = ", ".join(sorted(p.name for p in found))
    raise ValueError(f"problem '{name}' is ambiguous ({names}); add --domain, e.g. --domain {found[0].domain.text}")


def ftplan_planner(program: m.Program, name: str, domain: pm.PlanningDomain) -> Planner:
    """The planner `name` of the program's ftplan block as a run of the robot plans with it
    (`specc plan --planner`): its heuristics, controllability and improvement, and the node
    limit FTplan's deterministic timing gives it (what its watchdog pays for under the cost
    model). ValueError when no ftplan block has it, or it plans in another domain."""
    from specc.analysis.ftplan import ftplan_config
    from specc.runtime.ftplan.component import planners_as_run
    from specc.runtime.ftplan.planners import standard_planner

    found = [(block, config) for block in program.items if isinstance(block, m.FtPlan)
             for config in planners_as_run(ftplan_config(block, program), "model") if config.name == name]
    if not found:
        known = sorted(p.name for block in program.items if isinstance(block, m.FtPlan) for p in block.planners)
        raise ValueError(f"no FTplan planner '{name}'{did_you_mean(name, known)} "
                         f"(planners: {', '.join(known) or 'none'})")
    if len(found) > 1:
        raise ValueError(f"planner '{name}' is in ftplan blocks {', '.join(b.name for b, _ in found)}: rename one")
    block, config = found[0]
    if config.domain != domain.name:
        raise ValueError(f"planner '{name}' of ftplan '{block.name}' plans in domain '{config.domain}', and the "
                         f"problem is for '{domain.name}': name one of its problems, or another planner")
    return standard_planner(config, {domain.name: domain})


def solve(program: m.Program, name: str, domain_name: str | None, horizon: float | None, now: float,
          facts: list[str], goals: list[int] | None, nodes: int, exact: bool,
          controllability: str = "strong", improve: int = 0, planner_name: str | None = None) -> Outcome:
    chosen = choose_problem(program, name, domain_name)
    model = domain_model(program, domain_block(program, chosen))
    problem = problem_model(program, chosen)
    planner = ftplan_planner(program, planner_name, model) if planner_name is not None else Planner(
        model, nodes=nodes, goal_nodes=nodes, exact=exact, controllability=controllability, improve=improve)
    own = math.inf
    if horizon is not None:
        if not (math.isfinite(horizon) and horizon > 0):
            raise ValueError(f"--horizon must be a positive number of seconds, not {horizon:g}")
        own = pm.latest_end(problem)
        problem = pm.with_horizon(problem, horizon)
    if not (math.isfinite(now) and now >= 0):
        raise ValueError(f"--now must be a mission time of 0 s or more, not {now:g}")
    if facts or goals is not None or now:
        lines = {a.line for a in problem.assertions if a.goal is not None}
        unknown = sorted(set(goals or ()) - lines)
        if unknown:
            raise ValueError(f"no goal on line(s) {', '.join(map(str, unknown))} of {problem.source} "
                             f"(goal lines: {', '.join(map(str, sorted(lines)))})")
        parsed = checked_facts(model, [Fact.parse(f) for f in facts])
        problem = replanning_problem(problem, parsed, lines if goals is None else goals, now)
    result = planner.plan(problem, now=now)
    if horizon is not None and horizon > own:
        result = replace(result, notes=(*result.notes, f"--horizon {horizon:g} s is later than the problem's own end "
                                        f"(at most {own:g} s after its start): the problem's bound stays"))
    violations = []
    if result.plan is not None:
        violations = validate(model, problem, result.plan, dropped_lines={g.line for g in result.dropped})
    return Outcome(model, problem, result, violations)


def print_result(outcome: Outcome, out: Console) -> None:
    result, problem = outcome.result, outcome.problem
    out.print(f"problem {problem.name} for domain {outcome.domain.name}: "
              f"{result.nodes} partial plans, {result.seconds:.2f} s", markup=False)
    if result.goals:  # none when the problem could not be read
        goals = Table(title="goals", title_justify="left", show_edge=False)
        for column in ("", "goal", "why dropped"):
            goals.add_column(column, overflow="fold")
        for g in result.goals:
            goals.add_row("kept" if g.kept else "DROPPED", g.description, g.reason)
        out.print(goals)
    if not outcome.useful:
        dropped = "every goal that needs an action is" if any(g.kept for g in result.goals) else "every goal is"
        why = result.reason or f"{dropped} dropped, for the reasons above"
        out.print(f"no plan: {why}", markup=False)
        return
    assert result.plan is not None
    plan = result.plan
    holds = ("whatever nature picks" if plan.controllability == "strong" else
             "whatever durations nature picks, with its instants at " +
             ", ".join(f"{name}={date:.2f}" for name, date in sorted(plan.assumed.items(), key=lambda kv: kv[1])))
    table = Table(title=f"plan ({len(plan.actions)} actions, {plan.controllability_text}: the dates hold "
                        f"{holds})", title_justify="left", show_edge=False)
    for column in ("start", "action", "duration", "ends by", "may start", "preemption"):
        table.add_column(column, justify="right" if column in ("start", "ends by") else "left", no_wrap=True)
    for a in plan.ordered():
        low, high = a.duration
        kind = "contingent" if a.contingent else "controllable"
        table.add_row(_date(a.dispatch), a.text(), f"{_date(low)}-{_date(high)} {kind}", _date(plan.ends_by(a)),
                      f"{_date(a.window[0])}-{_date(a.window[1])}", "preemptible" if a.preemptible else "")
    out.print(table)
    points = ", ".join(f"{name}={_date(date)}" for name, date in sorted(plan.schedule.items(), key=lambda kv: kv[1])
                       if "." not in name)
    out.print(f"mission timepoints: {points}", markup=False)
    bound = {k: v for k, v in plan.bindings.items() if k not in plan.free}
    if bound:
        out.print("bindings: " + ", ".join(f"{k}={format_value(v)}" for k, v in bound.items()), markup=False)
    if plan.free:
        out.print(f"free (no action of the plan names them): {', '.join(plan.free)}", markup=False)
    out.print(f"completes by {plan.makespan:.2f} s at worst", markup=False)
    for note in result.notes:
        out.print(f"note: {note}", markup=False)
    if outcome.violations:
        out.print("the validator REJECTS this plan (a planner bug):", markup=False)
        for v in outcome.violations:
            out.print(f"  {v}", markup=False)
    else:
        holds_for = ("duration and window instant nature may pick" if plan.controllability == "strong" else
                     "duration nature may pick, with its contingent instants at the dates it assumes (above)")
        out.print(f"validator: the plan is valid for every {holds_for}", markup=False)


PLAN_FORMAT = "specc-plan/1"


def _number(value: float) -> float | None:
    """A date or bound as JSON has it: an unbounded one (infinite) is null."""
    return value + 0.0 if math.isfinite(value) else None  # + 0.0: no -0.0 in the file


def plan_document(outcome: Outcome) -> dict[str, Any]:
    """The plan for other tools (`specc plan --json`; the format is docs/planning.md's "Plans for
    other tools"): what `print_result` shows, as data, with the partial order that justifies it."""
    result, plan = outcome.result, outcome.result.plan
    document: dict[str, Any] = {
        "format": PLAN_FORMAT,
        "domain": outcome.domain.name,
        "problem": outcome.problem.name,
        "search": {"partial_plans": result.nodes, "seconds": round(result.seconds, 6)},
        "goals": [{"description": g.description, "line": g.line, "priority": g.priority, "kept": g.kept,
                   "reason": g.reason} for g in result.goals],
        "plan": None,
        "reason": result.reason if plan is None else "",
        "notes": list(result.notes),
        "validator": {"violations": list(outcome.violations)},
    }
    if plan is None:
        return document
    document["plan"] = {
        "controllability": plan.controllability,
        "now": plan.now,
        "makespan": _number(plan.makespan),
        "actions": [{
            "id": a.id, "task": a.task, "args": list(a.args), "start": a.start, "end": a.end,
            "dispatch": a.dispatch, "duration": [a.duration[0], _number(a.duration[1])],
            "contingent": a.contingent, "preemptible": a.preemptible,
            "window": [_number(a.window[0]), _number(a.window[1])], "ends_by": _number(plan.ends_by(a)),
            "values": dict(a.values)} for a in plan.ordered()],
        "orderings": [[before, after, _number(delay)] for before, after, delay in plan.orderings],
        "links": [{"producer": link.producer, "consumer": link.consumer, "attribute": link.attribute,
                   "value": link.value} for link in plan.links],
        "timepoints": {name: _number(date) for name, date in plan.schedule.items()},
        "uncontrolled": {name: [_number(low), _number(high)] for name, (low, high) in plan.uncontrolled.items()},
        "assumed": dict(plan.assumed),
        "bindings": {k: v for k, v in plan.bindings.items() if k not in plan.free},
        "free": list(plan.free),
    }
    return document


def _date(seconds: float) -> str:
    """A date or a duration to the hundredth: never "-0.00" (a date a rounding error put at -1e-9)."""
    return f"{round(seconds, 2) + 0.0:.2f}"
