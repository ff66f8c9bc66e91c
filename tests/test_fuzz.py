"""Mutated specs (tokens dropped, duplicated, swapped; random bytes) never crash specc:
every outcome is a model or diagnostics."""

from __future__ import annotations

import re
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.check import check_program
from specc.diagnostics import render
from specc.model import nodes as m
from specc.syntax.parser import parse_text
from tests.conftest import EXAMPLES

SPECS = sorted(EXAMPLES.rglob("*.spec"))
TOKEN = re.compile(r"\s+|[A-Za-z_][\w\-]*|\d+(?:\.\d*)?|\S")


def tokens(text: str) -> list[str]:
    return TOKEN.findall(text)


def run_front_end(text: str, path: Path) -> None:
    result = parse_text(text, str(path))
    for diagnostic in result.diagnostics:
        assert diagnostic.code and diagnostic.span.line >= 1
        render(diagnostic, {str(path): text})
    if result.source is not None:
        program = m.Program(files=(result.source,))
        for diagnostic in check_program(program, {str(path): path.parent}):
            render(diagnostic, {str(path): text})


mutation = st.sampled_from(["drop", "duplicate", "swap", "bytes"])


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SPECS), st.lists(st.tuples(mutation, st.integers(0, 10**6), st.integers(0, 10**6),
                                                  st.binary(min_size=1, max_size=8)), min_size=1, max_size=4))
def test_mutated_examples_never_raise(path: Path, edits: list[tuple[str, int, int, bytes]]) -> None:
    parts = tokens(path.read_text())
    for kind, a, b, noise in edits:
        i, j = a % len(parts), b % len(parts)
        if kind == "drop":
            del parts[i]
        elif kind == "duplicate":
            parts.insert(i, parts[i])
        elif kind == "swap":
            parts[i], parts[j] = parts[j], parts[i]
        else:
            parts.insert(i, noise.decode("utf-8", errors="replace"))
        if not parts:
            parts = [" "]
    run_front_end("".join(parts), path)


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=200))
def test_arbitrary_text_never_raises(text: str) -> None:
    run_front_end(text, EXAMPLES / "hilare" / "fuzz.spec")
