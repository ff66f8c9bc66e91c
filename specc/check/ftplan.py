"""FTplan blocks (seed 004 ch. 3): planners use existing domains, the analyzer and the state
updates speak of tasks and attributes that some planner's domain defines."""

from __future__ import annotations

from specc.check.context import Context
from specc.check.expressions import NotConstant, bound, term
from specc.check.planning import VALUE_VAR, DomainTables, tables
from specc.model import nodes as m
from specc.runtime.ftplan.config import FLAW_ORDERS, HEURISTICS


def check(ctx: Context) -> None:
    for ftplan in ctx.items(m.FtPlan):
        ctx.duplicates(ftplan.planners, "planner")
        ctx.duplicates(ftplan.missions, "mission")
        planners = {p.name: p for p in ftplan.planners}
        viewed = viewed_planners(ftplan)
        # FTplan's state speaks the vocabulary of the planners without a view; each planner with
        # one speaks its own domain's, which its state rules and correspondences are checked in.
        known = DomainTables()
        own: dict[str, DomainTables] = {}
        domains: dict[str, tuple[m.Domain, DomainTables]] = {}
        for planner in ftplan.planners:
            if planner.domain is None:
                ctx.report("missing-property", f"planner '{planner.name}' needs 'domain: <domain>;'", planner.span)
                continue
            if planner.heuristic is not None and planner.heuristic.text not in HEURISTICS:
                choices = ", ".join(sorted(HEURISTICS)) or "none yet: leave 'heuristic' out"
                ctx.report("unknown-heuristic", f"specc's planner has no heuristic '{planner.heuristic.text}' "
                           f"(it knows {choices})", planner.heuristic.span)
            if planner.flaws is not None and planner.flaws.text not in FLAW_ORDERS:
                ctx.report("unknown-heuristic", f"specc's planner has no flaw order '{planner.flaws.text}' "
                           f"(it knows {', '.join(sorted(FLAW_ORDERS))})", planner.flaws.span)
            domain = ctx.lookup(m.Domain, planner.domain, planner.domain.span, "undefined-domain")
            if domain is not None:
                found = tables(_quiet(ctx), domain.members)
                domains[planner.name] = (domain, found)
                if planner.name in viewed:
                    own[planner.name] = found
                else:
                    known.tasks.update(found.tasks)
                    known.attributes.update(found.attributes)
                    known.constants.update(found.constants)
        everything = DomainTables()
        for found in (known, *own.values()):
            everything.tasks.update(found.tasks)
            everything.attributes.update(found.attributes)
            everything.constants.update(found.constants)
        for ref in ftplan.order:
            if ref.text not in planners:
                ctx.unknown("undefined-planner", "planner", ref.text, planners, ref.span)
        if not ftplan.planners:
            ctx.report("missing-property", f"ftplan '{ftplan.name}' declares no 'planner' block", ftplan.span)
        elif not set(planners) - viewed:
            ctx.report("missing-property", f"every planner of ftplan '{ftplan.name}' has a view: FTplan's state "
                       "speaks the vocabulary of a planner without one", ftplan.span)
        if ftplan.watchdog is not None and ftplan.watchdog.seconds <= 0:
            ctx.report("bad-duration", "the watchdog must be longer than zero", ftplan.watchdog.span)
        for rule in ftplan.analyzer:
            tasks = (rule.tasks if isinstance(rule, m.AnalyzerNoOverlap)
                     else (rule.task,))
            for task in tasks:
                check_task(ctx, everything, task, rule.span, getattr(rule, "args", None))
            if isinstance(rule, m.AnalyzerCondition):
                # judged on FTplan's state, whichever planner's task it is about
                check_attribute(ctx, known, rule.requirement.attribute, len(rule.requirement.args), rule.span)
                value = rule.requirement.value
                if isinstance(value, m.Transition):
                    ctx.report("bad-rule-argument", "a requirement names one value, not a transition "
                               "(write `ATTRIBUTE(args): VALUE`)", value.span)
                else:
                    check_terms(ctx, (*rule.args, *rule.requirement.args, value))
                    check_bound(ctx, rule.args, (*rule.requirement.args, value), f"task '{rule.task}'")
                    check_variable_domains(ctx, (known, *own.values()), rule.task, rule.args, known,
                                           rule.requirement.attribute, (*rule.requirement.args, value))
        for update in ftplan.state_updates:
            vocabulary = known
            if update.report != "report":
                check_task(ctx, everything, update.task, update.span, update.args)
                if update.task not in known.tasks:  # a viewed planner's task: its vocabulary
                    vocabulary = next((t for t in own.values() if update.task in t.tasks), known)
            for fact in update.updates:
                check_attribute(ctx, vocabulary, fact.attribute, len(fact.args), fact.span)
                check_terms(ctx, (*fact.args, fact.value))
                check_value(ctx, vocabulary, fact.attribute, fact.value)
                check_bound(ctx, update.args, (*fact.args, fact.value), f"{update.report} '{update.task}'")
                if update.report != "report":
                    check_variable_domains(ctx, (vocabulary,), update.task, update.args, vocabulary, fact.attribute,
                                           (*fact.args, fact.value))
            check_terms(ctx, update.args)
        for planner in ftplan.planners:
            check_view(ctx, planner.view, own.get(planner.name), known)
        for mission in ftplan.missions:
            check_mission(ctx, mission, planners, domains, own, known)


