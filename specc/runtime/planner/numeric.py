"""The numeric side of a task: its non-temporal constraints (Modele1's `distance = |dx| + |dy|`
written with max, `dist = speed * duration` with the speed an interval, Modele2's distance
tables) and what they imply for its duration.

Two solvers, for two jobs:
- `Closure` propagates interval and symbol-set domains to a fixed point (HC4: each constraint
  narrows its variables forwards and backwards). It is sound (it never loses a value a solution
  could take), fast, and cached per task and ground arguments, so the search can ask it at
  every node.
- `exact_duration` gives the true smallest and largest duration of a ground task, which the
  interval enclosure may overestimate; the final plan is scheduled with those. When a point
  meeting every constraint reaches each bound of the enclosure (`_attained`), the enclosure is
  exact; otherwise CasADi (Opti + IPOPT) solves for them. On the rover's missions the enclosure
  always is exact, so planning never loads CasADi (0.1-0.2 s of a process' first plan).
"""

from __future__ import annotations

import collections
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache, reduce

from specc.runtime.planner import model as pm
from specc.runtime.planner.model import describe

INF = math.inf
Interval = tuple[float, float]
Dom = Interval | frozenset[str]
Value = float | str
TOLERANCE = 1e-9


class Empty(Exception):
    """A domain became empty: the constraints cannot all hold."""


def is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


# ---------------------------------------------------------------- interval arithmetic


def add(a: Interval, b: Interval) -> Interval:
    return a[0] + b[0], a[1] + b[1]


def sub(a: Interval, b: Interval) -> Interval:
    return a[0] - b[1], a[1] - b[0]


def _products(a: Interval, b: Interval) -> list[float]:
    out = []
    for x in a:
        for y in b:
            # 0 * inf is 0 here: a bounded factor of zero keeps the product at zero.
            out.append(0.0 if (x == 0 or y == 0) else x * y)
    return out


def mul(a: Interval, b: Interval) -> Interval:
    products = _products(a, b)
    return min(products), max(products)


def div(a: Interval, b: Interval) -> Interval:
    if b[0] <= 0 <= b[1]:
        return -INF, INF
    return mul(a, (1 / b[1], 1 / b[0]))


def square(a: Interval) -> Interval:
    """`x * x`: never negative, which the product of two independent factors in the same interval
    may be (a Euclidean distance written `?d * ?d = dx * dx + dy * dy`)."""
    low, high = a
    if low >= 0:
        return low * low, high * high
    if high <= 0:
        return high * high, low * low
    return 0.0, max(low * low, high * high)


def square_root(goal: Interval, current: Interval) -> Interval:
    """The values of `x` in `current` whose square lies in `goal` (their hull)."""
    if goal[1] < 0:
        raise Empty(f"a square cannot be in {show(goal)}")
    low, high = math.sqrt(max(goal[0], 0.0)), math.sqrt(goal[1])
    parts = [(max(a, current[0]), min(b, current[1])) for a, b in ((low, high), (-high, -low))]
    parts = [p for p in parts if p[0] <= p[1] + TOLERANCE]
    if not parts:
        raise Empty(f"no value in {show(current)} has its square in {show(goal)}")
    return min(p[0] for p in parts), max(p[1] for p in parts)


def evaluate(op: str, args: list[Interval]) -> Interval:
    """The interval an operator (`+ - * / neg max min abs`) gives its argument intervals."""
    if op == "+":
        low, high = add(args[0], args[1])
    elif op == "-":
        low, high = sub(args[0], args[1])
    elif op == "*":
        return mul(args[0], args[1])
    elif op == "/":
        return div(args[0], args[1])
    elif op == "neg":
        return (-args[0][1], -args[0][0])
    elif op == "max":
        return (max(a[0] for a in args), max(a[1] for a in args))
    elif op == "min":
        return (min(a[0] for a in args), min(a[1] for a in args))
    elif op == "abs":
        low, high = args[0]
        if low >= 0:
            return (low, high)
        if high <= 0:
            return (-high, -low)
        return (0.0, max(-low, high))
    else:
        raise ValueError(f"unknown operator {op!r}")
    # inf - inf: the sum of unbounded intervals is unbounded.
    return (-INF if math.isnan(low) else low, INF if math.isnan(high) else high)


