"""Planning-domain normalisation: a `domain` or `problem` block (with its includes) lowered to
the records of `specc.runtime.planner.model` that the generated planner modules hold.

Includes are expanded, macros inlined (a macro's own `variable`s renamed `?name#k` for its k-th
call, so two calls never share them), constant sets spelled out, constant arithmetic folded and
the dotted IxTeT operators (`=.`, `-.`) written plainly. An assertion whose time is an
expression (`t_start + 5`) gets a timepoint of its own, tied to the expression.

Runs on programs that passed `specc check`; what the checks let through but the planner cannot
run raises PlanningError (a bug, not a user error).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from specc.check.expressions import UnknownFunction, lowered
from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.runtime.planner import model as pm

VALUE_VAR = "?value"
PROBLEM_START, PROBLEM_END = "t_start", "t_end"


class PlanningError(ValueError):
    pass


def members(program: m.Program, items: Iterable[Any], chain: tuple[str, ...] = ()) -> Iterator[Any]:
    """`items` with every include replaced by the included fragment's members, each once."""
    fragments = symbols_of(program).blocks[m.Fragment]
    seen: set[int] = set()

    def expand(items: Iterable[Any], chain: tuple[str, ...]) -> Iterator[Any]:
        for item in items:
            if isinstance(item, m.Include):
                if item.name in fragments and item.name not in chain:
                    yield from expand(fragments[item.name].members, chain + (item.name,))
            elif id(item) not in seen:
                seen.add(id(item))
                yield item

    yield from expand(items, chain)


@dataclass
class Scope:
    """What names mean while one task, macro call or problem is lowered."""

    constants: dict[str, tuple[str, ...]]
    macros: dict[str, m.Macro]
    timepoints: set[str] = field(default_factory=set)
    arguments: dict[str, pm.Expr] = field(default_factory=dict)  # macro parameters
    renames: dict[str, str] = field(default_factory=dict)  # macro variables
    variables: list[str] = field(default_factory=list)
    fresh_timepoints: list[str] = field(default_factory=list)
    calls: list[int] = field(default_factory=lambda: [0])  # shared by nested scopes


