"""generated/ holds what `specc compile` writes for each example; a diff means it is stale."""

from __future__ import annotations

import difflib
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import EXAMPLE_ROBOTS, EXAMPLES, ROOT

GENERATED = ROOT / "generated"


@pytest.mark.parametrize("robot", EXAMPLE_ROBOTS)
def test_generated_package_matches_the_golden_files(robot: str, tmp_path: Path) -> None:
    result = subprocess.run([sys.executable, "-m", "specc.cli", "compile", str(EXAMPLES / robot), "-o",
                             str(tmp_path)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    fresh = {p.relative_to(tmp_path): p.read_text() for p in tmp_path.rglob("*") if p.is_file()}
    golden = {p.relative_to(GENERATED): p.read_text() for p in (GENERATED / robot).rglob("*")
              if p.is_file() and "__pycache__" not in p.parts}
    problems = [f"missing from generated/: {path}" for path in sorted(set(fresh) - set(golden))]
    problems += [f"stale in generated/: {path}" for path in sorted(set(golden) - set(fresh))]
    for path in sorted(set(fresh) & set(golden)):
        if fresh[path] != golden[path]:
            problems.append("".join(difflib.unified_diff(
                golden[path].splitlines(True), fresh[path].splitlines(True), f"generated/{path}", "compiled")))
    assert not problems, "\n".join(problems) + "\n\nThe golden files are out of date: run `make goldens`."


def test_generated_package_imports_and_lists_its_blocks() -> None:
    sys.path.insert(0, str(GENERATED))
    try:
        import hilare  # type: ignore[import-not-found]
    finally:
        sys.path.remove(str(GENERATED))
    assert hilare.ROBOT == "hilare"
    assert set(hilare.MODULES) == {"arm", "avoid", "explor", "loco", "pilo", "plan", "us", "visual"}
    assert hilare.EXECUTIVES == ("hilare",) and hilare.PROCEDURES == ("hilare_tasks",)
