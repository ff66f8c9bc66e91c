"""An independent plan validator: does a `Plan` really solve a `Problem` of a `PlanningDomain`?

Written from the semantics alone, sharing no code with the planner's search (only the records of
`model` and `plan`), so that the two can check each other. What a valid plan satisfies:

1. Actions. Each `Action` names a task of the domain and binds its parameters in order (`args`);
   `Action.values` may bind other variables of the task. Every task constraint that these bindings
   decide holds: symbolic `Member`s (value in the set), numeric `Member`s (value in the interval),
   `Relation`s (`= != < <= > >=`) and `Implies` whose condition they decide.
2. Durations. With the parameters bound, the task's numeric constraints (the contingent
   `t_end - t_start in [a, b]`, or `?d = t_end - t_start` with `?d` tied by the other constraints, e.g.
   distance / speed) allow durations in [dmin, dmax], computed here by interval constraint
   propagation (HC4 projections of `+ - * / neg max min abs`) and confirmed by a witness point at each
   bound (if a witness cannot be found, the propagated bound is kept: the check stays on the safe
   side). Symbolic variables the plan leaves unbound are enumerated (union of the ranges). The range
   must be non-empty (otherwise the action is impossible) and the plan's claimed `Action.duration`
   must contain it: `low <= dmin` and `high >= dmax` (within 1e-6): a planner must not underestimate
   nature.
3. Time. `t_start` is date 0. Controllable timepoints take their date from the plan: action starts
   are `Action.dispatch`, problem timepoints (`t_end`, goal timepoints) and internal task timepoints
   (`"<action id>.<name>"`) come from `Plan.schedule`. Nature chooses the rest: each action's end is
   its start plus a duration in [dmin, dmax], and each problem timepoint carrying a `contingent`
   event (a visibility window instant) lies in the bounds the problem's constraints give it relative
   to `t_start`; a pseudo-controllable plan (`Plan.controllability`) fixes these instants at the
   dates it assumes (`Plan.assumed`, which must lie in those bounds) and leaves nature the
   durations. The plan must be valid whatever nature does (strong controllability); the checks
   below run on several realisations of nature: all at the minimum, all at the maximum, all at the
   middle, each one at its maximum with the others at their minimum and the converse, and `samples`
   seeded random draws. Realisations breaking the constraints nature itself obeys (constraints among
   window timepoints only) are discarded. A violation is reported once, with the first realisation
   that shows it when it does not show in all of them.
4. Timelines. Each ground attribute instance (name + evaluated arguments; numbers equal within 1e-6)
   is a piecewise-constant function changed by events: the problem's (its explained and contingent
   events are given; planned ones, like the tasks', need support) and every action's. Two events on
   one instance at the same date are a violation. An event (v1 -> v2) at t needs the value just
   before t (the `after` of the latest event strictly before t) to be v1; no earlier event means
   "not supported". A hold (v, [t1, t2]) needs t1 <= t2, no event strictly inside (t1, t2), and the
   value just after t1 (events at t1 included) to be v. A hold on a symbolic variable the plan left
   unbound accepts any value of its domain (one value per variable and realisation). Resources: at
   no date may the amounts of the overlapping `use`s of one resource instance exceed its capacity.
5. The problem. Its non-goal holds and planned events are required; its goals (assertions with a
   `goal` mark) too, except those whose source line is in `dropped_lines` (the plan dropped them;
   their own timepoints then need no date). Its temporal constraints hold in every realisation,
   except those that only relate window timepoints (they describe nature). Controllable problem
   timepoints lie in [0, t_end]; each action starts at or after `Plan.now` and ends by `t_end`.
6. Task constraints that involve internal task timepoints are checked on every realisation.

Comparisons use an absolute tolerance of 1e-6 (`<` and `>` are strict).
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
import random
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache

from specc.runtime.planner.model import (
    Constraint,
    Event,
    Expr,
    Hold,
    Implies,
    Interval,
    Member,
    Num,
    Op,
    PlanningDomain,
    Problem,
    Relation,
    Sym,
    Symbols,
    Task,
    Time,
    Use,
    Var,
    assertion_timepoints,
    constraint_names,
    describe,
    timepoints_of,
)
from specc.runtime.planner.plan import Action, Plan, Value, format_value

TOLERANCE = 1e-6
INF = math.inf
MAX_SYMBOLIC_COMBINATIONS = 20000
PROPAGATION_ROUNDS = 100


# ================================================================ values and plain evaluation


class Unbound(Exception):
    """An expression needs a variable or a timepoint that has no value."""


class NotNumeric(Exception):
    """Arithmetic on a symbol."""


def normalise(value: Value | int) -> Value:
    return float(value) if isinstance(value, (int, float)) else value


def same(a: Value, b: Value) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= TOLERANCE
    return a == b


def text(value: Value | None) -> str:
    return "?" if value is None else format_value(value)


def date_text(date: float) -> str:
    return f"{date:.2f}".rstrip("0").rstrip(".") if math.isfinite(date) else str(date)


def constraint_text(c: Constraint) -> str:
    if isinstance(c, Member):
        if isinstance(c.domain, Symbols):
            domain = "{" + ", ".join(c.domain.values) + "}"
        else:
            domain = f"[{text(c.domain.low)}, {text(c.domain.high)}]"
        return f"{describe(c.expr)} in {domain}"
    if isinstance(c, Relation):
        return f"{describe(c.left)} {c.op} {describe(c.right)}"
    return f"{constraint_text(c.condition)} => {constraint_text(c.consequence)}"


def evaluate(expr: Expr, env: Mapping[str, Value], time_of: Callable[[str], float] | None = None) -> Value:
    """The value of `expr`; raises Unbound or NotNumeric."""
    if isinstance(expr, Num):
        return expr.value
    if isinstance(expr, Sym):
        return expr.name
    if isinstance(expr, Var):
        if expr.name not in env:
            raise Unbound(expr.name)
        return normalise(env[expr.name])
    if isinstance(expr, Time):
        if time_of is None:
            raise Unbound(expr.name)
        return time_of(expr.name)
    values = [evaluate(a, env, time_of) for a in expr.args]
    numbers = [v for v in values if isinstance(v, float)]
    if len(numbers) != len(values):
        raise NotNumeric(describe(expr))
    return arithmetic(expr.op, numbers)


def arithmetic(op: str, x: list[float]) -> float:
    if op == "+":
        return x[0] + x[1]
    if op == "-":
        return x[0] - x[1]
    if op == "*":
        return x[0] * x[1]
    if op == "/":
        return x[0] / x[1] if x[1] else math.copysign(INF, x[0])
    if op == "neg":
        return -x[0]
    if op == "max":
        return max(x)
    if op == "min":
        return min(x)
    if op == "abs":
        return abs(x[0])
    raise NotNumeric(f"unknown operator {op}")


def decide(c: Constraint, env: Mapping[str, Value], time_of: Callable[[str], float] | None = None) -> bool | None:
    """Does `c` hold? None when it needs something unbound."""
    try:
        if isinstance(c, Implies):
            condition = decide(c.condition, env, time_of)
            if condition is None:
                return None
            return True if not condition else decide(c.consequence, env, time_of)
        if isinstance(c, Member):
            value = evaluate(c.expr, env, time_of)
            if isinstance(c.domain, Symbols):
                return isinstance(value, str) and value in c.domain.values
            return isinstance(value, float) and c.domain.low - TOLERANCE <= value <= c.domain.high + TOLERANCE
        left, right = evaluate(c.left, env, time_of), evaluate(c.right, env, time_of)
    except Unbound:
        return None
    except NotNumeric:
        return False
    if c.op == "=":
        return same(left, right)
    if c.op == "!=":
        return not same(left, right)
    if not isinstance(left, float) or not isinstance(right, float):
        return False
    return {"<": left < right, "<=": left <= right + TOLERANCE,
            ">": left > right, ">=": left >= right - TOLERANCE}.get(c.op, False)


# ================================================================ interval propagation (durations)

Range = tuple[float, float]
Box = dict[str, Range]
EVERYTHING: Range = (-INF, INF)


def slack(lo: float, hi: float) -> float:
    return 1e-9 * max(1.0, abs(lo) if math.isfinite(lo) else 1.0, abs(hi) if math.isfinite(hi) else 1.0)


def meet(a: Range, b: Range) -> Range | None:
    """Intersection; None when empty (a rounding-sized gap closes to a point)."""
    lo, hi = max(a[0], b[0]), min(a[1], b[1])
    if lo <= hi:
        return lo, hi
    if lo - hi <= slack(lo, hi):
        return (lo + hi) / 2, (lo + hi) / 2
    return None


def times(a: float, b: float) -> float:
    return 0.0 if a == 0.0 or b == 0.0 else a * b  # 0 * inf is 0 for bounds


def multiply(a: Range, b: Range) -> Range:
    products = [times(x, y) for x in a for y in b]
    return min(products), max(products)


def divide(a: Range, b: Range) -> Range:
    if b[0] <= 0.0 <= b[1]:
        return EVERYTHING
    return multiply(a, (1.0 / b[1], 1.0 / b[0]))


def clean(r: Range) -> Range:
    lo, hi = r
    return (-INF if math.isnan(lo) else lo), (INF if math.isnan(hi) else hi)


class Propagator:
    """HC4: forward interval evaluation, backward projection onto the variables, to a fixpoint.
    Box keys: variable names, and '@name' for the task's timepoints."""

    def __init__(self, constraints: list[Constraint], env: Mapping[str, Value]):
        self.constraints = constraints
        self.env = env

    def forward(self, expr: Expr, box: Box) -> Range:
        if isinstance(expr, Num):
            return expr.value, expr.value
        if isinstance(expr, Sym):
            raise NotNumeric(expr.name)
        if isinstance(expr, Var):
            if expr.name in self.env:
                value = normalise(self.env[expr.name])
                if not isinstance(value, float):
                    raise NotNumeric(expr.name)
                return value, value
            return box.setdefault(expr.name, EVERYTHING)
        if isinstance(expr, Time):
            return box.setdefault("@" + expr.name, EVERYTHING)
        a = [self.forward(x, box) for x in expr.args]
        if expr.op == "*" and expr.args[0] == expr.args[1]:  # a square is never negative
            lo, hi = a[0]
            if lo >= 0:
                return lo * lo, hi * hi
            if hi <= 0:
                return hi * hi, lo * lo
            return 0.0, max(lo * lo, hi * hi)
        if expr.op == "+":
            return clean((a[0][0] + a[1][0], a[0][1] + a[1][1]))
        if expr.op == "-":
            return clean((a[0][0] - a[1][1], a[0][1] - a[1][0]))
        if expr.op == "*":
            return multiply(a[0], a[1])
        if expr.op == "/":
            return divide(a[0], a[1])
        if expr.op == "neg":
            return -a[0][1], -a[0][0]
        if expr.op == "max":
            return max(x[0] for x in a), max(x[1] for x in a)
        if expr.op == "min":
            return min(x[0] for x in a), min(x[1] for x in a)
        if expr.op == "abs":
            lo, hi = a[0]
            if lo >= 0:
                return lo, hi
            if hi <= 0:
                return -hi, -lo
            return 0.0, max(-lo, hi)
        raise NotNumeric(f"unknown operator {expr.op}")

    def narrow(self, expr: Expr, target: Range, box: Box) -> bool:
        """Shrink the box so that `expr` may lie in `target`; False when it cannot."""
        t = meet(self.forward(expr, box), target)
        if t is None:
            return False
        if isinstance(expr, Var) and expr.name not in self.env:
            box[expr.name] = t
            return True
        if isinstance(expr, Time):
            box["@" + expr.name] = t
            return True
        if not isinstance(expr, Op):
            return True
        args = expr.args
        if expr.op == "*" and args[0] == args[1]:
            # x * x in t: x within the square roots of t, on either side of zero (dividing t by
            # x's own range would never tighten it).
            if t[1] < 0:
                return False
            root_lo, root_hi = math.sqrt(max(t[0], 0.0)), math.sqrt(t[1])
            x = self.forward(args[0], box)
            sides = [s for s in (meet(x, (root_lo, root_hi)), meet(x, (-root_hi, -root_lo))) if s is not None]
            if not sides:
                return False
            return self.narrow(args[0], (min(s[0] for s in sides), max(s[1] for s in sides)), box)
        if expr.op in ("+", "-", "*", "/"):
            left, right = args
            b = self.forward(right, box)
            if expr.op == "+":
                ok = self.narrow(left, clean((t[0] - b[1], t[1] - b[0])), box)
            elif expr.op == "-":
                ok = self.narrow(left, clean((t[0] + b[0], t[1] + b[1])), box)
            elif expr.op == "*":
                ok = self.narrow(left, divide(t, b), box)
            else:
                ok = self.narrow(left, multiply(t, b), box)
            if not ok:
                return False
            a = self.forward(left, box)
            if expr.op == "+":
                return self.narrow(right, clean((t[0] - a[1], t[1] - a[0])), box)
            if expr.op == "-":
                return self.narrow(right, clean((a[0] - t[1], a[1] - t[0])), box)
            if expr.op == "*":
                return self.narrow(right, divide(t, a), box)
            return t[0] <= 0.0 <= t[1] or self.narrow(right, divide(a, t), box)
        if expr.op == "neg":
            return self.narrow(args[0], (-t[1], -t[0]), box)
        if expr.op in ("max", "min"):
            bound: Range = (-INF, t[1]) if expr.op == "max" else (t[0], INF)
            if not all(self.narrow(x, bound, box) for x in args):
                return False
            # the one argument that can still reach the target is the max (min) itself
            ranges = [self.forward(x, box) for x in args]
            reaching = [x for x, r in zip(args, ranges, strict=True)
                        if (r[1] >= t[0] if expr.op == "max" else r[0] <= t[1])]
            if not reaching:
                return False
            return len(reaching) > 1 or self.narrow(reaching[0], t, box)
        if expr.op == "abs":
            positive = meet(t, (0.0, INF))
            if positive is None:
                return False
            a = self.forward(args[0], box)
            parts = [p for p in (meet(a, positive), meet(a, (-positive[1], -positive[0]))) if p is not None]
            if not parts:
                return False
            return self.narrow(args[0], (min(p[0] for p in parts), max(p[1] for p in parts)), box)
        return True

    def apply(self, c: Constraint, box: Box) -> bool:
        if isinstance(c, Member):
            if isinstance(c.domain, Symbols):
                return True  # decided before the propagation
            return self.narrow(c.expr, (c.domain.low, c.domain.high), box)
        if isinstance(c, Relation):
            if c.op == "=":
                both = meet(self.forward(c.left, box), self.forward(c.right, box))
                return both is not None and self.narrow(c.left, both, box) and self.narrow(c.right, both, box)
            if c.op in ("<", "<=", ">", ">="):
                low, high = (c.left, c.right) if c.op in ("<", "<=") else (c.right, c.left)
                if not self.narrow(low, (-INF, self.forward(high, box)[1]), box):
                    return False
                return self.narrow(high, (self.forward(low, box)[0], INF), box)
            return True  # != only removes points
        return True  # implications are resolved before the propagation

    def propagate(self, box: Box) -> bool:
        try:
            for _ in range(PROPAGATION_ROUNDS):
                before = dict(box)
                if not all(self.apply(c, box) for c in self.constraints):
                    return False
                if not any(moved(before.get(k, EVERYTHING), v) for k, v in box.items()):
                    return True
            return True
        except NotNumeric:
            return False

    def witness(self, box: Box, key: str, value: float) -> bool:
        """Is there a point of the box, with `key` at `value`, satisfying every constraint?"""
        trial = dict(box)
        trial[key] = (value, value)
        if not self.propagate(trial):
            return False
        for name in sorted(trial):
            lo, hi = trial[name]
            if hi - lo <= slack(lo, hi):
                continue
            for choice in candidates(lo, hi):
                attempt = dict(trial)
                attempt[name] = (choice, choice)
                if self.propagate(attempt):
                    trial = attempt
                    break
            else:
                return False
        point: dict[str, Value] = {k: (lo + hi) / 2 for k, (lo, hi) in trial.items() if not k.startswith("@")}
        dates = {k[1:]: (lo + hi) / 2 for k, (lo, hi) in trial.items() if k.startswith("@")}
        env = {**self.env, **point}
        return all(decide(c, env, lambda name: dates.get(name, 0.0)) is True for c in self.constraints)