class Lowering:
    def __init__(self, program: m.Program, items: Iterable[Any]):
        self.members = list(members(program, items))
        self.constants: dict[str, tuple[str, ...]] = {}
        for member in self.members:
            if isinstance(member, m.Constant):
                self.constants[member.name] = self.symbols(member.value)
        self.macros = {mm.name: mm for mm in self.members if isinstance(mm, m.Macro)}

    # ------------------------------------------------------------ values
    def symbols(self, union: m.SetUnion) -> tuple[str, ...]:
        values: set[str] = set()
        for part in union.parts:
            if isinstance(part, m.SetLiteral):
                values.update(part.values)
            elif part.name in self.constants:
                values.update(self.constants[part.name])
            else:
                raise PlanningError(f"unknown constant set '{part.name}'")
        return tuple(sorted(values))

    def expr(self, e: m.IxExpr, scope: Scope) -> pm.Expr:
        try:
            return lowered(e, scope.timepoints, scope.arguments, scope.renames)
        except UnknownFunction as error:
            raise PlanningError(str(error)) from None

    def domain(self, d: m.DomainValue, scope: Scope) -> pm.Values | tuple[pm.Expr, pm.Expr]:
        """A constant domain, or the two bound expressions of a non-constant interval."""
        if isinstance(d, m.SetUnion):
            return pm.Symbols(self.symbols(d))
        low, high = self.expr(d.low, scope), self.expr(d.high, scope)
        if isinstance(low, pm.Num) and isinstance(high, pm.Num):
            return pm.Interval(low.value, high.value)
        return low, high

    def time(self, e: m.IxExpr, scope: Scope, out: list[pm.Constraint]) -> str:
        value = self.expr(e, scope)
        if isinstance(value, pm.Time):
            return value.name
        name = f"t#{len(scope.fresh_timepoints) + 1}"
        scope.fresh_timepoints.append(name)
        scope.timepoints.add(name)
        out.append(pm.Relation("=", pm.Time(name), value, line=e.span.line))
        return name

    # ------------------------------------------------------------ statements
    def statements(self, body: Iterable[Any], scope: Scope) -> tuple[list[pm.Assertion], list[pm.Constraint]]:
        assertions: list[pm.Assertion] = []
        constraints: list[pm.Constraint] = []
        body = list(body)
        for s in body:  # a timepoint may be declared after its first use
            if isinstance(s, m.TimepointDecl):
                scope.timepoints.update(s.names)
        for s in body:
            line = s.span.line
            if isinstance(s, m.VariableDecl):
                for v in s.names:
                    name = scope.renames.get(v.name, v.name)
                    if name not in scope.variables:
                        scope.variables.append(name)
            elif isinstance(s, m.TimepointDecl):
                scope.timepoints.update(s.names)
            elif isinstance(s, m.Hold):
                args, value = self.attr_args(s.attr, scope)
                assertions.append(pm.Hold(s.attr.attribute, args, self.value(value, scope),
                                          self.time(s.start, scope, constraints), self.time(s.end, scope, constraints),
                                          goal=self.goal(s.goal, scope), line=line))
            elif isinstance(s, m.Event):
                args, value = self.attr_args(s.attr, scope)
                if not isinstance(value, m.Transition):
                    raise PlanningError(f"line {line}: an event needs a transition (before, after)")
                assertions.append(pm.Event(s.attr.attribute, args, self.expr(value.before, scope),
                                           self.expr(value.after, scope), self.time(s.time, scope, constraints),
                                           kind=s.kind or "", goal=self.goal(s.goal, scope), line=line))
            elif isinstance(s, m.ResourceUse):
                if s.verb != "use" or not isinstance(s.when, m.Window):
                    raise PlanningError(f"line {line}: only use(R(): amount, (start, end)) is planned")
                args, value = self.attr_args(s.attr, scope)
                assertions.append(pm.Use(s.attr.attribute, args, self.value(value, scope),
                                         self.time(s.when.start, scope, constraints),
                                         self.time(s.when.end, scope, constraints), line=line))
            elif isinstance(s, (m.InConstraint, m.RelConstraint)):
                constraints.extend(self.constraint(s, scope))
            elif isinstance(s, m.Implication):
                condition = self.constraint(s.condition, scope)
                consequence = self.constraint(s.consequence, scope)
                then = consequence[0] if len(consequence) == 1 else None
                if len(condition) != 1 or not isinstance(condition[0], pm.Member) or not isinstance(
                        then, (pm.Member, pm.Relation)):
                    raise PlanningError(f"line {line}: an implication needs constant domains")
                constraints.append(pm.Implies(condition[0], then, line=line))
            elif isinstance(s, m.MacroCall):
                inner_assertions, inner_constraints = self.inline(s, scope)
                assertions.extend(inner_assertions)
                constraints.extend(inner_constraints)
        return assertions, constraints

    def constraint(self, s: m.InConstraint | m.RelConstraint, scope: Scope) -> list[pm.Constraint]:
        line = s.span.line
        if isinstance(s, m.RelConstraint):
            op = "=" if s.op in ("=.", "==") else s.op
            return [pm.Relation(op, self.expr(s.left, scope), self.expr(s.right, scope), s.contingent, line)]
        expr = self.expr(s.expr, scope)
        domain = self.domain(s.domain, scope)
        if isinstance(domain, tuple):
            return [pm.Relation(">=", expr, domain[0], s.contingent, line),
                    pm.Relation("<=", expr, domain[1], s.contingent, line)]
        return [pm.Member(expr, domain, s.contingent, line)]

    def inline(self, call: m.MacroCall, scope: Scope) -> tuple[list[pm.Assertion], list[pm.Constraint]]:
        macro = self.macros.get(call.name)
        if macro is None:
            raise PlanningError(f"unknown macro '{call.name}'")
        scope.calls[0] += 1
        k = scope.calls[0]
        inner = Scope(scope.constants, scope.macros, scope.timepoints,
                      {p: self.expr(a, scope) for p, a in zip(macro.params, call.args, strict=False)},
                      {v.name: f"{v.name}#{k}" for s in macro.body if isinstance(s, m.VariableDecl) for v in s.names},
                      scope.variables, scope.fresh_timepoints, scope.calls)
        return self.statements(macro.body, inner)

    def attr_args(self, a: m.AttrValue, scope: Scope) -> tuple[tuple[pm.Expr, ...], Any]:
        return tuple(self.expr(x, scope) for x in a.args), a.value

    def value(self, value: Any, scope: Scope) -> pm.Expr:
        if isinstance(value, m.Transition):
            raise PlanningError(f"line {value.span.line}: a hold takes one value, not a transition")
        return self.expr(value, scope)

    def goal(self, mark: m.GoalMark | None, scope: Scope) -> pm.GoalMark | None:
        if mark is None:
            return None
        priority, weight = self.expr(mark.priority, scope), self.expr(mark.weight, scope)
        if not isinstance(priority, pm.Num) or not isinstance(weight, pm.Num):
            raise PlanningError(f"line {mark.span.line}: goal(priority, weight) takes two numbers")
        return pm.GoalMark(priority.value, weight.value)

    # ------------------------------------------------------------ declarations
    def scope(self, timepoints: Iterable[str] = ()) -> Scope:
        return Scope(self.constants, self.macros, set(timepoints))

    def param_domains(self, params: tuple[m.IxVar, ...], body: Iterable[Any]) -> tuple[pm.Values | None, ...]:
        found: dict[str, pm.Values] = {}
        for s in body:
            if isinstance(s, m.InConstraint) and isinstance(s.expr, m.IxVar):
                d = self.domain(s.domain, self.scope())
                if not isinstance(d, tuple):
                    found[s.expr.name] = d
        return tuple(found.get(p.name) for p in params)

    def attribute(self, a: m.Attribute) -> pm.Attribute:
        (values,) = self.param_domains((m.IxVar(name=VALUE_VAR, span=a.span),), a.body)
        return pm.Attribute(a.name, tuple(p.name for p in a.params), self.param_domains(a.params, a.body), values)

    def resource(self, r: m.Resource) -> pm.Resource:
        (values,) = self.param_domains((m.IxVar(name=VALUE_VAR, span=r.span),), r.body)
        capacity = values.high if isinstance(values, pm.Interval) else 1.0
        return pm.Resource(r.name, tuple(p.name for p in r.params), self.param_domains(r.params, r.body), capacity)

    def task(self, t: m.Task) -> pm.Task:
        scope = self.scope((t.start, t.end))
        scope.variables.extend(p.name for p in t.params)
        assertions, constraints = self.statements(t.body, scope)
        declared = sorted(scope.timepoints - {t.start, t.end})
        return pm.Task(t.name, tuple(p.name for p in t.params), t.start, t.end, tuple(declared),
                       tuple(v for v in scope.variables if v not in {p.name for p in t.params}),
                       tuple(assertions), tuple(constraints), t.preemption or "", t.span.line)

    def domain_model(self, name: str, source: str) -> pm.PlanningDomain:
        return pm.PlanningDomain(
            name,
            tuple(self.attribute(a) for a in self.members if isinstance(a, m.Attribute)),
            tuple(self.resource(r) for r in self.members if isinstance(r, m.Resource)),
            tuple(self.task(t) for t in self.members if isinstance(t, m.Task)),
            source)


