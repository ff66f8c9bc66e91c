"""PRS procedures (seed 000 ch. 4): predicates and their finite domains, goals naming known
predicates with the right arity, KA shape, and unreachable statements."""

from __future__ import annotations

from specc.check.codels import check_call, python_functions
from specc.check.context import Context
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import Visitor
from specc.runtime.procedures import literal

# Heads PRS evaluates itself: connectives, comparisons and arithmetic.
BUILTIN_HEADS = frozenset("& | ~ < <= > >= = + - * / BOUNDP".split())
# What `property:` may say of a KA: `meta` (it orders the KAs applicable to the goals it
# matches), `executive` (it is the executive's request protocol, Fig 4.3: verification models
# its goal by the executive's services instead of its body).
KA_PROPERTIES = ("meta", "executive")
# Unbounded domains: fine for the interpreter, rejected later by the Petri-net translation.
BUILTIN_DOMAINS = frozenset({"int", "float", "number", "string", "symbol"})


class ProcedureVisitor(Visitor):
    def __init__(self, ctx: Context, procedures: m.Procedures):
        self.ctx = ctx
        self.types = {t.name: t for t in procedures.types}
        self.domains = Domains(procedures)
        self.signatures: dict[str, tuple[m.PParam, ...] | None] = {p.name: p.params for p in procedures.predicates}
        # Primitive actions are called from a KA's `action:` only, in a namespace of their own
        # (Fig. 4.2: goal SEND-REQUEST $REQUEST $ID is achieved by action SEND-REQUEST $REQUEST).
        self.actions = {a.name: a.params for a in procedures.actions}
        self.returning = {a.name for a in procedures.actions if a.result is not None}
        # A goal achieved by a KA needs no predicate declaration: its invocation declares it, and
        # the number of arguments it takes (the KAs invoked by one head may take several).
        self.invoked: dict[str, set[int]] = {}
        for ka in procedures.kas:
            invocation = ka.invocation
            head = invocation.body if isinstance(invocation, m.Goal) else invocation
            if head is not None and head.head not in self.signatures:
                self.invoked.setdefault(head.head, set()).add(len(head.args))
        self.signatures.update(dict.fromkeys(self.invoked))

    def visit_KAAction(self, node: m.KAAction) -> None:
        call = node.call
        params = self.actions.get(call.head)
        if params is None:
            self.ctx.unknown("undefined-action", "primitive action", call.head, self.actions, call.span,
                             "; declare it with 'action NAME(...) = \"python.module.function\";'")
        elif len(params) != len(call.args):
            self.ctx.report("arity-mismatch",
                            f"action '{call.head}' takes {len(params)} argument(s), {len(call.args)} given", call.span)
        for arg in call.args:
            self.visit(arg)

    def visit_IntRange(self, node: m.IntRange) -> None:
        if node.low > node.high:
            self.ctx.report("empty-domain", f"the range {node.low}..{node.high} is empty; write the lower bound first",
                            node.span)

    def visit_DomainRef(self, node: m.DomainRef) -> None:
        if node.name in BUILTIN_DOMAINS:
            return
        if node.name not in self.types:
            self.ctx.unknown("undefined-type", "type", node.name, self.types, node.span)

    def visit_SExp(self, node: m.SExp) -> None:
        if node.head not in BUILTIN_HEADS:
            if node.head not in self.signatures and node.head in self.actions:
                # An action is called from a primitive KA's `action:`, never achieved as a goal.
                params = "".join(f" ${p.name.upper()}" for p in self.actions[node.head])
                result = (" $ID", " -> $ID") if node.head in self.returning else ("", "")
                self.ctx.report("undefined-predicate",
                                f"'{node.head}' is an action, not a goal: a primitive KA carries it out, e.g. `ka "
                                f"Do{node.head.title().replace('-', '')} {{ invocation: !(DO-{node.head}{params}"
                                f"{result[0]}); action: ({node.head}{params}){result[1]}; }}`, and a body achieves "
                                f"that KA's goal", node.span)
            elif node.head not in self.signatures:
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
            taken = self.invoked.get(node.head, set())
            if taken and len(node.args) not in taken:
                counts = " or ".join(str(n) for n in sorted(taken))
                self.ctx.report("arity-mismatch", f"'{node.head}' takes {counts} argument(s) (the KAs invoked by it), "
                                f"{len(node.args)} given", node.span)
            return
        if len(node.args) != len(params):
            self.ctx.report("arity-mismatch",
                            f"'{node.head}' takes {len(params)} argument(s), {len(node.args)} given", node.span)
            return
        for arg, param in zip(node.args, params, strict=True):
            found = self.domains.values(param.domain)
            values = None if found is None else tuple(str(v) for v in found)
            shown = arg.text if isinstance(arg, m.Ref) else str(arg.value) if isinstance(arg, m.Number) else None
            if shown is not None and values is not None and shown not in values:
                self.ctx.report("value-outside-domain",
                                f"'{shown}' is not in the domain of {node.head}'s '{param.name}' "
                                f"({', '.join(values)}){did_you_mean(shown, values)}", arg.span)

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
        ctx.duplicates(procedures.predicates, "predicate")
        ctx.duplicates(procedures.actions, "action")
        ctx.duplicates(procedures.kas, "KA")
        visitor = ProcedureVisitor(ctx, procedures)
        visitor.visit(procedures)
        for ka in procedures.kas:
            check_ka(ctx, ka)
        for action in procedures.actions:
            if isinstance(action.binding, m.String):  # a service binding is checked with the system
                check_binding(ctx, action.name, action.binding, action.params)
        for predicate in procedures.predicates:
            evaluable = "evaluable" in predicate.kinds
            if evaluable and predicate.binding is None:
                ctx.report("missing-binding", f"evaluable predicate '{predicate.name}' needs "
                           f"'= \"python.module.function\"' to be evaluated", predicate.span)
            elif predicate.binding is not None and not evaluable:
                ctx.report("missing-binding", f"only an evaluable predicate is bound to Python; add 'evaluable' "
                           f"to '{predicate.name}' or remove the binding", predicate.binding.span)
            if predicate.binding is not None:
                check_binding(ctx, predicate.name, predicate.binding, predicate.params)


