"""The rover of examples/atrv for the tests: its program, its planning models, and the
mutations of its Modele1 that make planners faulty on purpose (seed 004 §4.1.3). Planner
processes import this module: nothing heavy is imported at its top."""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

from specc.runtime.planner import model as pm

if TYPE_CHECKING:
    from specc.model import nodes as m

ATRV = Path(__file__).resolve().parents[1] / "examples" / "atrv"


@cache
def program() -> m.Program:
    from specc.pipeline import load

    loaded = load([ATRV])
    assert loaded.program is not None
    return loaded.program


@cache
def atrv_models(name: str) -> tuple[pm.PlanningDomain, pm.Problem]:
    """The rover's problem `name` ("M1_model1") and its domain."""
    from specc.analysis.planning import domain_model, problem_model
    from specc.model import nodes as m

    problem = next(p for p in program().items if isinstance(p, m.Problem) and p.name == name)
    domain = next(d for d in program().items if isinstance(d, m.Domain) and d.name == problem.domain.text)
    return domain_model(program(), domain), problem_model(program(), problem)


def mutation_1_592(domain: pm.PlanningDomain) -> pm.PlanningDomain:
    """Modele1 with the pan-tilt unit pointing STRAIGHT while TAKE_PICTURE runs (seed §4.2.2.3, the
    mutation 1-592): plans valid by the mutated model, whose photos miss their targets."""
    task = domain.task("TAKE_PICTURE")
    assert task is not None
    assertions = tuple(replace(a, value=pm.Sym("STRAIGHT"))
                       if isinstance(a, pm.Hold) and a.attribute == "PTU_POSITION" else a
                       for a in task.assertions)
    assert assertions != task.assertions, "TAKE_PICTURE no longer holds PTU_POSITION"
    mutated = replace(task, assertions=assertions)
    return replace(domain, tasks=tuple(mutated if t.name == task.name else t for t in domain.tasks))


def optimistic_speed(domain: pm.PlanningDomain, factor: float = 10.0) -> pm.PlanningDomain:
    """Modele1 believing the rover `factor` times faster than it is (its `speed(?s)` interval
    [0.17, 0.35] m/s scaled): moves planned far too short, which execution shows."""
    move = next(t for t in domain.tasks if t.name == "MOVE")
    speed = pm.Interval(0.17, 0.35)
    constraints = tuple(replace(c, domain=pm.Interval(speed.low * factor, speed.high * factor))
                        if isinstance(c, pm.Member) and c.domain == speed else c for c in move.constraints)
    assert constraints != move.constraints, "Modele1's MOVE no longer bounds its speed by [0.17, 0.35]"
    mutated = replace(move, constraints=constraints)
    return replace(domain, tasks=tuple(mutated if t.name == "MOVE" else t for t in domain.tasks))


def mutation_1_592_modele2(domain: pm.PlanningDomain) -> pm.PlanningDomain:
    """Modele2 with the seed's mutation 1-592 in its own terms: TAKE_SHOT holds the camera at the
    moving tilt (-30) instead of the ground's (-45)."""
    task = domain.task("TAKE_SHOT")
    assert task is not None
    moving = pm.Num(-30.0)
    assertions = tuple(replace(a, value=moving) if isinstance(a, pm.Hold) and a.attribute == "PTU_TILT" else a
                       for a in task.assertions)
    assert assertions != task.assertions, "TAKE_SHOT no longer holds PTU_TILT"
    mutated = replace(task, assertions=assertions)
    return replace(domain, tasks=tuple(mutated if t.name == task.name else t for t in domain.tasks))