def moved(old: Range, new: Range) -> bool:
    return any(o != n and not (abs(o - n) <= 1e-12 * max(1.0, abs(o))) for o, n in zip(old, new, strict=True))


def candidates(lo: float, hi: float) -> list[float]:
    finite = [x for x in (lo, hi) if math.isfinite(x)]
    if len(finite) == 2:
        return [(lo + hi) / 2, lo, hi]
    if finite == [lo]:
        return [lo + 1.0, lo, 2 * abs(lo) + 1.0]
    if finite == [hi]:
        return [hi - 1.0, hi, -2 * abs(hi) - 1.0]
    return [0.0, 1.0, -1.0]


# ================================================================ one task with its parameters bound


@dataclass(frozen=True)
class TaskCheck:
    """What the task's constraints say of one binding of its parameters."""

    violations: tuple[str, ...]  # constraints the binding breaks
    low: float = 0.0  # nature's duration range
    high: float = 0.0
    impossible: str = ""  # why no duration exists at all


def symbolic_domains(task: Task) -> dict[str, tuple[str, ...]]:
    """The task's symbolic variables (besides its parameters) and their domains."""
    domains: dict[str, set[str]] = {}
    for c in task.constraints:
        if isinstance(c, Member) and isinstance(c.expr, Var) and isinstance(c.domain, Symbols):
            if c.expr.name in task.variables:
                known = domains.get(c.expr.name)
                domains[c.expr.name] = set(c.domain.values) if known is None else known & set(c.domain.values)
    return {v: tuple(sorted(values)) for v, values in domains.items()}


