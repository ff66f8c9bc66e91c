"""A `procedures` block as the supervisor runs it: the spec's KAs, predicates and primitive
actions converted to the runtime records of `specc.runtime.procedures`, and the finite domains
of the predicates' arguments (for the Petri-net translation)."""

from __future__ import annotations

from specc.check.procedures import Domains
from specc.model import nodes as m
from specc.runtime import procedures as rp


def term(arg: m.SArg) -> rp.Term:
    if isinstance(arg, (m.LogicVar, m.ProgramVar)):
        return rp.Var(arg.name)
    if isinstance(arg, m.Ref):
        return arg.text
    if isinstance(arg, (m.Number, m.String)):
        return arg.value
    return compound(arg)


def compound(expr: m.SExp) -> rp.Compound:
    return rp.Compound(expr.head, tuple(term(a) for a in expr.args))


def goal(node: m.Goal) -> rp.Goal:
    return rp.Goal(node.op, compound(node.body), node.span.line)


def trigger(node: m.Goal | m.SExp) -> rp.Goal | rp.Compound:
    return goal(node) if isinstance(node, m.Goal) else compound(node)


def block(node: m.Block) -> tuple[rp.Statement, ...]:
    return tuple(statement(s) for s in node.statements)


def statement(node: m.Stmt) -> rp.Statement:
    line = node.span.line
    if isinstance(node, m.GoalStmt):
        return rp.Step(goal(node.goal))
    if isinstance(node, m.IfStmt):
        orelse = node.orelse
        otherwise = () if orelse is None else block(orelse) if isinstance(orelse, m.Block) else (statement(orelse),)
        return rp.If(goal(node.condition), block(node.then), otherwise, line)
    if isinstance(node, m.WhileStmt):
        return rp.While(goal(node.condition), block(node.body), line)
    if isinstance(node, m.ParallelStmt):
        return rp.Parallel(tuple(block(b) for b in node.branches), line)
    if isinstance(node, m.ChooseStmt):
        return rp.Choose(tuple(block(b) for b in node.branches), line)
    if isinstance(node, m.AssignStmt):
        return rp.Assign(rp.Var(node.var), term(node.value), line)
    return rp.Fail(line)


def ka(node: m.KA) -> rp.KA:
    assert node.invocation is not None, "checked: every KA has an invocation"
    action = None
    if node.action is not None:
        result = node.action.result
        action = rp.Action(compound(node.action.call), rp.Var(result.name) if result else None, node.action.span.line)
    return rp.KA(
        name=node.name,
        invocation=trigger(node.invocation),
        context=trigger(node.context) if node.context is not None else None,
        body=block(node.body) if node.body is not None else None,
        action=action,
        effects=tuple(goal(e) for e in node.effects),
        documentation=node.documentation.value if node.documentation else "",
        properties=node.properties,
        line=node.span.line,
    )


def primitive(node: m.ActionDecl, domains: Domains) -> rp.Primitive:
    if isinstance(node.binding, m.ServiceBinding):
        return rp.Primitive(node.name, len(node.params), "", node.result is not None, service=node.binding.service)
    domain = domains.values(node.result) if node.result is not None else None
    return rp.Primitive(node.name, len(node.params), node.binding.value, node.result is not None, domain=domain)


def predicate_kind(node: m.PredicateDecl) -> str:
    for kind in ("evaluable", "event", "functional", "closed"):
        if kind in node.kinds:
            return kind
    return "standard"


def predicate(node: m.PredicateDecl, domains: Domains) -> rp.Predicate:
    finite = tuple(domains.values(p.domain) for p in node.params)
    return rp.Predicate(node.name, predicate_kind(node), len(node.params), node.binding.value if node.binding else "",
                        finite if any(d is not None for d in finite) else ())


def library(node: m.Procedures) -> rp.Library:
    domains = Domains(node)
    return rp.Library(
        name=node.name,
        predicates=tuple(predicate(p, domains) for p in node.predicates),
        primitives=tuple(primitive(a, domains) for a in node.actions),
        kas=tuple(ka(k) for k in node.kas),
        source=node.span.file,
    )