def domain_of(values: pm.Values) -> Dom:
    """A declared domain as the propagators hold it: a set of symbols or an interval."""
    return frozenset(values.values) if isinstance(values, pm.Symbols) else (values.low, values.high)


def intersect(a: Interval, b: Interval) -> Interval:
    low, high = max(a[0], b[0]), min(a[1], b[1])
    if low > high + 1e-9 * max(1.0, abs(low)):
        raise Empty(f"[{a[0]:g}, {a[1]:g}] and [{b[0]:g}, {b[1]:g}] do not meet")
    return (low, max(low, high))


# ---------------------------------------------------------------- propagation


@dataclass
class Closure:
    """Domains of a task's variables after propagating its constraints."""

    domains: dict[str, Dom] = field(default_factory=dict)
    constraints: tuple[pm.Constraint, ...] = ()
    narrowed: list[str] = field(default_factory=list, repr=False)  # variables narrowed, in order

    def value(self, name: str) -> Value | None:
        d = self.domains.get(name)
        if isinstance(d, frozenset):
            return next(iter(d)) if len(d) == 1 else None
        if d is not None and d[0] == d[1]:
            return d[0]
        return None

    # ------------------------------------------------------------ evaluation
    def forward(self, e: pm.Expr) -> Dom:
        if isinstance(e, pm.Num):
            return (e.value, e.value)
        if isinstance(e, pm.Sym):
            return frozenset((e.name,))
        if isinstance(e, pm.Var):
            return self.domains.setdefault(e.name, (-INF, INF))
        if isinstance(e, pm.Time):
            return (-INF, INF)  # timepoints are the temporal network's business
        if e.op == "*" and e.args[0] == e.args[1]:
            return square(self.numeric(self.forward(e.args[0])))
        return evaluate(e.op, [self.numeric(self.forward(a)) for a in e.args])

    @staticmethod
    def numeric(d: Dom) -> Interval:
        if isinstance(d, frozenset):
            raise Empty(f"the symbols {sorted(d)} are used as a number")
        return d

    def narrow(self, e: pm.Expr, target: Dom) -> bool:
        """Make `e` take its value in `target`; True when a domain shrank."""
        if isinstance(e, (pm.Num, pm.Sym)):
            here = self.forward(e)
            if isinstance(here, frozenset) or isinstance(target, frozenset):
                if not (isinstance(here, frozenset) and isinstance(target, frozenset) and here & target):
                    raise Empty(f"{describe(e)} is not in {show(target)}")
            else:
                intersect(here, target)
            return False
        if isinstance(e, pm.Time):
            return False
        if isinstance(e, pm.Var):
            current = self.domains.get(e.name)
            if current is None:
                self.domains[e.name] = target
                self.narrowed.append(e.name)
                return True
            if isinstance(current, frozenset) or isinstance(target, frozenset):
                if not (isinstance(current, frozenset) and isinstance(target, frozenset)):
                    raise Empty(f"{e.name} mixes symbols and numbers")
                narrowed = current & target
                if not narrowed:
                    raise Empty(f"{e.name} in {show(current)} cannot be in {show(target)}")
                if narrowed != current:
                    self.domains[e.name] = narrowed
                    self.narrowed.append(e.name)
                    return True
                return False
            narrowed_iv = intersect(current, target)
            if narrowed_iv[0] > current[0] + TOLERANCE or narrowed_iv[1] < current[1] - TOLERANCE:
                self.domains[e.name] = narrowed_iv
                self.narrowed.append(e.name)
                return True
            return False
        goal = self.numeric(target)
        args = [self.numeric(self.forward(a)) for a in e.args]
        changed = False
        if e.op == "+":
            changed |= self.narrow(e.args[0], sub(goal, args[1]))
            changed |= self.narrow(e.args[1], sub(goal, args[0]))
        elif e.op == "-":
            changed |= self.narrow(e.args[0], add(goal, args[1]))
            changed |= self.narrow(e.args[1], sub(args[0], goal))
        elif e.op == "*" and e.args[0] == e.args[1]:
            changed |= self.narrow(e.args[0], square_root(goal, args[0]))
        elif e.op == "*":
            changed |= self.narrow(e.args[0], div(goal, args[1]))
            changed |= self.narrow(e.args[1], div(goal, args[0]))
        elif e.op == "/":
            changed |= self.narrow(e.args[0], mul(goal, args[1]))
            if not (goal[0] <= 0 <= goal[1]):
                changed |= self.narrow(e.args[1], div(args[0], goal))
        elif e.op == "neg":
            changed |= self.narrow(e.args[0], (-goal[1], -goal[0]))
        elif e.op in ("max", "min"):
            bigger = e.op == "max"
            for i, arg in enumerate(e.args):
                # max: no argument exceeds the result; min: none is below it.
                bound = (-INF, goal[1]) if bigger else (goal[0], INF)
                changed |= self.narrow(arg, bound)
                others = [a for j, a in enumerate(args) if j != i]
                # The argument must be the result when every other one is out of its reach.
                if bigger and all(o[1] < goal[0] for o in others):
                    changed |= self.narrow(arg, goal)
                if not bigger and all(o[0] > goal[1] for o in others):
                    changed |= self.narrow(arg, goal)
        elif e.op == "abs":
            changed |= self.narrow(e.args[0], (-goal[1], goal[1]))
        # Check the result itself is reachable.
        intersect(self.numeric(self.forward(e)), goal)
        return changed

    # ------------------------------------------------------------ constraints
    def apply(self, c: pm.Constraint) -> bool:
        if isinstance(c, pm.Member):
            return self.narrow(c.expr, domain_of(c.domain))
        if isinstance(c, pm.Relation):
            return self.relation(c.op, c.left, c.right)
        return self.implication(c)

    def relation(self, op: str, left: pm.Expr, right: pm.Expr) -> bool:
        if has_time(left) or has_time(right):
            return False
        a, b = self.forward(left), self.forward(right)
        if op == "=":
            if isinstance(a, frozenset) or isinstance(b, frozenset):
                return self.narrow(left, b) | self.narrow(right, a)
            meet = intersect(a, b)
            return self.narrow(left, meet) | self.narrow(right, meet)
        if op == "!=":
            if isinstance(a, frozenset) and isinstance(b, frozenset):
                if len(a) == 1 and a == b:
                    raise Empty(f"{describe(left)} and {describe(right)} must differ but are both {next(iter(a))}")
                changed = False
                if len(b) == 1 and isinstance(left, pm.Var):
                    changed |= self.narrow(left, a - b) if a - b else _empty(left, b)
                if len(a) == 1 and isinstance(right, pm.Var):
                    changed |= self.narrow(right, b - a) if b - a else _empty(right, a)
                return changed
            if not isinstance(a, frozenset) and not isinstance(b, frozenset):
                if a[0] == a[1] == b[0] == b[1]:
                    raise Empty(f"{describe(left)} and {describe(right)} must differ but are both {a[0]:g}")
            return False
        a_iv, b_iv = self.numeric(a), self.numeric(b)
        if op in (">", ">="):
            left, right, a_iv, b_iv = right, left, b_iv, a_iv
        # left <= right (strictness does not change interval bounds)
        return self.narrow(left, (-INF, b_iv[1])) | self.narrow(right, (a_iv[0], INF))

    def implication(self, c: pm.Implies) -> bool:
        condition = self.decided(c.condition)
        if condition is True:
            return self.apply(c.consequence)
        if condition is None and isinstance(c.consequence, pm.Member):
            if self.decided(c.consequence) is False and isinstance(c.condition.expr, pm.Var):
                # Contrapositive: the consequence cannot hold, so neither can the condition.
                current = self.forward(c.condition.expr)
                if isinstance(current, frozenset) and isinstance(c.condition.domain, pm.Symbols):
                    rest = current - frozenset(c.condition.domain.values)
                    if not rest:
                        raise Empty(f"line {c.line}: {describe(c.condition.expr)} has no value left")
                    return self.narrow(c.condition.expr, rest)
        return False

    def decided(self, c: pm.Member) -> bool | None:
        """True when `c` surely holds, False when it surely fails, None when unknown."""
        d = self.forward(c.expr)
        if isinstance(c.domain, pm.Symbols):
            if not isinstance(d, frozenset):
                return False
            allowed = frozenset(c.domain.values)
            if d <= allowed:
                return True
            return False if not d & allowed else None
        if isinstance(d, frozenset):
            return False
        if c.domain.low <= d[0] and d[1] <= c.domain.high:
            return True
        return False if d[1] < c.domain.low or d[0] > c.domain.high else None

    def propagate(self, rounds: int = 30) -> None:
        """Apply the constraints until none narrows a domain: each one first in order, then again
        only when a variable it reads has narrowed since (AC-3's queue; sweeping every constraint
        until a sweep changes nothing re-applied most of them for nothing). Each is applied at most
        `rounds` times: interval narrowing may converge only in the limit."""
        readers = _readers(self.constraints)
        queue = collections.deque(range(len(self.constraints)))
        queued = [True] * len(self.constraints)
        applied = [0] * len(self.constraints)
        while queue:
            index = queue.popleft()
            queued[index] = False
            if applied[index] >= rounds:
                continue
            applied[index] += 1
            self.narrowed.clear()
            self.apply(self.constraints[index])
            for name in self.narrowed:
                for other in readers.get(name, ()):
                    if not queued[other]:
                        queued[other] = True
                        queue.append(other)