def split(constraints: Iterable[Constraint], env: Mapping[str, Value],
          symbolic: set[str]) -> tuple[list[Constraint], list[Constraint], list[Constraint]]:
    """(broken, numeric, pending): the constraints `env` breaks, those left to the propagation,
    those waiting for an unbound symbolic variable. Implications decided true give their consequence."""
    broken: list[Constraint] = []
    numeric: list[Constraint] = []
    pending: list[Constraint] = []
    for c in constraints:
        if isinstance(c, Implies):
            condition = decide(c.condition, env)
            if condition is True:
                c_broken, c_numeric, c_pending = split([c.consequence], env, symbolic)
                broken.extend(c if b is c.consequence else b for b in c_broken)
                numeric.extend(c_numeric)
                pending.extend(c_pending)
            elif condition is None and constraint_names(c.condition, Var) & symbolic:
                pending.append(c)
            # a condition on numeric variables is left out: the duration range can only widen
            continue
        verdict = decide(c, env)
        if verdict is False:
            broken.append(c)
        elif verdict is None:
            (pending if constraint_names(c, Var) & symbolic else numeric).append(c)
    return broken, numeric, pending


@lru_cache(maxsize=4096)
def check_task(task: Task, args: tuple[Value, ...], values: tuple[tuple[str, Value], ...]) -> TaskCheck:
    """Constraints broken by the binding, and the durations nature may take (see the module doc)."""
    env: dict[str, Value] = {**dict(zip(task.params, args, strict=True)), **dict(values)}
    domains = {v: d for v, d in symbolic_domains(task).items() if v not in env}
    broken, _, _ = split(task.constraints, env, set(domains))
    violations = tuple(f"{constraint_text(c)} is false with {bindings_text(c, env)} (line {c.line})"
                       for c in broken)
    if broken:
        return TaskCheck(violations, impossible="its arguments break its constraints")
    # Nature's range uses the symbolic bindings only: a number the planner wrote down must not
    # narrow what nature does (it is checked against the range instead).
    symbolic_env = {k: v for k, v in env.items() if isinstance(v, str) or k in task.params}
    numbers = {k: float(v) for k, v in env.items() if k not in symbolic_env}
    combinations = math.prod(len(d) for d in domains.values())
    if combinations > MAX_SYMBOLIC_COMBINATIONS:
        return TaskCheck(violations, impossible=f"too many values of {', '.join(domains)} to enumerate")
    low, high = INF, -INF
    why = "no value of its variables satisfies its constraints"
    for combination in itertools.product(*domains.values()):
        trial_env = {**symbolic_env, **dict(zip(domains, combination, strict=True))}
        c_broken, numeric, pending = split(task.constraints, trial_env, set())
        if c_broken or pending:
            continue
        propagator = Propagator(numeric, trial_env)
        box: Box = {"@" + task.start: (0.0, 0.0), "@" + task.end: (0.0, INF)}
        if not propagator.propagate(box):
            continue
        if any(name in box and meet(box[name], (x, x)) is None for name, x in numbers.items()):
            why = ", ".join(f"{k} = {text(x)}" for k, x in numbers.items()) + " is not possible"
            continue
        d_low, d_high = box["@" + task.end]
        # Propagation only narrows: its bounds contain the true range. A witness point proves the
        # range is not empty; when no point is found (at a bound or the middle) the binding is
        # taken as impossible. An unproven bound is kept as it is (on the safe side).
        trials = [d for d in (d_low, d_high, (d_low + d_high) / 2) if math.isfinite(d)]
        if not any(propagator.witness(box, "@" + task.end, d) for d in trials):
            continue
        low, high = min(low, d_low), max(high, d_high)
    if low > high:
        return TaskCheck(violations, impossible=why)
    return TaskCheck(violations, low, high)


