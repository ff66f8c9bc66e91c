"""IxTeT domains and problems (seed 004 §3.2.1.2, annex A).

Includes are expanded first (fragments play the seed's `#include`); then every task, macro,
attribute and problem is checked in its own scope: `?variables` declared, timepoints declared,
attributes and macros known with the right arity, symbolic values inside their domains.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from specc.check.context import Context
from specc.model import nodes as m
from specc.model.visitor import Visitor, walk
from specc.runtime.planner.model import FUNCTIONS, fold

VALUE_VAR = "?value"
PROBLEM_TIMEPOINTS = ("t_start", "t_end")


def declared_domain(block: m.Attribute | m.Resource | m.Task, variable: str) -> Any:
    """The domain the block's `variable in ...` declares (a set union, an interval), or None."""
    for statement in block.body:
        if (isinstance(statement, m.InConstraint) and isinstance(statement.expr, m.IxVar)
                and statement.expr.name == variable):
            return statement.domain
    return None


@dataclass
class DomainTables:
    """What one domain (or problem) sees once its includes are expanded."""

    members: list[Any] = field(default_factory=list)
    constants: dict[str, m.Constant] = field(default_factory=dict)
    attributes: dict[str, m.Attribute | m.Resource] = field(default_factory=dict)
    macros: dict[str, m.Macro] = field(default_factory=dict)
    tasks: dict[str, m.Task] = field(default_factory=dict)

    def symbols(self) -> set[str]:
        """Every symbolic value a constant set or an attribute domain mentions."""
        found: set[str] = set()
        for node in list(self.constants.values()) + list(self.attributes.values()):
            found.update(v for n in walk(node) if isinstance(n, m.SetLiteral) for v in n.values)
        return found

    def value_domain(self, attribute: m.Attribute | m.Resource | m.Task, variable: str = VALUE_VAR) -> set[str] | None:
        """The symbolic values `?value` (or another of the attribute's variables, one of its
        parameters; or a task's parameter) may take, when its domain is a set of symbols."""
        domain = declared_domain(attribute, variable)
        return self.set_values(domain) if isinstance(domain, m.SetUnion) else None

    def set_values(self, union: m.SetUnion) -> set[str] | None:
        values: set[str] = set()
        for part in union.parts:
            if isinstance(part, m.SetLiteral):
                values.update(part.values)
                continue
            constant = self.constants.get(part.name)
            if constant is None:
                return None
            inner = self.set_values(constant.value)
            if inner is None:
                return None
            values |= inner
        return values


def expand(ctx: Context, members: Iterable[Any], chain: tuple[str, ...] = ()) -> Iterator[Any]:
    """Members with every `include` replaced by the fragment's own (expanded) members.

    A cycle is cut silently here: `check_include_cycles` reports each one once.
    """
    for member in members:
        if not isinstance(member, m.Include):
            yield member
        elif member.name not in chain:
            other = next((kind for kind in (m.Domain, m.Problem) if member.name in ctx.named(kind)), None)
            if member.name not in ctx.named(m.Fragment) and other is not None:
                word = "domain" if other is m.Domain else "problem"
                ctx.report("undefined-fragment", f"'{member.name}' is a {word}: only fragments are included; "
                           "move what both need into a fragment", member.span)
                continue
            fragment = ctx.lookup(m.Fragment, member.name, member.span, "undefined-fragment")
            if fragment is not None:
                yield from expand(ctx, fragment.members, chain + (member.name,))


def check_include_cycles(ctx: Context) -> None:
    fragments = ctx.named(m.Fragment)

    def visit(name: str, chain: tuple[str, ...]) -> None:
        for member in fragments[name].members:
            if not isinstance(member, m.Include) or member.name not in fragments:
                continue
            if member.name == chain[0]:
                # Reported from the cycle's first fragment in source order only, so once.
                if chain[0] == min(chain, key=list(fragments).index):
                    ctx.report("include-cycle", "fragments include each other: "
                               f"{' -> '.join(chain + (member.name,))}", member.span)
            elif member.name not in chain:
                visit(member.name, chain + (member.name,))

    for name in fragments:
        visit(name, (name,))


