"""IxTeT domains and problems (seed 004 §3.2.1.2, annex A).

Includes are expanded first (fragments play the seed's `#include`); then every task, macro,
attribute and problem is checked in its own scope: `?variables` declared, timepoints declared,
attributes and macros known with the right arity, symbolic values inside their domains.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from specc.check.context import Context
from specc.check.expressions import UnknownFunction, lowered
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import Visitor, walk
from specc.runtime.planner import model as pm
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
    # An include names no fragment (reported): what it would declare is missing, so the names
    # it would have declared are not checked, which would say each use of them is unknown.
    incomplete: bool = False

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


MISSING_FRAGMENT = object()  # what `expand` gives for an include of a fragment that does not exist


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
            else:
                yield MISSING_FRAGMENT


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
        if member is MISSING_FRAGMENT:
            result.incomplete = True
            continue
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

    def unknown(self, code: str, kind: str, name: str, known: Iterable[str], span: m.Span, suffix: str = "") -> None:
        """An unknown name, said unless an include names no fragment (reported there): the names
        that fragment would have declared would each be said unknown, at every use."""
        if not self.domain.incomplete:
            self.ctx.unknown(code, kind, name, known, span, suffix)

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
            elif goal is not None:
                for what, part in (("priority", goal.priority), ("weight", goal.weight)):
                    value = constant_value(part)
                    if value is None or not math.isfinite(value):
                        self.ctx.report("bad-goal", f"a goal's {what} is a finite number (goal(priority, "
                                        "weight), e.g. goal(2, 0)): the planner keeps the goals of highest "
                                        "priority first", part.span)
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
            self.unknown("undefined-macro", "macro", s.name, self.domain.macros, s.span)
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
            if attribute is not None and k < len(attribute.params):
                self.symbols_for_numbers(arg, attribute, attribute.params[k].name,
                                         f"{a.attribute}'s {attribute.params[k].name}", scope)
        values = (a.value.before, a.value.after) if isinstance(a.value, m.Transition) else (a.value,)
        allowed = self.domain.value_domain(attribute) if attribute is not None else None
        for value in values:
            if not (allowed is not None and isinstance(value, m.IxName)):
                self.expr(value, scope)  # symbols of a known domain are checked against it below
        if attribute is None:
            self.unknown("undefined-attribute", "resource" if resource else "attribute", a.attribute,
                             self.domain.attributes, a.span)
            return
        if len(attribute.params) != len(a.args):
            self.ctx.report("arity-mismatch",
                            f"'{a.attribute}' takes {len(attribute.params)} argument(s), {len(a.args)} given", a.span)
        for value in values:
            self.symbols_for_numbers(value, attribute, VALUE_VAR, a.attribute, scope)
        if allowed is None:
            return
        for value in values:
            if isinstance(value, m.IxName) and value.name not in allowed and value.name not in scope.macro_params:
                self.ctx.report("value-outside-domain",
                                f"'{value.name}' is not a value of {a.attribute} ({', '.join(sorted(allowed))})",
                                value.span)

    def symbols_for_numbers(self, e: m.IxExpr, block: m.Attribute | m.Resource, variable: str, what: str,
                            scope: Scope) -> None:
        """Report the symbols `e` gives where `block`'s `variable` takes numbers (its domain is an
        interval; a resource's amount always is): the planner would only fail on them deep in
        its search, as if the goals were out of reach."""
        domain = declared_domain(block, variable)
        numeric = isinstance(domain, m.Interval) or (isinstance(block, m.Resource) and variable == VALUE_VAR)
        if not numeric:
            return
        low, high = (constant_value(domain.low), constant_value(domain.high)) if isinstance(
            domain, m.Interval) else (None, None)
        numbers = f"numbers in [{low:g}, {high:g}]" if low is not None and high is not None else "numbers"
        said = (f"an amount of {what}, which is a number" if isinstance(block, m.Resource) and variable == VALUE_VAR
                else f"a value of {what}, which takes {numbers}")
        for node in walk(e):
            if (isinstance(node, m.IxName) and node.name in self.symbols
                    and node.name not in scope.timepoints | scope.macro_params):
                self.ctx.report("value-outside-domain",
                                f"'{node.name}' is not {said}; write a number or a ?variable", node.span)

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
                self.unknown("undefined-constant", "constant set", part.name, self.domain.constants, part.span)

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
                close = did_you_mean(node.name, scope.variables)
                declared = sorted(scope.variables)
                fix = (f"add 'variable {node.name};'{close}" if close else
                       f"add 'variable {node.name};', or use one of {', '.join(declared)}"
                       if 0 < len(declared) <= 6 else f"add 'variable {node.name};'")
                self.ctx.report("undeclared-variable", f"variable '{node.name}' is not declared; {fix}", node.span)
            elif isinstance(node, m.IxName):
                self.named.add(node.name)
                known = scope.timepoints | scope.macro_params | self.symbols
                if node.name not in known:
                    self.unknown("undefined-name", "name", node.name, known, node.span,
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


def check_macro_cycles(ctx: Context, macros: dict[str, m.Macro]) -> None:
    """A macro is inlined where it is called: one that calls itself, directly or through other
    macros, would be inlined without end. Said at the call that closes the cycle."""
    calls = {name: [c for statement in macro.body for c in walk(statement)
                    if isinstance(c, m.MacroCall) and c.name in macros] for name, macro in macros.items()}

    def visit(name: str, chain: tuple[str, ...]) -> None:
        for call in calls[name]:
            if call.name == chain[0]:
                if chain[0] == min(chain):  # said once, from the cycle's first macro by name
                    what = "itself" if len(chain) == 1 else (
                        f"'{call.name}', which leads back to it ({' -> '.join(chain + (call.name,))})")
                    ctx.report("macro-cycle", f"macro '{name}' calls {what}: a macro is written out where it "
                               "is called, so this never ends; write the statements out instead of the call",
                               call.span)
            elif call.name not in chain:
                visit(call.name, chain + (call.name,))

    for name in macros:
        visit(name, (name,))


def check_members(ctx: Context, tables_: DomainTables) -> None:
    check_macro_cycles(ctx, tables_.macros)
    checker = ScopeChecker(ctx, tables_)
    for member in tables_.members:
        if isinstance(member, m.Task):
            scope = checker.scope_for("task", member.body, member.params, (member.start, member.end))
            checker.statements(member.body, scope)
            check_task_network(ctx, member, scope.timepoints)
        elif isinstance(member, m.Macro):
            scope = checker.scope_for("macro", member.body, macro_params=member.params)
            scope.timepoints.update(member.params)
            checker.statements(member.body, scope)
        elif isinstance(member, (m.Attribute, m.Resource)):
            scope = checker.scope_for("attribute", member.body, member.params)
            checker.statements(member.body, scope)


def check(ctx: Context) -> None:
    domains: dict[str, DomainTables] = {}
    misplaced: set[int] = set()  # statements said misplaced already (a fragment several domains include)
    for domain in ctx.items(m.Domain):
        domains[domain.name] = tables(ctx, domain.members)
        check_members(ctx, domains[domain.name])
        for member in domains[domain.name].members:  # what a fragment it includes brings
            if not isinstance(member, (m.Constant, m.Attribute, m.Resource, m.Macro, m.Task)) \
                    and id(member) not in misplaced:
                misplaced.add(id(member))
                ctx.report("statement-outside-problem", f"domain '{domain.name}' includes this statement (through "
                           "a fragment), but a domain declares constants, attributes, resources, macros and "
                           "tasks only: a statement belongs to a problem, or to a fragment only problems include",
                           member.span)
    for problem in ctx.items(m.Problem):
        target = ctx.lookup(m.Domain, problem.domain, problem.domain.span, "undefined-domain")
        if target is None:
            continue
        problem_tables = tables(ctx, problem.body, domains[target.name])
        problem_tables.incomplete |= domains[target.name].incomplete
        check_members(ctx, problem_tables)  # what its own fragments bring (macros, attributes)
        statements = [s for s in problem_tables.members if not isinstance(
            s, (m.Constant, m.Attribute, m.Resource, m.Macro, m.Task))]
        checker = ScopeChecker(ctx, problem_tables)
        scope = checker.scope_for("problem", statements, timepoints=PROBLEM_TIMEPOINTS)
        checker.statements(statements, scope)
        if not any(getattr(s, "goal", None) is not None for s in statements):
            ctx.warn("no-goals", f"problem '{problem.name}' has no goal(...) to plan for", problem.span)
        check_temporal_network(ctx, problem, statements, scope.timepoints)
    check_include_cycles(ctx)
    included = {member.name for item in ctx.program.items if isinstance(item, (m.Domain, m.Problem, m.Fragment))
                for member in getattr(item, "members", getattr(item, "body", ())) if isinstance(member, m.Include)}
    for fragment in ctx.items(m.Fragment):
        if fragment.name not in included:
            ctx.warn("unused-fragment", f"fragment '{fragment.name}' is included by no domain, problem or "
                     "fragment, so nothing checks or uses it", fragment.span)


@dataclass(frozen=True)
class Bound:
    """`t(second) - t(first) <= weight` in a problem's temporal network, and where it comes from:
    a constraint as written (with its span), or what the planner always requires (no span)."""

    first: str
    second: str
    weight: float
    text: str
    span: m.Span | None = None


def temporal_bounds(statements: Iterable[Any], timepoints: set[str]) -> list[Bound]:
    """The problem's temporal network: its constraints that bound a difference of two timepoints
    (or a date), as the planner reads them, and what the planner requires of every problem: each
    timepoint at or after t_start, each it schedules by t_end, each hold's start before its end."""
    start, end = PROBLEM_TIMEPOINTS
    bounds: list[Bound] = []

    def add(first: str, second: str, low: float, high: float, text: str, span: m.Span | None) -> None:
        if high < pm.INF:
            bounds.append(Bound(first, second, high, text, span))
        if low > -pm.INF:
            bounds.append(Bound(second, first, -low, text, span))

    natures: set[str] = set()
    for s in statements:
        constraint: pm.Member | pm.Relation | None = None
        try:
            if isinstance(s, m.InConstraint) and isinstance(s.domain, m.Interval):
                low, high = constant_value(s.domain.low), constant_value(s.domain.high)
                if low is not None and high is not None and low <= high:  # else `empty-interval` says it
                    expr = lowered(s.expr, timepoints)
                    constraint = pm.Member(expr, pm.Interval(low, high))
                    text = f"{pm.describe(expr)} in [{low:g}, {high:g}]"
            elif isinstance(s, m.RelConstraint):
                left, right = lowered(s.left, timepoints), lowered(s.right, timepoints)
                constraint = pm.Relation("=" if s.op in ("=.", "==") else s.op, left, right)
                text = f"{pm.describe(left)} {s.op} {pm.describe(right)}"
        except UnknownFunction:
            continue  # reported by the scope checks
        if constraint is not None and pm.timepoints_of(constraint):
            try:
                pieces = pm.differences(constraint, origin=start)
            except ValueError:
                continue  # not a difference of dates: not a temporal constraint the planner takes
            for first, second, low, high in pieces:
                add(first, second, low, high, f"{text} (line {s.span.line})", s.span)
        elif isinstance(s, m.Hold) and isinstance(s.start, m.IxName) and isinstance(s.end, m.IxName):
            add(s.start.name, s.end.name, 0.0, pm.INF,
                f"the hold of {s.attr.attribute} from {s.start.name} to {s.end.name} (line {s.span.line})", None)
        elif isinstance(s, m.Event) and s.kind == "contingent" and isinstance(s.time, m.IxName):
            natures.add(s.time.name)
    for point in sorted(timepoints - {start}):
        add(start, point, 0.0, pm.INF, f"{point} >= {start} (every timepoint comes at or after the start)", None)
        if point not in natures | {end}:
            add(point, end, 0.0, pm.INF, f"{point} <= {end} (the planner dates every timepoint by the end)", None)
    return bounds