def _empty(e: pm.Expr, excluded: frozenset[str]) -> bool:
    raise Empty(f"{describe(e)} cannot avoid {sorted(excluded)}")


def _readers(constraints: tuple[pm.Constraint, ...]) -> dict[str, tuple[int, ...]]:
    """Variable name -> the positions of the constraints that read it (cached by the tuple's
    identity, which it keeps: a task's constraints are propagated again and again)."""
    found = _READERS.get(id(constraints))
    if found is None or found[0] is not constraints:
        positions: dict[str, list[int]] = {}
        for index, c in enumerate(constraints):
            for name in sorted(pm.constraint_names(c, pm.Var)):
                positions.setdefault(name, []).append(index)
        if len(_READERS) >= IDENTITY_CACHE_LIMIT:
            _READERS.clear()
        found = _READERS[id(constraints)] = (constraints, {k: tuple(v) for k, v in positions.items()})
    return found[1]


_READERS: dict[int, tuple[tuple[pm.Constraint, ...], dict[str, tuple[int, ...]]]] = {}


def has_time(e: pm.Expr) -> bool:
    if isinstance(e, pm.Time):
        return True
    return isinstance(e, pm.Op) and any(has_time(a) for a in e.args)


def show(d: Dom) -> str:
    if isinstance(d, frozenset):
        return "{" + ", ".join(sorted(d)) + "}"
    return f"[{d[0]:g}, {d[1]:g}]"


