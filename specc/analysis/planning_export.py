"""Export of a planning domain and problem (`specc.runtime.planner.model`) to the `unified_planning`
library, and through it to PDDL 2.1 with timed initial literals.

The encoding, chosen for the temporal planners of unified_planning (Aries) and for PDDLWriter:

- an attribute instance is a set of boolean fluents, one true at a time: `A_v(args)` for each value
  v when the assertions only use constant values, `A(args, value)` when a value is a variable
  (Modele1's PTU_POSITION, Modele2's FRAME_POS) or the attribute is numeric;
- symbolic sets become user types (a laminar family of the sets the parameters and the fluents
  need; a set crossing another falls back to its smallest enclosing type, or to `symbol`);
- a numeric slot (attribute argument or value) is ground over the numbers that appear in the
  domain's and the problem's assertions, those a task's constraint sets a variable to (`?x =. 7`,
  or a macro's table: `_p in {A} => _x =. 7`, `constrained_numbers`), and those the tasks' events
  lead to from them one number at a time (`reach_numbers`), within the declared domains: the slots
  a task variable links share one user type, with one object per number (`AT_ROBOT_X_4`), so
  Modele1's real-valued MOVE and TAKE_PICTURE become finite. A number reached only through a
  choice (`?b2 =. ?b1 - 1.5 * ?d` with ?d taken from a table) is not enumerated: the sums of such
  steps grow without a useful bound;
- a task is a durative action; its variables used in assertions (`?state`) become parameters. The
  duration comes from a small interval propagation of the task's constraints with the parameters
  ground: constant, or a static function of the parameters (`MOVE_duration(?x1, ?y1, ?x2, ?y2)`),
  with a static `TASK_allowed(...)` table when some ground tuples break the constraints.
  Durations are whole seconds: Aries only takes integer durations;
- an event (v1 -> v2) at the task's start or end is a condition v1 and effects -v1, +v2 there; a
  hold over (start, end) is a condition over the interval, left open when the task's own start
  event gives the value;
- compact (the default): a value that only marks a task in progress (`in_progress_values`: MOVE's
  AT_ROBOT_X = 1000, ROBOT_STATUS = MOVING) is left out. The task's start only deletes the old
  value and its end only adds the new one: in between the attribute has no value, which keeps
  every other task needing a value out as the marker did, with a fluent and objects fewer. Aries
  solves M1-M4 of both models in 0.3-5 s this way; with the markers, it took 2-12 s or timed out;
- the problem's explained events at t_start are the initial state; its other given events are
  timed initial literals, pessimistic for nature: the old value stops being true at the
  event's earliest date, the new one starts at its latest date (a window is open from its latest
  opening to its earliest closing);
- goals are final goals (priorities dropped); a goal whose window ends by a bounded date is also
  reached by then: the effects achieving it need `before_T`, which a timed literal makes false;
  a required hold from t_start is kept by guarding the effects that would end it until the
  latest date of its end (`past_T`); the horizon's latest end is a deadline (`within_horizon`,
  made false by a timed literal, is required by every action).

Whatever cannot be said this way is listed, one sentence each, in `Exported.unsupported`. A task
that could run but gets no action (no ground instance, too many, no bounded duration) is in
`Exported.left_out` instead, with why and what to do: the files then lack an action specc's
planner may use, and a problem needing it has no plan from them (`specc export` fails).
"""

from __future__ import annotations

import itertools
import math
from collections import OrderedDict
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any, Union

from unified_planning.io import PDDLWriter
from unified_planning.model import Problem as UPProblem
from unified_planning.shortcuts import (
    FALSE,
    And,
    BoolType,
    ClosedTimeInterval,
    DurativeAction,
    EndTiming,
    Equals,
    Fluent,
    GlobalStartTiming,
    Int,
    IntType,
    LeftOpenTimeInterval,
    Not,
    Object,
    OpenTimeInterval,
    Or,
    RightOpenTimeInterval,
    StartTiming,
    UserType,
)

from specc.analysis.planning import Lowering
from specc.model import nodes as m
from specc.runtime.planner import model as pm
from specc.runtime.planner.model import describe
from specc.runtime.planner.numeric import Empty, div, evaluate, mul, square, square_root
from specc.runtime.planner.replan import replanning_problem

VALUE = -1  # the position of an attribute's value, next to its argument positions 0, 1, ...
ROOT_TYPE = "symbol"
HORIZON_FLUENT = "within_horizon"
TABLE_LIMIT = 200_000  # ground parameter tuples enumerated for one task's duration table
REACHED_NUMBERS = 64  # numbers a numeric class may gain from the tasks' arithmetic (`reach_numbers`)
CHOICE_LIMIT = 4096  # combinations of symbolic variables tried to bound one ground task
TOLERANCE = 1e-9

Span = tuple[float, float]
Dom = Union[Span, frozenset[str], None]  # a numeric interval, a set of symbols, or any symbol
Key = tuple[str, str]  # ("var", "?x") or ("time", "t_end")
Slot = tuple[str, int]  # (attribute, argument index or VALUE)
FULL: Span = (-math.inf, math.inf)


@dataclass
class Exported:
    problem: UPProblem  # a temporal unified_planning problem (durative actions)
    unsupported: list[str] = field(default_factory=list)  # what could not be expressed faithfully
    # The domain's tasks with no action in the problem, each with why and what the user may do about it.
    left_out: dict[str, str] = field(default_factory=dict)


def export(domain: pm.PlanningDomain, problem: pm.Problem,
           set_names: Mapping[frozenset[str], str] | None = None, compact: bool = True) -> Exported:
    """The unified_planning problem of `problem` in `domain`. `set_names` names the user types made
    from symbol sets (see `constant_set_names`); unnamed sets get a name from their members or
    from their first user. A goal impossible even alone (specc's planner exhausts every partial
    plan for it: a window too short for the task, a horizon too near), which `specc plan` drops,
    is left out and said so: PDDL 2.1 has no oversubscription, and a problem keeping it would have
    no plan at all. `compact` leaves out the values that only mark a task in progress
    (`in_progress_values`)."""
    impossible = impossible_goals(domain, problem)
    if impossible:
        kept = [a.line for a in problem.assertions if a.goal is not None and a.line not in impossible]
        # The problem without them (their own timepoints and constraints go too), from its origin.
        problem = replace(replanning_problem(problem, (), kept, 0.0), name=problem.name)
    exported = _Exporter(domain, problem, dict(set_names or {}), compact).run()
    for line, why in sorted(impossible.items()):
        exported.unsupported.insert(0, f"the goal of line {line} is left out: it is {why}, as `specc plan` finds "
                                       "(PDDL 2.1 has no oversubscription: a problem keeping it has no plan).")
    return exported


def impossible_goals(domain: pm.PlanningDomain, problem: pm.Problem) -> dict[int, str]:
    """The source lines of the goals specc's planner finds impossible even alone, with why."""
    from specc.runtime.planner.planner import Planner

    return Planner(domain).impossible_goals(problem)


@dataclass(frozen=True)
class _Transit:
    """A task's passage through an in-progress value: `event(A(args): (x, v), start)`,
    `hold(A(args): v, (start, end))` and `event(A(args): (v, y), end)`."""

    leave: pm.Event
    hold: pm.Hold
    arrive: pm.Event


def _transits(task: pm.Task) -> list[_Transit]:
    events = [a for a in task.assertions if isinstance(a, pm.Event)]
    found = []
    for hold in (a for a in task.assertions if isinstance(a, pm.Hold)):
        if hold.start != task.start or hold.end != task.end or not _constant(hold.value):
            continue
        same = [e for e in events if e.attribute == hold.attribute and e.args == hold.args]
        leave = [e for e in same if e.time == task.start and e.after == hold.value and e.before != hold.value]
        arrive = [e for e in same if e.time == task.end and e.before == hold.value and e.after != hold.value]
        if len(leave) == 1 and len(arrive) == 1:
            found.append(_Transit(leave[0], hold, arrive[0]))
    return found


def in_progress_values(domain: pm.PlanningDomain, problem: pm.Problem) -> dict[tuple[str, pm.Expr], list[str]]:
    """The values that only mark a task in progress (Modele1's AT_ROBOT_X = 1000 while the robot
    moves, ROBOT_STATUS = MOVING), with the tasks that pass through them: every assertion naming
    the value belongs to a passage (`_Transit`) of a task, as the value passed through (a
    passage's values before and after are values like any other), but for the meaningless old
    value of an event given at the problem's start. Such a value says only "this task runs",
    which the absence of any value of the attribute says as well: the compact encoding leaves it
    out."""
    passages: dict[tuple[str, pm.Expr], list[str]] = {}
    inside: set[int] = set()
    named: set[tuple[str, pm.Expr]] = set()
    for task in domain.tasks:
        for transit in _transits(task):
            attribute = transit.hold.attribute
            passages.setdefault((attribute, transit.hold.value), []).append(task.name)
            inside |= {id(transit.leave), id(transit.hold), id(transit.arrive)}
            named |= {(attribute, transit.leave.before), (attribute, transit.arrive.after)}
    for task in domain.tasks:
        for a in task.assertions:
            if isinstance(a, (pm.Event, pm.Hold)) and id(a) not in inside:
                named |= {(a.attribute, e) for pos, e, _ in _positions(a) if pos == VALUE}
    for a in problem.assertions:
        if isinstance(a, pm.Event):
            given = a.kind != "" and a.time == problem.start
            named |= {(a.attribute, a.after)} | (set() if given else {(a.attribute, a.before)})
        elif isinstance(a, pm.Hold):
            named.add((a.attribute, a.value))
    return {marker: tasks for marker, tasks in passages.items() if marker not in named}


