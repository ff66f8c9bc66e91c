"""Parsed files are kept (specc.syntax.parser.parsed_cache): a file parsed before by the same front
end is read back instead of parsed again, and what is read back is what a parse gives."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from specc.syntax import parser

ROOT = Path(__file__).resolve().parents[1]
SPEC = (ROOT / "examples" / "tug" / "modules" / "drive.spec").read_text()
BROKEN = "module arm {\n  request Grab { type: control }\n}\n"


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    parser.parsed_cache.cache_clear()
    folder = parser.parsed_cache()
    assert folder is not None and str(folder).startswith(str(tmp_path))
    yield folder
    parser.parsed_cache.cache_clear()


def fresh(text: str, path: str) -> parser.ParseResult:
    return parser._parse_text(text, path)  # the parse the cache stands for


def test_a_file_parsed_again_is_read_back_and_equal_to_a_parse(cache: Path) -> None:
    first = parser.parse_text(SPEC, "drive.spec")
    assert len(list(cache.glob("*.pickle"))) == 1
    again = parser.parse_text(SPEC, "drive.spec")
    assert again is not first  # read back, not the same object
    assert again.source == fresh(SPEC, "drive.spec").source == first.source
    assert [str(t) for t in again.comments] == [str(t) for t in first.comments]


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
    assert len(list(tmp_path.rglob("*.pickle"))) == len(list((ROOT / "examples" / "tug").rglob("*.spec")))
