"""The interpreter and the Petri net agree: for random procedures (tests, conclusions,
retractions, waits, conditions, choices, parallel branches, subgoals achieved by one or two KAs),
every way the interpreter ends a posted goal is an end the net can reach, and an intention the
interpreter leaves blocked is a deadlock the net reports."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from specc.analysis.procedures import library
from specc.analysis.prs_net import TranslationError
from specc.analysis.prs_verify import verify
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime import procedures as rp
from specc.runtime.supervisor import Supervisor

SIMPLE = [
    "=>(P A);", "=>(P B);", "~>(P A);", "=>(Q);", "~>(Q);", "?(P A);", "?(Q);", "?(~ (Q));", "?(P $X);",
    "=>(R $X);", "fail;", "^(Q);", "^(P B);", "!(SUB);", "!(SUB);",
]


def blocks(depth: int) -> st.SearchStrategy[list[str]]:
    simple = st.sampled_from(SIMPLE)
    if depth == 0:
        return st.lists(simple, min_size=1, max_size=4).map(upto_fail)
    inner = blocks(depth - 1)
    test = st.sampled_from(["?(P A)", "?(Q)", "?(~ (Q))"])
    compound = st.one_of(
        st.builds(lambda c, t, e: f"if {c} {{ {' '.join(t)} }} else {{ {' '.join(e)} }}", test, inner, inner),
        st.builds(lambda a, b, f1, f2:
                  f"choose {{ branch {{ {f1}; {' '.join(a)} }} branch {{ {f2}; {' '.join(b)} }} }}",
                  inner, inner, test, test),
        st.builds(lambda a, b: f"parallel {{ branch {{ {' '.join(a)} }} branch {{ {' '.join(b)} }} }}", inner, inner),
    )
    return st.lists(st.one_of(simple, simple, compound), min_size=1, max_size=4).map(upto_fail)


def upto_fail(statements: list[str]) -> list[str]:
    """The statements up to the first `fail;` (what follows it would never run: a spec error)."""
    return statements[:statements.index("fail;") + 1] if "fail;" in statements else statements


def spec(main: list[str], sub: list[str], second: list[str] | None) -> str:
    other = f"\n  ka Sub2 {{ invocation: !(SUB); body {{ {' '.join(second)} }} }}" if second is not None else ""
    return f"""procedures random {{
  predicate closed P(v: {{A, B}});
  predicate closed Q();
  predicate closed R(v: {{A, B}});
  predicate GO();
  predicate SUB();
  ka Main {{ invocation: !(GO); body {{ {' '.join(main)} }} }}
  ka Sub {{ invocation: !(SUB); body {{ {' '.join(s for s in sub if s != "!(SUB);") or "=>(Q);"} }} }}{other}
}}
"""


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(blocks(2), blocks(1), st.one_of(st.none(), blocks(0)), st.integers(0, 3))
# A parallel's join once dropped what a branch bound for the statement after it (the net said
# `=>(R $X)` never succeeds; the interpreter succeeded).
@example(["!(SUB);"], ["parallel { branch { =>(P A); } branch { ?(P $X); } }", "=>(R $X);"], None, 0)
def test_the_interpreter_ends_only_where_the_net_can(main: list[str], sub: list[str], second: list[str] | None,
                                                     seed: int) -> None:
    if second is not None:
        second = [s for s in second if s != "!(SUB);"]
        if not second:
            second = ["fail;"]
    text = spec(main, sub, second)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "random.spec"
        path.write_text(text, encoding="utf-8")
        loaded = load([path])
        assert loaded.program is not None and not loaded.errors, [d.message for d in loaded.errors]
        block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
        try:
            report = verify(loaded.program, block, [rp.parse_goal("!(GO)")], limit=20_000)
        except TranslationError as rejected:  # branches sharing a variable: the net has no copy to share
            assert {d.code for d in rejected.diagnostics} == {"shared-variable"}, rejected.diagnostics
            assume(False)
        assume(report.space.complete)  # a few parallel interleavings explode; they prove nothing more
        supervisor = Supervisor(library(block), seed=seed)
        intention = supervisor.post("!(GO)")
        supervisor.run()
    possible = set()
    if report.succeeded:
        possible.add("succeeded")
    if report.failed:
        possible.add("failed")
    if "deadlock" in report.kinds():
        possible.add("running")
    assert intention.status in possible, (text, intention.status, report.kinds(), intention.lines())


def outcome_spec(body: str, extra: str = "") -> str:
    return f"""procedures cases {{
  predicate closed P(v: {{A, B}});
  predicate closed Q();
  predicate closed R(v: {{A, B}});
  predicate event EV(v: {{A, B}});
  predicate functional F(v: {{A, B}});
  predicate GO();
  {extra}
  ka Main {{ invocation: !(GO); body {{ {body} }} }}
}}
"""


TWICE_FAILING = ("ka Sub { invocation: !(SUB); body { if ?(Q) { =>(P A); } else { =>(Q); "
                 "parallel { branch { fail; } branch { fail; } } } } }")


@pytest.mark.parametrize("body, facts, expected", [
    # both branches fail, the KA fails once: the second !(SUB) is not answered by a leftover
    ("choose { branch { !(SUB); } branch { ^(Q); } } !(SUB);", [], "succeeded"),
    ("if ?(~ (& (Q) (P A))) { =>(Q); } else { fail; }", [], "succeeded"),  # negation of a conjunction
    ("!(Q);", ["(Q)"], "succeeded"),  # the database satisfies the goal before any KA is tried
    ("!(< 1 2);", [], "succeeded"),
    ("=>(P A); ?(& (P @X) (R @X));", [], "failed"),  # @X keeps the value P gave it within the test
    ("assign @X = A; if ?(P @X) { fail; } else { =>(R @X); }", [], "succeeded"),  # a failed match keeps @X
    ("if ?(< @Y 3) { =>(Q); } else { =>(Q); }", [], "failed"),  # comparing an unbound value is an error
    ("=>(F A); ~>(F $V); ?(F A);", [], "succeeded"),  # retracting with an unbound value changes nothing
    ("=>(EV A); =>(EV B); ^(EV $X); ^(EV $Y);", [], "succeeded"),  # each wait uses one occurrence
])
def test_the_net_and_the_interpreter_agree_on_the_finer_points(tmp_path: Path, body: str, facts: list[str],
                                                                expected: str) -> None:
    text = outcome_spec(body, TWICE_FAILING if "SUB" in body else "")
    spec_file = tmp_path / "cases.spec"
    spec_file.write_text(text, encoding="utf-8")
    loaded = load([spec_file])
    assert loaded.program is not None and not loaded.errors, [d.message for d in loaded.errors]
    block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
    report = verify(loaded.program, block, [rp.parse_goal("!(GO)")], [rp.parse_fact(f) for f in facts])
    supervisor = Supervisor(library(block))
    for fact in facts:
        supervisor.conclude(fact)
    intention = supervisor.post("!(GO)")
    supervisor.run()
    assert intention.status == expected, intention.lines()
    ends = {"succeeded": report.succeeded, "failed": report.failed}
    assert ends[expected] >= 1 and all(n == 0 for outcome, n in ends.items() if outcome != expected), report.kinds()


def test_a_value_outside_its_declared_domain_is_a_finding_of_the_net_and_a_failure_of_the_interpreter(
        tmp_path: Path) -> None:
    """A counter counting past N's domain 0..2: the net reports the value it has no room for,
    and the interpreter refuses to conclude it (the KA fails) instead of running on outside
    what was proved."""
    spec_file = tmp_path / "cases.spec"
    spec_file.write_text(outcome_spec("assign @I = 0; while ?(< @I 4) { assign @I = (+ @I 1); } =>(N @I);",
                                      "predicate functional N(v: 0..2);"), encoding="utf-8")
    loaded = load([spec_file])
    assert loaded.program is not None and not loaded.errors
    block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
    report = verify(loaded.program, block, [rp.parse_goal("!(GO)")])
    assert "out-of-domain" in report.kinds() and report.succeeded == 0
    supervisor = Supervisor(library(block))
    intention = supervisor.post("!(GO)")
    supervisor.run()
    assert intention.status == "failed" and supervisor.database.facts("N") == []
    said = "4 is outside the domain the spec declares for N's argument 1 ({0, 1, 2})"
    assert any(said in line for line in intention.lines())


def test_branches_sharing_a_variable_are_rejected(tmp_path: Path) -> None:
    spec_file = tmp_path / "cases.spec"
    spec_file.write_text(outcome_spec("assign @X = A; parallel { branch { assign @X = B; } branch { ^(P @X); } }"),
                         encoding="utf-8")
    loaded = load([spec_file])
    assert loaded.program is not None
    block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
    with pytest.raises(TranslationError) as rejected:
        verify(loaded.program, block, [rp.parse_goal("!(GO)")])
    assert [d.code for d in rejected.value.diagnostics] == ["shared-variable"]


def test_an_event_whose_ka_context_fails_stays_for_a_wait(tmp_path: Path) -> None:
    extra = "predicate closed ARMED();\n  ka OnPing { invocation: (EV A); context: ?(ARMED); body { =>(Q); } }"
    spec_file = tmp_path / "cases.spec"
    spec_file.write_text(outcome_spec("=>(EV A); ^(EV A);", extra), encoding="utf-8")
    loaded = load([spec_file])
    assert loaded.program is not None and not loaded.errors, [d.message for d in loaded.errors]
    block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
    report = verify(loaded.program, block, [rp.parse_goal("!(GO)")])
    assert report.kinds() == ["unreachable"] and "OnPing" in report.findings[0].message  # never armed
    assert report.succeeded >= 1 and report.failed == 0
    supervisor = Supervisor(library(block))
    intention = supervisor.post("!(GO)")
    supervisor.run()
    assert intention.status == "succeeded"


def test_a_set_domain_may_hold_negative_numbers(tmp_path: Path) -> None:
    """`{-30, 0}` as a range `-30..0` is: the numbers, negative ones included, reach the
    interpreter's domains, and `fmt` writes them back as they were."""
    from specc.syntax.printer import format_source

    text = "procedures p {\n  predicate TILT(t: {-30, +5, 0});\n}\n"
    spec_file = tmp_path / "tilt.spec"
    spec_file.write_text(text, encoding="utf-8")
    loaded = load([spec_file])
    assert loaded.program is not None and not loaded.errors, [d.message for d in loaded.errors]
    block = next(i for i in loaded.program.items if isinstance(i, m.Procedures))
    (tilt,) = library(block).predicates
    assert tilt.domains == ((-30, 5, 0),)
    (source,) = loaded.program.files
    assert format_source(source, text, loaded.comments[source.path]) == text.replace("+5", "5")
