"""Which values of a domain's attributes a problem can ever reach: a relaxed reachability.

From what the problem's explained and contingent events set, each task whose needs (its holds,
and the values its events change from) some value reached so far meets gives what its events
set, and so on until nothing new comes. Time, resources, the order of the tasks and what a task
changes away from are ignored, so the relaxation reaches at least everything a plan could: a
goal value it never reaches is impossible, whatever the search budget (a key on a roof no move
goes to). The planner says so at once instead of searching its whole budget and suggesting a
larger one.

Only what can be enumerated is judged: an attribute whose values are numbers, or that a task
may set to a value its finite parameter domains do not give, is `open` (anything may be reached
there), and so is every attribute when the tasks' parameter combinations exceed
MOST_ASSIGNMENTS."""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

from specc.runtime.planner import model as pm
from specc.runtime.planner.search import task_constraints

# Parameter combinations of all the domain's tasks together past which nothing is judged: a
# domain with numeric parameters (coordinates) has none to enumerate anyway, and one with many
# symbolic ones would cost more than its search.
MOST_ASSIGNMENTS = 20_000
ANY = None  # a pattern's free place: any value matches
Value = str | float
Pattern = tuple[Value | None, ...]  # an attribute's arguments then its value; ANY where free


@dataclass
class Reach:
    """The values reached, by attribute: each a tuple of its arguments then its value."""

    facts: dict[str, set[tuple[Value, ...]]] = field(default_factory=dict)
    open: set[str] = field(default_factory=set)  # attributes not judged: anything may be reached there

    def holds(self, attribute: str, pattern: Pattern) -> bool:
        """May a value matching `pattern` (ANY matching anything) be reached?"""
        if attribute in self.open:
            return True
        return any(all(p is ANY or _same(p, v) for p, v in zip(pattern, fact, strict=True))
                   for fact in self.facts.get(attribute, ()))

    def add(self, attribute: str, pattern: Pattern, choices: Mapping[int, frozenset[str]]) -> bool:
        """Reach the values `pattern` gives (a free place takes each of `choices`, or the
        attribute is open); True when something is new."""
        if attribute in self.open:
            return False
        if any(p is ANY and i not in choices for i, p in enumerate(pattern)):
            self.open.add(attribute)
            return True
        places = [sorted(choices[i]) if p is ANY else [p] for i, p in enumerate(pattern)]
        known = self.facts.setdefault(attribute, set())
        before = len(known)
        known.update(itertools.product(*places))
        return len(known) > before


def _same(a: Value, b: Value) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    return abs(float(a) - float(b)) <= 1e-9


def reach(domain: pm.PlanningDomain, problem: pm.Problem) -> Reach | None:
    """The relaxed reachability of `problem` in `domain`; None when it is not judged at all
    (more parameter combinations than MOST_ASSIGNMENTS)."""
    attributes = {a.name: a for a in domain.attributes}
    found = Reach()
    for name, declared in attributes.items():
        if not isinstance(declared.values, pm.Symbols):
            found.open.add(name)  # numbers: not enumerated
    for a in problem.assertions:
        if isinstance(a, pm.Event) and a.kind in ("explained", "contingent") and a.attribute in attributes:
            found.add(a.attribute, tuple(valued(x) for x in (*a.args, a.after)), {})
    instances = list(itertools.islice(_instances(domain), MOST_ASSIGNMENTS + 1))
    if len(instances) > MOST_ASSIGNMENTS:
        return None
    waiting = [_Instance(task, chosen, finite, attributes) for task, chosen, finite in instances]
    while True:
        still: list[_Instance] = []
        grew = False
        for instance in waiting:
            if not instance.ready(found):
                still.append(instance)
                continue
            for subject, pattern, choices in instance.gives.values():
                grew = found.add(subject, pattern, choices) or grew
        if not grew or not still:
            return found
        waiting = still