def check_mission(ctx: Context, mission: m.Mission, planners: dict[str, m.Planner],
                  domains: dict[str, tuple[m.Domain, DomainTables]], own: dict[str, DomainTables],
                  known: DomainTables) -> None:
    named: set[str] = set()
    planned_in: dict[str, tuple[str, m.MissionProblem]] = {}  # planner -> the domain it plans the mission in
    for entry in mission.problems:
        planner = entry.planner.text
        if planner not in planners:
            ctx.unknown("undefined-planner", "planner", planner, planners, entry.planner.span)
            continue
        if planner in named:
            ctx.report("duplicate-definition", f"mission '{mission.name}' names planner '{planner}' twice",
                       entry.span)
        named.add(planner)
        problem = ctx.lookup(m.Problem, entry.problem, entry.problem.span, "undefined-problem")
        if problem is None or planner not in domains:
            continue
        domain, found = domains[planner]
        planned_in[planner] = (problem.domain.text, entry)
        if problem.domain.text != domain.name:
            other = ctx.lookup(m.Domain, problem.domain, problem.domain.span, "undefined-domain")
            if other is not None and set(tables(_quiet(ctx), other.members).tasks) != set(found.tasks):
                ctx.report("domain-mismatch", f"problem '{problem.name}' is for domain '{other.name}', whose tasks "
                           f"are not those of planner '{planner}''s domain '{domain.name}': name a problem for "
                           f"'{domain.name}' or a domain with the same tasks", entry.problem.span)
    check_diversity(ctx, mission, planners, planned_in)
    for planner in planners:
        if planner not in named:
            ctx.report("missing-property", f"mission '{mission.name}' names no problem for planner '{planner}': "
                       f"add '{planner}: <problem>;'", mission.span)
    for view in mission.views:
        if view.planner.text not in planners:
            ctx.unknown("undefined-planner", "planner", view.planner.text, planners, view.planner.span)
            continue
        check_view(ctx, view.correspondences, own.get(view.planner.text), known)


def check_diversity(ctx: Context, mission: m.Mission, planners: dict[str, m.Planner],
                    planned_in: dict[str, tuple[str, m.MissionProblem]]) -> None:
    """A planner plans a mission in its problem's domain (a domain with its own domain's tasks:
    Modele2's per-mission places). One given a problem for the domain another planner of the
    block declares plans on that planner's model: two planners declared diverse are not, in
    this mission (a user meant the problem written for its own model)."""
    declared = {name: p.domain.text for name, p in planners.items() if p.domain is not None}
    for planner, (domain, entry) in planned_in.items():
        own = declared.get(planner)
        others = sorted(other for other, (there, _) in planned_in.items() if other != planner and declared.get(
            other) not in (None, own) and domain in (there, declared.get(other)))
        if own is None or domain == own or not others:
            continue
        ctx.warn("planners-share-domain", f"planner '{planner}' (domain '{own}') plans mission '{mission.name}' in "
                 f"domain '{domain}', planner '{others[0]}''s: problem '{entry.problem.text}' is for '{domain}', so "
                 f"'{planner}' plans on that planner's model and the two are not diverse here; name a problem for "
                 f"'{own}'", entry.problem.span)


def check_view(ctx: Context, correspondences: tuple[m.Correspondence, ...], planner: DomainTables | None,
               state: DomainTables) -> None:
    """Each side in its vocabulary; constant arguments; usable to read FTplan's state or to write it."""
    for c in correspondences:
        for facts, vocabulary in ((c.planner_facts, planner), (c.state_facts, state)):
            for fact in facts:
                if vocabulary is not None:
                    check_attribute(ctx, vocabulary, fact.attribute, len(fact.args), fact.span)
                value = fact.value
                check_terms(ctx, fact.args if isinstance(value, m.Interval) else (*fact.args, value))
                if isinstance(value, m.Interval) and not all(_is_bound(b) for b in (value.low, value.high)):
                    ctx.report("bad-rule-argument", "an interval's bounds are numbers, -oo or +oo", value.span)
                if isinstance(value, m.Interval) and facts is c.planner_facts:
                    ctx.report("bad-rule-argument", "an interval reads FTplan's state: it belongs on the right of "
                               "`<=>`, the planner's facts name one value", value.span)
        left, right = _variables(c.planner_facts), _variables(c.state_facts)
        readable = left <= right
        writable = right <= left and not any(isinstance(f.value, m.Interval) for f in c.state_facts)
        if not readable and not writable:
            ctx.report("unusable-correspondence", "this correspondence can neither read FTplan's state (a ?variable "
                       "of the left is not on the right) nor write it (a ?variable or an interval of the right "
                       "is not bound by the left): bind the ?variables on both sides", c.span)


