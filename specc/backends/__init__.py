"""Back ends: model (+ analyses) -> files of the generated robot package."""

from __future__ import annotations

import dataclasses
import posixpath
from pathlib import Path

from specc.backends import executive, ftplan, modules, package, planner, rules, supervisor, systems
from specc.backends.manifest import Output
from specc.model import nodes as m
from specc.model.renamed import with_files_renamed

# Every back end, in the order they write into the package.
BACKENDS = (package.generate_package, modules.generate, rules.generate, executive.generate, supervisor.generate,
            planner.generate, ftplan.generate, systems.generate)


def generate_all(program: m.Program, robot: str) -> Output:
    """The whole robot package in memory (raises KheopsError for a non-propositional rule base).
    The package names the spec files from the robot's folder (`tug/planning.spec`), whatever
    folder the specs were loaded from: the same specs give the same package, byte for byte; the
    warnings name them as the program does."""
    names = packaged_names(program)
    packaged = with_files_renamed(program, names)
    output = Output()
    for generate in BACKENDS:
        generate(packaged, output, robot)
    shown = {name: file for file, name in names.items()}
    output.warnings = [dataclasses.replace(d, span=dataclasses.replace(d.span, file=shown.get(d.span.file,
                                                                                                   d.span.file)))
                       for d in output.warnings]
    return output


def packaged_names(program: m.Program) -> dict[str, str]:
    """Each spec file as the package names it: its robot folder's name, then its path in it."""
    root = systems.robot_folder(program)
    folder = Path(root).resolve().name or "robot"
    return {f.path: posixpath.join(folder, posixpath.relpath(f.path, root)) for f in program.files}