def check_ka(ctx: Context, ka: m.KA) -> None:
    for word in ka.properties:
        if word not in KA_PROPERTIES:
            span = word.span if isinstance(word, m.Word) else ka.span
            ctx.report("unknown-property", f"unknown KA property '{word}'{did_you_mean(word, KA_PROPERTIES)}; "
                       f"a KA may be {' or '.join(KA_PROPERTIES)}", span)
    if ka.invocation is None:
        ctx.report("missing-invocation", f"KA '{ka.name}' needs 'invocation: !(GOAL ...);' or a fact", ka.span)
    if "executive" in ka.properties and not (isinstance(ka.invocation, m.Goal) and ka.invocation.op == "!"
                                              and len(ka.invocation.body.args) >= 2):
        span = ka.invocation.span if ka.invocation is not None else ka.span
        ctx.report("bad-executive-ka", f"the executive KA '{ka.name}' must be invoked by a goal naming a service "
                   "first and its result last, like !(EXEC-REQUEST $REQUEST $RESULT)", span)
    if ka.body is not None and ka.action is not None:
        ctx.report("conflicting-ka-kinds",
                   f"KA '{ka.name}' has both a body and a primitive 'action:'; keep one", ka.action.span)
    if ka.body is None and ka.action is None and "meta" not in ka.properties:
        ctx.report("empty-ka-body", f"KA '{ka.name}' has neither a body nor a primitive 'action:'", ka.span)
    if ka.body is not None and not ka.body.statements:
        ctx.report("empty-ka-body", f"KA '{ka.name}' has an empty body", ka.body.span)
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
    check_concluded_once(ctx, ka)


