"""Hypothesis strategies that build random, syntactically valid specc models (no spans)."""

from __future__ import annotations

from hypothesis import strategies as st

from specc.model import nodes as m
from specc.syntax.grammar import keyword_texts

KEYWORDS = {text for text in keyword_texts().values() if text.isidentifier()} | {"oo"}

lower = st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True).filter(lambda s: s not in KEYWORDS)
upper = st.from_regex(r"[A-Z][A-Z0-9_]{0,6}", fullmatch=True).filter(lambda s: s not in KEYWORDS)
hyphenated = st.from_regex(r"[A-Z][A-Z0-9]{0,4}(-[A-Z0-9]{1,4}){0,2}", fullmatch=True).filter(
    lambda s: s not in KEYWORDS)
ints = st.integers(min_value=0, max_value=10**6)
floats = st.floats(min_value=0, max_value=1e6, allow_nan=False, allow_infinity=False)
numbers = st.builds(m.Number, value=st.one_of(ints, floats))
int_numbers = st.builds(m.Number, value=ints)
strings = st.builds(m.String, value=st.text(st.characters(codec="utf-8", exclude_categories=("Cs", "Cc")),
                                            max_size=12))
refs = st.builds(m.Ref, parts=st.tuples(lower))
dotted = st.builds(m.Ref, parts=st.tuples(lower, lower))
durations = st.builds(m.Duration, value=st.one_of(ints, floats), unit=st.sampled_from(["us", "ms", "s", "min"]))
type_refs = st.builds(m.TypeRef, name=lower, size=st.none() | st.integers(1, 64))
typed = st.builds(m.TypedName, name=lower, type=type_refs)


def small(strategy: st.SearchStrategy, min_size: int = 0, max_size: int = 3) -> st.SearchStrategy:
    return st.lists(strategy, min_size=min_size, max_size=max_size).map(tuple)


# ---------------------------------------------------------------- modules and executive

codels = st.builds(m.Codel, state=lower, function=lower, yields=small(lower))
requests = st.builds(
    m.Request, name=lower, kind=st.none() | st.sampled_from(["control", "exec"]), activity=st.none() | refs,
    inputs=small(typed), outputs=small(typed), validate=st.none() | refs, task=st.none() | refs,
    fail=small(refs), incompatible_with=small(refs), doc=st.none() | strings, codels=small(codels))
exec_tasks = st.builds(
    m.ExecTask, name=lower, period=st.none() | durations, delay=st.none() | durations,
    priority=st.none() | int_numbers, stack=st.none() | int_numbers, resources=small(refs), codels=small(codels))
fields = st.builds(m.Field, name=lower, type=type_refs)
posters = st.builds(m.Poster, name=lower, update=st.none() | st.sampled_from(["auto", "manual"]),
                    data=small(refs), activity=st.none() | refs)
modules = st.builds(
    m.Module, name=lower, number=st.none() | int_numbers, codel_module=st.none() | strings,
    structs=small(st.builds(m.StructDecl, name=lower, fields=small(fields))),
    enums=small(st.builds(m.EnumDecl, name=lower, values=small(upper, 1))),
    internal_data=small(fields), requests=small(requests), exec_tasks=small(exec_tasks), posters=small(posters))

prop_values = st.one_of(refs, dotted, numbers, durations, strings)
services = st.builds(
    m.Service, name=hyphenated, request=st.none() | dotted, input=st.none() | refs, output=st.none() | dotted,
    timeout=st.none() | st.builds(m.Timeouts, start=st.none() | durations, interm=st.none() | durations,
                                  final=st.none() | durations),
    args=small(st.builds(m.Argument, name=lower, value=prop_values)), takes=small(refs),
    conflicts=small(st.builds(m.Conflict, service=hyphenated, policy=st.sampled_from(["interrupt", "wait"]))))
reflexes = st.builds(
    m.Reflex, name=st.none() | lower, trigger=st.sampled_from(["reply", "warning", "interm"]), source=dotted,
    comparison=st.none() | st.builds(m.Comparison, op=st.sampled_from(["==", "!="]), value=prop_values),
    actions=small(st.builds(m.ReflexAction, verb=st.sampled_from(["request", "abort", "start"]), target=dotted), 1))
executives = st.builds(
    m.Executive, name=lower, rules=small(refs), codel_module=st.none() | strings, services=small(services),
    reflexes=small(reflexes),
    parameters=small(st.builds(m.Parameter, name=hyphenated, get=st.none() | dotted, set=st.none() | dotted)))