# ---------------------------------------------------------------- a task's duration


@dataclass(frozen=True)
class DurationSpec:
    """How long a task lasts: a range, and whether nature or the plan picks it."""

    low: float
    high: float
    contingent: bool
    variables: Mapping[str, Value] = field(default_factory=dict)  # values the given arguments decide


def duration_of(task: pm.Task, args: Mapping[str, Value]) -> DurationSpec:
    """The duration range of `task` with some parameters bound (raises Empty when the
    constraints cannot hold); cached, since the search asks again and again."""
    key = tuple(sorted(args.items()))
    # Keyed by the task's identity: hashing a task (a deep frozen record) would cost more than
    # the propagation it saves.
    found = _DURATIONS.get((id(task), key))
    if found is None:
        try:
            outcome: DurationSpec | Empty = _duration_cached(task, key)
        except Empty as error:
            outcome = error
        if len(_DURATIONS) >= IDENTITY_CACHE_LIMIT:
            _DURATIONS.clear()
        found = _DURATIONS[(id(task), key)] = (task, outcome)  # the task is kept so that its id stays its own
    if isinstance(found[1], Empty):
        raise found[1]
    return found[1]


_DURATIONS: dict[tuple[int, tuple[tuple[str, Value], ...]], tuple[pm.Task, DurationSpec | Empty]] = {}
# Entries a cache keyed by a task's identity holds before it starts afresh: it keeps its tasks (and
# their domains) alive, and one process may plan many domains (a campaign's mutants, one after another).
IDENTITY_CACHE_LIMIT = 4096