def bindings_text(c: Constraint, env: Mapping[str, Value]) -> str:
    names = sorted(constraint_names(c, Var) & set(env))
    return ", ".join(f"{n} = {text(normalise(env[n]))}" for n in names) or "its constants"


# ================================================================ ground assertions

Instance = tuple[str, tuple[Value, ...]]


def instance_key(instance: Instance) -> tuple[str, tuple[Value, ...]]:
    name, args = instance
    return name, tuple(round(a, 6) + 0.0 if isinstance(a, float) else a for a in args)


def instance_text(instance: Instance) -> str:
    return f"{instance[0]}({', '.join(text(a) for a in instance[1])})"


@dataclass
class GroundEvent:
    """An event of the plan with its values known."""

    instance: Instance
    before: Value
    after: Value
    time: str  # a key of the dates
    owner: str  # "MOVE#3" or "line 59"
    needs_support: bool

    def describe(self) -> str:
        return f"event({instance_text(self.instance)}: ({text(self.before)} -> {text(self.after)}))"


@dataclass
class GroundHold:
    """A hold of the plan with its value known (or its choices)."""

    instance: Instance
    value: Value | None  # None: any of `choices` (a symbolic variable the plan left unbound)
    start: str
    end: str
    owner: str
    what: str = "hold"  # "hold", "goal hold" or "required hold"
    choices: tuple[str, ...] = ()
    variable: str = ""  # "<action id>.<variable>" when value is None

    @functools.cached_property
    def key(self) -> tuple[str, tuple[Value, ...]]:
        """Its attribute instance, as the validator's timelines group events."""
        return instance_key(self.instance)

    def describe(self) -> str:
        value = text(self.value) if self.value is not None else "{" + ", ".join(self.choices) + "}"
        return f"{self.what}({instance_text(self.instance)}: {value})"


