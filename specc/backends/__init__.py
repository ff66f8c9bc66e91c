"""Back ends: model (+ analyses) -> files of the generated robot package."""

from __future__ import annotations

from specc.backends import executive, ftplan, modules, package, planner, rules, supervisor, systems
from specc.backends.manifest import Output
from specc.model import nodes as m

# Every back end, in the order they write into the package.
BACKENDS = (package.generate_package, modules.generate, rules.generate, executive.generate, supervisor.generate,
            planner.generate, ftplan.generate, systems.generate)


def generate_all(program: m.Program, robot: str) -> Output:
    """The whole robot package in memory (raises KheopsError for a non-propositional rule base)."""
    output = Output()
    for generate in BACKENDS:
        generate(program, output, robot)
    return output