def check_concluded_once(ctx: Context, ka: m.KA) -> None:
    """A `=>` in the body concludes a fact of values: a variable it names that nothing else in the
    KA names (not the invocation, the context, another statement) can have none when it runs, and
    the KA fails there at run time, after what it did before (a move made for nothing). A warning:
    the KA still runs, and fails where the net (`verify --goal`) says it does. (A retraction `~>`
    with a variable no one binds is a pattern: it retracts whatever value the fact has.)"""
    from specc.model.visitor import walk

    if ka.body is None:
        return
    named: dict[str, int] = {}
    for part in (ka.invocation, ka.context, ka.body, ka.action, *ka.effects):
        for var in _variables(part):
            named[var.name] = named.get(var.name, 0) + 1
    for goal in (n for n in walk(ka.body) if isinstance(n, m.Goal) and n.op == "=>"):
        for var in _variables(goal):
            if isinstance(var, m.LogicVar) and named[var.name] == 1:
                ctx.warn("unbound-variable", f"'{var.name}' has no value when {goal.op}({goal.body.head} ...) "
                           f"runs: nothing else in KA '{ka.name}' names it; bind it first (a test `?(...)` or a "
                           "goal's result) or write the value", var.span)
    # `?(= $RR2 OK)` for `?(= $R2 OK)`: the misspelt variable has no value, the test gives it one
    # and holds, whatever the reply was: a check of a result that checks nothing.
    others = sorted(name for name, count in named.items() if count > 1)
    for goal in (n for n in walk(ka.body) if isinstance(n, m.Goal) and n.op == "?" and n.body.head == "="):
        for arg in goal.body.args:
            if isinstance(arg, m.LogicVar) and named[arg.name] == 1:
                ctx.warn("always-true-test", f"'{arg.name}' is named nowhere else in KA '{ka.name}', so "
                         f"?(= ...) gives it the value and always holds{did_you_mean(arg.name, others)}: compare "
                         "a variable bound before (a reply's result, the invocation's), or a value", arg.span)


def _variables(node: m.Node | None) -> list[m.LogicVar | m.ProgramVar]:
    from specc.model.visitor import walk

    if node is None:
        return []
    return [n for n in walk(node) if isinstance(n, (m.LogicVar, m.ProgramVar))]


def check_binding(ctx: Context, name: str, binding: m.String, params: tuple[m.PParam, ...]) -> None:
    """A PRS action or evaluable predicate is bound to a function called as function(ctx, *args)."""
    module, _, function = binding.value.rpartition(".")
    if not module or not function:
        ctx.report("bad-binding", f"bind '{name}' to \"python.module.function\"", binding.span)
        return
    functions = python_functions(ctx, m.String(value=module, span=binding.span))
    if functions is None:
        return
    if function not in functions:
        ctx.report("undefined-codel",
                   f"function '{function}' is not defined in {module}{did_you_mean(function, functions)}; "
                   "`specc skeleton` can write a stub for it", binding.span)
        return
    check_call(ctx, function, functions[function], ("ctx", *(p.name for p in params)), module, binding.span)


class Domains:
    """The values each predicate argument may take: a tuple when finite, None when unbounded
    (`int`, `string`, ... — fine for the interpreter, not for a Petri net)."""

    def __init__(self, node: m.Procedures):
        self.types = {t.name: t.domain for t in node.types}
        self.params = {p.name: p.params for p in node.predicates}

    def values(self, domain: m.PDomain, seen: frozenset[str] = frozenset()
               ) -> tuple[str | int | float, ...] | None:
        if isinstance(domain, m.SymbolSet):
            return tuple(literal(v) for v in domain.values)
        if isinstance(domain, m.IntRange):
            return tuple(range(domain.low, domain.high + 1))
        declared = self.types.get(domain.name)
        if declared is None or domain.name in seen:
            return None
        return self.values(declared, seen | {domain.name})

    def argument(self, predicate: str, index: int) -> tuple[str | int | float, ...] | None:
        params = self.params.get(predicate)
        if params is None or index >= len(params):
            return None
        return self.values(params[index].domain)