def negative_cycle(bounds: list[Bound]) -> list[Bound] | None:
    """Bounds that cannot all hold (a cycle of the network whose weights sum below zero), or None
    (Bellman-Ford from a source before every timepoint)."""
    points = sorted({b.first for b in bounds} | {b.second for b in bounds})
    distance = dict.fromkeys(points, 0.0)
    last: dict[str, Bound] = {}
    relaxed: Bound | None = None
    for _ in range(len(points)):
        relaxed = None
        for b in bounds:
            if distance[b.first] + b.weight < distance[b.second] - 1e-9:
                distance[b.second] = distance[b.first] + b.weight
                last[b.second] = relaxed = b
        if relaxed is None:
            return None
    assert relaxed is not None
    point = relaxed.second
    for _ in range(len(points)):  # back far enough to be on the cycle, not on a path into it
        point = last[point].first
    cycle: list[Bound] = []
    at = point
    while True:
        b = last[at]
        cycle.append(b)
        at = b.first
        if at == point:
            return cycle[::-1]


def check_task_network(ctx: Context, task: m.Task, timepoints: set[str]) -> None:
    """A task's own temporal constraints (its durations, contingent or not, the delays between its
    timepoints) must be able to hold together: else no instance of it is ever in a plan, which
    only planning would show ("duration would lie in [100, 30]")."""
    written = [b for b in temporal_bounds(task.body, timepoints) if b.span is not None]
    written.append(Bound(task.end, task.start, 0.0, f"{task.start} <= {task.end} (a task ends after it starts)"))
    report_cycle(ctx, negative_cycle(written), f"task '{task.name}'", task.span)