def tables(ctx: Context, members: Iterable[Any], base: DomainTables | None = None) -> DomainTables:
    result = DomainTables()
    if base is not None:
        result.constants.update(base.constants)
        result.attributes.update(base.attributes)
        result.macros.update(base.macros)
        result.tasks.update(base.tasks)
    seen_ids: set[int] = set()
    for member in expand(ctx, members):
        if id(member) in seen_ids:
            continue  # the same fragment included twice adds nothing new
        seen_ids.add(id(member))
        result.members.append(member)
        table: dict[str, Any] | None = None
        if isinstance(member, m.Constant):
            table = result.constants
        elif isinstance(member, (m.Attribute, m.Resource)):
            table = result.attributes
        elif isinstance(member, m.Macro):
            table = result.macros
        elif isinstance(member, m.Task):
            table = result.tasks
        if table is None:
            continue
        previous = table.get(member.name)
        if previous is not None and previous is not member:
            ctx.report("duplicate-definition", f"'{member.name}' is defined twice in this domain", member.span,
                       (previous.span, "first defined here"))
        else:
            table[member.name] = member
    return result


@dataclass
class Scope:
    """The names visible in a task, macro, attribute, problem or fragment being checked."""

    kind: str  # task | macro | attribute | problem | fragment
    variables: set[str] = field(default_factory=set)
    timepoints: set[str] = field(default_factory=set)
    macro_params: set[str] = field(default_factory=set)
    goals_allowed: bool = False