# ---------------------------------------------------------------- rules (Kheops)

attr_refs = st.builds(m.AttrRef, name=lower, previous=st.booleans(), index=st.none() | lower)
kexprs = st.recursive(
    st.one_of(numbers, strings, attr_refs),
    lambda inner: st.one_of(
        st.builds(m.KBinary, op=st.sampled_from(["+", "-", "*", "/"]), left=inner, right=inner),
        st.builds(m.KNegate, operand=inner)),
    max_leaves=4)
kitems = st.one_of(strings, numbers, refs)
kitem_lists = small(st.one_of(kitems, st.builds(m.KRange, low=strings, high=strings),
                              st.builds(m.KRange, low=numbers, high=numbers)), 1)
cmp_ops = st.sampled_from(["==", "!=", "<", "<=", ">", ">="])
restrictions = st.one_of(
    st.builds(m.KCompare, attr=attr_refs, op=cmp_ops, value=kexprs),
    st.builds(m.KMember, attr=attr_refs, op=st.sampled_from(["oneof", "noneof"]), items=kitem_lists),
    st.builds(m.KTrue, attr=attr_refs))
conds = st.recursive(
    restrictions,
    lambda inner: st.one_of(
        st.builds(m.KNot, operand=inner),
        st.builds(m.KAnd, operands=small(inner, 2)),
        st.builds(m.KOr, operands=small(inner, 2)),
        st.builds(m.KForeach, var=lower, items=kitem_lists, body=inner)),
    max_leaves=6)
do_statements = st.one_of(st.builds(m.DoAssign, target=lower, value=kexprs),
                          st.builds(m.DoCall, function=lower, args=small(kexprs)))
actions = st.one_of(
    st.builds(m.Restrict, restriction=st.one_of(restrictions, st.builds(m.KFalse, attr=attr_refs))),
    st.builds(m.DoAction, statements=small(do_statements, 1)))
rules_ = st.one_of(
    st.builds(m.Rule, name=lower, index=st.none() | lower, kind=st.just("when"), condition=conds,
              actions=small(actions, 1)),
    st.builds(m.Rule, name=lower, kind=st.just("impossible"), condition=conds, actions=st.just(())),
    st.builds(m.Rule, name=lower, kind=st.just("else"), condition=st.none(), actions=small(actions, 1)))
domains = st.one_of(
    st.none(), st.builds(m.SymbolDomain, values=small(kitems, 1)), st.builds(m.BoolDomain),
    st.builds(m.NumericDomain), st.builds(m.NumericDomain, low=kexprs, high=kexprs))
rule_bases = st.builds(
    m.RuleBase, name=lower, constants=small(st.builds(m.ConstDecl, name=lower, value=kexprs)),
    attributes=small(st.builds(m.AttrDecl, role=st.sampled_from(["inputs", "outputs", "intermediate"]),
                               name=lower, domain=domains), 0, 5),
    inits=small(st.builds(m.InitDecl, name=lower, value=kexprs)),
    rules=small(st.one_of(rules_, st.builds(m.RuleForeach, var=lower, items=kitem_lists, rules=small(rules_)))))

# ---------------------------------------------------------------- procedures (PRS)

logic_vars = st.builds(m.LogicVar, name=hyphenated.map(lambda s: "$" + s))
program_vars = st.builds(m.ProgramVar, name=hyphenated.map(lambda s: "@" + s))
symbols = st.builds(m.Ref, parts=st.tuples(hyphenated))
# A PRS argument may be negative (`!(GO -3 4)`); -0.0 would print as -0, read back as 0.
negative_numbers = st.builds(m.Number, value=st.one_of(
    st.integers(-10**6, -1), st.floats(min_value=-1e6, max_value=-1e-3, allow_nan=False)))
sexps = st.recursive(
    st.builds(m.SExp, head=hyphenated, args=small(st.one_of(logic_vars, program_vars, symbols, numbers, strings,
                                                           negative_numbers))),
    lambda inner: st.builds(m.SExp, head=st.one_of(hyphenated, st.sampled_from(["&", "|", "~", "<", "+", "="])),
                            args=small(st.one_of(inner, logic_vars, symbols))),
    max_leaves=5)