def _could_take(task: pm.Task, var: str, value: pm.Expr) -> bool:
    """May the task's variable take `value`, as far as its own unary constraints say?"""
    own = [c for c in task.constraints if _keys(c) == {("var", var)}]
    dom: Dom = (value.value, value.value) if isinstance(value, pm.Num) else frozenset((describe(value),))
    return bounds(own, {("var", var): dom}, []) is not None


def write_pddl(exported: Exported, folder: Path) -> tuple[Path, Path]:
    """Writes `domain.pddl` and `problem.pddl` into `folder`."""
    folder.mkdir(parents=True, exist_ok=True)
    writer = PDDLWriter(exported.problem)
    domain_path, problem_path = folder / "domain.pddl", folder / "problem.pddl"
    writer.write_domain(str(domain_path))
    writer.write_problem(str(problem_path))
    # PDDLWriter leaves static functions (the duration tables) out of the problem kind, so it omits the
    # requirement they need; strict PDDL parsers (VAL) reject `:functions` without it.
    text = _sorted_constants(domain_path.read_text())
    if "(:functions" in text and ":numeric-fluents" not in text:
        text = text.replace("(:requirements :strips", "(:requirements :strips :numeric-fluents", 1)
    domain_path.write_text(text)
    return domain_path, problem_path


def _sorted_constants(domain: str) -> str:
    """The domain's `(:constants ...)` with each type's names sorted: PDDLWriter lists them from a
    set, in an order that changes from one process to the next, and the same specs should give
    the same files."""
    head, found, rest = domain.partition(" (:constants")
    if not found:
        return domain
    block, end, tail = rest.partition("\n )\n")
    lines = [" ".join(sorted(names.split())) + " - " + kind if " - " in line else line
             for line in block.split("\n") for names, _, kind in [line.partition(" - ")]]
    return head + found + "\n   ".join(line.strip() for line in lines) + end + tail


def read_pddl(domain: Path, problem: Path) -> UPProblem:
    """The files `write_pddl` wrote, read back by unified-planning's reader as a planner through it
    takes them: Aries (`OneshotPlanner(name="aries")`) solves what this returns, not the reader's
    problem itself, whose durations PDDL's `number` makes real (`with_integer_functions`)."""
    from unified_planning.io import PDDLReader

    return with_integer_functions(PDDLReader().parse_problem(str(domain), str(problem)))


def with_integer_functions(problem: UPProblem) -> UPProblem:
    """The problem as unified-planning's PDDL reader gives it, with each static numeric function
    whose values are all whole numbers typed as an integer: PDDL has only `number`, which the
    reader makes real, and Aries takes only integer durations (Modele1's MOVE_duration). The
    files are not changed; nothing else in the problem is."""
    changed = {effect.fluent.fluent().name for action in problem.actions for effects in action.effects.values()
               for effect in effects} | {effect.fluent.fluent().name for effects in problem.timed_effects.values()
                                         for effect in effects}
    values = problem.explicit_initial_values
    retyped = {}
    for fluent in problem.fluents:
        if fluent.type.is_real_type() and fluent.name not in changed and all(
                value.constant_value() == int(value.constant_value())
                for key, value in values.items() if key.fluent() == fluent):
            retyped[fluent.name] = Fluent(fluent.name, IntType(), fluent.signature)

    def integer(expression: Any) -> Any:
        if expression.is_fluent_exp() and expression.fluent().name in retyped:
            return retyped[expression.fluent().name](*expression.args)
        return expression

    result = UPProblem(problem.name)
    for fluent in problem.fluents:
        default = problem.fluents_defaults.get(fluent)
        if fluent.name in retyped:
            whole = None if default is None else Int(int(default.constant_value()))
            result.add_fluent(retyped[fluent.name], default_initial_value=whole)
        else:
            result.add_fluent(fluent, default_initial_value=default)
    result.add_objects(problem.all_objects)
    for action in problem.actions:
        copy = action.clone()
        duration = action.duration
        copy.set_closed_duration_interval(integer(duration.lower), integer(duration.upper))
        result.add_action(copy)
    for key, value in values.items():
        fresh = integer(key)
        result.set_initial_value(fresh, Int(int(value.constant_value())) if fresh is not key else value)
    for timing, effects in problem.timed_effects.items():
        for effect in effects:
            result.add_timed_effect(timing, effect.fluent, effect.value)
    for goal in problem.goals:
        result.add_goal(goal)
    return result


def constant_set_names(program: m.Program, domain: m.Domain) -> dict[frozenset[str], str]:
    """The domain's named constant sets (`constant OBJECTS = {...}`), by their members: the
    planning records spell the sets out, so the names are found again here."""
    names: dict[frozenset[str], str] = {}
    for name, values in Lowering(program, domain.members).constants.items():
        names.setdefault(frozenset(values), name)
    return names


# ================================================================ interval propagation


class _Infeasible(Exception):
    """The constraints admit no value."""


def _key(e: pm.Expr) -> Key | None:
    if isinstance(e, pm.Var):
        return ("var", e.name)
    if isinstance(e, pm.Time):
        return ("time", e.name)
    return None


def _keys(e: pm.Expr | pm.Constraint) -> set[Key]:
    if isinstance(e, pm.Member):
        return _keys(e.expr)
    if isinstance(e, pm.Relation):
        return _keys(e.left) | _keys(e.right)
    if isinstance(e, pm.Implies):
        return _keys(e.condition) | _keys(e.consequence)
    if isinstance(e, pm.Op):
        return set().union(*(_keys(a) for a in e.args))
    key = _key(e)
    return {key} if key else set()


def _apply(op: str, args: list[Span]) -> Span:
    return evaluate(op, args) if op in ("+", "-", "*", "/", "neg", "max", "min", "abs") else FULL


def _close(a: float, b: float) -> bool:
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= TOLERANCE * (1 + abs(a) + abs(b))


def _meet(a: Dom, b: Dom) -> Dom:
    if isinstance(a, tuple) and isinstance(b, tuple):
        low, high = max(a[0], b[0]), min(a[1], b[1])
        if low > high:
            if not _close(low, high):
                raise _Infeasible
            low = high
        return (low, high)
    if isinstance(a, tuple) or isinstance(b, tuple):
        return a  # a number met with a symbol: a mistake of the model, not the exporter's to judge
    if a is None:
        return b
    if b is None:
        return a
    if not a & b:
        raise _Infeasible
    return a & b


def _join(a: Dom, b: Dom) -> Dom:
    if isinstance(a, tuple) and isinstance(b, tuple):
        return (min(a[0], b[0]), max(a[1], b[1]))
    if isinstance(a, frozenset) and isinstance(b, frozenset):
        return a | b
    return None


