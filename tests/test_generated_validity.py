"""What `specc check` accepts compiles, imports and builds (issue #23, item 2): specs at the edge
of what the checks allow, each compiled, every generated module imported, `create_all` run."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from specc.backends import generate_all
from specc.pipeline import load

EDGES = {
    # A module without codels: nothing to call, nothing to import.
    "no_codels": """
        module bare { number: 1; internal_data { x: double; } poster Pose { update: auto; data: x; } }
    """,
    # Enum values an Enum keeps as members (only `mro` and _sunder_ ones are refused), names that
    # are soft keywords or builtins, rule symbols holding backslashes.
    "odd_names": """
        module m {
          number: 2;
          enum Mode { name, value, match, type, list }
          struct Pair { print: double; id: Mode; }
          internal_data { mode: Mode; pair: Pair; }
          request case { type: control; input: match: double; }
        }
        rules speed_policy {
          inputs load: {"C:\\\\users", "\\\\N{x}"};
          outputs speed: {"slow"};
          r: load == "C:\\\\users" ==> restrict speed == "slow";
        }
    """,
}


@pytest.mark.parametrize("name", sorted(EDGES))
def test_what_check_accepts_imports_and_builds(name: str, tmp_path: Path) -> None:
    (tmp_path / "robot.spec").write_text(textwrap.dedent(EDGES[name]), encoding="utf-8")
    loaded = load([tmp_path / "robot.spec"])
    assert loaded.program is not None and not loaded.errors, [str(d) for d in loaded.errors]
    generate_all(loaded.program, "edge").write(tmp_path / "out" / "edge")
    script = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(tmp_path / 'out')!r})
        import edge, edge.modules
        from specc.runtime import functional as rt
        made = edge.modules.create_all(rt.Registry())
        print(sorted(made))
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