goals = st.builds(m.Goal, op=st.sampled_from(["!", "?", "^", "=>", "~>", "#", "%"]), body=sexps)
tests = st.builds(m.Goal, op=st.just("?"), body=sexps)
statements = st.recursive(
    st.one_of(st.builds(m.GoalStmt, goal=goals), st.builds(m.FailStmt),
              st.builds(m.AssignStmt, var=program_vars.map(lambda v: v.name), value=st.one_of(sexps, numbers))),
    lambda inner: st.one_of(
        st.builds(m.IfStmt, condition=tests, then=st.builds(m.Block, statements=small(inner)),
                  orelse=st.none() | st.builds(m.Block, statements=small(inner))),
        st.builds(m.WhileStmt, condition=tests, body=st.builds(m.Block, statements=small(inner))),
        st.builds(m.ParallelStmt, branches=small(st.builds(m.Block, statements=small(inner)), 1)),
        st.builds(m.ChooseStmt, branches=small(st.builds(m.Block, statements=small(inner)), 1))),
    max_leaves=6)
pdomains = st.one_of(st.builds(m.SymbolSet, values=small(hyphenated, 1)), st.builds(m.DomainRef, name=hyphenated),
                     st.builds(m.IntRange, low=st.integers(-50, 50), high=st.integers(-50, 50)))
pparams = st.builds(m.PParam, name=lower, domain=pdomains)
kas = st.builds(
    m.KA, name=lower, invocation=st.none() | goals | sexps, context=st.none() | goals,
    body=st.none() | st.builds(m.Block, statements=small(statements)),
    action=st.none() | st.builds(m.KAAction, call=sexps, result=st.none() | logic_vars),
    effects=small(goals), documentation=st.none() | strings, properties=small(lower))
procedures = st.builds(
    m.Procedures, name=lower, types=small(st.builds(m.TypeDecl, name=hyphenated, domain=pdomains)),
    predicates=small(st.builds(m.PredicateDecl, name=hyphenated,
                               kinds=small(st.sampled_from(["closed", "functional", "event", "evaluable"])),
                               params=small(pparams), result=st.none() | pdomains)),
    actions=small(st.builds(m.ActionDecl, name=hyphenated, params=small(pparams), result=st.none() | pdomains,
                            binding=strings | st.builds(m.ServiceBinding, service=hyphenated))),
    kas=small(kas))

# ---------------------------------------------------------------- IxTeT

ixvars = st.builds(m.IxVar, name=lower.map(lambda s: "?" + s))
ixexprs = st.recursive(
    st.one_of(numbers, st.builds(m.Infinity), ixvars, st.builds(m.IxName, name=st.one_of(lower, upper))),
    lambda inner: st.one_of(
        st.builds(m.IxBinary, op=st.sampled_from(["+.", "-.", "+", "-", "*.", "/.", "*", "/"]), left=inner,
                  right=inner),
        st.builds(m.IxUnary, op=st.sampled_from(["+", "-"]), operand=inner),
        st.builds(m.IxCall, function=lower, args=small(inner))),
    max_leaves=4)
set_unions = st.builds(m.SetUnion, parts=small(st.one_of(st.builds(m.SetLiteral, values=small(upper, 1)),
                                                          st.builds(m.SetRef, name=upper)), 1))
domain_values = st.one_of(st.builds(m.Interval, low=ixexprs, high=ixexprs), set_unions)
attr_values = st.builds(m.AttrValue, attribute=upper, args=small(ixexprs),
                        value=st.one_of(ixexprs, st.builds(m.Transition, before=ixexprs, after=ixexprs)))
goal_marks = st.none() | st.builds(m.GoalMark, priority=ixexprs, weight=ixexprs)
in_constraints = st.builds(m.InConstraint, expr=ixexprs, domain=domain_values, contingent=st.booleans())
rel_constraints = st.builds(m.RelConstraint, left=ixexprs, op=st.sampled_from(["=.", "!=", "<", "<=", "=="]),
                            right=ixexprs, contingent=st.booleans())
tstatements = st.one_of(
    st.builds(m.VariableDecl, names=small(ixvars, 1)),
    st.builds(m.TimepointDecl, names=small(lower, 1)),
    st.builds(m.Hold, attr=attr_values, start=ixexprs, end=ixexprs, goal=goal_marks),
    st.builds(m.Event, kind=st.sampled_from([None, "explained", "contingent"]), attr=attr_values, time=ixexprs,
              goal=goal_marks),
    st.builds(m.ResourceUse, verb=st.sampled_from(["use", "consume", "produce"]), attr=attr_values,
              when=st.one_of(ixexprs, st.builds(m.Window, start=ixexprs, end=ixexprs)), goal=goal_marks),
    in_constraints, rel_constraints,
    st.builds(m.Implication, condition=in_constraints.map(lambda c: m.InConstraint(expr=c.expr, domain=c.domain)),
              consequence=st.one_of(in_constraints, rel_constraints).map(
                  lambda c: type(c)(**{**c.__dict__, "contingent": False}))),
    st.builds(m.MacroCall, name=lower, args=small(ixexprs)))
