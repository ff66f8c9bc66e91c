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


def test_a_stamped_package_is_current_without_compiling_until_a_spec_changes(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil

    import specc.pipeline

    specs = tmp_path / "generic"
    shutil.copytree(GENERIC, specs, ignore=shutil.ignore_patterns("__pycache__"))
    assert ensure_compiled(specs, tmp_path / "out").rewritten

    def no_compiling(paths: list[Path], **_: object) -> None:
        raise AssertionError("compiled although the stamp says the package is current")

    with monkeypatch.context() as patch:
        patch.setattr(specc.pipeline, "load", no_compiling)
        assert not ensure_compiled(specs, tmp_path / "out").rewritten
        # A changed spec is another input: the stamp no longer holds, so it compiles.
        spec = next(specs.rglob("*.spec"))
        spec.write_text(spec.read_text() + "\n// a comment changes nothing generated\n")
        with pytest.raises(AssertionError, match="compiled although"):
            ensure_compiled(specs, tmp_path / "out")
    again = ensure_compiled(specs, tmp_path / "out")
    assert not again.rewritten  # compiled, and found the same files on disk
    # A generated file deleted behind the stamp's back is rewritten.
    next(p for p in sorted(again.folder.rglob("*.py")) if p.name != "__init__.py").unlink()
    assert ensure_compiled(specs, tmp_path / "out").rewritten


def test_a_stamp_judges_the_package_folder_it_was_made_for(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same relative output from two working directories names two packages: editing one is
    seen even when the other was stamped last."""
    for place in ("c1", "c2"):
        (tmp_path / place).mkdir()
        monkeypatch.chdir(tmp_path / place)
        ensure_compiled(GENERIC, Path("g"))
    edited = next(p for p in sorted((tmp_path / "c1" / "g").rglob("*.py")) if p.name != "__init__.py")
    edited.write_text("# edited by hand\n", encoding="utf-8")
    assert ensure_compiled(GENERIC, Path("../c1/g")).rewritten
    assert "edited by hand" not in edited.read_text(encoding="utf-8")
