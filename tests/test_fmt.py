"""`specc fmt` keeps every comment, keeps it where it was, and is idempotent."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.model import nodes as m
from specc.syntax.parser import parse_text
from specc.syntax.printer import format_source
from tests.conftest import EXAMPLES

SPECS = sorted(EXAMPLES.rglob("*.spec"))
# Strings and comments are whole pieces, so a comment is only ever inserted into whitespace.
PIECE = re.compile(r'"(?:[^"\\\n]|\\.)*"|//[^\n]*|/\*.*?\*/|\s+|[^\s"/]+|/', re.S)


def parsed(text: str) -> tuple[m.SourceFile, list[str]]:
    result = parse_text(text, "case.spec")
    assert result.source is not None, [d.headline() for d in result.diagnostics]
    return result.source, [" ".join(c.text.split()) for c in result.comments]


def fmt(text: str) -> str:
    result = parse_text(text, "case.spec")
    assert result.source is not None, [d.headline() for d in result.diagnostics]
    return format_source(result.source, text, result.comments)


def assert_formats_well(text: str) -> str:
    """Same model, every comment exactly as often as before (whitespace aside), stable."""
    source, comments = parsed(text)
    once = fmt(text)
    again_source, again_comments = parsed(once)
    assert again_source.items == source.items, once
    assert Counter(again_comments) == Counter(comments), once
    assert fmt(once) == once
    return once


comment_kind = st.sampled_from(["line", "block", "long-block"])


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(SPECS), st.lists(st.tuples(st.integers(0, 10**6), comment_kind), min_size=1, max_size=8))
def test_random_comments_in_the_examples_survive_formatting(path: Path,
                                                            inserts: list[tuple[int, str]]) -> None:
    pieces = PIECE.findall(path.read_text())
    gaps = [i for i, piece in enumerate(pieces) if piece.isspace()]
    tags = []
    for n, (where, kind) in enumerate(inserts):
        i = gaps[where % len(gaps)]
        tag = f"note{n}x"
        tags.append(tag)
        if kind == "line":
            pieces[i] += f"// {tag}\n"
        elif kind == "block":
            pieces[i] += f"/* {tag} */ "
        else:
            pieces[i] += f"/* {tag}\n      more {tag}y */ "
    once = assert_formats_well("".join(pieces))
    for tag in tags:
        assert len(re.findall(rf"\b{tag}\b", once)) == 1, (tag, once)


@pytest.mark.parametrize("path", SPECS, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_example_formats_well(path: Path) -> None:
    assert_formats_well(path.read_text())


# Odd layouts, with where each comment must end up.
PLACEMENT = [
    ("comment last in a block stays inside it",
     "module a {\n  number: 1;\n  // end of a\n}\nmodule b { number: 2; }\n",
     "module a {\n  number: 1;\n  // end of a\n}\n\nmodule b {\n  number: 2;\n}\n"),
    ("comment after a closing brace stays on its line",
     "module a { number: 1; } // after a\n",
     "module a {\n  number: 1;\n}  // after a\n"),
    ("comment after a keyword-valued property stays on its line",
     "ftplan f {\n  planners: p1;\n  policy: successive; // why\n}\n",
     "ftplan f {\n  planners: p1;\n  policy: successive;  // why\n}\n"),
    ("comment after a request type stays in the request",
     "module a { request R {\n  type: exec; // t\n  task: T; } }\n",
     "module a {\n  request R {\n    type: exec;  // t\n    task: T;\n  }\n}\n"),
    ("comment after a KA property stays on its line",
     "procedures p { ka K { invocation: !(A);\n property: x; // p\n } }\n",
     "procedures p {\n  ka K {\n    invocation: !(A);\n    property: x;  // p\n  }\n}\n"),
    ("multi-line block comment keeps its inner layout",
     "module a {\n    /* one\n         two\n       three */\n    number: 1;\n}\n",
     "module a {\n  /* one\n       two\n     three */\n  number: 1;\n}\n"),
    ("multi-line block comment after code stays in its block",
     "module a { number: 1; /* x\n y */ }\nmodule b { number: 2; }\n",
     "module a {\n  number: 1;\n  /* x\n  y */\n}\n\nmodule b {\n  number: 2;\n}\n"),
    ("comment before else stays in the then branch",
     "procedures p { ka K { body { if ?(X) { !(Y);\n // last of then\n } else { !(Z); // z\n } } } }\n",
     "procedures p {\n  ka K {\n    body {\n      if ?(X) {\n        !(Y);\n        // last of then\n"
     "      } else {\n        !(Z);  // z\n      }\n    }\n  }\n}\n"),
    ("comment at the end of an IxTeT task stays inside it",
     "domain d { task T()(ts, te) { hold(A(): 1, (ts, te));\n // end\n } latePreemptive }\n",
     "domain d {\n  task T() (ts, te) {\n    hold(A(): 1, (ts, te));\n    // end\n  } latePreemptive\n}\n"),
    ("a one-line block after a blank line is not split into paragraphs",
     "module a { number: 1; }\n\nmodule b { number: 2; codels: \"x\"; }\n",
     "module a {\n  number: 1;\n}\n\nmodule b {\n  number: 2;\n  codels: \"x\";\n}\n"),
    ("blank lines above comments are kept even when two comments read the same",
     "module a {\n  number: 1;\n  // same\n  codels: \"x\";\n\n  // same\n  doc: \"y\";\n}\n",
     "module a {\n  number: 1;\n  // same\n  codels: \"x\";\n\n  // same\n  doc: \"y\";\n}\n"),
    ("a comment above a section with no node of its own stays above it",
     "module a {\n  number: 1;\n  // the data\n  internal_data {\n    x: double;\n  }\n}\n",
     "module a {\n  number: 1;\n  // the data\n  internal_data {\n    x: double;\n  }\n}\n"),
    ("a block comment above a conflicts section stays above it",
     "executive e {\n  service S {\n    request: m.R;\n    /* who waits */\n    conflicts { T: wait; }\n  }\n}\n",
     "executive e {\n  service S {\n    request: m.R;\n    /* who waits */\n    conflicts {\n      T: wait;\n    }\n"
     "  }\n}\n"),
    ("a file of comments only",
     "// one\n\n/* two\n   three */\n",
     "// one\n\n/* two\n   three */\n"),
]


@pytest.mark.parametrize(("source", "expected"), [p[1:] for p in PLACEMENT], ids=[p[0] for p in PLACEMENT])
def test_comment_placement(source: str, expected: str) -> None:
    assert assert_formats_well(source) == expected


def test_windows_line_endings_format_like_unix_ones() -> None:
    text = "module a { number: 1; // n\r\n  /* b\r\n  c */\r\n}\r\n"
    assert fmt(text) == fmt(text.replace("\r\n", "\n"))