def domain_model(program: m.Program, domain: m.Domain) -> pm.PlanningDomain:
    return Lowering(program, domain.members).domain_model(domain.name, domain.span.file)


def domain_block(program: m.Program, problem: m.Problem) -> m.Domain:
    """The `domain` block a problem is written for."""
    domain: m.Domain | None = symbols_of(program).blocks[m.Domain].get(problem.domain.text)
    if domain is None:
        raise PlanningError(f"unknown domain '{problem.domain.text}'")
    return domain


def problem_model(program: m.Program, problem: m.Problem) -> pm.Problem:
    domain = domain_block(program, problem)
    # The problem sees the domain's constants and macros, then what its own fragments bring.
    lowering = Lowering(program, list(domain.members) + list(problem.body))
    statements = [s for s in lowering.members if not isinstance(s, (m.Constant, m.Attribute, m.Resource, m.Macro,
                                                                     m.Task))]
    scope = lowering.scope((PROBLEM_START, PROBLEM_END))
    assertions, constraints = lowering.statements(statements, scope)
    return pm.Problem(problem.name, domain.name, tuple(sorted(scope.timepoints - {PROBLEM_START, PROBLEM_END})),
                      tuple(scope.variables), tuple(assertions), tuple(constraints), problem.preemption or "",
                      problem.span.file)
