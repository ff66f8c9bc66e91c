"""Parsed files are kept (specc.disk_cache): a file parsed before by the same front end is read back
instead of parsed again, and what is read back is what a parse gives; so are the top-level
functions of a codel module (specc.pysource), and a command on files seen before loads no lark."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from specc import disk_cache
from specc.syntax import grammar, parser
from specc.syntax.parsed import ParseResult

ROOT = Path(__file__).resolve().parents[1]
SPEC = (ROOT / "examples" / "tug" / "modules" / "drive.spec").read_text()
BROKEN = "module arm {\n  request Grab { type: control }\n}\n"


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    disk_cache.folder.cache_clear()
    folder = disk_cache.folder(parser.PARSED)
    assert folder is not None and str(folder).startswith(str(tmp_path))
    yield folder
    disk_cache.folder.cache_clear()


def fresh(text: str, path: str) -> ParseResult:
    return grammar.parse_uncached(text, path)  # the parse the cache stands for


def test_a_file_parsed_again_is_read_back_and_equal_to_a_parse(cache: Path) -> None:
    first = parser.parse_text(SPEC, "drive.spec")
    assert len(list(cache.glob("*.pickle"))) == 1
    again = parser.parse_text(SPEC, "drive.spec")
    assert again is not first  # read back, not the same object
    assert again.source == fresh(SPEC, "drive.spec").source == first.source
    assert again.comments == first.comments == fresh(SPEC, "drive.spec").comments != []


def test_the_model_parsed_or_read_back_is_frozen(cache: Path) -> None:
    """The model's classes are frozen by their base class (specc.model.nodes.Node), not by
    dataclass(frozen=True): no field is set again, none deleted, no attribute added, on a
    parse as on what the cache reads back; `dataclasses.replace` makes the changed copy."""
    for result in (parser.parse_text(SPEC, "drive.spec"), parser.parse_text(SPEC, "drive.spec")):
        assert result.source is not None
        module = result.source.items[0]
        for change in (lambda: setattr(module, "name", "other"), lambda: delattr(module, "name"),
                       lambda: setattr(module, "added", 1)):
            with pytest.raises(dataclasses.FrozenInstanceError):
                change()
        renamed = dataclasses.replace(module, name="other")
        assert (renamed.name, module.name) == ("other", "drive") and renamed != module


def test_a_changed_text_or_path_is_parsed_anew(cache: Path) -> None:
    parser.parse_text(SPEC, "drive.spec")
    changed = SPEC.replace("period: 50 ms", "period: 60 ms")
    assert changed != SPEC
    assert parser.parse_text(changed, "drive.spec").source == fresh(changed, "drive.spec").source
    moved = parser.parse_text(SPEC, "elsewhere/drive.spec")
    assert moved.source is not None and moved.source.span.file == "elsewhere/drive.spec"
    assert len(list(cache.glob("*.pickle"))) == 3


def test_a_syntax_error_is_read_back_with_its_diagnostic(cache: Path) -> None:
    first = parser.parse_text(BROKEN, "arm.spec")
    again = parser.parse_text(BROKEN, "arm.spec")
    assert first.source is None and again.source is None
    assert [(d.code, d.span, d.message) for d in again.diagnostics] == [
        (d.code, d.span, d.message) for d in first.diagnostics]


def test_a_damaged_entry_is_parsed_again(cache: Path) -> None:
    parser.parse_text(SPEC, "drive.spec")
    (entry,) = cache.glob("*.pickle")
    entry.write_bytes(b"not a pickle")
    assert parser.parse_text(SPEC, "drive.spec").source == fresh(SPEC, "drive.spec").source


def test_the_cache_can_be_turned_off(tmp_path: Path) -> None:
    environment = {**os.environ, "XDG_CACHE_HOME": str(tmp_path), "SPECC_PARSE_CACHE": "0"}
    done = subprocess.run([sys.executable, "-m", "specc.cli", "check", "examples/tug"], cwd=ROOT,
                          capture_output=True, text=True, env=environment, timeout=300)
    assert done.returncode == 0, done.stderr
    assert not list(tmp_path.rglob("*.pickle"))
    environment["SPECC_PARSE_CACHE"] = "1"
    done = subprocess.run([sys.executable, "-m", "specc.cli", "check", "examples/tug"], cwd=ROOT,
                          capture_output=True, text=True, env=environment, timeout=300)
    assert done.returncode == 0, done.stderr
    parsed = list((tmp_path / "specc" / parser.PARSED).glob("*.pickle"))
    assert len(parsed) == len(list((ROOT / "examples" / "tug").rglob("*.spec")))


CODELS = "def start(sdi):\n    return 'ok'\n\n\ndef step(sdi, x, y=1):\n    return 'done'\n"


def test_a_codel_module_read_again_is_read_back_and_an_edit_is_read_anew(cache: Path, tmp_path: Path) -> None:
    from specc.pysource import PYTHON_NAMES, _names_in, top_level_functions

    module = tmp_path / "arm_codels.py"
    module.write_text(CODELS)
    first = top_level_functions(module)
    assert not isinstance(first, SyntaxError) and set(first) == {"start", "step"}
    (entry,) = (cache.parent / PYTHON_NAMES).glob("*.pickle")
    _names_in.cache_clear()  # what a new process sees: only the disk
    again = top_level_functions(module)
    assert again == first and again is not first
    module.write_text(CODELS.replace("def step(sdi, x, y=1)", "def step(sdi)"))
    edited = top_level_functions(module)
    assert not isinstance(edited, SyntaxError)
    shape = edited["step"]
    assert shape is not None and (shape.least, shape.most) == (1, 1)


def test_a_codel_syntax_error_keeps_its_line_through_the_cache(cache: Path, tmp_path: Path) -> None:
    from specc.pysource import _names_in, top_level_functions

    module = tmp_path / "broken_codels.py"
    module.write_text("def start(sdi):\n    return 'ok'\n\ndef step(sdi:\n")
    first = top_level_functions(module)
    _names_in.cache_clear()
    again = top_level_functions(module)
    assert isinstance(first, SyntaxError) and isinstance(again, SyntaxError)
    assert again.lineno == first.lineno == 4 and again.msg == first.msg


def test_a_check_of_specs_seen_before_does_not_load_lark(tmp_path: Path) -> None:
    """Parsing is lark's, but a file read back from the cache needs none of it (a cold command on
    a robot seen before saves lark's import)."""
    environment = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    probe = ("import sys; from pathlib import Path; from specc.pipeline import load; "
             "loaded = load([Path('examples/tug')]); assert not loaded.errors; "
             "print('lark' in sys.modules)")
    runs = [subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True,
                           env=environment, timeout=300) for _ in range(2)]
    assert [r.stdout.strip() for r in runs] == ["True", "False"], [r.stderr for r in runs]


def test_a_relative_xdg_cache_home_is_ignored(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The XDG specification: a relative path there is invalid and ignored (no `relative/` made
    in whatever folder a command runs from)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/cache")
    assert disk_cache.root() == tmp_path / "home" / ".cache" / "specc"
    assert not (tmp_path / "relative").exists()
