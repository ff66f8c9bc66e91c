"""parse(print(model)) == model, for every example and for random models."""

from __future__ import annotations

from pathlib import Path

from hypothesis import HealthCheck, given, settings

from specc.model import nodes as m
from specc.syntax.parser import parse_text
from specc.syntax.printer import print_source
from tests.strategies import source_files

EXAMPLES = Path(__file__).parent.parent / "examples"


def reparse(source: m.SourceFile) -> m.SourceFile:
    text = print_source(source)
    result = parse_text(text, source.path)
    assert result.source is not None, (text, [d.headline() for d in result.diagnostics])
    assert not [d for d in result.diagnostics if d.severity == "error"], text
    return result.source


def test_every_example_file_round_trips() -> None:
    files = sorted(EXAMPLES.rglob("*.spec"))
    assert len(files) >= 20
    for path in files:
        result = parse_text(path.read_text(), str(path))
        assert result.source is not None, path
        assert reparse(result.source).items == result.source.items, path


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(source_files)
def test_random_models_round_trip(source: m.SourceFile) -> None:
    assert reparse(source).items == source.items