class _Instance:
    """A task with some of its parameters chosen: what it needs and gives, worked out once (the
    reachability asks every round whether its needs are reached yet)."""

    def __init__(self, task: pm.Task, chosen: dict[str, Value], finite: dict[str, frozenset[str]],
                 attributes: Mapping[str, pm.Attribute]):
        mine = [a for a in task.assertions if isinstance(a, (pm.Hold, pm.Event)) and a.attribute in attributes]
        self.gives = {k: (a.attribute, _pattern(a, chosen, need=False), _choices(a, finite, chosen, attributes))
                      for k, a in enumerate(mine) if isinstance(a, pm.Event)}
        self.needs = [(k, a.attribute, _pattern(a, chosen, need=True)) for k, a in enumerate(mine)]
        self._met_by_itself: dict[int, bool] = {}

    def ready(self, found: Reach) -> bool:
        """Are all its needs reached, in `found` or by the task itself?"""
        return all(found.holds(attribute, need) or self.met_by_itself(k, attribute, need)
                   for k, attribute, need in self.needs)

    def met_by_itself(self, k: int, attribute: str, need: Pattern) -> bool:
        """A need another of the task's own events gives (a communication IDLE from its start,
        for the rest of it) is met by the task itself, whatever comes first."""
        met = self._met_by_itself.get(k)
        if met is None:
            own = Reach()
            for j, (subject, pattern, choices) in self.gives.items():
                if j != k and subject == attribute:
                    own.add(subject, pattern, choices)
            met = self._met_by_itself[k] = own.holds(attribute, need)
        return met


def _instances(domain: pm.PlanningDomain) -> Iterator[tuple[pm.Task, dict[str, Value], dict[str, frozenset[str]]]]:
    """Each task with each combination of its parameters that have finite symbolic domains (the
    others stay free), and the finite domains of its variables."""
    for task in domain.tasks:
        finite = {local: values for local, values in task_constraints(task).domains if isinstance(values, frozenset)}
        enumerated = [p for p in task.params if p in finite]
        for combination in itertools.product(*(sorted(finite[p]) for p in enumerated)):
            yield task, dict(zip(enumerated, combination, strict=True)), finite


def _choices(event: pm.Event, finite: Mapping[str, frozenset[str]], chosen: Mapping[str, Value],
             attributes: Mapping[str, pm.Attribute]) -> dict[int, frozenset[str]]:
    """The values each free place of what the event gives may take: its variable's finite domain
    in the task, else what the attribute declares there."""
    declared = attributes[event.attribute]
    said = [*declared.param_domains, declared.values]
    found = {}
    for i, x in enumerate((*event.args, event.after)):
        if not isinstance(x, pm.Var) or x.name in chosen:
            continue
        domain = said[i] if i < len(said) else None
        if x.name in finite:
            found[i] = finite[x.name]
        elif isinstance(domain, pm.Symbols):
            found[i] = frozenset(domain.values)
    return found


def valued(expr: pm.Expr, chosen: Mapping[str, Value] | None = None) -> Value | None:
    """What a task's (or the problem's) term stands for: a symbol's name, a number, a variable's
    value in `chosen`; ANY for a variable `chosen` does not value, or an expression."""
    if isinstance(expr, pm.Sym):
        return expr.name
    if isinstance(expr, pm.Num):
        return expr.value
    if isinstance(expr, pm.Var) and chosen is not None:
        return chosen.get(expr.name, ANY)
    return ANY


def _pattern(a: pm.Hold | pm.Event, chosen: Mapping[str, Value], need: bool) -> Pattern:
    """The assertion's arguments and the value it needs (`need`: a hold's, an event's value
    before) or gives (an event's value after), with the task's parameters as `chosen`."""
    value = a.value if isinstance(a, pm.Hold) else a.before if need else a.after
    return tuple(valued(x, chosen) for x in (*a.args, value))


def impossible_goal(found: Reach, goal: pm.Hold | pm.Event) -> str | None:
    """Why no plan can meet `goal`, or None: its value is never reached."""
    value = goal.value if isinstance(goal, pm.Hold) else goal.after
    pattern = tuple(valued(x) for x in (*goal.args, value))
    if found.holds(goal.attribute, pattern):
        return None
    shown = ", ".join(pm.describe(x) for x in goal.args)
    return (f"impossible: no task ever makes {goal.attribute}({shown}) = {pm.describe(value)}, from what the problem "
            f"starts from, even with time, resources and what tasks undo left aside (a task that could give it "
            f"needs a value nothing gives)")
