"""Back end `package`: the robot package's skeleton (its `__init__` lists what the spec holds).

Later back ends (modules, executive, supervisor, planner, ftplan) add their files to the same
Output; this one only needs the model.
"""

from __future__ import annotations

from dataclasses import dataclass

from specc.backends.env import render
from specc.backends.manifest import HEADER, Output, describe_sources
from specc.model import nodes as m

BACKEND = "package"


@dataclass(frozen=True)
class PackageView:
    robot: str
    program: m.Program

    @property
    def header(self) -> str:
        return HEADER.format(sources=describe_sources(self.sources))

    def names(self, kind: type) -> list[str]:
        return sorted(item.name for item in self.program.items if isinstance(item, kind))

    @property
    def blocks(self) -> list[tuple[str, str]]:
        """(CONSTANT, Python tuple literal of block names) for each block kind."""
        kinds = (("MODULES", m.Module), ("EXECUTIVES", m.Executive), ("RULE_BASES", m.RuleBase),
                 ("PROCEDURES", m.Procedures), ("DOMAINS", m.Domain), ("PROBLEMS", m.Problem),
                 ("FTPLANS", m.FtPlan), ("SYSTEMS", m.System))
        return [(constant, python_tuple(self.names(kind))) for constant, kind in kinds]

    @property
    def sources(self) -> list[str]:
        return sorted(f.path for f in self.program.files)


def python_tuple(names: list[str]) -> str:
    return repr(tuple(names))


def robot_name(program: m.Program, fallback: str) -> str:
    """The system's name when the spec has exactly one system block, else `fallback`."""
    systems = [item for item in program.items if isinstance(item, m.System)]
    return systems[0].name if len(systems) == 1 else fallback


def generate_package(program: m.Program, output: Output, robot: str) -> None:
    view = PackageView(robot, program)
    output.add(BACKEND, "__init__.py", render("package/__init__.py.j2", view=view))
