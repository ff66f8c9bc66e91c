"""The planning model as data: what the back end `planner` generates from a `domain` or a
`problem` block (seed 004 §3.2.1.2, annex A), and what the planner, the validator and the
exports read.

Everything is already normalised: includes expanded, macros inlined (their own variables
renamed `?name#k` for the k-th call), constant sets spelled out, constant arithmetic folded
(`0.0 - 10.0` is -10.0), the IxTeT dotted operators (`=.`, `-.`) written without their dot, and
every time an assertion refers to is a named timepoint.

Semantics (shared with docs/planning.md):
- an attribute instance `A(args)` is a piecewise-constant function of time;
- `event(A(args): (v1, v2), t)`: A(args) is v1 just before t and v2 from t on;
- `hold(A(args): v, (t1, t2))`: A(args) is v over [t1, t2] and no event on it happens strictly
  inside; holds and events of a task must be supported (the value comes from an earlier
  event, with nothing changing it in between); events of the problem marked `explained` or
  `contingent` are given and need no support;
- `contingent` constraints are chosen by nature within their bounds: a plan must hold for
  every value they may take.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Union

INF = float("inf")
EPS = 0.01  # seconds between two events that must not be simultaneous (IxTeT's strict precedence)

# ---------------------------------------------------------------- expressions


@dataclass(frozen=True)
class Num:
    """A number in a planning expression."""

    value: float


@dataclass(frozen=True)
class Sym:
    """A symbolic value (a member of a constant set, e.g. STRAIGHT)."""

    name: str


@dataclass(frozen=True)
class Var:
    """A `?variable` of a task or of the problem."""

    name: str


@dataclass(frozen=True)
class Time:
    """A timepoint."""

    name: str


@dataclass(frozen=True)
class Op:
    """`+ - * /` (two arguments), `neg` (one), or the functions `max min abs`."""

    op: str
    args: tuple[Expr, ...]


Expr = Union[Num, Sym, Var, Time, Op]


def fold(op: str, left: float, right: float) -> float | None:
    """`left op right` for the four operations; None for a division by zero."""
    if op == "+":
        return left + right
    if op == "-":
        return left - right
    if op == "*":
        return left * right
    return left / right if op == "/" and right else None


FUNCTIONS = ("max", "min", "abs")


def describe(e: Expr) -> str:
    """An expression as the specification writes it (`(?x2 - ?x1)`, `max(?a, ?b)`), for messages."""
    if isinstance(e, Num):
        return f"{e.value:g}"
    if isinstance(e, (Sym, Var, Time)):
        return e.name
    if e.op in FUNCTIONS:
        return f"{e.op}({', '.join(describe(a) for a in e.args)})"
    if e.op == "neg":
        return f"-{describe(e.args[0])}"
    return f"({describe(e.args[0])} {e.op} {describe(e.args[1])})"


# ---------------------------------------------------------------- domains


@dataclass(frozen=True)
class Interval:
    """The numbers from `low` to `high`: a variable's domain."""

    low: float
    high: float


@dataclass(frozen=True)
class Symbols:
    """A finite set of symbols: a variable's domain."""

    values: tuple[str, ...]  # sorted


Values = Union[Interval, Symbols]


# ---------------------------------------------------------------- constraints


@dataclass(frozen=True)
class Member:
    """`expr in domain`; `contingent` when nature chooses the value."""

    expr: Expr
    domain: Values
    contingent: bool = False
    line: int = 0


@dataclass(frozen=True)
class Relation:
    """`left op right` with op one of `= != < <= > >=` (`=.` and `==` are `=`)."""

    op: str
    left: Expr
    right: Expr
    contingent: bool = False
    line: int = 0


@dataclass(frozen=True)
class Implies:
    """`condition => consequence` (Modele2's distance tables)."""

    condition: Member
    consequence: Member | Relation
    line: int = 0


Constraint = Union[Member, Relation, Implies]


def names_in(expr: Expr, kind: type) -> set[str]:
    """The names of the variables (kind Var) or timepoints (kind Time) an expression reads."""
    if isinstance(expr, kind) and isinstance(expr, (Var, Time)):
        return {expr.name}
    if isinstance(expr, Op):
        return set().union(*(names_in(a, kind) for a in expr.args))
    return set()


def constraint_names(c: Constraint, kind: type) -> set[str]:
    """The names of the variables (kind Var) or timepoints (kind Time) a constraint reads."""
    if isinstance(c, Member):
        return names_in(c.expr, kind)
    if isinstance(c, Relation):
        return names_in(c.left, kind) | names_in(c.right, kind)
    return constraint_names(c.condition, kind) | constraint_names(c.consequence, kind)