@dataclass
class GroundUse:
    """A resource use of the plan with its amount known."""

    instance: Instance
    amount: float
    start: str
    end: str
    owner: str


@dataclass
class TemporalCheck:
    """A temporal constraint of the plan, and which action or problem states it."""

    constraint: Constraint
    owner: str
    env: Mapping[str, Value]
    time_key: Callable[[str], str]


@dataclass
class Nature:
    """A contingent duration or date: the range nature picks it from."""

    key: str
    low: float
    high: float
    label: str


@dataclass
class Findings:
    """Violations by a stable key, with the realisations that showed them."""

    messages: dict[object, str] = field(default_factory=dict)
    seen_in: dict[object, list[str]] = field(default_factory=dict)

    def add(self, key: object, message: str, realisation: str = "") -> None:
        if key not in self.messages:
            self.messages[key] = message
            self.seen_in[key] = []
        if realisation and realisation not in self.seen_in[key][-1:]:
            self.seen_in[key].append(realisation)


# ================================================================ the validator


def validate(domain: PlanningDomain, problem: Problem, plan: Plan, samples: int = 32, seed: int = 0,
             dropped_lines: frozenset[int] | set[int] = frozenset()) -> list[str]:
    """Human-readable violations of `plan` (empty: the plan is valid); see the module doc."""
    return Validator(domain, problem, plan, frozenset(dropped_lines)).run(samples, seed)