@dataclass(frozen=True)
class _TaskConstraints:
    """A task's constraints sorted once for its duration computations: those the numeric
    propagation applies (neither a bound on its duration nor a relation of timepoints, which the
    propagation leaves to the temporal network), and the bounds on its duration with their range."""

    task: pm.Task  # kept so that its id stays its own
    propagated: tuple[pm.Constraint, ...]
    durations: tuple[tuple[pm.Constraint, Interval], ...]


def _task_constraints(task: pm.Task) -> _TaskConstraints:
    found = _TASK_CONSTRAINTS.get(id(task))
    if found is None:
        durations = tuple((c, span) for c in task.constraints
                          if (span := _duration_constraint(c, task)) is not None)
        propagated = tuple(c for c in task.constraints if _duration_constraint(c, task) is None
                           and not (isinstance(c, pm.Relation) and (has_time(c.left) or has_time(c.right))))
        if len(_TASK_CONSTRAINTS) >= IDENTITY_CACHE_LIMIT:
            _TASK_CONSTRAINTS.clear()
        found = _TASK_CONSTRAINTS[id(task)] = _TaskConstraints(task, propagated, durations)
    return found


_TASK_CONSTRAINTS: dict[int, _TaskConstraints] = {}


def _propagated(task: pm.Task, key: tuple[tuple[str, Value], ...]) -> Closure:
    """The task's numeric constraints propagated with its parameters bound (Empty: inconsistent)."""
    closure = Closure(constraints=_task_constraints(task).propagated)
    for name, value in key:
        closure.domains[name] = frozenset((value,)) if isinstance(value, str) else (float(value), float(value))
    closure.propagate()
    return closure


def _duration_cached(task: pm.Task, key: tuple[tuple[str, Value], ...]) -> DurationSpec:
    closure = _propagated(task, key)
    low, high, contingent = 0.0, INF, False
    for c, span in _task_constraints(task).durations:
        if isinstance(c, pm.Implies):
            continue
        if isinstance(c, pm.Relation):
            assert isinstance(c.left, pm.Var) or isinstance(c.right, pm.Var)
            var = c.left if isinstance(c.left, pm.Var) else c.right
            assert isinstance(var, pm.Var)
            d = closure.numeric(closure.forward(var))
            span = d
        low, high = max(low, span[0]), min(high, span[1])
        contingent |= c.contingent
    if low > high + 1e-9:
        raise Empty(f"{task.name}: its duration would lie in [{low:g}, {high:g}]")
    known: dict[str, Value] = {}
    given = {name for name, _ in key}
    for name in (*task.params, *task.variables):  # a parameter too (`?left =. ?b - 1`, both parameters)
        found = closure.value(name)
        if found is not None and name not in given:
            known[name] = found
    return DurationSpec(max(0.0, low), high, contingent, known)