preemptions = st.sampled_from([None, "latePreemptive", "earlyPreemptive", "nonPreemptive", "preemptive"])
domain_members = st.one_of(
    st.builds(m.Include, name=lower),
    st.builds(m.Constant, name=upper, value=set_unions),
    st.builds(m.Attribute, name=upper, params=small(ixvars), body=small(tstatements)),
    st.builds(m.Resource, name=upper, params=small(ixvars), body=small(tstatements)),
    st.builds(m.Macro, name=lower, params=small(lower.map(lambda s: "_" + s)), body=small(tstatements)),
    st.builds(m.Task, name=upper, params=small(ixvars), start=lower, end=lower, body=small(tstatements),
              preemption=preemptions))
planning_items = st.one_of(
    st.builds(m.Domain, name=lower, members=small(domain_members)),
    st.builds(m.Problem, name=lower, domain=refs, body=small(st.one_of(tstatements, st.builds(m.Include, name=lower))),
              preemption=preemptions),
    st.builds(m.Fragment, name=lower, members=small(st.one_of(domain_members, tstatements))))

# ---------------------------------------------------------------- ftplan and system

analyzer_rules = st.one_of(
    st.builds(m.AnalyzerCondition, kind=st.sampled_from(["during", "at_start", "at_end"]), task=upper,
              args=small(ixexprs), requirement=attr_values),
    st.builds(m.AnalyzerNoOverlap, tasks=small(upper, 2)),
    st.builds(m.AnalyzerMaxDuration, task=upper, limit=durations))
view_facts = st.builds(m.ViewFact, attribute=upper, args=small(ixexprs),
                       value=ixexprs | st.builds(m.Interval, low=ixexprs, high=ixexprs))
correspondences = small(st.builds(m.Correspondence, planner_facts=small(view_facts, 1),
                                  state_facts=small(view_facts, 1)))
ftplans = st.builds(
    m.FtPlan, name=lower, order=small(refs), policy=st.none() | st.sampled_from(["successive", "concurrent"]),
    watchdog=st.none() | durations,
    planners=small(st.builds(m.Planner, name=lower, domain=st.none() | refs, heuristic=st.none() | refs,
                             view=correspondences)),
    missions=small(st.builds(
        m.Mission, name=lower,
        problems=small(st.builds(m.MissionProblem, planner=lower.map(lambda s: m.Ref(parts=(s,))), problem=refs)),
        views=small(st.builds(m.MissionView, planner=refs, correspondences=correspondences)))),
    analyzer=small(analyzer_rules),
    state_updates=small(st.builds(
        m.StateUpdate, report=st.sampled_from(["ended", "failed", "report"]), task=upper, args=small(ixexprs),
        updates=small(st.builds(m.FactUpdate, attribute=upper, args=small(ixexprs), value=ixexprs), 1))))
systems = st.builds(
    m.System, name=lower, modules=small(refs), executive=st.none() | refs, supervisor=st.none() | refs,
    planning=st.none() | refs, doc=st.none() | strings,
    body=st.none() | st.builds(m.Settings, entries=small(st.builds(m.Setting, name=lower, value=numbers))),
    worlds=st.none() | st.builds(m.Settings, entries=small(st.builds(m.Setting, name=lower, value=strings))),
    devices=st.none() | st.builds(m.DeviceGrants, entries=small(st.builds(m.DeviceGrant, module=lower,
                                                                          devices=small(refs, 1)))),
    missions=small(st.builds(m.SystemMission, name=lower, world=st.none() | refs, horizon=st.none() | durations,
                             plan=st.none() | refs, doc=st.none() | strings, goals=small(goals))),
    bindings=st.none() | st.builds(m.Bindings, entries=small(st.builds(
        m.Binding, task=upper, args=small(ixexprs), kind=st.sampled_from(["goal", "service", "request"]),
        target=refs | dotted, target_args=small(ixexprs),
        report=st.none() | st.builds(m.BindingReport, name=upper, values=small(dotted))))))

items = st.one_of(modules, executives, rule_bases, procedures, planning_items, ftplans, systems)
source_files = st.builds(m.SourceFile, path=st.just("generated.spec"), items=small(items, 1, 3))