class Validator:
    def __init__(self, domain: PlanningDomain, problem: Problem, plan: Plan, dropped: frozenset[int]):
        self.domain, self.problem, self.plan, self.dropped = domain, problem, plan, dropped
        self.findings = Findings()
        self.fixed: dict[str, float] = {problem.start: 0.0}  # controllable dates
        self.nature: list[Nature] = []
        self.events: list[GroundEvent] = []
        self.holds: list[GroundHold] = []
        self.uses: list[GroundUse] = []
        self.temporal: list[TemporalCheck] = []
        self.nature_rules: list[Constraint] = []
        self.action_ends: list[tuple[Action, str]] = []
        self.optional: set[str] = set()  # timepoints of dropped goals only
        self.missing: set[str] = set()  # timepoints without a date

    def report(self, key: object, message: str) -> None:
        self.findings.add(key, message)

    # ------------------------------------------------------------ realisation-independent part
    def run(self, samples: int, seed: int) -> list[str]:
        self.problem_timepoints()
        self.problem_assertions()
        for action in self.plan.actions:
            self.action(action)
        if len({a.id for a in self.plan.actions}) != len(self.plan.actions):
            self.report("ids", "plan: two actions share an id")
        realisations = list(self.realisations(samples, seed))
        checked = []
        for kind, dates in realisations:
            if all(decide(c, {}, dates.__getitem__) is not False for c in self.nature_rules):
                checked.append(kind)
                self.realisation(kind, dates)
        if realisations and not checked:
            self.report("nature", "plan: nature cannot keep the problem's constraints on its instants with the "
                                  f"dates the plan assumes ({', '.join(sorted(self.plan.assumed)) or 'none'})")
        out = []
        for key, message in self.findings.messages.items():
            seen = self.findings.seen_in[key]
            if seen and len(seen) < len(checked):
                message += f" [nature: {seen[0]}]"
            out.append(message)
        return out

    def problem_timepoints(self) -> None:
        p = self.problem
        windows = sorted({a.time for a in p.assertions if isinstance(a, Event) and a.kind == "contingent"}
                         - {p.start})
        uses: dict[str, list[bool]] = {}  # timepoint -> is each use a dropped goal's?
        for a in p.assertions:
            dropped = a.goal is not None and a.line in self.dropped if isinstance(a, (Event, Hold)) else False
            for t in assertion_timepoints(a):
                uses.setdefault(t, []).append(dropped)
        # A timepoint only dropped goals use, or one nothing uses (declared and forgotten: `specc
        # check` warns), needs no date.
        constrained = set().union(*(timepoints_of(c) for c in p.constraints))
        self.optional = {t for t, flags in uses.items() if all(flags)} | {
            t for t in p.timepoints if t not in uses and t not in constrained}
        for name, date in self.plan.schedule.items():
            if name == p.start and abs(date) > TOLERANCE:
                self.report("t_start", f"schedule: {p.start} is date 0, not {date_text(date)}")
        for t in [p.end, *p.timepoints]:
            if t in windows:
                continue
            if t in self.plan.schedule:
                self.fixed[t] = float(self.plan.schedule[t])
            else:
                self.missing.add(t)
                if t not in self.optional:
                    self.report(("missing", t), f"schedule: timepoint {t} of the problem has no date")
        end = self.fixed.get(p.end, INF)
        for t, date in self.fixed.items():
            if t != p.start and not (-TOLERANCE <= date <= end + TOLERANCE):
                self.report(("outside", t), f"schedule: {t} at {date_text(date)} is outside [0, {p.end}]")
        for w in windows:
            low, high = self.window_bounds(w)
            if not (math.isfinite(low) and math.isfinite(high)):
                self.report(("window", w), f"problem: cannot tell when nature puts {w} (no bounds from {p.start})")
                low = high = low if math.isfinite(low) else high if math.isfinite(high) else 0.0
            assumed = self.plan.assumed.get(w)
            if assumed is None:
                self.nature.append(Nature(w, low, high, w))
                continue
            self.fixed[w] = float(assumed)
            if not (low - TOLERANCE <= assumed <= high + TOLERANCE):
                self.report(("assumed", w), f"plan: assumes {w} at {date_text(assumed)}, outside its bounds "
                                            f"[{date_text(low)}, {date_text(high)}]")
        for c in p.constraints:
            times = constraint_names(c, Time)
            if times and times <= set(windows) | {p.start} and times & set(windows):
                self.nature_rules.append(c)  # nature obeys these: they describe the windows
            elif times:
                self.temporal.append(TemporalCheck(c, f"line {c.line}", self.plan.bindings, lambda t: t))
            else:
                verdict = decide(c, self.plan.bindings)
                if verdict is False:
                    with_bindings = bindings_text(c, self.plan.bindings)
                    self.report(("constraint", c.line, constraint_text(c)),
                                f"line {c.line}: {constraint_text(c)} is false with {with_bindings}")

    def window_bounds(self, w: str) -> Range:
        low, high = -INF, INF
        offset = Op("-", (Time(w), Time(self.problem.start)))
        for c in self.problem.constraints:
            if isinstance(c, Member) and isinstance(c.domain, Interval) and c.expr in (offset, Time(w)):
                low, high = max(low, c.domain.low), min(high, c.domain.high)
            elif isinstance(c, Relation) and isinstance(c.right, Num) and c.left in (offset, Time(w)):
                bound = c.right.value
                if c.op in ("<", "<=", "="):
                    high = min(high, bound)
                if c.op in (">", ">=", "="):
                    low = max(low, bound)
        return low, high

    def ground_args(self, args: tuple[Expr, ...], env: Mapping[str, Value]) -> tuple[Value, ...]:
        return tuple(evaluate(a, env) for a in args)

    def problem_assertions(self) -> None:
        p = self.problem
        env = self.plan.bindings
        for a in p.assertions:
            if isinstance(a, (Event, Hold)) and a.goal is not None and a.line in self.dropped:
                continue
            owner = f"line {a.line}"
            times = assertion_timepoints(a)
            if any(t in self.missing for t in times):
                continue  # reported with the schedule
            try:
                if isinstance(a, Event):
                    instance = (a.attribute, self.ground_args(a.args, env))
                    self.events.append(GroundEvent(instance, evaluate(a.before, env), evaluate(a.after, env), a.time,
                                                   owner, a.kind not in ("explained", "contingent")))
                elif isinstance(a, Hold):
                    what = "goal hold" if a.goal is not None else "required hold"
                    self.holds.append(GroundHold((a.attribute, self.ground_args(a.args, env)),
                                                 evaluate(a.value, env), a.start, a.end, owner, what))
                else:
                    self.use(a, env, owner, lambda t: t)
            except (Unbound, NotNumeric) as e:
                self.report(("ground", owner), f"{owner}: cannot evaluate the assertion ({type(e).__name__}: {e}); "
                                               "the plan's bindings miss a variable of the problem")

    def use(self, a: Use, env: Mapping[str, Value], owner: str, key: Callable[[str], str]) -> None:
        amount = evaluate(a.amount, env)
        if not isinstance(amount, float):
            raise NotNumeric(describe(a.amount))
        instance = (a.resource, self.ground_args(a.args, env))
        self.uses.append(GroundUse(instance, amount, key(a.start), key(a.end), owner))

    def action(self, action: Action) -> None:
        task = self.domain.task(action.task)
        label = action.id
        if task is None:
            self.report(("task", label), f"{label}: {action.task} is not a task of domain {self.domain.name}")
            return
        if len(action.args) != len(task.params):
            self.report(("arity", label), f"{label}: {action.task} takes {len(task.params)} arguments, "
                                          f"not {len(action.args)}")
            return
        unknown = [name for name, _ in action.values if name not in task.variables]
        if unknown:
            self.report(("values", label), f"{label}: {', '.join(unknown)} is not a variable of {task.name}")
        args = tuple(normalise(a) for a in action.args)
        values = tuple((k, normalise(v)) for k, v in action.values)
        check = check_task(task, args, values)
        for message in check.violations:
            self.report(("args", label, message), f"{label}: {action.text()}: {message}")
        low, high = action.duration
        if check.impossible:
            self.report(("impossible", label), f"{label}: {action.text()} is impossible: {check.impossible}")
            d_low, d_high = low, high  # go on with the plan's claim
        else:
            d_low, d_high = check.low, check.high
            if low > d_low + TOLERANCE:
                self.report(("short", label), f"{label}: duration [{date_text(low)}, {date_text(high)}] claimed, "
                                              f"but nature may take only {date_text(d_low)} s")
            if high < d_high - TOLERANCE:
                self.report(("long", label), f"{label}: duration [{date_text(low)}, {date_text(high)}] claimed, "
                                             f"but nature may take up to {date_text(d_high)} s")

        def key(name: str) -> str:
            return f"{label}.{name}"

        start = float(action.dispatch)
        self.fixed[key(task.start)] = start
        if action.start in self.plan.schedule and abs(self.plan.schedule[action.start] - start) > TOLERANCE:
            self.report(("dispatch", label), f"{label}: dispatched at {date_text(start)} but scheduled at "
                                             f"{date_text(self.plan.schedule[action.start])}")
        if start < self.plan.now - TOLERANCE:
            self.report(("early", label), f"{label}: starts at {date_text(start)}, before now "
                                          f"({date_text(self.plan.now)})")
        self.nature.append(Nature(key(task.end), start + d_low, start + d_high, f"{label} end"))
        self.action_ends.append((action, key(task.end)))
        unscheduled = [t for t in task.timepoints if key(t) not in self.plan.schedule]
        for t in task.timepoints:
            if key(t) in self.plan.schedule:
                self.fixed[key(t)] = float(self.plan.schedule[key(t)])
        if unscheduled:
            self.report(("internal", label), f"{label}: unsupported: task timepoints {', '.join(unscheduled)} have "
                                             f"no date (expected as {key(unscheduled[0])} in the schedule)")
        env: dict[str, Value] = {**dict(zip(task.params, args, strict=True)), **dict(values)}
        choices = symbolic_domains(task)
        for a in task.assertions:
            times = assertion_timepoints(a)
            if any(t in unscheduled for t in times):
                continue
            try:
                if isinstance(a, Event):
                    instance = (a.attribute, self.ground_args(a.args, env))
                    self.events.append(GroundEvent(instance, evaluate(a.before, env), evaluate(a.after, env),
                                                   key(a.time), label, True))
                elif isinstance(a, Hold):
                    instance = (a.attribute, self.ground_args(a.args, env))
                    if isinstance(a.value, Var) and a.value.name not in env and a.value.name in choices:
                        self.holds.append(GroundHold(instance, None, key(a.start), key(a.end), label,
                                                     choices=choices[a.value.name],
                                                     variable=f"{label}.{a.value.name}"))
                    else:
                        self.holds.append(GroundHold(instance, evaluate(a.value, env), key(a.start), key(a.end),
                                                     label))
                else:
                    self.use(a, env, label, key)
            except (Unbound, NotNumeric) as e:
                self.report(("ground", label, a.line), f"{label}: cannot evaluate the assertion at line {a.line} "
                                                       f"({type(e).__name__}: {e}); bind it in Action.values")
        if task.timepoints:
            for c in task.constraints:
                if constraint_names(c, Time) - {task.start, task.end}:
                    self.temporal.append(TemporalCheck(c, label, env, key))

    # ------------------------------------------------------------ realisations of nature
    def realisations(self, samples: int, seed: int) -> Iterable[tuple[str, dict[str, float]]]:
        def dates(choice: Callable[[Nature], float]) -> dict[str, float]:
            return {**self.fixed, **{n.key: choice(n) for n in self.nature}}

        yield "every contingent at its minimum", dates(lambda n: n.low)
        yield "every contingent at its maximum", dates(lambda n: n.high)
        yield "every contingent at its middle", dates(lambda n: (n.low + n.high) / 2)
        for one in self.nature:
            yield f"{one.label} at its maximum, the rest at their minimum", \
                dates(lambda n: n.high if n is one else n.low)
            yield f"{one.label} at its minimum, the rest at their maximum", \
                dates(lambda n: n.low if n is one else n.high)
        rng = random.Random(seed)
        for k in range(samples):
            yield f"random draw {k + 1} (seed {seed})", dates(lambda n: rng.uniform(n.low, n.high))

    def realisation(self, kind: str, dates: dict[str, float]) -> None:
        def add(key: object, message: str) -> None:
            self.findings.add(key, message, kind)

        self.timelines(dates, add)
        self.resources(dates, add)
        for check in self.temporal:
            try:
                verdict = decide(check.constraint, check.env, lambda t: dates[check.time_key(t)])
            except KeyError:
                continue  # a timepoint without a date: reported already
            if verdict is False:
                names = sorted(constraint_names(check.constraint, Time))
                at = ", ".join(f"{n} = {date_text(dates[check.time_key(n)])}" for n in names)
                add(("temporal", check.owner, check.constraint),
                    f"{check.owner}: {constraint_text(check.constraint)} is false with {at}")
        end = dates.get(self.problem.end)
        if end is not None:
            for action, key in self.action_ends:
                if dates[key] > end + TOLERANCE:
                    add(("late", action.id), f"{action.id}: may end at {date_text(dates[key])}, after "
                                             f"{self.problem.end} ({date_text(end)})")

    @functools.cached_property
    def _events_by_instance(self) -> dict[object, list[tuple[int, GroundEvent]]]:
        """The events of each attribute instance (the same in every realisation: only dates change)."""
        grouped: dict[object, list[tuple[int, GroundEvent]]] = {}
        for i, e in enumerate(self.events):
            grouped.setdefault(instance_key(e.instance), []).append((i, e))
        return grouped

    def timelines(self, dates: Mapping[str, float], add: Callable[[object, str], None]) -> None:
        by_instance: dict[object, list[tuple[float, int, GroundEvent]]] = {}
        for instance, events in self._events_by_instance.items():
            dated = [(dates[e.time], i, e) for i, e in events if e.time in dates]
            if dated:
                by_instance[instance] = dated
        times: dict[object, list[float]] = {}  # each timeline's dates, for bisect
        for instance, timeline in by_instance.items():
            timeline.sort(key=lambda x: (x[0], x[1]))
            times[instance] = [entry[0] for entry in timeline]
            for (t1, i, a), (t2, j, b) in itertools.pairwise(timeline):
                if abs(t2 - t1) < TOLERANCE:
                    add(("simultaneous", i, j), f"{a.owner}: {a.describe()} and {b.owner}'s {b.describe()} "
                                                f"happen at the same date {date_text(t1)}")
            for t, i, e in timeline:
                if not e.needs_support:
                    continue
                prior = last_before(timeline, times[instance], t - TOLERANCE)
                if prior is None:
                    add(("support", i), f"{e.owner}: {e.describe()} at {date_text(t)} is not supported "
                                        f"(nothing sets {instance_text(e.instance)} before)")
                elif not same(prior[2].after, e.before):
                    add(("support", i), f"{e.owner}: {e.describe()} at {date_text(t)} needs "
                                        f"{instance_text(e.instance)} = {text(e.before)}, but it is "
                                        f"{text(prior[2].after)} (set by {prior[2].owner} at {date_text(prior[0])})")
        chosen: dict[str, tuple[Value, GroundHold]] = {}
        for k, h in enumerate(self.holds):
            if h.start not in dates or h.end not in dates:
                continue
            t1, t2 = dates[h.start], dates[h.end]
            timeline, moments = by_instance.get(h.key, []), times.get(h.key, [])
            if t1 > t2 + TOLERANCE:
                add(("hold-order", k), f"{h.owner}: {h.describe()} ends at {date_text(t2)}, before it starts "
                                       f"at {date_text(t1)}")
            inside = timeline[bisect.bisect_right(moments, t1 + TOLERANCE):bisect.bisect_left(moments, t2 - TOLERANCE)]
            for t, _, e in inside:  # strictly between the hold's ends, give or take TOLERANCE
                add(("hold-broken", k, e.owner), f"{h.owner}: {h.describe()} over [{date_text(t1)}, "
                                                 f"{date_text(t2)}] is broken by {e.owner}'s {e.describe()} "
                                                 f"at {date_text(t)}")
            prior = last_before(timeline, moments, t1 + TOLERANCE)
            value = prior[2].after if prior is not None else None
            if value is not None and h.value is not None and same(value, h.value):
                continue  # met: the findings' texts below are only built when one is added
            prefix = f"{h.owner}: {h.describe()}" + (" not met" if h.what == "goal hold" else "")
            if value is None:
                add(("hold-value", k), f"{prefix}: {instance_text(h.instance)} has no value at {date_text(t1)} "
                                       "(not supported)")
            elif h.value is not None and not same(value, h.value):
                add(("hold-value", k), f"{prefix}: value {text(value)} at {date_text(t1)}")
            elif h.value is None:
                if value not in h.choices:
                    add(("hold-value", k), f"{prefix}: value {text(value)} at {date_text(t1)}")
                elif h.variable in chosen and not same(chosen[h.variable][0], value):
                    add(("hold-binding", k), f"{prefix}: {h.variable} would be both {text(chosen[h.variable][0])} "
                                             f"and {text(value)}")
                else:
                    chosen[h.variable] = (value, h)

    def resources(self, dates: Mapping[str, float], add: Callable[[object, str], None]) -> None:
        capacity = {r.name: r.capacity for r in self.domain.resources}
        by_instance: dict[object, list[tuple[float, float, GroundUse]]] = {}
        for u in self.uses:
            if u.start in dates and u.end in dates:
                by_instance.setdefault(instance_key(u.instance), []).append((dates[u.start], dates[u.end], u))
        for key, uses in by_instance.items():
            limit = capacity.get(uses[0][2].instance[0])
            if limit is None:
                add(("resource", key), f"{uses[0][2].owner}: {uses[0][2].instance[0]} is not a resource of the domain")
                continue
            for instant, _, _ in uses:
                active = [u for s, e, u in uses if s <= instant + TOLERANCE and instant < e - TOLERANCE]
                total = sum(u.amount for u in active)
                if total > limit + TOLERANCE:
                    owners = ", ".join(sorted({u.owner for u in active}))
                    add(("resource", key), f"{owners}: use {text(total)} of {instance_text(uses[0][2].instance)} "
                                           f"at {date_text(instant)}, more than its capacity {text(limit)}")


def last_before(timeline: list[tuple[float, int, GroundEvent]], dates: list[float],
                date: float) -> tuple[float, int, GroundEvent] | None:
    """The latest event at or before `date` (the timeline is sorted; `dates` are its dates)."""
    index = bisect.bisect_right(dates, date)
    return timeline[index - 1] if index else None
