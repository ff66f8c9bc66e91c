"""Waypoints: a move split in two, so that the robot goes part of the way while it would wait.

A plan often keeps the robot still where it is for a while: it has taken its photo and waits for
a visibility window to open, communicates, and only then leaves for the next place. The search
binds a move's destination only to places the goals and the problem name, so it cannot stop
half-way to wait there; a planner grounding every coordinate (Aries on `specc export`'s files)
can. The improvement (`Setup.waypoints`) tries, on a plan found, the moves that follow such an
idle time: each split at a waypoint, the first leg run during the idle time and the rest after.

Nothing here knows a robot. A *mover* is any task that takes an attribute from one of its
parameters to another (an event at its start from ?from, one at its end to ?to: Modele1's MOVE
takes AT_ROBOT_X from ?x1 to ?x2 and AT_ROBOT_Y from ?y1 to ?y2). Its waypoints are values
between the two (numbers: those the plan's movers already reach, and the whole numbers, as a
planner grounding the problem's numbers would try; symbols: the places the plan visits). A split
whose first leg cannot fit in the idle time at its slowest (the task's own duration bounds) is
not searched; the others are planned as a repair of the plan (`Setup.root`'s), which keeps every
other action and lets the search link and order the two legs again. Once the improvement has its
best plan, a waypoint the robot drives through without stopping there (a split may have led the
search to a better plan in which it serves nothing) is merged back into one move where the plan
is no worse for it (`Setup.merge_drive_throughs`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

from specc.runtime.planner import model as pm
from specc.runtime.planner.numeric import Empty, duration_of
from specc.runtime.planner.plan import Action, Plan, Repair, Value

# Whole numbers tried between the two ends of a move, per attribute, at most (evenly spaced
# beyond): a robot measured in millimetres does not try every millimetre.
STEPS = 24


@dataclass(frozen=True)
class Mover:
    """A task that takes attributes from some of its parameters to others."""

    task: pm.Task
    pairs: tuple[tuple[str, int, int], ...]  # (attribute, index of ?from, index of ?to), by attribute
    changes: frozenset[str]  # every attribute the task's events change


def movers(domain: pm.PlanningDomain) -> dict[str, Mover]:
    """The domain's movers, by task name: the tasks that take an attribute from a parameter to
    another (an event at the start from ?from and one at the end to ?to, or one event from ?from
    to ?to) and whose duration depends on those parameters (a split of a move of fixed duration,
    a pan-tilt unit's, only adds a whole duration)."""
    found = {}
    for task in domain.tasks:
        events = [a for a in task.assertions if isinstance(a, pm.Event)]
        froms = {(a.attribute, a.args): a.before.name for a in events
                 if a.time == task.start and isinstance(a.before, pm.Var) and a.before.name in task.params}
        tos = {(a.attribute, a.args): a.after.name for a in events
               if a.time == task.end and isinstance(a.after, pm.Var) and a.after.name in task.params}
        for a in events:  # `event(AT(): (?from, ?to), t_end)`: one event takes it from one to the other
            if (isinstance(a.before, pm.Var) and isinstance(a.after, pm.Var)
                    and a.before.name in task.params and a.after.name in task.params):
                froms.setdefault((a.attribute, a.args), a.before.name)
                tos.setdefault((a.attribute, a.args), a.after.name)
        pairs = tuple(sorted((key[0], task.params.index(froms[key]), task.params.index(tos[key]))
                             for key in froms.keys() & tos.keys() if froms[key] != tos[key]))
        timed = _duration_reads(task)
        if pairs and any(task.params[i] in timed or task.params[j] in timed for _, i, j in pairs):
            found[task.name] = Mover(task, pairs, frozenset(a.attribute for a in events))
    return found


def _duration_reads(task: pm.Task) -> set[str]:
    """The variables the task's duration depends on: those its constraints on timepoints read,
    and on, through the constraints that share a variable with them."""
    reads = [(pm.constraint_names(c, pm.Var), bool(pm.constraint_names(c, pm.Time))) for c in task.constraints]
    found: set[str] = set().union(*(names for names, timed in reads if timed))
    grown = True
    while grown:
        grown = False
        for names, _ in reads:
            if names & found and not names <= found:
                found |= names
                grown = True
    return found


def idle_time(plan: Plan, move: Action) -> float:
    """The longest time the plan leaves the robot idle between the end of its previous move (of
    the same task) and this one's dispatch: no other action running (at its slowest), those
    begun before the robot arrived and still running included."""
    actions = plan.ordered()
    arrived = max((plan.ends_by(a) for a in actions if a.task == move.task and a.dispatch < move.dispatch),
                  default=plan.now)
    busy = sorted((a.dispatch, plan.ends_by(a)) for a in actions
                  if a.task != move.task and a.dispatch < move.dispatch and plan.ends_by(a) > arrived)
    longest, free_from = 0.0, arrived
    for start, end in busy:
        longest = max(longest, start - free_from)
        free_from = max(free_from, end)
    return max(longest, move.dispatch - free_from)


def places(plan: Plan, mover: Mover) -> dict[str, set[Value]]:
    """Every value the plan's moves of this task take each attribute from or to."""
    found: dict[str, set[Value]] = {}
    for action in plan.actions:
        if action.task == mover.task.name:
            for attribute, i, j in mover.pairs:
                found.setdefault(attribute, set()).update((action.args[i], action.args[j]))
    return found


def candidates(move: Action, mover: Mover, reached: dict[str, set[Value]]) -> list[tuple[Value, ...]]:
    """The waypoints to try for a move, one value per attribute of `mover.pairs`, the farthest
    along first (the longest first leg the idle time may hold)."""
    axes: list[list[tuple[Value, float]]] = []
    for attribute, i, j in mover.pairs:
        start, end = move.args[i], move.args[j]
        if isinstance(start, str) or isinstance(end, str):
            axes.append([(v, 0.0) for v in sorted(reached.get(attribute, set()), key=str)])
            continue
        low, high = min(start, end), max(start, end)
        values = {v for v in reached.get(attribute, set()) if isinstance(v, float) and low <= v <= high}
        whole = range(int(-(-low // 1)), int(high // 1) + 1)
        stride = max(1, -(-len(whole) // STEPS))
        values |= {float(k) for k in whole[::stride]}
        span = abs(end - start) or 1.0
        axes.append([(v, abs(v - start) / span) for v in values])
    ends = {tuple(move.args[i] for _, i, _ in mover.pairs), tuple(move.args[j] for _, _, j in mover.pairs)}
    ranked = sorted((-sum(progress for _, progress in combination), tuple(str(v) for v, _ in combination),
                     tuple(v for v, _ in combination)) for combination in itertools.product(*axes))
    return [point for _, _, point in ranked if point not in ends]


def first_leg_fits(move: Action, mover: Mover, point: tuple[Value, ...], idle: float) -> bool:
    """May the first leg to `point` end within `idle` seconds at its slowest? (The task's own
    constraints give its duration: nothing is searched for a leg that cannot.)"""
    args = list(move.args)
    for (_, _, j), value in zip(mover.pairs, point, strict=True):
        args[j] = value
    try:
        spec = duration_of(mover.task, dict(zip(mover.task.params, args, strict=True)))
    except Empty:
        return False
    return spec.high <= idle + 1e-6


def drive_throughs(plan: Plan, movers: dict[str, Mover]) -> list[tuple[Action, Action, Mover]]:
    """The plan's pairs of moves of one task, the second leaving from where the first arrives
    (not back to where the first left), with no other action starting from the first's dispatch
    to the second's: the robot drives through the waypoint without stopping there for anything."""
    found = []
    for name, mover in movers.items():
        legs = sorted((a for a in plan.actions if a.task == name), key=lambda a: (a.dispatch, a.id))
        others = [a.dispatch for a in plan.actions if a.task != name]
        for first, second in itertools.pairwise(legs):
            back = all(first.args[i] == second.args[j] for _, i, j in mover.pairs)  # there and back: no move
            if (not back and all(first.args[j] == second.args[i] for _, i, j in mover.pairs)
                    and not any(first.dispatch <= d < second.dispatch for d in others)):
                found.append((first, second, mover))
    return found


def _replaced(plan: Plan, old: tuple[Action, ...], new: tuple[Action, ...], mover: Mover) -> Repair:
    """The plan with the moves `old` replaced by `new`, as a repair to search: every other action
    kept with its orders and links, except the links of the attributes the moves change that
    came from the action before them (the robot's position and state as that action left them):
    the actions in between may take them from another move now. The new moves follow each other."""
    gone = {a.id for a in old}
    points = {p for a in old for p in (a.start, a.end)}
    orderings = tuple(o for o in plan.orderings if o[0] not in points and o[1] not in points)
    orderings += tuple((a.end, b.start, 0.0) for a, b in itertools.pairwise(new))

    def owner(description: str) -> str:
        return description.split(":", 1)[0]

    before = {owner(k.producer) for k in plan.links if owner(k.consumer) in gone} - gone
    links = tuple(k for k in plan.links if owner(k.producer) not in gone and owner(k.consumer) not in gone
                  and not (k.attribute in mover.changes and owner(k.producer) in before))
    actions = tuple(a for a in plan.actions if a.id not in gone) + new
    return Repair(replace(plan, actions=actions, orderings=orderings, links=links), tuple(a.id for a in actions))


def merge(plan: Plan, first: Action, second: Action, mover: Mover) -> Repair:
    """The plan with two legs of a drive-through made one move again, as a repair to search."""
    args = list(first.args)
    for _, _, j in mover.pairs:
        args[j] = second.args[j]
    whole = replace(first, id=f"{first.id}m", args=tuple(args), start=f"{first.start}~m", end=f"{first.end}~m")
    return _replaced(plan, (first, second), (whole,), mover)


def split(plan: Plan, move: Action, mover: Mover, point: tuple[Value, ...]) -> Repair:
    """The plan with `move` replaced by two moves through `point`, as a repair to search."""
    first_args, second_args = list(move.args), list(move.args)
    for (_, i, j), value in zip(mover.pairs, point, strict=True):
        first_args[j] = value
        second_args[i] = value
    first = replace(move, id=f"{move.id}a", args=tuple(first_args), start=f"{move.start}~a", end=f"{move.end}~a")
    second = replace(move, id=f"{move.id}b", args=tuple(second_args), start=f"{move.start}~b", end=f"{move.end}~b")
    return _replaced(plan, (move,), (first, second), mover)