class _Box:
    """Domains of the variables and timepoints of one set of constraints (HC4-style revision)."""

    def __init__(self, symbolic: frozenset[Key], domains: dict[Key, Dom] | None = None):
        self.symbolic = symbolic
        self.domains: dict[Key, Dom] = dict(domains or {})

    def copy(self) -> _Box:
        return _Box(self.symbolic, self.domains)

    def get(self, key: Key) -> Dom:
        if key in self.domains:
            return self.domains[key]
        return None if key in self.symbolic else FULL

    def narrow(self, key: Key, dom: Dom) -> bool:
        old = self.get(key)
        new = _meet(old, dom)
        if isinstance(old, tuple) and isinstance(new, tuple):
            if _close(old[0], new[0]) and _close(old[1], new[1]):
                return False
        elif new == old:
            return False
        self.domains[key] = new
        return True

    def value(self, e: pm.Expr) -> Dom:
        if isinstance(e, pm.Num):
            return (e.value, e.value)
        if isinstance(e, pm.Sym):
            return frozenset((e.name,))
        if isinstance(e, (pm.Var, pm.Time)):
            key = _key(e)
            assert key is not None
            return self.get(key)
        if e.op == "*" and e.args[0] == e.args[1]:
            return square(self.span(e.args[0]))
        return _apply(e.op, [self.span(a) for a in e.args])

    def span(self, e: pm.Expr) -> Span:
        v = self.value(e)
        return v if isinstance(v, tuple) else FULL

    def project(self, e: pm.Expr, target: Dom) -> bool:
        """Narrows the variables of `e` so that `e` may take a value in `target`."""
        if isinstance(e, pm.Num):
            if isinstance(target, tuple):
                _meet((e.value, e.value), target)
            return False
        if isinstance(e, pm.Sym):
            if isinstance(target, frozenset) and e.name not in target:
                raise _Infeasible
            return False
        if isinstance(e, (pm.Var, pm.Time)):
            key = _key(e)
            assert key is not None
            return self.narrow(key, target)
        if not isinstance(target, tuple):
            return False
        spans = [self.span(a) for a in e.args]
        _meet(self.span(e), target)
        args, op, changed = e.args, e.op, False
        if op == "*" and args[0] == args[1]:
            try:
                changed |= self.project(args[0], square_root(target, spans[0]))
            except Empty:
                raise _Infeasible from None
        elif op == "+":
            changed |= self.project(args[0], _apply("-", [target, spans[1]]))
            changed |= self.project(args[1], _apply("-", [target, spans[0]]))
        elif op == "-":
            changed |= self.project(args[0], _apply("+", [target, spans[1]]))
            changed |= self.project(args[1], _apply("-", [spans[0], target]))
        elif op == "*":
            if not spans[1][0] <= 0 <= spans[1][1]:
                changed |= self.project(args[0], div(target, spans[1]))
            if not spans[0][0] <= 0 <= spans[0][1]:
                changed |= self.project(args[1], div(target, spans[0]))
        elif op == "/":
            changed |= self.project(args[0], mul(target, spans[1]))
            if not target[0] <= 0 <= target[1]:
                changed |= self.project(args[1], div(spans[0], target))
        elif op == "neg":
            changed |= self.project(args[0], (-target[1], -target[0]))
        elif op == "max":
            for a in args:
                changed |= self.project(a, (-math.inf, target[1]))
        elif op == "min":
            for a in args:
                changed |= self.project(a, (target[0], math.inf))
        elif op == "abs":
            changed |= self.project(args[0], (-target[1], target[1]))
        return changed

    def revise(self, c: pm.Constraint) -> bool:
        if isinstance(c, pm.Member):
            if isinstance(c.domain, pm.Interval):
                return self.project(c.expr, (c.domain.low, c.domain.high))
            return self.project(c.expr, frozenset(c.domain.values))
        if isinstance(c, pm.Implies):
            if self.holds(c.condition):
                return self.revise(c.consequence)
            return False
        left, right = self.value(c.left), self.value(c.right)
        if c.op == "=":
            both = _meet(left, right)
            return self.project(c.left, both) | self.project(c.right, both)
        if c.op == "!=":
            if _single(left) is not None and _single(left) == _single(right):
                raise _Infeasible
            return False
        if not isinstance(left, tuple) or not isinstance(right, tuple):
            return False
        if c.op in (">", ">="):
            left, right = right, left
            lesser, greater = c.right, c.left
        else:
            lesser, greater = c.left, c.right
        if c.op in ("<", ">") and left[0] >= right[1] and not (math.isinf(left[0]) and math.isinf(right[1])):
            raise _Infeasible
        return self.project(lesser, (-math.inf, right[1])) | self.project(greater, (left[0], math.inf))

    def holds(self, condition: pm.Member) -> bool:
        """Is the condition true for every value left?"""
        v = self.value(condition.expr)
        if isinstance(condition.domain, pm.Symbols):
            return isinstance(v, frozenset) and v <= set(condition.domain.values)
        return isinstance(v, tuple) and condition.domain.low <= v[0] and v[1] <= condition.domain.high

    def fixpoint(self, constraints: Sequence[pm.Constraint]) -> None:
        for _ in range(60):
            changed = False
            for c in constraints:
                changed |= self.revise(c)
            if not changed:
                return


def _single(d: Dom) -> float | str | None:
    if isinstance(d, tuple):
        return d[0] if d[0] == d[1] else None
    if isinstance(d, frozenset) and len(d) == 1:
        return next(iter(d))
    return None


def _symbolic_keys(constraints: Iterable[pm.Constraint]) -> set[Key]:
    found: set[Key] = set()
    for c in constraints:
        if isinstance(c, pm.Member) and isinstance(c.domain, pm.Symbols) and _key(c.expr):
            found.add(_key(c.expr))  # type: ignore[arg-type]
        elif isinstance(c, pm.Relation):
            for one, other in ((c.left, c.right), (c.right, c.left)):
                if isinstance(other, pm.Sym) and _key(one):
                    found.add(_key(one))  # type: ignore[arg-type]
        elif isinstance(c, pm.Implies):
            found |= _symbolic_keys((c.condition, c.consequence))
    return found


def bounds(constraints: Sequence[pm.Constraint], fixed: Mapping[Key, Dom],
           wanted: Sequence[Key]) -> dict[Key, Dom] | None:
    """The domains of `wanted` under the constraints once `fixed` is set (None: infeasible).
    The symbolic variables an implication tests are tried value by value (Modele2's distance
    tables), and the result is the hull of the feasible cases."""
    symbolic = _symbolic_keys(constraints) | {k for k, d in fixed.items() if not isinstance(d, tuple)}
    box = _Box(frozenset(symbolic))
    try:
        for key, dom in fixed.items():
            box.narrow(key, dom)
        box.fixpoint(constraints)
    except _Infeasible:
        return None
    tested = {_key(c.condition.expr) for c in constraints if isinstance(c, pm.Implies)}
    choices: list[tuple[Key, list[str]]] = []
    for key in sorted(k for k in tested if k is not None):
        dom = box.get(key)
        if isinstance(dom, frozenset) and len(dom) > 1:
            choices.append((key, sorted(dom)))
    if not choices or math.prod(len(values) for _, values in choices) > CHOICE_LIMIT:
        return {key: box.get(key) for key in wanted}
    hull: dict[Key, Dom] | None = None
    for combination in itertools.product(*(values for _, values in choices)):
        trial = box.copy()
        try:
            for (key, _), value in zip(choices, combination, strict=True):
                trial.narrow(key, frozenset((value,)))
            trial.fixpoint(constraints)
        except _Infeasible:
            continue
        found = {key: trial.get(key) for key in wanted}
        hull = found if hull is None else {key: _join(hull[key], found[key]) for key in wanted}
    return hull


# ================================================================ helpers


class _UnionFind:
    def __init__(self) -> None:
        self.parent: dict[Any, Any] = {}

    def find(self, x: Any) -> Any:
        self.parent.setdefault(x, x)
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a: Any, b: Any) -> None:
        self.parent[self.find(a)] = self.find(b)


def _positions(a: pm.Event | pm.Hold) -> Iterator[tuple[int, pm.Expr, str]]:
    """(position, expression, role) of an assertion: its arguments, then its value(s)."""
    for i, e in enumerate(a.args):
        yield i, e, "arg"
    if isinstance(a, pm.Event):
        yield VALUE, a.before, "before"
        yield VALUE, a.after, "after"
    else:
        yield VALUE, a.value, "value"


def _number_set(c: pm.Constraint) -> tuple[str, float] | None:
    """(variable, number) when the constraint sets a variable to one number: `?x =. 7`, `?x in [7, 7]`."""
    if isinstance(c, pm.Relation) and c.op == "=":
        for var, number in ((c.left, c.right), (c.right, c.left)):
            if isinstance(var, pm.Var) and isinstance(number, pm.Num):
                return var.name, number.value
    if isinstance(c, pm.Member) and isinstance(c.expr, pm.Var) and isinstance(c.domain, pm.Interval) \
            and c.domain.low == c.domain.high:
        return c.expr.name, c.domain.low
    return None


def _constant(e: pm.Expr) -> bool:
    return isinstance(e, (pm.Num, pm.Sym))


def _number_text(v: float) -> str:
    text = str(int(v)) if float(v).is_integer() else f"{v:.6g}"
    return text.replace("-", "m").replace(".", "p").replace("+", "")


def _describe(a: pm.Assertion) -> str:
    args = ", ".join(describe(x) for x in a.args)
    if isinstance(a, pm.Event):
        return f"event({a.attribute}({args}): ({describe(a.before)}, {describe(a.after)}), {a.time})"
    if isinstance(a, pm.Hold):
        return f"hold({a.attribute}({args}): {describe(a.value)}, ({a.start}, {a.end}))"
    return f"use({a.resource}({args}): {describe(a.amount)}, ({a.start}, {a.end}))"


def _seconds(v: float) -> str:
    return f"{v:.4g}"


def _date(v: float) -> Fraction:
    return Fraction(v).limit_denominator(1000)


def _ceil(v: float) -> int:
    return math.ceil(v - 1e-6)


def _floor(v: float) -> int:
    return math.floor(v + 1e-6)


@dataclass
class _NumericClass:
    """Numeric slots linked by task variables: one user type, one object per number."""

    type_name: str
    prefix: str  # of its objects' names
    values: set[float] = field(default_factory=set)


@dataclass
class _Guard:
    """A condition the problem puts on the effects that touch one ground attribute value: a required
    hold from t_start guards the effects that end it (`on_add` False) until `fluent` becomes true;
    a goal with a deadline guards the effects that achieve it (`on_add` True) while `fluent` is
    true. With no fluent, the guarded effects are forbidden."""

    attribute: str
    args: tuple[pm.Expr, ...]
    value: pm.Expr
    on_add: bool
    fluent: Any


@dataclass
class _ActionParam:
    name: str  # without '?'
    var: str  # the task's variable
    numeric: bool
    values: list[Any]  # the ground values it ranges over (symbol names or numbers)
    up_type: Any
    numbers: int = 0  # id of its numeric class


