"""An `ftplan` block as the runtime's configuration (`specc.runtime.ftplan.config`): what the
back end `ftplan` writes into the generated package."""

from __future__ import annotations

from specc.check.expressions import NotConstant, bound, term
from specc.check.ftplan import viewed_planners
from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.runtime.ftplan import config as fc

DEFAULT_WATCHDOG = 10.0  # seconds, when the block names none


def terms(exprs: tuple[m.IxExpr, ...]) -> tuple[fc.Term, ...]:
    return tuple(term(e) for e in exprs)


def analyzer_rule(rule: m.AnalyzerRule) -> fc.AnalyzerRule:
    line = rule.span.line
    if isinstance(rule, m.AnalyzerNoOverlap):
        first, second = (rule.tasks + rule.tasks)[:2]
        return fc.NoOverlap(first, second, line)
    if isinstance(rule, m.AnalyzerMaxDuration):
        return fc.MaxDuration(rule.task, rule.limit.seconds, line)
    value = rule.requirement.value
    if isinstance(value, m.Transition):
        raise NotConstant("an analyzer requirement names one value, not a transition")
    return fc.Requirement(rule.kind, rule.task, terms(rule.args), rule.requirement.attribute,
                          terms(rule.requirement.args), term(value), line)


def state_rule(update: m.StateUpdate) -> fc.StateRule:
    return fc.StateRule(update.report, update.task, terms(update.args),
                        tuple(fc.FactUpdate(f.attribute, terms(f.args), term(f.value)) for f in update.updates),
                        update.span.line)


def view_value(e: m.IxExpr | m.Interval) -> fc.Term | fc.Interval:
    if isinstance(e, m.Interval):
        return fc.Interval(bound(e.low), bound(e.high))
    return term(e)


def fact_pattern(fact: m.ViewFact) -> fc.FactPattern:
    return fc.FactPattern(fact.attribute, terms(fact.args), view_value(fact.value))


def correspondence(c: m.Correspondence) -> fc.Correspondence:
    return fc.Correspondence(tuple(fact_pattern(f) for f in c.planner_facts),
                             tuple(fact_pattern(f) for f in c.state_facts), c.span.line)


def planner_order(ftplan: m.FtPlan) -> list[m.Planner]:
    """The planners in the order successive planning tries them (unlisted ones last)."""
    planners = {p.name: p for p in ftplan.planners}
    order = [ref.text for ref in ftplan.order if ref.text in planners] or list(planners)
    order += [name for name in planners if name not in order]
    return [planners[name] for name in order]


def state_planner(ftplan: m.FtPlan) -> m.Planner | None:
    """The first planner speaking FTplan's state vocabulary (without a view): its problem of a
    mission gives FTplan's facts and goals."""
    viewed = viewed_planners(ftplan)
    return next((p for p in planner_order(ftplan) if p.name not in viewed), None)


def mission_config(mission: m.Mission, problems: dict[str, m.Problem], state_planner: str | None) -> fc.Mission:
    """One mission; `problems` are the program's by name, `state_planner` names the planner whose
    problem states the mission in FTplan's vocabulary."""
    entries = []
    for entry in mission.problems:
        problem = problems.get(entry.problem.text)
        domain = problem.domain.text if problem is not None else ""
        entries.append(fc.MissionProblem(entry.planner.text, entry.problem.text, domain))
    state_problem = next((e.problem for e in entries if e.planner == state_planner), "")
    views = tuple((v.planner.text, tuple(correspondence(c) for c in v.correspondences)) for v in mission.views)
    return fc.Mission(mission.name, tuple(entries), state_problem, views)


def ftplan_config(ftplan: m.FtPlan, program: m.Program | None = None) -> fc.FtPlanConfig:
    """The block's configuration; `program` (for the missions' problems) defaults to the block alone."""
    problems: dict[str, m.Problem] = dict(symbols_of(program).blocks[m.Problem]) if program is not None else {}
    own = state_planner(ftplan)
    return fc.FtPlanConfig(
        name=ftplan.name,
        planners=tuple(planner_config(p) for p in planner_order(ftplan)),
        policy=ftplan.policy or "successive",
        watchdog=ftplan.watchdog.seconds if ftplan.watchdog is not None else DEFAULT_WATCHDOG,
        analyzer=tuple(analyzer_rule(r) for r in ftplan.analyzer),
        state_rules=tuple(state_rule(u) for u in ftplan.state_updates),
        missions=tuple(mission_config(mission, problems, own.name if own is not None else None)
                       for mission in ftplan.missions),
    )


def planner_config(planner: m.Planner) -> fc.PlannerConfig:
    return fc.PlannerConfig(planner.name, planner.domain.text if planner.domain is not None else "",
                            planner.heuristic.text if planner.heuristic is not None else None,
                            controllability=planner.controllability or "strong", repair=planner.repair == "on",
                            improve=int(planner.improve.value) if planner.improve is not None else 0,
                            flaws=planner.flaws.text if planner.flaws is not None else None,
                            view=tuple(correspondence(c) for c in planner.view))