class ScopeChecker(Visitor):
    def __init__(self, ctx: Context, domain: DomainTables):
        self.ctx = ctx
        self.domain = domain
        self.symbols = domain.symbols()
        self.scope = Scope("task")
        self.named: set[str] = set()  # the names the statements checked mention: timepoints among them

    def scope_for(self, kind: str, body: Iterable[Any], params: Iterable[m.IxVar] = (),
                  timepoints: Iterable[str] = (), macro_params: Iterable[str] = ()) -> Scope:
        scope = Scope(kind, {p.name for p in params}, set(timepoints), set(macro_params),
                      goals_allowed=kind in ("problem", "fragment"))
        for statement in body:
            if isinstance(statement, m.VariableDecl):
                scope.variables.update(v.name for v in statement.names)
            elif isinstance(statement, m.TimepointDecl):
                scope.timepoints.update(statement.names)
        if kind == "attribute":
            scope.variables.add(VALUE_VAR)
        if kind == "fragment":
            # A fragment of statements is written for the problems that include it.
            scope.timepoints.update(PROBLEM_TIMEPOINTS)
        return scope

    def statements(self, body: Iterable[Any], scope: Scope) -> None:
        self.scope = scope
        self.named = set()
        for statement in body:
            goal = getattr(statement, "goal", None)
            if goal is not None and not scope.goals_allowed:
                self.ctx.report("goal-outside-problem",
                                "goals belong to a problem (or a fragment it includes), not to a task", goal.span)
            self.visit(statement)
        if scope.kind in ("task", "problem"):
            for statement in body:
                unused = [name for name in statement.names if name not in self.named] if isinstance(
                    statement, m.TimepointDecl) else []
                if unused:
                    self.ctx.warn("unused-timepoint", f"timepoint {', '.join(unused)} is declared but no statement "
                                  "uses it: nothing dates it; remove it, or use it in an assertion or a constraint",
                                  statement.span)

    # One visit method per statement kind; expressions are checked by `expr`, not visited.
    def visit_Hold(self, s: m.Hold) -> None:
        if isinstance(s.attr.value, m.Transition):
            self.ctx.report("hold-transition", "a hold keeps one value: write hold(A(): v, (t1, t2)), or "
                            "event(A(): (v1, v2), t) for a change", s.attr.value.span)
        self.attr_value(s.attr, self.scope)
        self.time(s.start, self.scope)
        self.time(s.end, self.scope)

    def visit_Event(self, s: m.Event) -> None:
        if not isinstance(s.attr.value, m.Transition):
            self.ctx.report("event-without-transition", "an event changes a value: write event(A(): (before, "
                            "after), t), or hold(A(): v, (t1, t2)) for a value that persists", s.attr.span)
        self.attr_value(s.attr, self.scope)
        self.time(s.time, self.scope)

    def visit_ResourceUse(self, s: m.ResourceUse) -> None:
        if s.verb != "use" or not isinstance(s.when, m.Window):
            self.ctx.report("unsupported-resource-use", f"the planner borrows resources over an interval only: "
                            f"write use(R(): amount, (t1, t2)); '{s.verb}' at one instant is not planned", s.span)
        elif s.when.start == s.when.end:
            instant = getattr(s.when.start, "name", "one timepoint")
            self.ctx.report("unsupported-resource-use", f"use over ({instant}, {instant}) is at one instant: "
                            "the planner borrows resources over an interval only; write use(R(): amount, (t1, t2)) "
                            "with two timepoints", s.span)
        self.attr_value(s.attr, self.scope, resource=True)
        for time in (s.when.start, s.when.end) if isinstance(s.when, m.Window) else (s.when,):
            self.time(time, self.scope)
        amount = None if isinstance(s.attr.value, m.Transition) else constant_value(s.attr.value)
        if amount is not None and amount < 0:
            self.ctx.warn("negative-amount", f"a task {s.verb}s {amount:g} of {s.attr.attribute}: an amount is 0 or "
                          "more (what it gives back is its end)", s.attr.value.span)
        capacity = self.capacity(s.attr.attribute)
        if s.verb == "use" and amount is not None and capacity is not None and amount > capacity:
            self.ctx.warn("over-capacity", f"a task {s.verb}s {amount:g} of {s.attr.attribute}, whose capacity is "
                          f"{capacity:g}: the planner never inserts it; lower the amount or raise the resource's "
                          "?value bound", s.attr.value.span)

    def capacity(self, name: str) -> float | None:
        """A resource's capacity: the upper bound of its `?value in [low, high]` when constant, 1
        without one (as the planner takes it)."""
        resource = self.domain.attributes.get(name)
        if not isinstance(resource, m.Resource):
            return None
        domain = declared_domain(resource, VALUE_VAR)
        return constant_value(domain.high) if isinstance(domain, m.Interval) else 1.0

    def visit_InConstraint(self, s: m.InConstraint) -> None:
        self.expr(s.expr, self.scope)
        self.domain_value(s.domain, self.scope)
        if s.contingent and isinstance(s.domain, m.Interval):
            low = constant_value(s.domain.low)
            if low is not None and low < 0:
                self.ctx.warn("negative-amount", f"a contingent duration of at least {low:g} s: nature's durations "
                              "are 0 s or more (the planner cuts it at 0)", s.domain.low.span)

    def visit_RelConstraint(self, s: m.RelConstraint) -> None:
        self.expr(s.left, self.scope)
        self.expr(s.right, self.scope)

    def visit_MacroCall(self, s: m.MacroCall) -> None:
        macro = self.domain.macros.get(s.name)
        if macro is None:
            self.ctx.unknown("undefined-macro", "macro", s.name, self.domain.macros, s.span)
        elif len(macro.params) != len(s.args):
            self.ctx.report("arity-mismatch",
                            f"macro '{s.name}' takes {len(macro.params)} argument(s), {len(s.args)} given", s.span)
        for arg in s.args:
            self.expr(arg, self.scope)

    def generic_visit(self, node: m.Node) -> None:
        # Implication visits its two constraints; declarations need nothing more.
        if isinstance(node, m.Implication):
            super().generic_visit(node)

    def attr_value(self, a: m.AttrValue, scope: Scope, resource: bool = False) -> None:
        attribute = self.domain.attributes.get(a.attribute)
        for k, arg in enumerate(a.args):
            allowed_arg = (self.domain.value_domain(attribute, attribute.params[k].name)
                           if attribute is not None and k < len(attribute.params) else None)
            if allowed_arg is None or not isinstance(arg, m.IxName) or arg.name in scope.macro_params:
                self.expr(arg, scope)
            elif arg.name not in allowed_arg:
                assert attribute is not None
                self.ctx.report("value-outside-domain",
                                f"'{arg.name}' is not a value of {a.attribute}'s {attribute.params[k].name} "
                                f"({', '.join(sorted(allowed_arg))})", arg.span)
        values = (a.value.before, a.value.after) if isinstance(a.value, m.Transition) else (a.value,)
        allowed = self.domain.value_domain(attribute) if attribute is not None else None
        for value in values:
            if not (allowed is not None and isinstance(value, m.IxName)):
                self.expr(value, scope)  # symbols of a known domain are checked against it below
        if attribute is None:
            self.ctx.unknown("undefined-attribute", "resource" if resource else "attribute", a.attribute,
                             self.domain.attributes, a.span)
            return
        if len(attribute.params) != len(a.args):
            self.ctx.report("arity-mismatch",
                            f"'{a.attribute}' takes {len(attribute.params)} argument(s), {len(a.args)} given", a.span)
        if allowed is None:
            return
        for value in values:
            if isinstance(value, m.IxName) and value.name not in allowed and value.name not in scope.macro_params:
                self.ctx.report("value-outside-domain",
                                f"'{value.name}' is not a value of {a.attribute} ({', '.join(sorted(allowed))})",
                                value.span)

    def domain_value(self, d: m.DomainValue, scope: Scope) -> None:
        if isinstance(d, m.Interval):
            self.expr(d.low, scope)
            self.expr(d.high, scope)
            low, high = constant_value(d.low), constant_value(d.high)
            if low is not None and high is not None and low > high:
                self.ctx.report("empty-interval", f"interval [{low}, {high}] is empty: its bounds are reversed",
                                d.span)
            return
        for part in d.parts:
            if isinstance(part, m.SetRef) and part.name not in self.domain.constants:
                self.ctx.unknown("undefined-constant", "constant set", part.name, self.domain.constants, part.span)

    def time(self, e: m.IxExpr, scope: Scope) -> None:
        if isinstance(e, m.IxName):
            self.named.add(e.name)
        if isinstance(e, m.IxName) and e.name not in scope.timepoints and e.name not in scope.macro_params:
            self.ctx.report("undeclared-timepoint",
                            f"timepoint '{e.name}' is not declared; add 'timepoint {e.name};'", e.span)
        else:
            self.expr(e, scope)

    def expr(self, e: m.IxExpr, scope: Scope) -> None:
        for node in walk(e):
            if isinstance(node, m.IxCall) and node.function not in FUNCTIONS:
                self.ctx.unknown("undefined-function", "function", node.function, FUNCTIONS, node.span)
            elif isinstance(node, m.IxCall) and node.function == "abs" and len(node.args) != 1:
                self.ctx.report("arity-mismatch", f"abs takes one argument, {len(node.args)} given", node.span)
            elif isinstance(node, m.IxCall) and len(node.args) < 2 and node.function != "abs":
                self.ctx.report("arity-mismatch", f"{node.function} takes two arguments or more", node.span)
            if isinstance(node, m.IxVar) and node.name not in scope.variables:
                self.ctx.report("undeclared-variable",
                                f"variable '{node.name}' is not declared; add 'variable {node.name};'", node.span)
            elif isinstance(node, m.IxName):
                self.named.add(node.name)
                known = scope.timepoints | scope.macro_params | self.symbols
                if node.name not in known:
                    self.ctx.unknown("undefined-name", "name", node.name, known, node.span,
                                     " (not a timepoint, a macro parameter or a declared symbolic value)")