# ---------------------------------------------------------------- temporal constraints


def linear(e: Expr) -> tuple[dict[str, float], float] | None:
    """`e` as sum(coefficient * timepoint) + constant, or None when it is not linear in time."""
    if isinstance(e, Num):
        return {}, e.value
    if isinstance(e, Time):
        return {e.name: 1.0}, 0.0
    if isinstance(e, Op) and e.op in ("+", "-", "neg"):
        parts = [linear(a) for a in e.args]
        if any(p is None for p in parts):
            return None
        sign = -1.0 if e.op in ("-", "neg") else 1.0
        first = parts[0]
        assert first is not None
        if e.op == "neg":
            return {k: -v for k, v in first[0].items()}, -first[1]
        second = parts[1]
        assert second is not None
        coefficients = dict(first[0])
        for k, v in second[0].items():
            coefficients[k] = coefficients.get(k, 0.0) + sign * v
        return {k: v for k, v in coefficients.items() if v}, first[1] + sign * second[1]
    return None


def differences(c: Member | Relation, rename: Callable[[str], str] = str,
                origin: str = "t_start") -> list[tuple[str, str, float, float]]:
    """A temporal constraint as `low <= t(b) - t(a) <= high` requirements, its timepoints
    renamed (a date alone is measured from `origin`); ValueError when it is not a difference of
    two timepoints."""
    if isinstance(c, Member):
        if not isinstance(c.domain, Interval):
            raise ValueError("a timepoint takes numbers")
        form = linear(c.expr)
        low, high = c.domain.low, c.domain.high
    else:
        left, right = linear(c.left), linear(c.right)
        form = None
        if left is not None and right is not None:
            coefficients = dict(left[0])
            for k, v in right[0].items():
                coefficients[k] = coefficients.get(k, 0.0) - v
            form = ({k: v for k, v in coefficients.items() if v}, left[1] - right[1])
        strict = EPS if c.op in ("<", ">") else 0.0
        bounds = {"=": (0.0, 0.0), "<": (-INF, -strict), "<=": (-INF, 0.0), ">": (strict, INF), ">=": (0.0, INF)}
        if c.op not in bounds:
            raise ValueError(f"'{c.op}' between timepoints")
        low, high = bounds[c.op]
    if form is None:
        raise ValueError("not linear in time")
    coefficients, constant = form
    low, high = low - constant, high - constant
    plus = [k for k, v in coefficients.items() if v == 1.0]
    minus = [k for k, v in coefficients.items() if v == -1.0]
    if len(coefficients) == 2 and len(plus) == 1 and len(minus) == 1:
        return [(rename(minus[0]), rename(plus[0]), low, high)]
    if len(coefficients) == 1 and len(plus) == 1:
        return [(origin, rename(plus[0]), low, high)]
    if len(coefficients) == 1 and len(minus) == 1:
        return [(rename(minus[0]), origin, low, high)]
    raise ValueError("only differences of two timepoints are temporal constraints")


# ---------------------------------------------------------------- assertions


@dataclass(frozen=True)
class GoalMark:
    """The priority and weight of a problem's goal."""

    priority: float
    weight: float


@dataclass(frozen=True)
class Event:
    """A change of an attribute's value, from `before` to `after`, at a timepoint."""

    attribute: str
    args: tuple[Expr, ...]
    before: Expr
    after: Expr
    time: str
    kind: str = ""  # "" (planned) | explained | contingent
    goal: GoalMark | None = None
    line: int = 0


@dataclass(frozen=True)
class Hold:
    """An attribute keeping a value from one timepoint to another."""

    attribute: str
    args: tuple[Expr, ...]
    value: Expr
    start: str
    end: str
    goal: GoalMark | None = None
    line: int = 0


@dataclass(frozen=True)
class Use:
    """`use(R(args): amount, (start, end))`: borrows `amount` of a resource over [start, end]."""

    resource: str
    args: tuple[Expr, ...]
    amount: Expr
    start: str
    end: str
    goal: GoalMark | None = None  # never set: a use is not a goal (kept for a uniform interface)
    line: int = 0


Assertion = Union[Event, Hold, Use]


def subject(a: Assertion) -> str:
    """The attribute (or resource) an assertion is about."""
    return a.resource if isinstance(a, Use) else a.attribute


def assertion_timepoints(a: Assertion) -> tuple[str, ...]:
    """The timepoints an assertion is at: an event's instant, or a hold's or a use's two ends."""
    return (a.time,) if isinstance(a, Event) else (a.start, a.end)


# ---------------------------------------------------------------- declarations


