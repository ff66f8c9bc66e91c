"""`specc.run.package`: a run compiles its robot first when the package on disk is stale."""

from __future__ import annotations

from pathlib import Path

import pytest

from specc.run import RunError
from specc.run.package import ensure_compiled, import_package

GENERIC = Path(__file__).resolve().parents[1] / "examples" / "generic"


def test_a_stale_package_is_rewritten_and_a_current_one_left_alone(tmp_path: Path) -> None:
    first = ensure_compiled(GENERIC, tmp_path)
    assert first.rewritten and (first.folder / "__init__.py").is_file()
    assert not ensure_compiled(GENERIC, tmp_path).rewritten
    some = next(p for p in sorted(first.folder.rglob("*.py")) if p.name != "__init__.py")
    some.write_text("# edited by hand\n", encoding="utf-8")
    again = ensure_compiled(GENERIC, tmp_path)
    assert again.rewritten and "edited by hand" not in some.read_text(encoding="utf-8")
    assert import_package(again).ROBOT == again.robot


def test_specs_with_errors_or_missing_are_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(RunError, match="no spec file or folder"):
        ensure_compiled(tmp_path / "nowhere", tmp_path)
    broken = tmp_path / "broken.spec"
    broken.write_text("module m { request R { type: exec; task: T; } }\n", encoding="utf-8")
    with pytest.raises(RunError, match=r"do not compile \(\d+ error"):
        ensure_compiled(broken, tmp_path / "out")