def is_duration(c: pm.Constraint, task: pm.Task) -> bool:
    """Does `c` bound the task's duration (`t_end - t_start`)?"""
    return _duration_constraint(c, task) is not None


def _duration_constraint(c: pm.Constraint, task: pm.Task) -> Interval | None:
    """`(t_end - t_start) in [a, b]` gives [a, b]; `?d = t_end - t_start` gives (-inf, inf) (the
    variable's domain says more)."""
    span = (pm.Op("-", (pm.Time(task.end), pm.Time(task.start))))
    if isinstance(c, pm.Member) and c.expr == span and isinstance(c.domain, pm.Interval):
        return (c.domain.low, c.domain.high)
    if isinstance(c, pm.Relation) and c.op == "=" and span in (c.left, c.right):
        other = c.right if c.left == span else c.left
        if isinstance(other, pm.Var):
            return (-INF, INF)
    return None


# ---------------------------------------------------------------- CasADi: exact ranges


@lru_cache(maxsize=1024)
def exact_duration(task: pm.Task, key: tuple[tuple[str, Value], ...]) -> tuple[float, float] | None:
    """The smallest and largest duration the task's numeric constraints allow once its
    parameters are bound: the interval enclosure's bounds when points reach them (`_attained`),
    else solved with CasADi; None when the task's duration is not a variable of its numeric
    constraints, or when the solver does not converge. Strict inequalities count as non-strict
    (a bound only approached counts as reached), as CasADi's constraints do."""
    variable = next((v for c in task.constraints if isinstance(c, pm.Relation) and _duration_constraint(c, task)
                     for v in (c.left, c.right) if isinstance(v, pm.Var)), None)
    if variable is None:
        return None
    enclosure = _duration_cached(task, key)
    # The interval enclosure is sound (no duration outside it); when a point meeting every
    # constraint has the duration at each of its bounds, it is exact, and CasADi (its import
    # is 0.1-0.2 s of a first plan) has nothing to add. On the rover's missions it always is.
    known = _propagated(task, key)  # consistent: the enclosure above was found
    low, high = Closure.numeric(known.forward(variable))
    if math.isfinite(low) and math.isfinite(high) and all(
            _attained(known, variable.name, bound) for bound in (low, high)):
        return (low, high)
    import casadi  # the planner's only CasADi user

    bound = dict(key)
    symbols = {name: value for name, value in list(enclosure.variables.items()) + list(bound.items())
               if isinstance(value, str)}
    # Variables the enclosure pins to one value are constants for the solver: IPOPT stalls on
    # degenerate equations such as Modele1's `?mindist = min(?di, ?mindist)` once ?di is known.
    numeric_bound = {name: float(value) for name, value in list(enclosure.variables.items()) + list(bound.items())
                     if not isinstance(value, str)}
    result = []
    for sense in (1.0, -1.0):
        opti = casadi.Opti()
        names: dict[str, casadi.MX] = {}

        def term(e: pm.Expr) -> casadi.MX | float:
            if isinstance(e, pm.Num):
                return e.value
            if isinstance(e, pm.Var):
                if e.name in numeric_bound:
                    return numeric_bound[e.name]
                if e.name not in names:
                    names[e.name] = opti.variable()
                return names[e.name]
            if isinstance(e, (pm.Sym, pm.Time)):
                raise ValueError("symbolic")
            xs = [term(a) for a in e.args]
            ops = {"+": lambda: xs[0] + xs[1], "-": lambda: xs[0] - xs[1], "*": lambda: xs[0] * xs[1],
                   "/": lambda: xs[0] / xs[1], "neg": lambda: -xs[0], "abs": lambda: casadi.fabs(xs[0]),
                   "max": lambda: reduce(casadi.fmax, xs), "min": lambda: reduce(casadi.fmin, xs)}
            return ops[e.op]()

        try:
            for c in task.constraints:
                _post(opti, c, term, symbols, task)
            goal = term(variable)
            opti.minimize(sense * goal)
            for name, v in names.items():  # start inside the enclosure
                d = enclosure.variables.get(name)
                if isinstance(d, float):
                    opti.set_initial(v, d)
            opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "max_iter": 200})
            solution = opti.solve()
            result.append(float(solution.value(goal)))
        except (RuntimeError, ValueError):
            return None
    return (min(result), max(result))