def constant_value(e: m.IxExpr) -> float | None:
    """The value of a constant numeric expression (`0.0 - 10.0`, `-oo`), else None."""
    if isinstance(e, m.Number):
        return float(e.value)
    if isinstance(e, m.Infinity):
        return float("inf")
    if isinstance(e, m.IxUnary):
        inner = constant_value(e.operand)
        return None if inner is None else (-inner if e.op == "-" else inner)
    if isinstance(e, m.IxBinary):
        left, right = constant_value(e.left), constant_value(e.right)
        if left is None or right is None:
            return None
        return fold(e.op.rstrip("."), left, right)
    return None


def check_members(ctx: Context, tables_: DomainTables) -> None:
    checker = ScopeChecker(ctx, tables_)
    for member in tables_.members:
        if isinstance(member, m.Task):
            scope = checker.scope_for("task", member.body, member.params, (member.start, member.end))
            checker.statements(member.body, scope)
        elif isinstance(member, m.Macro):
            scope = checker.scope_for("macro", member.body, macro_params=member.params)
            scope.timepoints.update(member.params)
            checker.statements(member.body, scope)
        elif isinstance(member, (m.Attribute, m.Resource)):
            scope = checker.scope_for("attribute", member.body, member.params)
            checker.statements(member.body, scope)


def check(ctx: Context) -> None:
    domains: dict[str, DomainTables] = {}
    for domain in ctx.items(m.Domain):
        domains[domain.name] = tables(ctx, domain.members)
        check_members(ctx, domains[domain.name])
    for problem in ctx.items(m.Problem):
        target = ctx.lookup(m.Domain, problem.domain, problem.domain.span, "undefined-domain")
        if target is None:
            continue
        problem_tables = tables(ctx, problem.body, domains[target.name])
        check_members(ctx, problem_tables)  # what its own fragments bring (macros, attributes)
        statements = [s for s in problem_tables.members if not isinstance(
            s, (m.Constant, m.Attribute, m.Resource, m.Macro, m.Task))]
        checker = ScopeChecker(ctx, problem_tables)
        scope = checker.scope_for("problem", statements, timepoints=PROBLEM_TIMEPOINTS)
        checker.statements(statements, scope)
        if not any(getattr(s, "goal", None) is not None for s in statements):
            ctx.warn("no-goals", f"problem '{problem.name}' has no goal(...) to plan for", problem.span)
    check_include_cycles(ctx)
    included = {member.name for item in ctx.program.items if isinstance(item, (m.Domain, m.Problem, m.Fragment))
                for member in getattr(item, "members", getattr(item, "body", ())) if isinstance(member, m.Include)}
    for fragment in ctx.items(m.Fragment):
        if fragment.name not in included:
            ctx.warn("unused-fragment", f"fragment '{fragment.name}' is included by no domain, problem or "
                     "fragment, so nothing checks or uses it", fragment.span)
