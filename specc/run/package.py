"""The compiled package a run imports, compiled first when it is stale.

"Stale" is decided by content, not by dates (a fresh clone gives every file the same date): the
specs are compiled in memory and the package on disk is rewritten only when some file differs.
A compilation takes about a second for a small robot and several for one with a large
executive (its controller is the longest to build), so each one leaves a stamp (in the user's
cache): the digests of the specs, of the compiler and of every file written. While all three still match, the package
is current without compiling; anything else compiles again, so an outdated package never runs.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib
import json
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from specc import disk_cache
from specc.diagnostics import render
from specc.run import RunError


@dataclass(frozen=True)
class Compiled:
    robot: str  # the package's name
    folder: Path  # OUTPUT/<robot>
    rewritten: bool  # the package on disk was stale (or missing) and has been written
    # What `specc check` warns of in these specs, a headline each: kept with the stamp, so that
    # every run says them, not only the one that compiled (a run may succeed for a reason a
    # warning gives, such as a codel reading a poster that does not exist).
    warnings: tuple[str, ...] = ()


def ensure_compiled(specs: Path, output: Path) -> Compiled:
    """Compile the specs of `specs` (a folder or a file) into OUTPUT/<robot> unless the package
    there already is what they compile to. A spec with errors is a RunError listing them."""
    from specc.analysis.kheops import KheopsError
    from specc.backends import generate_all, package
    from specc.pipeline import load

    if not specs.exists():
        raise RunError(f"no spec file or folder '{specs}': name a robot's spec folder, e.g. examples/tug")
    stamp = _Stamp(specs, output)
    stamped = stamp.still_current()
    if stamped is not None:
        return stamped
    loaded = load([specs])
    if loaded.errors or loaded.program is None:
        shown = "\n".join(render(d, loaded.sources) for d in loaded.errors[:20])
        raise RunError(f"the specs of '{specs}' do not compile ({len(loaded.errors)} error(s)):\n{shown}")
    try:
        robot = package.package_name(loaded.program, specs)
    except ValueError as exc:
        raise RunError(str(exc)) from None
    try:
        result = generate_all(loaded.program, robot)
    except KheopsError as exc:
        raise RunError(exc.headline()) from None
    folder = output / robot
    up_to_date = all(_reads(folder / relative) == text for relative, text in result.files.items())
    if not up_to_date:
        try:
            result.write(folder)
        except OSError as exc:
            raise RunError(f"cannot write the package into '{folder}': {exc.strerror}") from None
    warnings = tuple(d.headline() for d in [*loaded.diagnostics, *result.warnings] if d.severity == "warning")
    stamp.write(robot, folder, result.files, warnings)
    return Compiled(robot, folder, not up_to_date, warnings)


def remember_compilation(specs: Path, output: Path, robot: str, files: Mapping[str, str],
                         warnings: Sequence[str] = ()) -> None:
    """Stamp a compilation `specc compile` made (with the headlines of its warnings), so that the
    next run need not compile again."""
    _Stamp(specs, output).write(robot, output / robot, files, warnings)


class _Stamp:
    """What a compilation of `specs` into `output` was made from, and what it wrote."""

    def __init__(self, specs: Path, output: Path) -> None:
        from specc.syntax.parser import spec_files

        files, problems = spec_files([specs])
        where = _digest([str(specs.resolve()), str(output.resolve())])[:24]
        self.output = output
        cache = stamps_folder()
        self.path = cache / f"{where}.json" if cache is not None else None
        # Problems finding the specs: no digest, so `load` reports them as it does for `check`.
        self.inputs = None if problems or self.path is None else _digest([compiler_digest()] + [
            f"{file.name}:{_file_digest(file)}" for file in files])

    def still_current(self) -> Compiled | None:
        if self.inputs is None or self.path is None:
            return None
        try:
            data = json.loads(self.path.read_text(encoding="utf-8"))
            robot, folder, written = data["robot"], Path(data["folder"]), data["files"]
            warnings = tuple(str(w) for w in data["warnings"])
            if data["inputs"] != self.inputs or not isinstance(written, dict) \
                    or folder != (self.output / robot).resolve():  # another package of that name elsewhere
                return None
        except (OSError, ValueError, KeyError, TypeError):  # KeyError: a stamp of an older specc too
            return None
        if not all(_file_digest(folder / relative) == digest for relative, digest in written.items()):
            return None  # a file edited or deleted since
        return Compiled(robot, folder, False, warnings)

    def write(self, robot: str, folder: Path, files: Mapping[str, str], warnings: Sequence[str]) -> None:
        if self.inputs is None or self.path is None:
            return
        data = {"robot": robot, "folder": str(folder.resolve()), "inputs": self.inputs, "warnings": list(warnings),
                "files": {relative: _digest([text]) for relative, text in sorted(files.items())}}
        with contextlib.suppress(OSError):  # without a stamp the next run compiles again: slower, still right
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n", encoding="utf-8")


def stamps_folder() -> Path | None:
    """In specc's cache folder (`specc.disk_cache.root`), not the output folder: that one holds the
    package and nothing else. None without a cache folder: every run then compiles, slower but right."""
    base = disk_cache.root()
    return None if base is None else base / "stamps"


_COMPILER = Path(__file__).resolve().parents[1]  # the specc package: its sources, grammar and templates
# make the generated code


def _digest(parts: Sequence[str]) -> str:
    sha = hashlib.sha256()
    for part in parts:
        sha.update(part.encode("utf-8", "surrogateescape"))
        sha.update(b"\0")
    return sha.hexdigest()


def _file_digest(path: Path) -> str | None:
    text = _reads(path)
    return None if text is None else _digest([text])


@functools.cache
def compiler_digest() -> str:
    """Every source of the compiler (runtimes included: cheaper than telling which feed the
    generator, and a change there recompiles at worst)."""
    from specc.resources import grammar_path, templates_dir

    sources = sorted(p for p in _COMPILER.rglob("*.py") if p.is_file())
    sources += [grammar_path(), *sorted(p for p in templates_dir().rglob("*") if p.is_file())]
    return disk_cache.source_digest(sources)


ROBOT_FILES = (".spec", ".py", ".toml")  # what a robot's folder holds that its runs depend on


def robot_digest(folder: Path) -> str:
    """A digest of what runs of the robot in `folder` give depends on besides their options: its
    specs, codels and worlds (by path and content) and specc's own sources."""
    files = sorted(p for p in folder.rglob("*") if p.is_file() and p.suffix in ROBOT_FILES
                   and "__pycache__" not in p.parts)
    return _digest([compiler_digest()] + [f"{p.relative_to(folder).as_posix()}:{_file_digest(p)}" for p in files])


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


