"""Mutated specs (tokens dropped, duplicated, swapped; random bytes) never crash specc:
every outcome is a model or diagnostics."""

from __future__ import annotations

import contextlib
import re
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest
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


HEADLINE = re.compile(r"^[^\n]+:\d+:\d+: (error|warning): [^\n]+ \[[a-z]+(-[a-z]+)*\]$")
# Strings put where the grammar takes one: empty, a dot, a name longer than a file system allows,
# quotes and backslashes, control characters, unicode, a Python payload.
ODD_STRINGS = ['""', '"."', '"' + "a" * 300 + '"', '"a\\"b"', '"\\N{BULLET}"', '"\\x00"', '"\x1b[31m"',
               '"é✓😀"', '"""x"""', '"__import__(\'os\').system(\'true\')"', '"a.b."', '"..a"', '"1abc"']
NESTING = ["(" * 400 + "1" + ")" * 400, "{" * 300, "[" * 300 + "]" * 300, "!(" * 200]
CASE_LIMIT = 20.0  # s: generous, so that a loaded machine never fails it; a hang is far longer


@contextlib.contextmanager
def within_limit(seconds: float) -> Iterator[None]:
    """Raise TimeoutError if the body runs longer than `seconds` (a hang)."""

    def expired(signum: int, frame: object) -> None:
        raise TimeoutError(f"one case ran over {seconds} s")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def run_front_end(text: str, path: Path) -> None:
    """Parse and check `text`: no exception, no hang, every diagnostic one well-formed headline
    whose position lies in the text."""
    with within_limit(CASE_LIMIT):
        result = parse_text(text, str(path))
        diagnostics = list(result.diagnostics)
        if result.source is not None:
            program = m.Program(files=(result.source,))
            diagnostics += check_program(program, {str(path): path.parent})
    lines = text.split("\n")
    for diagnostic in diagnostics:
        assert diagnostic.code and diagnostic.span.line >= 1
        shown = render(diagnostic, {str(path): text})
        headline = shown.split("\n")[0]
        assert HEADLINE.match(headline), headline
        if diagnostic.span.file == str(path) and diagnostic.span.line <= len(lines):
            assert diagnostic.span.column <= len(lines[diagnostic.span.line - 1]) + 1, headline


mutation = st.sampled_from(["drop", "duplicate", "swap", "bytes", "truncate", "odd-string", "nest"])
EDITS = st.lists(st.tuples(mutation, st.integers(0, 10**6), st.integers(0, 10**6), st.binary(min_size=1, max_size=8)),
                 min_size=1, max_size=4)


def mutate(path: Path, edits: list[tuple[str, int, int, bytes]]) -> str:
    parts = tokens(path.read_text())
    for kind, a, b, noise in edits:
        i, j = a % len(parts), b % len(parts)
        if kind == "drop":
            del parts[i]
        elif kind == "duplicate":
            parts.insert(i, parts[i])
        elif kind == "swap":
            parts[i], parts[j] = parts[j], parts[i]
        elif kind == "truncate":
            del parts[i:]
        elif kind == "odd-string":
            strings = [k for k, part in enumerate(parts) if part == '"']
            if strings:  # the tokenizer splits a string at its quotes: replace the opening one's content
                k = strings[i % len(strings)]
                end = next((e for e in range(k + 1, len(parts)) if parts[e] == '"'), k)
                parts[k:end + 1] = [ODD_STRINGS[j % len(ODD_STRINGS)]]
        elif kind == "nest":
            parts.insert(i, NESTING[j % len(NESTING)])
        else:
            parts.insert(i, noise.decode("utf-8", errors="replace"))
        if not parts:
            parts = [" "]
    return "".join(parts)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SPECS), EDITS)
def test_mutated_examples_never_raise(path: Path, edits: list[tuple[str, int, int, bytes]]) -> None:
    run_front_end(mutate(path, edits), path)


@pytest.mark.slow
@settings(max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SPECS), EDITS)
def test_thousands_of_mutated_examples_never_raise(path: Path, edits: list[tuple[str, int, int, bytes]]) -> None:
    run_front_end(mutate(path, edits), path)


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=200))
def test_arbitrary_text_never_raises(text: str) -> None:
    run_front_end(text, EXAMPLES / "hilare" / "fuzz.spec")