@dataclass(frozen=True)
class Attribute:
    """A state variable of the domain, with the domains of its parameters and value."""

    name: str
    params: tuple[str, ...] = ()
    param_domains: tuple[Values | None, ...] = ()
    values: Values | None = None  # the domain of ?value


@dataclass(frozen=True)
class Resource:
    """A shared resource of the domain and its capacity."""

    name: str
    params: tuple[str, ...] = ()
    param_domains: tuple[Values | None, ...] = ()
    capacity: float = 1.0


@dataclass(frozen=True)
class Task:
    """An action a plan may hold: its parameters, timepoints, assertions and constraints."""

    name: str
    params: tuple[str, ...]
    start: str = "t_start"
    end: str = "t_end"
    timepoints: tuple[str, ...] = ()  # besides start and end
    variables: tuple[str, ...] = ()  # besides the parameters (macro variables included)
    assertions: tuple[Assertion, ...] = ()
    constraints: tuple[Constraint, ...] = ()
    preemption: str = ""  # latePreemptive | earlyPreemptive | nonPreemptive | preemptive | ""
    line: int = 0

    @property
    def preemptible(self) -> bool:
        """May the executive stop it while it runs (for a replanning)?"""
        return self.preemption in ("latePreemptive", "preemptive")


@dataclass(frozen=True)
class PlanningDomain:
    """Everything a planner plans with: attributes, resources and tasks."""

    name: str
    attributes: tuple[Attribute, ...] = ()
    resources: tuple[Resource, ...] = ()
    tasks: tuple[Task, ...] = ()
    source: str = ""

    def attribute(self, name: str) -> Attribute | None:
        return next((a for a in self.attributes if a.name == name), None)

    def task(self, name: str) -> Task | None:
        return next((t for t in self.tasks if t.name == name), None)


@dataclass(frozen=True)
class Problem:
    """The initial partial plan: explained and contingent events, goals with priorities,
    required assertions and constraints; `t_start` is the mission's time origin."""

    name: str
    domain: str
    timepoints: tuple[str, ...] = ()  # besides t_start and t_end
    variables: tuple[str, ...] = ()
    assertions: tuple[Assertion, ...] = ()
    constraints: tuple[Constraint, ...] = ()
    preemption: str = ""
    source: str = ""
    start: str = "t_start"
    end: str = "t_end"


def timepoints_of(e: Expr | Constraint) -> set[str]:
    """The timepoints an expression or a constraint mentions."""
    if isinstance(e, Time):
        return {e.name}
    if isinstance(e, Op):
        return set().union(*(timepoints_of(a) for a in e.args))
    if isinstance(e, Member):
        return timepoints_of(e.expr)
    if isinstance(e, Relation):
        return timepoints_of(e.left) | timepoints_of(e.right)
    if isinstance(e, Implies):
        return timepoints_of(e.condition) | timepoints_of(e.consequence)
    return set()


def end_bounds(problem: Problem) -> list[Member]:
    """The problem's own bounds on `t_end - t_start`: how long the mission may last."""
    span = Op("-", (Time(problem.end), Time(problem.start)))
    return [c for c in problem.constraints
            if isinstance(c, Member) and c.expr == span and isinstance(c.domain, Interval)]


def latest_end(problem: Problem) -> float:
    """The latest end its own bounds on `t_end - t_start` allow the mission (inf: none)."""
    return min((c.domain.high for c in end_bounds(problem) if isinstance(c.domain, Interval)), default=INF)


def without_latest_end(problem: Problem) -> Problem:
    """The problem with no latest end: the bounds written on `t_end - t_start` keep their lower
    bound only (the mission may still have to last so long)."""
    span = Op("-", (Time(problem.end), Time(problem.start)))
    return replace(problem, constraints=tuple(
        Member(span, Interval(c.domain.low, INF), c.contingent, c.line)
        if isinstance(c, Member) and c.expr == span and isinstance(c.domain, Interval) else c
        for c in problem.constraints))


def with_horizon(problem: Problem, seconds: float) -> Problem:
    """The problem with its mission ending by `seconds` after its start: the bounds written on
    `t_end - t_start` are cut to it (a lower bound beyond it comes down with it)."""
    span = Op("-", (Time(problem.end), Time(problem.start)))
    constraints: list[Constraint] = []
    for c in problem.constraints:
        if isinstance(c, Member) and c.expr == span and isinstance(c.domain, Interval):
            c = Member(span, Interval(min(c.domain.low, seconds), min(c.domain.high, seconds)), c.contingent, c.line)
        constraints.append(c)
    constraints.append(Member(span, Interval(0.0, seconds)))
    return replace(problem, constraints=tuple(constraints))
