"""FTplan blocks (seed 004 ch. 3): planners use existing domains, the analyzer and the state
updates speak of tasks and attributes that some planner's domain defines."""

from __future__ import annotations

from specc.analysis.ftplan import NotConstant, term
from specc.check.context import Context
from specc.check.planning import DomainTables, tables
from specc.model import nodes as m
from specc.runtime.ftplan.config import HEURISTICS


def check(ctx: Context) -> None:
    for ftplan in ctx.items(m.FtPlan):
        ctx.duplicates(ftplan.planners, "planner")
        planners = {p.name: p for p in ftplan.planners}
        known = DomainTables()
        for planner in ftplan.planners:
            if planner.domain is None:
                ctx.report("missing-property", f"planner '{planner.name}' needs 'domain: <domain>;'", planner.span)
                continue
            if planner.heuristic is not None and planner.heuristic.text not in HEURISTICS:
                choices = ", ".join(sorted(HEURISTICS)) or "none yet: leave 'heuristic' out"
                ctx.report("unknown-heuristic", f"specc's planner has no heuristic '{planner.heuristic.text}' "
                           f"(it knows {choices})", planner.heuristic.span)
            domain = ctx.lookup(m.Domain, planner.domain, planner.domain.span, "undefined-domain")
            if domain is not None:
                found = tables(_quiet(ctx), domain.members)
                known.tasks.update(found.tasks)
                known.attributes.update(found.attributes)
        for ref in ftplan.order:
            if ref.text not in planners:
                ctx.unknown("undefined-planner", "planner", ref.text, planners, ref.span)
        if not ftplan.planners:
            ctx.report("missing-property", f"ftplan '{ftplan.name}' declares no 'planner' block", ftplan.span)
        if ftplan.watchdog is not None and ftplan.watchdog.seconds <= 0:
            ctx.report("bad-duration", "the watchdog must be longer than zero", ftplan.watchdog.span)
        for rule in ftplan.analyzer:
            tasks = (rule.tasks if isinstance(rule, m.AnalyzerNoOverlap)
                     else (rule.task,))
            for task in tasks:
                check_task(ctx, known, task, rule.span, getattr(rule, "args", None))
            if isinstance(rule, m.AnalyzerCondition):
                check_attribute(ctx, known, rule.requirement.attribute, len(rule.requirement.args), rule.span)
                value = rule.requirement.value
                if isinstance(value, m.Transition):
                    ctx.report("bad-rule-argument", "a requirement names one value, not a transition "
                               "(write `ATTRIBUTE(args): VALUE`)", value.span)
                else:
                    check_terms(ctx, (*rule.args, *rule.requirement.args, value))
                    check_bound(ctx, rule.args, (*rule.requirement.args, value), f"task '{rule.task}'")
        for update in ftplan.state_updates:
            if update.report != "report":
                check_task(ctx, known, update.task, update.span, update.args)
            for fact in update.updates:
                check_attribute(ctx, known, fact.attribute, len(fact.args), fact.span)
                check_terms(ctx, (*fact.args, fact.value))
                check_bound(ctx, update.args, (*fact.args, fact.value), f"{update.report} '{update.task}'")
            check_terms(ctx, update.args)


def check_terms(ctx: Context, exprs: tuple[m.IxExpr, ...]) -> None:
    """FTplan matches and writes facts: a rule's arguments and values are ?variables or constants."""
    for expr in exprs:
        try:
            term(expr)
        except NotConstant:
            ctx.report("bad-rule-argument", "an FTplan rule argument is a ?variable, a symbol or a number, "
                       "not an expression", expr.span)


def check_bound(ctx: Context, binding: tuple[m.IxExpr, ...], used: tuple[m.IxExpr, ...], where: str) -> None:
    """A rule's ?variables take their values from the task's (or report's) arguments."""
    bound = {e.name for e in binding if isinstance(e, m.IxVar)}
    for expr in used:
        if isinstance(expr, m.IxVar) and expr.name not in bound:
            ctx.report("unbound-variable", f"{expr.name} is not an argument of {where}: name it among the "
                       f"arguments, or write a constant", expr.span)


def _quiet(ctx: Context) -> Context:
    """A context whose reports go nowhere: the domains are checked on their own already."""
    return Context(ctx.program, ctx.base_dirs)


def check_task(ctx: Context, known: DomainTables, name: str, span: m.Span, args: tuple[m.IxExpr, ...] | None) -> None:
    task = known.tasks.get(name)
    if task is None:
        ctx.unknown("undefined-task", "task", name, known.tasks, span, " in the planners' domains")
    elif args is not None and len(args) != len(task.params):
        ctx.report("arity-mismatch", f"task '{name}' takes {len(task.params)} parameter(s), {len(args)} given", span)


def check_attribute(ctx: Context, known: DomainTables, name: str, arity: int, span: m.Span) -> None:
    attribute = known.attributes.get(name)
    if attribute is None:
        ctx.unknown("undefined-attribute", "attribute", name, known.attributes, span, " in the planners' domains")
    elif len(attribute.params) != arity:
        ctx.report("arity-mismatch", f"'{name}' takes {len(attribute.params)} argument(s), {arity} given", span)