# ================================================================ the exporter


class _Exporter:
    def __init__(self, domain: pm.PlanningDomain, problem: pm.Problem, set_names: dict[frozenset[str], str],
                 compact: bool = True):
        self.domain, self.problem, self.set_names = domain, problem, set_names
        self.markers = in_progress_values(domain, problem) if compact else {}
        # The assertions of the passages through those values: what each becomes (see add_assertion).
        self.passage_parts: dict[int, str] = {}
        for task in domain.tasks:
            for transit in _transits(task):
                if (transit.hold.attribute, transit.hold.value) in self.markers:
                    self.passage_parts |= {id(transit.leave): "leave", id(transit.hold): "hold",
                                           id(transit.arrive): "arrive"}
        self.notes: dict[str, None] = {}  # ordered, deduplicated
        self.left_out: dict[str, str] = {}
        # Per numeric class (by id), the first event of each task that leads from one of its
        # numbers to a range rather than one number (`reach_numbers`): why a task may lack values.
        self.unreached: dict[int, dict[tuple[str, int], str]] = {}
        self.up = UPProblem(problem.name)
        self.names: set[str] = set()
        self.fluents: dict[str, Any] = {}
        self.objects: dict[str, Any] = {}  # symbol name -> Object
        self.number_objects: dict[tuple[int, float], Any] = {}  # (class id, number) -> Object
        self.attribute_order = {a.name: i for i, a in enumerate(domain.attributes)}

    def note(self, sentence: str) -> None:
        self.notes.setdefault(sentence, None)

    def unique(self, name: str) -> str:
        candidate, k = name, 1
        while candidate.lower() in self.names:  # PDDL names are case-insensitive
            k += 1
            candidate = f"{name}_{k}"
        self.names.add(candidate.lower())
        return candidate

    # ------------------------------------------------------------ run
    def run(self) -> Exported:
        self.note_markers()
        self.survey()
        self.time_bounds()
        self.make_types()
        self.make_problem_frame()
        for task in self.domain.tasks:
            self.add_task(task)
        self.add_problem()
        return Exported(self.up, list(self.notes), dict(self.left_out))

    def note_markers(self) -> None:
        if not self.markers:
            return
        shown = "; ".join(f"{attribute} = {describe(value)} ({', '.join(dict.fromkeys(tasks))})"
                          for (attribute, value), tasks in self.markers.items())
        self.note(f"the values that only mark a task in progress are left out (compact encoding): {shown}. While "
                  "such a task runs, its attribute has no value, which keeps out every other task needing one as "
                  "the marker did.")
        for task in self.domain.tasks:
            for a in task.assertions:
                if not isinstance(a, (pm.Event, pm.Hold)) or id(a) in self.passage_parts:
                    continue
                for pos, e, _ in _positions(a):
                    if pos != VALUE or not isinstance(e, pm.Var):
                        continue
                    for (attribute, value) in self.markers:
                        if attribute == a.attribute and _could_take(task, e.name, value):
                            self.note(f"{task.name}: {_describe(a)} could hold with {e.name} = {describe(value)}, "
                                      f"while the task marked by it runs; the compact encoding leaves that out.")

    # ------------------------------------------------------------ survey: slots, values, types needed
    def assertions(self) -> Iterator[tuple[pm.Task | None, pm.Event | pm.Hold]]:
        for task in self.domain.tasks:
            for a in task.assertions:
                if isinstance(a, (pm.Event, pm.Hold)):
                    yield task, a
        for a in self.problem.assertions:
            if isinstance(a, (pm.Event, pm.Hold)):
                yield None, a

    def declared(self, slot: Slot) -> pm.Values | None:
        attribute = self.domain.attribute(slot[0])
        if attribute is None:
            return None
        if slot[1] == VALUE:
            return attribute.values
        domains = attribute.param_domains
        return domains[slot[1]] if slot[1] < len(domains) else None

    def given_at_start(self, a: pm.Event | pm.Hold) -> bool:
        """An explained or contingent event at t_start: only its new value means anything."""
        return isinstance(a, pm.Event) and a.kind != "" and a.time == self.problem.start

    def survey(self) -> None:
        constants: dict[Slot, set[float | str]] = {}
        for task, a in self.assertions():
            for pos, e, role in _positions(a):
                meaningless = role == "before" and task is None and self.given_at_start(a)
                marker = pos == VALUE and (a.attribute, e) in self.markers
                if isinstance(e, (pm.Num, pm.Sym)) and not meaningless and not marker:
                    constants.setdefault((a.attribute, pos), set()).add(e.value if isinstance(e, pm.Num) else e.name)
        self.constants = constants

        def numeric(slot: Slot) -> bool:
            declared = self.declared(slot)
            if declared is not None:
                return isinstance(declared, pm.Interval)
            return any(isinstance(v, float) for v in constants.get(slot, ()))

        self.numeric_slot = numeric
        # An attribute gets a value parameter when a value is not a constant, or is a number.
        self.valued: set[str] = set()
        for _, a in self.assertions():
            if numeric((a.attribute, VALUE)) or any(not _constant(e) for pos, e, _ in _positions(a) if pos == VALUE):
                self.valued.add(a.attribute)
        # Numeric slots linked through the variables of a task (or of the problem) share a type.
        links = _UnionFind()
        for task, a in self.assertions():
            scope = task.name if task else ""
            for pos, e, _ in _positions(a):
                slot = (a.attribute, pos)
                if numeric(slot):
                    links.find(("slot",) + slot)
                    if isinstance(e, pm.Var):
                        links.union(("var", scope, e.name), ("slot",) + slot)
        self.links = links
        classes: dict[Any, _NumericClass] = {}
        slots = sorted((node for node in links.parent if node[0] == "slot"),
                       key=lambda n: (self.attribute_order.get(n[1], 1 << 30), n[2]))
        for node in slots:
            _, attribute, pos = node
            root = links.find(node)
            if root not in classes:
                if pos == VALUE:
                    stem, prefix = f"{attribute}_value", attribute
                else:
                    declared = self.domain.attribute(attribute)
                    params = declared.params if declared else ()
                    param = params[pos].lstrip("?") if pos < len(params) else str(pos)
                    stem = prefix = f"{attribute}_{param}"
                classes[root] = _NumericClass(stem, prefix)
            classes[root].values |= {v for v in constants.get((attribute, pos), ()) if isinstance(v, float)}
        self.classes = classes
        self.constrained_numbers()
        self.reach_numbers()

    def constrained_numbers(self) -> None:
        """Add to each numeric class the numbers a task's constraint sets one of its variables to:
        `?x =. 7`, alone or as what an implication concludes when its condition may hold (a macro's
        table: `_p in {A} => _x =. 7`). The planner may take them, and no assertion need write them:
        without them such a task would have no ground instance."""
        for task in self.domain.tasks:
            for c in task.constraints:
                set_to = _number_set(c.consequence if isinstance(c, pm.Implies) else c)
                if set_to is None:
                    continue
                var, value = set_to
                cls = self.numeric_class(task.name, var)
                if cls is None or value in cls.values or not self.declared_for(task, var, value):
                    continue
                if isinstance(c, pm.Implies) and bounds([*task.constraints, c.condition], {}, []) is None:
                    continue  # a row of the table this task never reads (`?p in {A}` with `_p in {B} => ...`)
                cls.values.add(value)

    def declared_for(self, task: pm.Task, var: str, value: float) -> bool:
        """Is `value` within the domains declared for every slot the task's variable fills?"""
        return all(d.low <= value <= d.high for slot in self.var_slots(task, var)
                   if isinstance(d := self.declared(slot), pm.Interval))

    def reach_numbers(self) -> None:
        """Add to each numeric class the numbers a task's events lead to from the numbers it has:
        `event(BATTERY(): (?b, ?b2))` with `?b2 =. ?b - 1` takes a battery of 3 charges to 2, then
        1, then 0 (forward only: what a value may become, never what it may have been), within
        the domains the slots declare. The numbers written alone would leave such a task no ground
        instance. Bounded (REACHED_NUMBERS per class): a class it cuts is said in the notes."""
        cut: set[str] = set()
        tried: set[tuple[int, float]] = set()  # (event, value before): each worked out once, not at every sweep
        grown = True
        while grown:
            grown = False
            for task in self.domain.tasks:
                for a in task.assertions:
                    if not (isinstance(a, pm.Event) and isinstance(a.before, pm.Var) and isinstance(a.after, pm.Var)):
                        continue
                    source, target = self.numeric_class(task.name, a.before.name), \
                        self.numeric_class(task.name, a.after.name)
                    if source is None or target is None:
                        continue
                    for before in sorted(source.values):
                        if (id(a), before) in tried:
                            continue
                        tried.add((id(a), before))
                        found = bounds(task.constraints, {("var", a.before.name): (before, before)},
                                       [("var", a.after.name)])
                        after = found[("var", a.after.name)] if found is not None else None
                        value = _single(after)
                        if isinstance(after, tuple) and value is None:
                            self.unreached.setdefault(id(target), {}).setdefault((task.name, id(a)), (
                                f"from {a.before.name} = {_seconds(before)}, {task.name}'s {_describe(a)} leads "
                                f"{a.after.name} anywhere in [{_seconds(after[0])}, {_seconds(after[1])}], not to one "
                                "number (it depends on another choice the planner makes); such numbers are not "
                                "enumerated, as their sums along a plan have no useful bound"))
                        if not isinstance(value, float) or value in target.values or not self.declared_for(
                                task, a.after.name, value):
                            continue
                        if len(target.values) >= REACHED_NUMBERS:
                            cut.add(target.type_name)
                            continue
                        target.values.add(value)
                        grown = True
        for name in sorted(cut):
            self.note(f"{name}: the numbers the tasks' events lead to are cut at {REACHED_NUMBERS}: the values "
                      "past them are not exported, and a plan needing them is not found from the files.")

    def numeric_class(self, scope: str, var: str) -> _NumericClass | None:
        node = ("var", scope, var)
        if node not in self.links.parent:
            return None
        return self.classes.get(self.links.find(node))

    def slot_class(self, slot: Slot) -> _NumericClass:
        return self.classes[self.links.find(("slot",) + slot)]

    # ------------------------------------------------------------ the problem's dates
    def time_bounds(self) -> None:
        p = self.problem
        wanted = [("time", t) for t in (*p.timepoints, p.end)]
        found = bounds(p.constraints, {("time", p.start): (0.0, 0.0)}, wanted)
        self.dates: dict[str, Span] = {p.start: (0.0, 0.0)}
        if found is None:
            self.note(f"{p.name}: the problem's temporal constraints are inconsistent; its dates are left unbounded.")
            found = {}
        for (_, name), dom in found.items():
            self.dates[name] = dom if isinstance(dom, tuple) else FULL
        # The latest dates the constraints give without the mission's latest end: a goal's own
        # deadline, not the horizon's, which is exported on its own.
        unbounded = bounds(pm.without_latest_end(p).constraints, {("time", p.start): (0.0, 0.0)}, wanted) or {}
        self.own_latest: dict[str, float] = {name: dom[1] if isinstance(dom, tuple) else math.inf
                                             for (_, name), dom in unbounded.items()}

    # ------------------------------------------------------------ types
    def task_variables(self, task: pm.Task) -> list[str]:
        """The parameters, then the variables the assertions use (the planner chooses them too)."""
        used: list[str] = []
        for a in task.assertions:
            if isinstance(a, (pm.Event, pm.Hold)):
                for _, e, _ in _positions(a):
                    for _, name in sorted(k for k in _keys(e) if k[0] == "var"):
                        if name not in task.params and name not in used:
                            used.append(name)
        return list(task.params) + [v for v in task.variables if v in used]

    def var_slots(self, task: pm.Task, var: str) -> list[Slot]:
        return [(a.attribute, pos) for a in task.assertions if isinstance(a, (pm.Event, pm.Hold))
                for pos, e, _ in _positions(a) if e == pm.Var(var)]

    def symbol_set(self, task: pm.Task, var: str) -> frozenset[str] | None:
        found: frozenset[str] | None = None
        for c in task.constraints:
            if isinstance(c, pm.Member) and c.expr == pm.Var(var) and isinstance(c.domain, pm.Symbols):
                found = frozenset(c.domain.values) if found is None else found & frozenset(c.domain.values)
        if found is None:
            for slot in self.var_slots(task, var):
                declared = self.declared(slot)
                if isinstance(declared, pm.Symbols):
                    found = frozenset(declared.values) if found is None else found & frozenset(declared.values)
        return found

    def slot_set(self, slot: Slot) -> frozenset[str]:
        declared = self.declared(slot)
        seen = frozenset(str(v) for v in self.constants.get(slot, ()) if isinstance(v, str))
        if isinstance(declared, pm.Symbols):
            return frozenset(declared.values) | seen
        return seen

    def make_types(self) -> None:
        needed: list[tuple[frozenset[str], str]] = []  # in priority order, with a name if none is given
        self.param_sets: dict[tuple[str, str], frozenset[str] | None] = {}
        for task in self.domain.tasks:
            for var in self.task_variables(task):
                if self.numeric_class(task.name, var) is None:
                    s = self.symbol_set(task, var)
                    self.param_sets[(task.name, var)] = s
                    if s:
                        needed.append((s, f"{task.name}_{var.lstrip('?')}"))
        for slot in self.fluent_slots():
            if not self.numeric_slot(slot):
                attribute = self.domain.attribute(slot[0])
                params = attribute.params if attribute else ()
                stem = "value" if slot[1] == VALUE else (params[slot[1]].lstrip("?") if slot[1] < len(params)
                                                         else str(slot[1]))
                needed.append((self.slot_set(slot), f"{slot[0]}_{stem}"))
        family: list[frozenset[str]] = []
        proposed: dict[frozenset[str], str] = {}
        for s, name in needed:
            if s and s not in proposed and all(not (s & f) or s <= f or f <= s for f in family):
                family.append(s)
                proposed[s] = name
        self.family = family
        universe = frozenset().union(*(s for s, _ in needed))
        self.root_values = universe
        # A set crossing another, or a variable or slot with no known set, falls back to a type of all symbols.
        unplaced = [s for s, _ in needed if s not in proposed] + [s for s in self.param_sets.values() if not s]
        root = UserType(self.unique(ROOT_TYPE)) if unplaced else None
        self.root = root
        self.types: dict[frozenset[str], Any] = {}
        for s in sorted(family, key=len, reverse=True):
            parents = [f for f in family if s < f]
            father = self.types[min(parents, key=len)] if parents else root
            name = self.set_names.get(s) or ("_".join(sorted(s)) if len(s) <= 2 else proposed[s])
            self.types[s] = UserType(self.unique(name), father)
        for symbol in sorted(universe):
            enclosing = [f for f in family if symbol in f]
            symbol_type = self.types[min(enclosing, key=len)] if enclosing else root
            self.objects[symbol] = Object(self.unique(symbol), symbol_type)
        self.class_types: dict[int, Any] = {}
        for cls in self.classes.values():
            cls_type = UserType(self.unique(cls.type_name))
            self.class_types[id(cls)] = cls_type
            for v in sorted(cls.values):
                self.number_objects[(id(cls), v)] = Object(self.unique(f"{cls.prefix}_{_number_text(v)}"), cls_type)
        self.up.add_objects(list(self.objects.values()) + list(self.number_objects.values()))

    def fluent_slots(self) -> list[Slot]:
        slots: list[Slot] = []
        for _, a in self.assertions():
            for pos, _, _ in _positions(a):
                slot = (a.attribute, pos)
                if slot not in slots and (pos != VALUE or a.attribute in self.valued):
                    slots.append(slot)
        return slots

    def set_type(self, s: frozenset[str] | None) -> Any:
        if s and s in self.types:
            return self.types[s]
        enclosing = [f for f in self.family if s and s <= f]
        return self.types[min(enclosing, key=len)] if enclosing else self.root

    def set_values(self, s: frozenset[str] | None) -> list[str]:
        """The objects of the type standing for `s` (a superset when `s` is not a type itself)."""
        if s and s in self.types:
            return sorted(s)
        enclosing = [f for f in self.family if s and s <= f]
        return sorted(min(enclosing, key=len) if enclosing else self.root_values)  # type: ignore[arg-type]

    def slot_type(self, slot: Slot) -> Any:
        if self.numeric_slot(slot):
            return self.class_types[id(self.slot_class(slot))]
        return self.set_type(self.slot_set(slot))

    # ------------------------------------------------------------ fluents and terms
    def fluent(self, attribute: str, value: pm.Expr) -> Any:
        """The boolean fluent of `attribute` (with a value parameter) or of `attribute` = value."""
        name = attribute if attribute in self.valued else f"{attribute}_{describe(value)}"
        if name not in self.fluents:
            attr = self.domain.attribute(attribute)
            params = list(attr.params) if attr else []
            arity = max((len(a.args) for _, a in self.assertions() if a.attribute == attribute), default=0)
            params += [f"?arg{i}" for i in range(len(params), arity)]
            signature = OrderedDict((p.lstrip("?"), self.slot_type((attribute, i))) for i, p in enumerate(params))
            if attribute in self.valued:
                signature["value"] = self.slot_type((attribute, VALUE))
            fluent = Fluent(self.unique(name), BoolType(), signature)
            self.up.add_fluent(fluent, default_initial_value=False)
            self.fluents[name] = fluent
        return self.fluents[name]

    def term(self, e: pm.Expr, slot: Slot, bound: Mapping[str, Any]) -> Any:
        """An argument or value: an action parameter, a symbol object or a number object."""
        if isinstance(e, pm.Var):
            return bound[e.name]
        if isinstance(e, pm.Sym):
            return self.objects[e.name]
        if isinstance(e, pm.Num):
            return self.number_objects[(id(self.slot_class(slot)), e.value)]
        raise KeyError(describe(e))

    def atom(self, attribute: str, args: Sequence[pm.Expr], value: pm.Expr, bound: Mapping[str, Any]) -> Any:
        fluent = self.fluent(attribute, value)
        terms = [self.term(e, (attribute, i), bound) for i, e in enumerate(args)]
        if attribute in self.valued:
            terms.append(self.term(value, (attribute, VALUE), bound))
        return fluent(*terms)

    # ------------------------------------------------------------ problem frame
    def make_problem_frame(self) -> None:
        """The deadlines and the required holds, which the actions refer to."""
        p = self.problem
        self.horizon_fluent = None
        latest_end = self.dates.get(p.end, FULL)[1]
        if math.isfinite(latest_end):
            self.horizon_fluent = Fluent(self.unique(HORIZON_FLUENT), BoolType())
            self.up.add_fluent(self.horizon_fluent, default_initial_value=False)
            self.up.set_initial_value(self.horizon_fluent, True)
            self.up.add_timed_effect(GlobalStartTiming(_date(latest_end)), self.horizon_fluent, False)
            self.note(f"the horizon ({p.end} - {p.start}) in [{_seconds(self.dates[p.end][0])}, "
                      f"{_seconds(latest_end)}] is exported as a deadline at {_seconds(latest_end)} s "
                      f"('{HORIZON_FLUENT}' is required by every action and made false by a timed initial literal); "
                      "its lower bound is dropped (the goals are final-state goals that persist).")
        else:
            self.note("the horizon has no finite latest end; no deadline is exported.")
        self.guards: list[_Guard] = []
        for a in p.assertions:
            if isinstance(a, (pm.Event, pm.Hold)) and a.goal is not None:
                self.add_goal_deadline(a)
            if not isinstance(a, pm.Hold) or a.goal is not None:
                continue
            if a.start != p.start or any(not _constant(e) for e in a.args) or not _constant(a.value):
                self.note(f"the required {_describe(a)} (line {a.line}) is dropped: only ground holds from "
                          f"{p.start} are kept.")
                continue
            release = None
            if a.end != p.end:
                latest = self.dates.get(a.end, FULL)[1]
                if math.isfinite(latest):
                    release = self.clock(f"past_{a.end}", latest, becomes=True)
            self.guards.append(_Guard(a.attribute, a.args, a.value, False, release))
            until = f"{a.end}'s latest date, {_seconds(self.dates.get(a.end, FULL)[1])} s" if release else "the end"
            self.note(f"the required {_describe(a)} is kept until {until}: the effects that could end it are "
                      "guarded (pessimistic for nature when its end is contingent).")

    def clock(self, name: str, date: float, becomes: bool) -> Any:
        """A boolean fluent that a timed initial literal sets to `becomes` at `date`."""
        if name not in self.fluents:
            self.fluents[name] = Fluent(self.unique(name), BoolType())
            self.up.add_fluent(self.fluents[name], default_initial_value=not becomes)
            self.up.add_timed_effect(GlobalStartTiming(_date(date)), self.fluents[name], becomes)
        return self.fluents[name]

    def add_goal_deadline(self, goal: pm.Event | pm.Hold) -> None:
        """A goal whose window must end by a bounded date is achieved before that date: PDDL 2.1 has
        no timed goals, so the effects achieving it are guarded by a fluent that a timed initial
        literal makes false then. The final goal keeps it true afterwards."""
        p = self.problem
        end = goal.time if isinstance(goal, pm.Event) else goal.end
        if isinstance(goal, pm.Hold) and end == p.end and math.isfinite(self.own_latest.get(goal.start, math.inf)):
            # Held to the end from a date with a deadline of its own (`(t1 - t_start) in [0, 100]`):
            # it must come true by then, and an effect achieving it later is refused as well.
            end = goal.start
        elif end == p.end:
            return  # bounded by the horizon's deadline
        latest = self.dates.get(end, FULL)[1]
        # `end - c in [a, b]` with c contingent: whatever nature picks for c, end <= earliest(c) + b.
        contingent = {e.time for e in p.assertions if isinstance(e, pm.Event) and e.kind == "contingent"}
        for c in p.constraints:
            if isinstance(c, pm.Member) and isinstance(c.domain, pm.Interval) and isinstance(c.expr, pm.Op) \
                    and c.expr.op == "-" and c.expr.args[0] == pm.Time(end) and isinstance(c.expr.args[1], pm.Time) \
                    and c.expr.args[1].name in contingent:
                latest = min(latest, self.dates.get(c.expr.args[1].name, FULL)[0] + c.domain.high)
        if not math.isfinite(latest) or any(not _constant(e) for e in goal.args):
            return
        value = goal.after if isinstance(goal, pm.Event) else goal.value
        self.guards.append(_Guard(goal.attribute, goal.args, value, True,
                                  self.clock(f"before_{end}", latest, becomes=False)))
        self.note(f"the goal {_describe(goal)} must be reached by {_seconds(latest)} s, the latest date of {end} "
                  f"whatever nature does: the effects achieving it are guarded by 'before_{end}', which a timed "
                  "initial literal makes false then (PDDL 2.1 has no timed goals).")

    # ------------------------------------------------------------ tasks
    def leave_out(self, task: pm.Task, why: str) -> None:
        """The task gets no action: a faithful encoding when no value at all meets its constraints,
        else a loss the user must hear of (`Exported.left_out`)."""
        if bounds(task.constraints, {("time", task.start): (0.0, 0.0)}, []) is None:
            self.note(f"{task.name} is left out: no values at all meet its constraints, so it can never run.")
        else:
            self.left_out[task.name] = why

    def grounding(self, task: pm.Task, params: Sequence[_ActionParam], kept: Mapping[str, Sequence[Any]]) -> str:
        """Why the numbers the parameters are ground over miss those the task needs (which
        parameter, a number it would take, and how the export failed to reach it), and what the user
        can do about it: the end of the sentence of `leave_out`."""
        numeric = [p for p in params if p.numeric]
        if not numeric:
            return ""
        shown = "; ".join(f"{p.var} in {{{', '.join(_seconds(v) for v in kept.get(p.var, p.values))}}}"
                          for p in numeric)
        why = (f"its numeric parameters are ground over the numbers written in the domain's and the problem's "
               f"assertions, those its constraints set them to, and those the tasks' events lead to one number at a "
               f"time ({shown})")
        short = self.short_of_numbers(task, params, kept)
        if short is not None:
            param, example = short
            why += f": {param.var} would need another number, e.g. {example}"
            suspects = [param]
        else:
            suspects = numeric
        reasons = [reason[0].upper() + reason[1:] for p in suspects
                   for reason in self.unreached.get(p.numbers, {}).values()]
        return ". ".join([why, *dict.fromkeys(reasons)]) + (
            ". Write the numbers it needs into the specs (as values of assertions, or as an implication's constants), "
            "or plan with `specc plan`, which takes every real value")

    def short_of_numbers(self, task: pm.Task, params: Sequence[_ActionParam],
                         kept: Mapping[str, Sequence[Any]]) -> tuple[_ActionParam, str] | None:
        """The first numeric parameter that, left free while the others take their ground values,
        meets the task's constraints: the one short of numbers, with a value it would take (one
        number if some tuple of the others fixes it, else a range). A value an event leads to is
        tried first (the battery after a move, not before it). Tries at most CHOICE_LIMIT tuples of
        the others per parameter: it only words a message."""
        reached = {a.after.name for a in task.assertions
                   if isinstance(a, pm.Event) and isinstance(a.before, pm.Var) and isinstance(a.after, pm.Var)}
        for param in sorted((p for p in params if p.numeric), key=lambda p: p.var not in reached):
            others = [p for p in params if p is not param]
            ranged: str | None = None
            for combination in itertools.islice(itertools.product(*(kept[p.var] for p in others)), CHOICE_LIMIT):
                fixed: dict[Key, Dom] = {("time", task.start): (0.0, 0.0)}
                fixed.update({("var", p.var): self.dom(p, v) for p, v in zip(others, combination, strict=True)})
                found = bounds(task.constraints, fixed, [("var", param.var)])
                dom = found[("var", param.var)] if found is not None else None
                if not isinstance(dom, tuple):
                    continue
                value = _single(dom)
                given = f" with {self.show_tuple(others, combination)}" if others else ""
                if isinstance(value, float):
                    return param, f"{param.var} = {_seconds(value)}{given}"
                ranged = ranged or f"{param.var} in [{_seconds(dom[0])}, {_seconds(dom[1])}]{given}"
            if ranged is not None:
                return param, ranged
        return None

    def add_task(self, task: pm.Task) -> None:
        variables = self.task_variables(task)
        params: list[_ActionParam] = []
        for var in variables:
            cls = self.numeric_class(task.name, var)
            if cls is not None:
                if not cls.values:
                    why = self.unreached.get(id(cls), {}).values()
                    self.leave_out(task, f"its numeric variable {var} takes no number written in the domain or the "
                                         f"problem{''.join('; ' + w for w in why)}. Write the numbers it needs into "
                                         "the specs (as values of assertions, or as an implication's constants)")
                    return
                params.append(_ActionParam(var.lstrip("?"), var, True, sorted(cls.values), self.class_types[id(cls)],
                                           id(cls)))
            else:
                s = self.param_sets.get((task.name, var))
                is_numeric = any(isinstance(c, pm.Member) and c.expr == pm.Var(var)
                                 and isinstance(c.domain, pm.Interval) for c in task.constraints)
                if is_numeric:
                    self.leave_out(task, f"its numeric variable {var} is in no attribute, so it cannot be ground. "
                                         "Name it in an assertion, or make it a local variable")
                    return
                params.append(_ActionParam(var.lstrip("?"), var, False, self.set_values(s), self.set_type(s)))
        action = DurativeAction(self.unique(task.name), OrderedDict((p.name, p.up_type) for p in params))
        bound = {p.var: action.parameter(p.name) for p in params}
        if not self.add_duration(task, action, params, bound):
            return
        for a in task.assertions:
            if isinstance(a, pm.Use):
                self.note(f"{task.name}: {_describe(a)} is dropped: resources are not exported.")
            elif not self.add_assertion(task, action, a, bound):
                self.note(f"{task.name}: {_describe(a)} is dropped: only assertions at the task's start and end, "
                          "with plain values, are exported.")
        if task.timepoints:
            self.note(f"{task.name}: its inner timepoints {', '.join(task.timepoints)} are not exported.")
        if self.horizon_fluent is not None:
            action.add_condition(ClosedTimeInterval(StartTiming(), EndTiming()), self.horizon_fluent)
        self.up.add_action(action)

    def add_duration(self, task: pm.Task, action: Any, params: list[_ActionParam], bound: Mapping[str, Any]) -> bool:
        """Sets the action's duration and the conditions on its parameters; False if it can never run."""
        by_var = {p.var: p for p in params}
        times = {("time", task.start), ("time", task.end)}
        unary: dict[str, list[pm.Constraint]] = {}
        coupled: list[pm.Constraint] = []
        for c in task.constraints:
            keys = _keys(c)
            param_keys = [k for k in keys if k[0] == "var" and k[1] in by_var]
            if isinstance(c, pm.Relation) and c.op in ("=", "!=") and isinstance(c.left, pm.Var) \
                    and isinstance(c.right, pm.Var) and len(param_keys) == 2 \
                    and not by_var[c.left.name].numeric and not by_var[c.right.name].numeric:
                # A (dis)equality of two symbolic parameters is a plain condition, not a table.
                same = Equals(bound[describe(c.left)], bound[describe(c.right)])
                action.add_condition(StartTiming(), same if c.op == "=" else Not(same))
            elif len(keys) == 1 and param_keys:
                unary.setdefault(param_keys[0][1], []).append(c)
            else:
                coupled.append(c)
        kept: dict[str, list[Any]] = {}
        for p in params:
            constraints = unary.get(p.var, [])
            kept[p.var] = [v for v in p.values
                           if not constraints or bounds(constraints, {("var", p.var): self.dom(p, v)}, []) is not None]
            if not kept[p.var]:
                advice = self.grounding(task, [p], {}) if p.numeric else ""
                self.leave_out(task, f"no value of {p.var} meets its constraints" + (f": {advice}" if advice else ""))
                return False
        coupled_params = [p for p in params if any(("var", p.var) in _keys(c) for c in coupled)]
        tuples = list(itertools.product(*(kept[p.var] for p in coupled_params)))
        if len(tuples) > TABLE_LIMIT:
            self.leave_out(task, f"its {len(tuples)} ground parameter tuples are too many to tabulate (at most "
                                 f"{TABLE_LIMIT}). Narrow its parameters' domains")
            return False
        contingent = any(c.contingent and (_keys(c) & times) for c in task.constraints
                         if isinstance(c, (pm.Relation, pm.Member)))
        durations: dict[tuple[Any, ...], Span] = {}
        for combination in tuples:
            fixed: dict[Key, Dom] = {("time", task.start): (0.0, 0.0)}
            fixed.update({("var", p.var): self.dom(p, v) for p, v in zip(coupled_params, combination, strict=True)})
            found = bounds(coupled, fixed, [("time", task.end)])
            if found is None:
                continue
            end = found[("time", task.end)]
            span = _meet(end if isinstance(end, tuple) else FULL, (0.0, math.inf))
            assert isinstance(span, tuple)
            durations[combination] = span
        if not durations:
            advice = self.grounding(task, coupled_params, kept)
            self.leave_out(task, "no ground parameters meet its constraints" + (f": {advice}" if advice else ""))
            return False
        numeric = [p for p in params if p.numeric]
        if numeric:
            ground = "; ".join(f"{p.var} in {{{', '.join(_seconds(v) for v in kept[p.var])}}}" for p in numeric)
            self.note(f"{task.name}: the real-valued {', '.join(p.var for p in numeric)} are ground over the numbers "
                      f"that appear in the domain and the problem, and those the tasks' events lead to from them, "
                      f"that meet its constraints ({ground}), which makes a "
                      "PDDL encoding possible; any other value the planner could choose is lost.")
        unbounded = [k for k, s in durations.items() if math.isinf(s[1])]
        if unbounded:
            latest = self.dates.get(self.problem.end, FULL)[1]
            if contingent or math.isinf(latest):
                # Nature could make these instances last forever: no schedule survives them.
                for k in unbounded:
                    del durations[k]
                if not durations:
                    remedy = "" if contingent else ", or give the problem a latest end"
                    self.leave_out(task, "its duration has no upper bound (nature could make it last forever, or "
                                         f"nothing bounds it). Bound it in the task{remedy}")
                    return False
                self.note(f"{task.name}: its {len(unbounded)} ground parameter tuples whose duration has no upper "
                          f"bound (e.g. {self.show_tuple(coupled_params, unbounded[0])}) are left out.")
            else:
                self.note(f"{task.name}: its unbounded duration is capped by the horizon, {_seconds(latest)} s.")
                durations = {k: (s[0], min(s[1], latest)) for k, s in durations.items()}
        low = min(s[0] for s in durations.values())
        high = max(s[1] for s in durations.values())
        if contingent:
            exported = {k: _ceil(s[1]) for k, s in durations.items()}
            if len(set(durations.values())) == 1:
                what, how = f"the contingent duration [{_seconds(low)}, {_seconds(high)}]", ""
            else:
                what = (f"the contingent duration, which depends on the parameters ({_seconds(low)} to "
                        f"{_seconds(high)} s over the ground tuples),")
                how = f", for each ground tuple through the static function {task.name}_duration,"
            self.note(f"{task.name}: {what} is exported{how} as its upper bound rounded up to a whole second "
                      "(PDDL 2.1 durations are controllable, and Aries takes integer durations only): the plan is "
                      "built for the slowest execution.")
        else:
            exported_intervals = {k: (_ceil(s[0]), max(_ceil(s[0]), _floor(s[1]))) for k, s in durations.items()}
            if any(not _close(e[0], s[0]) or not _close(e[1], s[1])
                   for e, s in zip(exported_intervals.values(), durations.values(), strict=True)):
                self.note(f"{task.name}: its duration bounds are rounded inwards to whole seconds (Aries takes "
                          "integer durations only).")
        table_needed = len(durations) < len(tuples)
        signature = OrderedDict((p.name, p.up_type) for p in coupled_params)
        if table_needed:
            allowed = Fluent(self.unique(f"{task.name}_allowed"), BoolType(), signature)
            self.up.add_fluent(allowed, default_initial_value=False)
            action.add_condition(StartTiming(), allowed(*(bound[p.var] for p in coupled_params)))
            for combination in durations:
                self.up.set_initial_value(allowed(*self.ground(coupled_params, combination)), True)
        for p in params:
            if len(kept[p.var]) < len(p.values) and not (table_needed and p in coupled_params):
                action.add_condition(StartTiming(), Or(*(Equals(bound[p.var], self.value_object(p, v))
                                                         for v in kept[p.var])))
        if contingent:
            if len(set(exported.values())) == 1:
                action.set_fixed_duration(Int(next(iter(exported.values()))))
            else:
                action.set_fixed_duration(self.table(f"{task.name}_duration", signature, coupled_params, exported,
                                                     bound))
        else:
            lows = {k: e[0] for k, e in exported_intervals.items()}
            highs = {k: e[1] for k, e in exported_intervals.items()}
            lower = Int(next(iter(lows.values()))) if len(set(lows.values())) == 1 else \
                self.table(f"{task.name}_min_duration", signature, coupled_params, lows, bound)
            upper = Int(next(iter(highs.values()))) if len(set(highs.values())) == 1 else \
                self.table(f"{task.name}_max_duration", signature, coupled_params, highs, bound)
            action.set_closed_duration_interval(lower, upper)
        return True

    def table(self, name: str, signature: OrderedDict[str, Any], params: list[_ActionParam],
              values: dict[tuple[Any, ...], int], bound: Mapping[str, Any]) -> Any:
        """A static integer function of the parameters, read by the action's duration."""
        function = Fluent(self.unique(name), IntType(0, max(values.values())), signature)
        self.up.add_fluent(function, default_initial_value=0)
        for combination, value in values.items():
            self.up.set_initial_value(function(*self.ground(params, combination)), Int(value))
        return function(*(bound[p.var] for p in params))

    def show_tuple(self, params: list[_ActionParam], combination: Sequence[Any]) -> str:
        shown = (f"{p.var} = {_seconds(v) if p.numeric else v}" for p, v in zip(params, combination, strict=True))
        return ", ".join(shown)

    def dom(self, p: _ActionParam, value: Any) -> Dom:
        return (value, value) if p.numeric else frozenset((value,))

    def value_object(self, p: _ActionParam, value: Any) -> Any:
        if p.numeric:
            return self.number_objects[(p.numbers, value)]
        return self.objects[value]

    def ground(self, params: list[_ActionParam], combination: Sequence[Any]) -> list[Any]:
        return [self.value_object(p, v) for p, v in zip(params, combination, strict=True)]

    def add_assertion(self, task: pm.Task, action: Any, a: pm.Event | pm.Hold, bound: Mapping[str, Any]) -> bool:
        timing = {task.start: StartTiming(), task.end: EndTiming()}
        passage = self.passage_parts.get(id(a))
        try:
            if passage is not None:
                # Through an in-progress value, left out: the attribute has no value while the task runs.
                if isinstance(a, pm.Event) and passage == "leave":
                    action.add_condition(StartTiming(), self.atom(a.attribute, a.args, a.before, bound))
                    self.effect(action, StartTiming(), a.attribute, a.args, a.before, bound, False)
                elif isinstance(a, pm.Event):
                    self.effect(action, EndTiming(), a.attribute, a.args, a.after, bound, True)
                return True
            if isinstance(a, pm.Event):
                if a.time not in timing:
                    return False
                at = timing[a.time]
                action.add_condition(at, self.atom(a.attribute, a.args, a.before, bound))
                if a.before != a.after:
                    self.effect(action, at, a.attribute, a.args, a.before, bound, False)
                    self.effect(action, at, a.attribute, a.args, a.after, bound, True)
                return True
            if a.start not in timing or a.end not in timing:
                return False
            condition = self.atom(a.attribute, a.args, a.value, bound)
            if a.start == a.end:
                action.add_condition(timing[a.start], condition)
                return True
            same = [e for e in task.assertions if isinstance(e, pm.Event) and e.attribute == a.attribute
                    and e.args == a.args]
            given_at_start = any(e.time == a.start and e.after == a.value for e in same)  # by the task's own event
            checked_at_end = any(e.time == a.end and e.before == a.value for e in same)
            interval = {(False, False): ClosedTimeInterval, (True, False): LeftOpenTimeInterval,
                        (False, True): RightOpenTimeInterval, (True, True): OpenTimeInterval}
            action.add_condition(interval[(given_at_start, checked_at_end)](timing[a.start], timing[a.end]), condition)
            return True
        except KeyError:
            return False

    def effect(self, action: Any, at: Any, attribute: str, args: Sequence[pm.Expr], value: pm.Expr,
               bound: Mapping[str, Any], positive: bool) -> None:
        """The effect that starts (`positive`) or ends `attribute(args) = value`, under the problem's guards."""
        for guard in self.guards:
            if guard.on_add != positive or guard.attribute != attribute or len(guard.args) != len(args):
                continue
            if attribute not in self.valued and guard.value != value:
                continue
            pairs = list(zip(args, guard.args, strict=True))
            if attribute in self.valued:
                pairs.append((value, guard.value))
            equalities, matches = [], True
            for i, (mine, theirs) in enumerate(pairs):
                slot = (attribute, VALUE if i == len(args) else i)
                if _constant(mine):
                    matches &= mine == theirs
                else:
                    equalities.append(Equals(self.term(mine, slot, bound), self.term(theirs, slot, bound)))
            if not matches:
                continue
            touches = And(*equalities) if equalities else None
            if guard.fluent is None and touches is None:
                self.note(f"{action.name} can never run: it would end the required "
                          f"{attribute}({', '.join(describe(a) for a in guard.args)}) = {describe(guard.value)}.")
                action.add_condition(at, FALSE())
            elif guard.fluent is None:
                action.add_condition(at, Not(touches))
            elif touches is None:
                action.add_condition(at, guard.fluent)
            else:
                action.add_condition(at, Or(guard.fluent, Not(touches)))
        action.add_effect(at, self.atom(attribute, args, value, bound), positive)

    # ------------------------------------------------------------ the problem
    def add_problem(self) -> None:
        p = self.problem
        timed: dict[tuple[Fraction, Any], bool] = {}
        goals_with_windows = False
        priorities: set[float] = set()
        for a in p.assertions:
            if isinstance(a, pm.Use):
                self.note(f"the problem's {_describe(a)} is dropped: resources are not exported.")
                continue
            if a.goal is not None:
                priorities.add(a.goal.priority)
                target = a.after if isinstance(a, pm.Event) else a.value
                if any(not _constant(e) for e in (*a.args, target)):
                    self.note(f"the goal {_describe(a)} is dropped: its arguments are not constants.")
                    continue
                self.up.add_goal(self.atom(a.attribute, a.args, target, {}))
                goals_with_windows |= isinstance(a, pm.Hold)
                continue
            if isinstance(a, pm.Hold):
                continue  # required holds: see make_problem_frame
            if a.kind == "":
                self.note(f"the required {_describe(a)} is dropped: a planned event the problem imposes has no "
                          "PDDL 2.1 counterpart.")
                continue
            for binding in self.instances(a):
                args = tuple(binding.get(e.name, e) if isinstance(e, pm.Var) else e for e in a.args)
                if a.time == p.start:
                    self.up.set_initial_value(self.atom(a.attribute, args, a.after, {}), True)
                    continue
                earliest, latest = self.dates.get(a.time, FULL)
                if not (math.isfinite(earliest) and math.isfinite(latest)):
                    self.note(f"the {a.kind} {_describe(a)} is dropped: its date is unbounded.")
                    continue
                old, new = self.atom(a.attribute, args, a.before, {}), self.atom(a.attribute, args, a.after, {})
                # Unknown between the two dates: neither value may be relied on (false wins a tie).
                timed[(_date(earliest), old)] = timed.get((_date(earliest), old), True) and False
                timed[(_date(latest), new)] = timed.get((_date(latest), new), True) and True
        for (date, atom), value in sorted(timed.items(), key=lambda item: (item[0][0], str(item[0][1]))):
            self.up.add_timed_effect(GlobalStartTiming(date), atom, value)
        if any(a.kind == "contingent" and a.time != p.start for a in p.assertions if isinstance(a, pm.Event)):
            self.note("the contingent events (e.g. visibility windows opening and closing) are exported as timed "
                      "initial literals, the old value ending at the event's earliest date and the new one starting "
                      "at its latest date: a window is open from its latest opening to its earliest closing.")
        if priorities:
            shown = ", ".join(f"{v:g}" for v in sorted(priorities, reverse=True))
            self.note(f"goal priorities ({shown}) are dropped: PDDL 2.1 has no oversubscription, so every goal is "
                      "required.")
        if goals_with_windows:
            self.note("the goals' time windows are reduced to final goals (PDDL 2.1 has no timed goals), with a "
                      "deadline when the window's end is bounded, or the start of a goal held to the end (see "
                      "above): a goal must still hold at the end of the plan, and the minimal delays (e.g. a goal "
                      "holding from 2 s before the horizon) are dropped.")

    def instances(self, a: pm.Event) -> list[dict[str, pm.Expr]]:
        """Bindings of the problem variables in the arguments of a given event: those that unify it
        with a ground assertion of the problem on the same attribute (Modele1's
        PICTURE(OBJ1, ?x1, ?y1) with the goal PICTURE(OBJ1, 0.0, 0.0)), else every value."""
        variables = sorted({e.name for e in a.args if isinstance(e, pm.Var)})
        if not variables:
            return [{}]
        found: list[dict[str, pm.Expr]] = []
        for other in self.problem.assertions:
            if not isinstance(other, (pm.Event, pm.Hold)) or other.attribute != a.attribute or other is a \
                    or len(other.args) != len(a.args) or not all(_constant(e) for e in other.args):
                continue
            binding: dict[str, pm.Expr] = {}
            if all((binding.setdefault(mine.name, theirs) == theirs) if isinstance(mine, pm.Var) else mine == theirs
                   for mine, theirs in zip(a.args, other.args, strict=True)) and binding not in found:
                found.append(binding)
        shown = ", ".join(variables)
        if found:
            choices = "; ".join(", ".join(f"{k} = {describe(v)}" for k, v in b.items()) for b in found)
            self.note(f"the problem variables {shown} of {_describe(a)} are bound by unification with the goals "
                      f"({choices}); the exported initial state holds each binding.")
            return found
        values: list[list[pm.Expr]] = []
        for name in variables:
            i = next(i for i, e in enumerate(a.args) if e == pm.Var(name))
            slot = (a.attribute, i)
            if self.numeric_slot(slot):
                values.append([pm.Num(v) for v in sorted(self.slot_class(slot).values)])
            else:
                values.append([pm.Sym(s) for s in sorted(self.slot_set(slot))])
        self.note(f"the problem variables {shown} of {_describe(a)} are ground over every value: the exported "
                  "initial state holds each of them.")
        return [dict(zip(variables, combination, strict=True)) for combination in itertools.product(*values)]
