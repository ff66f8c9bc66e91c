"""A built wheel carries the grammar and templates: `specc check` works outside the source tree."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.conftest import EXAMPLES, ROOT


def test_wheel_installs_and_checks_examples_from_another_directory(tmp_path: Path) -> None:
    wheels, target = tmp_path / "wheels", tmp_path / "site"
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
                            "-w", str(wheels), str(ROOT)], capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stderr
    (wheel,) = wheels.glob("specc-*.whl")
    install = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target),
                              str(wheel)], capture_output=True, text=True, timeout=300)
    assert install.returncode == 0, install.stderr
    assert (target / "specc" / "_data" / "grammars" / "specc.lark").is_file()
    env = {**os.environ, "PYTHONPATH": str(target)}
    probe = subprocess.run([sys.executable, "-c", "import specc, specc.resources as r; "
                            "print(specc.__file__); print(r.grammar_path())"],
                           cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    where, grammar = probe.stdout.split()
    assert where.startswith(str(target)) and grammar.startswith(str(target))
    result = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(EXAMPLES / "hilare")],
                            cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
