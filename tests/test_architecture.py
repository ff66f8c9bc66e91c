"""The architecture's import rules, for whoever runs pytest alone (`make test` also runs
`lint-imports` before the suite, so that a broken layer fails in a second, not after it).

- the contracts of .importlinter: the runtime imports no compiler, the layers point one way, no
  cycle between the packages of specc nor between the modules of one package;
- no cycle between any two modules at all, which also covers what import-linter's
  `acyclic_siblings` leaves out: a package's `__init__` and its own modules (`specc.run` holds
  `RunError`, which its modules import, so `specc/run/__init__.py` must never import them back).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from itertools import pairwise
from pathlib import Path

import grimp

from tests.conftest import ROOT


def lint_imports() -> str:
    """The `lint-imports` of the interpreter running the tests (its venv), else the PATH's."""
    found = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    assert found, "lint-imports is not installed: pip install -e '.[dev]'"
    return found


def test_import_contracts_hold() -> None:
    done = subprocess.run([lint_imports(), "--no-cache", "--no-logo"], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr


def import_cycles(graph: grimp.ImportGraph) -> list[list[str]]:
    """One shortest cycle through each import that lies on one, each cycle once, as the modules
    in import order (the first module repeated at the end)."""
    cycles: dict[frozenset[str], list[str]] = {}
    for importer in sorted(graph.modules):
        for imported in sorted(graph.find_modules_directly_imported_by(importer)):
            back = graph.find_shortest_chain(importer=imported, imported=importer)
            if back is not None:
                cycles.setdefault(frozenset(back), [importer, *back])
    return list(cycles.values())


def describe(graph: grimp.ImportGraph, cycle: list[str]) -> str:
    """`a:12 -> b:40 -> a`: each module with the line of its import of the next."""
    steps = []
    for importer, imported in pairwise(cycle):
        lines = sorted(d["line_number"] for d in graph.get_import_details(importer=importer, imported=imported))
        steps.append(f"{importer}:{','.join(map(str, lines))}")
    return " -> ".join([*steps, cycle[-1]])


def test_no_import_cycle_between_modules() -> None:
    # Imports inside functions and under TYPE_CHECKING count: grimp records them, and a cycle
    # through a lazy import is still two modules that cannot be understood one without the other.
    graph = grimp.build_graph("specc", cache_dir=None)
    cycles = [describe(graph, cycle) for cycle in import_cycles(graph)]
    assert not cycles, "import cycles in specc/ (module:line of each import):\n" + "\n".join(cycles)


def test_a_cycle_is_found_with_its_lines() -> None:
    graph = grimp.ImportGraph()
    for module in ("pkg", "pkg.a", "pkg.b", "pkg.c"):
        graph.add_module(module)
    graph.add_import(importer="pkg.a", imported="pkg.b", line_number=3, line_contents="import pkg.b")
    graph.add_import(importer="pkg.b", imported="pkg", line_number=5, line_contents="from pkg import Error")
    graph.add_import(importer="pkg", imported="pkg.a", line_number=7, line_contents="from pkg.a import thing")
    graph.add_import(importer="pkg.c", imported="pkg.a", line_number=1, line_contents="import pkg.a")
    assert [describe(graph, cycle) for cycle in import_cycles(graph)] == ["pkg:7 -> pkg.a:3 -> pkg.b:5 -> pkg"]


def test_the_tool_names_no_example_robot() -> None:
    """A robot is specs and codels in its own folder: nothing in specc/ (its code, its help texts)
    names one of the examples, so the tool works for any robot the same way."""
    import re

    named = [f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
             for path in sorted((ROOT / "specc").rglob("*.py"))
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"atrv|hilare", line, re.IGNORECASE)]
    assert named == []
