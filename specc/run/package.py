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
from collections.abc import Sequence
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
    parent = compiled.folder.parent.resolve()
    _put_first(parent)
    if compiled.rewritten:  # a package imported before its rewrite would be the old one
        _forget(compiled.robot)
    else:
        forget_unless_from(compiled.robot, parent)
    target = f"{compiled.robot}.{name}" if name else compiled.robot
    try:
        return importlib.import_module(target)
    except ImportError as exc:
        raise RunError(f"cannot import {target} from {parent} ({exc})") from None


def import_generated(generated: Path, example: Path, robot: str, codels: str,
                     names: Sequence[str]) -> tuple[ModuleType, ...]:
    """`<robot>.<name>` for each of `names`, the compiled package imported from `generated` and
    its codels (the package `codels`) from the example folder `example`. A package of the same
    name imported from elsewhere is forgotten first, so the one asked for is the one run."""
    generated, example = Path(generated).resolve(), Path(example).resolve()
    if not (generated / robot / "__init__.py").is_file():
        raise RunError(f"{generated}: no compiled {robot} package in this folder; "
                       f"run `specc compile examples/{robot} -o {generated}` first")
    if not (example / codels / "__init__.py").is_file():
        raise RunError(f"{example}: not the {robot} example folder (no {codels}/ with the codels in it)")
    for folder, package in ((example, codels), (generated, robot)):
        _put_first(folder)
        forget_unless_from(package, folder)
    try:
        return tuple(importlib.import_module(f"{robot}.{name}") for name in names)
    except ImportError as error:
        raise RunError(f"{generated}/{robot}: the compiled package is incomplete or stale ({error}); "
                       f"run `specc compile examples/{robot} -o {generated}` again") from None


def _put_first(folder: Path) -> None:
    while str(folder) in sys.path:
        sys.path.remove(str(folder))
    sys.path.insert(0, str(folder))


def forget_unless_from(package: str, folder: Path) -> None:
    """Forget `package` (and its submodules) when it was imported from outside `folder`."""
    loaded = sys.modules.get(package)
    origin = getattr(loaded, "__file__", None)
    if loaded is None or (origin is not None and Path(origin).resolve().is_relative_to(folder)):
        return
    _forget(package)


def _forget(package: str) -> None:
    for name in [n for n in sys.modules if n == package or n.startswith(package + ".")]:
        del sys.modules[name]