def check_temporal_network(ctx: Context, problem: m.Problem, statements: list[Any], timepoints: set[str]) -> None:
    """The problem's temporal constraints must be able to hold together: when they cannot, the
    planner has no plan to give, whatever its domain (and nature's instants promise dates no
    realisation keeps: a plan would be judged against no nature at all)."""
    report_cycle(ctx, negative_cycle(temporal_bounds(statements, timepoints)), f"problem '{problem.name}'",
                 problem.span)


def report_cycle(ctx: Context, cycle: list[Bound] | None, owner: str, owner_span: m.Span) -> None:
    """`contradictory-constraints` at the first constraint written of `cycle`, noting the others."""
    if cycle is None:
        return
    said: list[str] = []
    # The written constraints in source order, then what the planner requires of every problem.
    for b in sorted(cycle, key=lambda b: (b.span is None, b.span.line if b.span else 0)):
        if b.text not in said:
            said.append(b.text)
    written = sorted({id(b.span): b.span for b in cycle if b.span is not None}.values(),
                     key=lambda span: (span.file, span.line, span.column))
    listed = said[0] if len(said) == 1 else f"{', '.join(said[:-1])} and {said[-1]}"
    span = written[0] if written else owner_span
    ctx.report("contradictory-constraints", f"the temporal constraints of {owner} cannot all hold: "
               f"{listed}; loosen or remove one of them", span,
               *((other, "and this constraint") for other in written[1:]))