def _variables(facts: tuple[m.ViewFact, ...]) -> set[str]:
    names = set()
    for fact in facts:
        for e in (*fact.args, fact.value):
            if isinstance(e, m.IxVar):
                names.add(e.name)
    return names


def _is_bound(e: m.IxExpr) -> bool:
    try:
        bound(e)
    except NotConstant:
        return False
    return True


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


def planned_tasks(ctx: Context, ftplan: m.FtPlan) -> DomainTables:
    """Every task the planners of `ftplan` may put in a plan (their domains', includes expanded),
    and the attributes of FTplan's state (those of the planners without a view)."""
    found = DomainTables()
    viewed = viewed_planners(ftplan)
    for name, tabled in planner_tables(ctx, ftplan).items():
        found.tasks.update(tabled.tasks)
        if name not in viewed:
            found.attributes.update(tabled.attributes)
    return found


def planner_tables(ctx: Context, ftplan: m.FtPlan) -> dict[str, DomainTables]:
    """Each planner's domain (includes expanded), by planner name: those whose domain exists."""
    found = {}
    for planner in ftplan.planners:
        domain = ctx.named(m.Domain).get(planner.domain.text) if planner.domain is not None else None
        if domain is not None:
            found[planner.name] = tables(_quiet(ctx), domain.members)
    return found


def _quiet(ctx: Context) -> Context:
    """A context whose reports go nowhere: the domains are checked on their own already."""
    return Context(ctx.program, ctx.base_dirs)


def check_variable_domains(ctx: Context, domains: tuple[DomainTables, ...], task_name: str,
                           binders: tuple[m.IxExpr, ...], attributes: DomainTables, attribute_name: str,
                           terms: tuple[m.IxExpr, ...]) -> None:
    """A task's parameter given as an attribute's argument or value (`PICK(?o, ?p) requires
    SEEN(?o): YES`) must be able to take one of the values the attribute holds there: with no
    value in common (?o an object, SEEN's argument a place) the rule names a fact FTplan's state
    never has, and it refuses every plan with such an action, or writes what no planner reads.
    The task as each of `domains` declares it (planners' models may give it other domains)."""
    declared = [(found, found.tasks[task_name]) for found in domains if task_name in found.tasks]
    attribute = attributes.attributes.get(attribute_name)
    if not declared or attribute is None or len(terms) != len(attribute.params) + 1:
        return
    names = [b.name if isinstance(b, m.IxVar) else None for b in binders]
    slots = [*(p.name for p in attribute.params), VALUE_VAR]
    for written, slot in zip(terms, slots, strict=True):
        if not isinstance(written, m.IxVar) or written.name not in names:
            continue
        position = names.index(written.name)
        given: set[str] | None = set()
        for found, task in declared:
            said = found.value_domain(task, task.params[position].name) if position < len(task.params) else None
            given = None if said is None or given is None else given | said
        held = attributes.value_domain(attribute, slot)
        if given is not None and held is not None and not given & held:
            where = "value" if slot == VALUE_VAR else f"argument {slot}"
            ctx.report("bad-rule-argument", f"{written.name} of task '{task_name}' is one of "
                       f"{', '.join(sorted(given))}, none of which {attribute_name}'s {where} holds "
                       f"({', '.join(sorted(held))}): name the task's parameter meant there", written.span)


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


def check_value(ctx: Context, known: DomainTables, attribute_name: str, value: m.IxExpr) -> None:
    """A symbol a state rule writes is a value of the attribute (else the planner refuses the
    facts at the first replanning, and the run ends in a planning failure)."""
    attribute = known.attributes.get(attribute_name)
    allowed = known.value_domain(attribute) if attribute is not None else None
    if allowed is not None and isinstance(value, m.IxName) and value.name not in allowed:
        ctx.report("value-outside-domain",
                   f"'{value.name}' is not a value of {attribute_name} ({', '.join(sorted(allowed))})", value.span)


def viewed_planners(ftplan: m.FtPlan) -> set[str]:
    """The planners speaking another vocabulary than FTplan's state: those with a view, in their
    block or in a mission."""
    return {p.name for p in ftplan.planners if p.view} | {
        v.planner.text for mission in ftplan.missions for v in mission.views}