def _attained(closure: Closure, variable: str, value: float) -> bool:
    """Is there a point meeting every constraint with `variable` at `value`? Found by fixing the
    variable, then each variable still free at a point of its domain (its lower bound, middle or
    upper bound, the first that propagation keeps consistent), and checked by propagating over
    the point: every constraint is applied to it, and one it breaks empties a domain. False says
    only that no such point was found."""
    trial = Closure(dict(closure.domains), closure.constraints)
    try:
        trial.narrow(pm.Var(variable), (value, value))
        trial.propagate()
    except Empty:
        return False
    for _ in range(len(trial.domains) + 1):
        free = next(((name, d) for name, d in sorted(trial.domains.items(), key=lambda item: item[0])
                     if (len(d) > 1 if isinstance(d, frozenset) else d[0] != d[1])), None)
        if free is None:
            return True
        name, d = free
        candidates: list[Dom] = [frozenset((symbol,)) for symbol in sorted(d)] if isinstance(d, frozenset) else [
            (point, point) for point in dict.fromkeys((d[0], (d[0] + d[1]) / 2, d[1])) if math.isfinite(point)]
        for candidate in candidates:
            fixed = Closure(dict(trial.domains), trial.constraints)
            try:
                fixed.domains[name] = candidate
                fixed.propagate()
            except Empty:
                continue
            trial = fixed
            break
        else:
            return False
    return False


def _post(opti: object, c: pm.Constraint, term: object, symbols: Mapping[str, str], task: pm.Task) -> None:
    """One numeric constraint into an Opti problem; symbolic and temporal ones are decided
    already (the enclosure fixed the symbols) or belong to the temporal network."""
    import casadi

    assert isinstance(opti, casadi.Opti)
    build = term  # type: ignore[assignment]
    if isinstance(c, pm.Implies):
        condition = c.condition
        if isinstance(condition.expr, pm.Var) and condition.expr.name in symbols:
            if isinstance(condition.domain, pm.Symbols) and symbols[condition.expr.name] in condition.domain.values:
                _post(opti, c.consequence, term, symbols, task)
        return
    if _duration_constraint(c, task) is not None and isinstance(c, pm.Member):
        return
    expr = c.expr if isinstance(c, pm.Member) else None
    if isinstance(c, pm.Member):
        if isinstance(c.domain, pm.Symbols) or has_time(c.expr) or _symbolic(c.expr, symbols):
            return
        assert expr is not None
        value = build(expr)  # type: ignore[operator]
        if isinstance(value, float):
            return
        if c.domain.low > -INF:
            opti.subject_to(value >= c.domain.low)
        if c.domain.high < INF:
            opti.subject_to(value <= c.domain.high)
        return
    if has_time(c.left) or has_time(c.right) or _symbolic(c.left, symbols) or _symbolic(c.right, symbols):
        return
    left, right = build(c.left), build(c.right)  # type: ignore[operator]
    if isinstance(left, float) and isinstance(right, float):
        return
    if c.op == "=":
        opti.subject_to(left == right)
    elif c.op in ("<", "<="):
        opti.subject_to(left <= right)
    elif c.op in (">", ">="):
        opti.subject_to(left >= right)


def _symbolic(e: pm.Expr, symbols: Mapping[str, str]) -> bool:
    if isinstance(e, pm.Sym):
        return True
    if isinstance(e, pm.Var):
        return e.name in symbols
    return isinstance(e, pm.Op) and any(_symbolic(a, symbols) for a in e.args)