def import_robot(generated: Path, folder: Path, robot: str) -> ModuleType:
    """The compiled package `robot` imported from `generated`, whole, with the codels its
    modules, executive and procedures name imported from the robot's folder `folder`. A
    package or codel package of the same name imported from elsewhere is forgotten first."""
    generated, folder = Path(generated).resolve(), Path(folder).resolve()
    if not (generated / robot / "__init__.py").is_file():
        raise RunError(f"{generated}: no compiled {robot} package in this folder; "
                       f"run `specc compile {folder} -o {generated}` first")
    for place, package in ((folder, None), (generated, robot)):
        _put_first(place)
        if package is not None:
            forget_unless_from(package, place)
    try:
        root = importlib.import_module(robot)
        for part in ("modules", "executive", "supervisor", "planner", "ftplan", "systems"):
            if (generated / robot / part / "__init__.py").is_file():
                importlib.import_module(f"{robot}.{part}")
    except ImportError as error:
        raise RunError(f"{generated}/{robot}: the compiled package is incomplete or stale ({error}); "
                       f"run `specc compile {folder} -o {generated}` again") from None
    for codels in _codel_packages(root):
        if not ((folder / codels / "__init__.py").is_file() or (folder / f"{codels}.py").is_file()):
            elsewhere = sorted(str(p.parent.relative_to(folder)) for p in folder.glob(f"*/**/{codels}/__init__.py"))
            moved = (f"; it is in {', '.join(elsewhere)}: move {codels}/ up into the robot's folder, where `specc run` "
                     "imports it from" if elsewhere else "")
            raise RunError(f"{folder}: no {codels}/ with the codels robot '{robot}' names here (looked for "
                           f"{folder / codels}/__init__.py and {folder / codels}.py){moved}; or give the robot's "
                           "folder (the one holding its specs and codels)")
        forget_unless_from(codels, folder)
    return root


def _codel_packages(package: ModuleType) -> set[str]:
    """The top-level packages of the codels the robot's modules name (imported when they start)."""
    modules = getattr(getattr(package, "modules", None), "MODULES", {})
    named = {generated.SPEC.codel_module or "" for generated in modules.values()}
    return {name.partition(".")[0] for name in named if name}


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
