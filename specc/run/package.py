"""The compiled package a run imports, compiled first when it is stale.

"Stale" is decided by content, not by dates (a fresh clone gives every file the same date): the
specs are compiled in memory and the package on disk is rewritten only when some file differs.
That costs a compilation per run (about a second for the rover, a few for Hilare, whose
controller is the longest to build) and can never run an outdated package.
"""

from __future__ import annotations

import importlib
import keyword
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from specc.diagnostics import render
from specc.run import RunError


@dataclass(frozen=True)
class Compiled:
    robot: str  # the package's name
    folder: Path  # OUTPUT/<robot>
    rewritten: bool  # the package on disk was stale (or missing) and has been written


def ensure_compiled(specs: Path, output: Path) -> Compiled:
    """Compile the specs of `specs` (a folder or a file) into OUTPUT/<robot> unless the package
    there already is what they compile to. A spec with errors is a RunError listing them."""
    from specc.analysis.kheops import KheopsError
    from specc.backends import generate_all, package
    from specc.pipeline import load

    if not specs.exists():
        raise RunError(f"no spec file or folder '{specs}': name a robot's spec folder, e.g. examples/atrv")
    loaded = load([specs])
    if loaded.errors or loaded.program is None:
        shown = "\n".join(render(d, loaded.sources) for d in loaded.errors[:20])
        raise RunError(f"the specs of '{specs}' do not compile ({len(loaded.errors)} error(s)):\n{shown}")
    fallback = specs.resolve().name if specs.is_dir() else specs.stem
    robot = package.robot_name(loaded.program, fallback)
    if not robot.isidentifier() or keyword.iskeyword(robot):
        raise RunError(f"'{robot}' is not a valid Python package name: rename the system block")
    try:
        result = generate_all(loaded.program, robot)
    except KheopsError as exc:
        raise RunError(f"{exc.node.span}: error: {exc} [not-propositional]") from None
    folder = output / robot
    current = all(_reads(folder / relative) == text for relative, text in result.files.items())
    if current:
        return Compiled(robot, folder, False)
    try:
        result.write(folder)
    except OSError as exc:
        raise RunError(f"cannot write the package into '{folder}': {exc.strerror}") from None
    return Compiled(robot, folder, True)


def _reads(path: Path) -> str | None:
    try:
        return path.read_text(encoding="utf-8")
    except OSError:
        return None


def import_package(compiled: Compiled, name: str = "") -> ModuleType:
    """`<robot>` (or `<robot>.<name>`) from the compiled package's folder."""
    parent = str(compiled.folder.parent.resolve())
    if parent not in sys.path:
        sys.path.insert(0, parent)
    if compiled.rewritten:  # a package imported before its rewrite would be the old one
        for loaded in [m for m in sys.modules if m == compiled.robot or m.startswith(compiled.robot + ".")]:
            del sys.modules[loaded]
    target = f"{compiled.robot}.{name}" if name else compiled.robot
    try:
        return importlib.import_module(target)
    except ImportError as exc:
        raise RunError(f"cannot import {target} from {parent} ({exc})") from None
