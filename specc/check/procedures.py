"""PRS procedures (seed 000 ch. 4): predicates and their finite domains, goals naming known
predicates with the right arity, KA shape, and unreachable statements."""

from __future__ import annotations

from specc.check.codels import python_functions
from specc.check.context import Context
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import Visitor

# Heads PRS evaluates itself: connectives, comparisons and arithmetic.
BUILTIN_HEADS = frozenset("& | ~ < <= > >= = + - * /".split())


class ProcedureVisitor(Visitor):
    def __init__(self, ctx: Context, procedures: m.Procedures):
        self.ctx = ctx
        self.types = {t.name: t for t in procedures.types}
        self.signatures: dict[str, tuple[m.PParam, ...] | None] = {}
        for p in procedures.predicates:
            self.signatures[p.name] = p.params
        for a in procedures.actions:
            self.signatures[a.name] = a.params
        # A goal achieved by a KA needs no predicate declaration: its invocation declares it.
        for ka in procedures.kas:
            invocation = ka.invocation
            head = invocation.body if isinstance(invocation, m.Goal) else invocation
            if head is not None and head.head not in self.signatures:
                self.signatures[head.head] = None

    def domain_values(self, domain: m.PDomain) -> tuple[str, ...] | None:
        if isinstance(domain, m.SymbolSet):
            return domain.values
        declared = self.types.get(domain.name)
        if declared is None:
            return None
        return self.domain_values(declared.domain) if declared.domain != domain else None

    def visit_DomainRef(self, node: m.DomainRef) -> None:
        if node.name not in self.types:
            self.ctx.unknown("undefined-type", "type", node.name, self.types, node.span)

    def visit_SExp(self, node: m.SExp) -> None:
        if node.head not in BUILTIN_HEADS:
            if node.head not in self.signatures:
                self.ctx.report("undefined-predicate",
                                f"unknown predicate or goal '{node.head}'{did_you_mean(node.head, self.signatures)};"
                                f" declare it with 'predicate {node.head}(...);' or write a KA invoked by it",
                                node.span)
            else:
                self.check_arguments(node)
        self.generic_visit(node)

    def check_arguments(self, node: m.SExp) -> None:
        params = self.signatures[node.head]
        if params is None:
            return
        if len(node.args) != len(params):
            self.ctx.report("arity-mismatch",
                            f"'{node.head}' takes {len(params)} argument(s), {len(node.args)} given", node.span)
            return
        for arg, param in zip(node.args, params, strict=True):
            values = self.domain_values(param.domain)
            if isinstance(arg, m.Ref) and values is not None and arg.text not in values:
                self.ctx.report("value-outside-domain",
                                f"'{arg.text}' is not in the domain of {node.head}'s '{param.name}' "
                                f"({', '.join(values)}){did_you_mean(arg.text, values)}", arg.span)

    def visit_Block(self, node: m.Block) -> None:
        for previous, statement in zip(node.statements, node.statements[1:], strict=False):
            if isinstance(previous, m.FailStmt):
                self.ctx.report("unreachable-statement", "this statement can never run: 'fail;' comes before it",
                                statement.span)
                break
        self.generic_visit(node)

    def visit_IfStmt(self, node: m.IfStmt) -> None:
        self.check_condition(node.condition)
        self.generic_visit(node)

    def visit_WhileStmt(self, node: m.WhileStmt) -> None:
        self.check_condition(node.condition)
        if not node.body.statements:
            self.ctx.report("empty-ka-body", "this loop has an empty body", node.span)
        self.generic_visit(node)

    def check_condition(self, goal: m.Goal) -> None:
        if goal.op != "?":
            self.ctx.report("condition-not-test",
                            f"a condition is a test goal '?(...)', not '{goal.op}(...)'", goal.span)


def check(ctx: Context) -> None:
    for procedures in ctx.items(m.Procedures):
        ctx.duplicates(procedures.types, "type")
        ctx.duplicates(procedures.predicates + procedures.actions, "predicate or action")  # type: ignore[operator]
        ctx.duplicates(procedures.kas, "KA")
        visitor = ProcedureVisitor(ctx, procedures)
        visitor.visit(procedures)
        for ka in procedures.kas:
            check_ka(ctx, ka)
        for action in procedures.actions:
            check_binding(ctx, action)


def check_ka(ctx: Context, ka: m.KA) -> None:
    if ka.invocation is None:
        ctx.report("missing-invocation", f"KA '{ka.name}' needs 'invocation: !(GOAL ...);' or a fact", ka.span)
    if ka.body is not None and ka.action is not None:
        ctx.report("conflicting-ka-kinds",
                   f"KA '{ka.name}' has both a body and a primitive 'action:'; keep one", ka.action.span)
    if ka.body is None and ka.action is None and "meta" not in ka.properties:
        ctx.report("empty-ka-body", f"KA '{ka.name}' has neither a body nor a primitive 'action:'", ka.span)
    if ka.body is not None and not ka.body.statements:
        ctx.report("empty-ka-body", f"KA '{ka.name}' has an empty body", ka.body.span)
    if isinstance(ka.invocation, m.Goal) and ka.invocation.op not in ("!", "?", "^", "=>", "~>", "#", "%"):
        ctx.report("bad-invocation", "an invocation is a goal or a fact", ka.invocation.span)
    bound = {v.name for v in _variables(ka.invocation)} | {v.name for v in _variables(ka.context)}
    if ka.body is not None:
        bound |= {v.name for v in _variables(ka.body)}
    if ka.action is not None:
        bound |= {v.name for v in _variables(ka.action)}
    for effect in ka.effects:
        for var in _variables(effect):
            if isinstance(var, m.LogicVar) and var.name not in bound:
                ctx.report("unbound-variable",
                           f"'{var.name}' appears first in the effects, so it is never bound", var.span)


def _variables(node: m.Node | None) -> list[m.LogicVar | m.ProgramVar]:
    from specc.model.visitor import walk

    if node is None:
        return []
    return [n for n in walk(node) if isinstance(n, (m.LogicVar, m.ProgramVar))]


def check_binding(ctx: Context, action: m.ActionDecl) -> None:
    module, _, function = action.binding.value.rpartition(".")
    if not module or not function:
        ctx.report("bad-binding", f"bind '{action.name}' to \"python.module.function\"", action.binding.span)
        return
    functions = python_functions(ctx, m.String(value=module, span=action.binding.span))
    if functions is not None and function not in functions:
        ctx.report("undefined-codel",
                   f"function '{function}' is not defined in {module}{did_you_mean(function, functions)}",
                   action.binding.span)
