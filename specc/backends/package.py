"""Back end `package`: the robot package's skeleton (its `__init__` lists what the spec holds).

Later back ends (modules, executive, supervisor, planner, ftplan) add their files to the same
Output; this one only needs the model.
"""

from __future__ import annotations

import keyword
from dataclasses import dataclass
from pathlib import Path

from specc.backends.env import render
from specc.backends.manifest import Output, describe_sources, header
from specc.model import nodes as m
from specc.pysource import shadowed_by_the_standard_library

BACKEND = "package"


@dataclass(frozen=True)
class PackageView:
    robot: str
    program: m.Program

    @property
    def header(self) -> str:
        return header(describe_sources(self.sources))

    def names(self, kind: type) -> list[str]:
        return sorted(item.name for item in self.program.items if isinstance(item, kind))

    @property
    def blocks(self) -> list[tuple[str, tuple[str, ...]]]:
        """(CONSTANT, the block names) for each block kind."""
        kinds = (("MODULES", m.Module), ("EXECUTIVES", m.Executive), ("RULE_BASES", m.RuleBase),
                 ("PROCEDURES", m.Procedures), ("DOMAINS", m.Domain), ("PROBLEMS", m.Problem),
                 ("FTPLANS", m.FtPlan), ("SYSTEMS", m.System))
        return [(constant, tuple(self.names(kind))) for constant, kind in kinds]

    @property
    def sources(self) -> list[str]:
        return sorted(f.path for f in self.program.files)


def robot_name(program: m.Program, fallback: str) -> str:
    """The system's name when the spec has exactly one system block, else `fallback`."""
    systems = [item for item in program.items if isinstance(item, m.System)]
    return systems[0].name if len(systems) == 1 else fallback


def package_name(program: m.Program, specs: Path, robot: str | None = None) -> str:
    """The package `specs` (a spec folder or file) compiles to: `robot` when given, else the
    system block's name, else the folder's (the file's stem). ValueError when Python cannot
    import it under that name."""
    fallback = specs.resolve().name if specs.is_dir() else specs.stem
    name = robot or robot_name(program, fallback)
    if not name.isidentifier() or keyword.iskeyword(name):  # `import class` cannot be written
        raise ValueError(f"'{name}' is not a valid Python package name; pass --robot NAME or rename the system "
                         "block")
    if shadowed_by_the_standard_library(name) or name == "specc":  # `import sys` would never reach it
        owner = "specc" if name == "specc" else "the standard library's"
        raise ValueError(f"'{name}' names a module Python imports first ({owner}): the package would never be "
                         "imported; pass --robot NAME or rename the system block")
    return name


def generate_package(program: m.Program, output: Output, robot: str) -> None:
    view = PackageView(robot, program)
    output.add(BACKEND, "__init__.py", render("package/__init__.py.j2", view=view))
