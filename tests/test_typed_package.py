"""specc is typed for its users (PEP 561): a program using the runtime's types gets them checked by
mypy, as docs/reference.md says, instead of mypy skipping the package as untyped."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def test_a_user_program_s_type_error_against_specc_s_types_is_found_by_mypy(tmp_path: Path) -> None:
    program = tmp_path / "user.py"
    program.write_text("from specc.runtime.functional import Status\n\nwrong: int = Status.END\n")
    done = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache"), str(program)],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert "import-untyped" not in done.stdout, done.stdout
    assert 'user.py:3: error: Incompatible types in assignment (expression has type "Status", variable has ' \
           'type "int")' in done.stdout, done.stdout


def test_the_compiled_decisions_type_check(tmp_path: Path) -> None:
    """The rule bases and resource controllers `specc compile` writes pass mypy as they are: a
    user's program importing them is not told about their own types (empty lists and dicts of a
    base with no numeric input or `init` used to need annotations, a list stood for a tuple)."""
    root = Path(__file__).resolve().parent.parent / "generated"
    modules = sorted([*root.glob("*/rules/*.py"), *root.glob("*/executive/*_controller.py")])
    modules = [m for m in modules if m.name != "__init__.py"]
    assert len(modules) >= 6
    done = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache"),
                           "--follow-imports", "silent", *map(str, modules)], cwd=root, capture_output=True, text=True,
                          timeout=600, env={**os.environ, "PYTHONPATH": str(root)})
    assert done.returncode == 0, done.stdout + done.stderr
