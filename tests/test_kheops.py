"""The Kheops rule compiler (seed 000 §3.7, annex A): the decision DAG agrees with the naive
forward-chaining interpreter, and compilation reports inconsistent and incomplete inputs."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specc.analysis import kheops as k
from specc.analysis.controller import executive_controller
from specc.model import nodes as m
from specc.pipeline import load
from specc.syntax.parser import parse_text
from tests.conftest import EXAMPLES
from tests.scale import threshold_base


def repository_bases() -> dict[str, tuple[k.Base, k.Compiled]]:
    """Every rule base of the examples, and every executive's resource controller (its generated
    rules joined by its own, compiled as one decision per service), each with its compiled graph."""
    bases = {}
    for robot in ("generic", "hilare"):
        loaded = load([EXAMPLES / robot])
        assert loaded.program is not None
        for item in loaded.program.items:
            if isinstance(item, m.RuleBase):
                base = k.normalise(item)
                bases[item.name] = (base, k.compile_base(base))
            elif isinstance(item, m.Executive):
                controller = executive_controller(loaded.program, item)
                bases[controller.name] = (controller.base, controller.compile())
    return bases


REPOSITORY = repository_bases()
BASES = {name: base for name, (base, _) in REPOSITORY.items()}
COMPILED = {name: compiled for name, (_, compiled) in REPOSITORY.items()}
# Every combination of the Hilare controller's domains is 45,360 interpreter runs: random ones only.
EXHAUSTIVE = sorted(name for name, base in BASES.items() if math.prod(
    len(base.attributes[i].values) for i in base.inputs) <= 5_000)


def base_from(text: str) -> k.Base:
    result = parse_text(text, "test.spec")
    assert result.source is not None, [d.headline() for d in result.diagnostics]
    (rules,) = result.source.items
    assert isinstance(rules, m.RuleBase)
    return k.normalise(rules)


def input_values(base: k.Base) -> st.SearchStrategy[dict[str, Any]]:
    """Random actual inputs: any symbol of the domain (or one it does not mention), any number."""
    fields = {}
    for name in base.inputs:
        attribute = base.attributes[name]
        if attribute.kind == "number":
            fields[name] = st.one_of(st.floats(-1e4, 1e4, allow_nan=False),
                                     st.sampled_from([p.low for p in attribute.values if p.low > -1e308]
                                                     or [0.0]))
        elif attribute.kind == "bool":
            fields[name] = st.booleans()
        else:
            choices = [v for v in attribute.values if v != k.OTHER]
            fields[name] = st.sampled_from(choices + (["not-mentioned"] if k.OTHER in attribute.values else []))
    return st.fixed_dictionaries(fields)


@pytest.mark.parametrize("name", EXHAUSTIVE)
def test_compiled_dag_equals_the_reference_interpreter_on_every_domain_combination(name: str) -> None:
    base, compiled = BASES[name], COMPILED[name]
    for inputs in k.sample_inputs(base):
        assert k.evaluate(compiled, inputs).key() == k.interpret(base, inputs).key(), inputs


@pytest.mark.parametrize("name", sorted(BASES))
def test_compiled_dag_equals_the_reference_interpreter_on_random_inputs(name: str) -> None:
    base, compiled = BASES[name], COMPILED[name]

    @settings(max_examples=200, deadline=None)
    @given(input_values(base))
    def check(inputs: dict[str, Any]) -> None:
        assert k.evaluate(compiled, inputs).key() == k.interpret(base, inputs).key()

    check()


def test_fig_3_8_domains_come_from_the_constants_the_rules_compare_with() -> None:
    base = BASES["diagnosis"]
    assert [str(p) for p in base.attributes["pres1"].values] == ["]-inf, 138[", "[138, 160[", "[160, inf["]
    assert [str(p) for p in base.attributes["difP"].values] == ["]-inf, 0[", "[0, 10[", "[10, inf["]
    assert set(base.attributes["diagn"].values) == {"b1", "b2", "b3", k.OTHER}
    assert base.attributes["difP"].assigned and base.attributes["diagn"].role == "intermediate"


def test_fig_3_8_decisions() -> None:
    base, compiled = BASES["diagnosis"], COMPILED["diagnosis"]
    normal = dict(pres1=150.0, pres2=50.0, deltaP=1.0, temp=300.0, drain="off", level="high", valve="open")
    assert k.evaluate(compiled, normal).outputs == {"proced": "i3"}
    drained = {**normal, "drain": "on"}
    assert k.evaluate(compiled, drained).outputs == {"proced": "a3"}
    # Low pressure, big jump: diagnosis b2 (r05), hot -> a22 (r07); difP is computed (r04) on the way.
    hot = {**normal, "pres1": 100.0, "deltaP": 25.0}
    assert k.evaluate(compiled, hot).outputs == {"proced": "a22"}
    assert k.interpret(base, hot).fired[:2] == ["r01", "r03"]
    assert compiled.depth <= len(base.inputs) + 1  # every observable attribute tested at most once
    assert compiled.dag_nodes < compiled.tree_nodes  # identical subtrees are shared


COMPLETE = """
rules door {
  inputs sensor: {"open", "closed"}, armed: bool;
  outputs alarm: {"ring", "quiet"};
  r1: sensor == "open", armed ==> restrict alarm == "ring";
  r2: sensor == "closed" ==> restrict alarm == "quiet";
  r3: !armed ==> restrict alarm == "quiet";
}
"""


def test_a_complete_base_has_no_findings() -> None:
    compiled = k.compile_base(base_from(COMPLETE))
    assert compiled.findings == []
    assert compiled.depth == 2


def test_a_deleted_rule_is_reported_incomplete_with_a_witness() -> None:
    compiled = k.compile_base(base_from(COMPLETE.replace('  r3: !armed ==> restrict alarm == "quiet";\n', "")))
    (finding,) = compiled.findings
    assert finding.kind == "incomplete" and finding.attributes == ("alarm",)
    assert dict(finding.witness) == {"sensor": "open", "armed": False}


def test_a_contradictory_rule_is_reported_inconsistent_with_the_rules_fired() -> None:
    text = COMPLETE.replace("}\n", '  r4: sensor == "closed" ==> restrict alarm == "ring";\n}\n')
    compiled = k.compile_base(base_from(text))
    kinds = {(f.kind, f.attributes) for f in compiled.findings}
    assert kinds == {("inconsistent", ("alarm",))}
    assert all({"r2", "r4"} <= set(f.fired) and dict(f.witness)["sensor"] == "closed" for f in compiled.findings)


def test_else_impossible_previous_values_and_foreach() -> None:
    base = base_from("""
rules cycle {
  inputs zeroOrOne: [0, 1], level[1]: [0, 20], level[2]: [0, 20];
  outputs out: bool, stab: bool, alert: {"yes", "no"};
  init @out = false;
  r1: zeroOrOne == 0 ==> restrict !out;
  r2: zeroOrOne != 0 ==> restrict out;
  r3: (@out, out) | (!@out, !out) ==> restrict stab;
  r4: (@out, !out) | (!@out, out) ==> restrict !stab;
  foreach i in ["1".."2"] {
    high[i]: level[i] > 10.0 ==> restrict alert == "yes";
  }
  quiet: else restrict alert == "no";
  never: impossible zeroOrOne == 0.5;
}
""")
    compiled = k.compile_base(base)
    assert compiled.findings == []
    run = k.evaluate(compiled, {"zeroOrOne": 1, "@out": False, "level[1]": 3.0, "level[2]": 12.0})
    assert run.outputs == {"out": True, "stab": False, "alert": "yes"}
    calm = k.evaluate(compiled, {"zeroOrOne": 0, "@out": False, "level[1]": 3.0, "level[2]": 2.0})
    assert calm.outputs == {"out": False, "stab": True, "alert": "no"}
    assert k.evaluate(compiled, {"zeroOrOne": 0.5, "@out": False, "level[1]": 0, "level[2]": 0}).impossible == "never"
    assert base.attributes["@out"].init is False


def test_generated_decision_functions_equal_the_interpreter(tmp_path_factory: pytest.TempPathFactory) -> None:
    import importlib
    import sys

    from tests.functional.conftest import compile_robot

    target = tmp_path_factory.mktemp("rules")
    package = {robot: compile_robot(EXAMPLES / robot, target) for robot in ("generic", "hilare")}
    sys.path.insert(0, str(target))
    try:
        generated = {name: importlib.import_module(f"{package[robot]}.{folder}.{name}")
                     for robot, folder, names in (
                         ("generic", "rules", ("diagnosis", "generic_controller")),
                         ("hilare", "rules", ("hilare_controller",)),
                         ("generic", "executive", ("generic_resource_controller", "fig35_resource_controller")),
                         ("hilare", "executive", ("hilare_resource_controller",)))
                     for name in names}
        assert set(generated) == set(BASES)
    finally:
        sys.path.remove(str(target))
    for name, module in generated.items():
        base = BASES[name]
        assert module.DEPTH == COMPILED[name].depth and module.INPUTS == base.inputs

        @settings(max_examples=150, deadline=None)
        @given(input_values(base))
        def check(inputs: dict[str, Any]) -> None:
            calls: list[tuple[str, tuple[Any, ...]]] = []
            decision = module.decide(inputs, lambda f, args: calls.append((f, args)))
            expected = k.interpret(base, inputs)
            shown = {o: str(v) if isinstance(v, k.Piece) else v for o, v in expected.outputs.items()}
            if expected.impossible:
                assert decision.impossible == expected.impossible
                return
            assert dict(decision.outputs) == shown
            assert list(decision.inconsistent) == expected.inconsistent
            assert list(decision.incomplete) == expected.incomplete
            assert sorted(calls, key=repr) == sorted(expected.calls, key=repr)

        check()


def test_a_base_past_the_work_limit_is_refused_with_its_figures_not_built() -> None:
    source = parse_text(threshold_base(5, 20), "big.spec").source
    assert source is not None
    base = k.normalise(next(i for i in source.items if isinstance(i, m.RuleBase)))
    built = k.compile_base(base, limit=10**7)
    with pytest.raises(k.TooLarge) as refused:
        k.compile_base(base, limit=built.tree_nodes // 2)
    assert refused.value.code == "rules-too-large" and refused.value.node.span.line == 1
    message = str(refused.value)
    bound, counts = k.paths_bound(base)
    assert f"more than {built.tree_nodes // 2:,} decision-tree nodes" in message and f"{bound:,}" in message
    assert bound >= built.tree_nodes // 2 and len(counts) == 5  # the estimate bounds what was built
    assert "split it into bases" in message


def test_compile_rules_and_verify_stop_at_the_limit_with_one_message(tmp_path: Path) -> None:
    spec = tmp_path / "big.spec"
    spec.write_text(threshold_base(5, 20))
    small = {**os.environ, k.WORK_LIMIT_VARIABLE: "100"}  # Hilare's controller takes about 280 nodes
    for args in (["compile", str(spec), "-o", str(tmp_path / "out")], ["rules", str(spec)],
                 ["compile", str(EXAMPLES / "hilare"), "-o", str(tmp_path / "out")],
                 ["verify", str(EXAMPLES / "hilare"), "--requests", "1"]):
        result = subprocess.run([sys.executable, "-m", "specc.cli", *args], capture_output=True, text=True,
                                timeout=120, env=small)
        shown = result.stdout + result.stderr
        # verify could not verify anything (2); compile and rules report an error in the specs (1)
        assert result.returncode == (2 if args[0] == "verify" else 1) and "Traceback" not in shown, shown
        headline = next(line for line in shown.splitlines() if line.endswith("[rules-too-large]"))
        if "hilare" in args[1]:
            assert "executive.spec:" in headline and "resource controller of executive 'hilare'" in headline
            assert "needs more than 100 decision-tree nodes" in headline and "the decision for service " in headline
        else:
            assert headline.startswith(f"{spec}:1:1: error: rule base 'big' needs more than 100")


@pytest.mark.parametrize("given, limit", [("500", 500), ("5e2", 500), ("5_00", 500), ("0", 1), ("lots", k.WORK_LIMIT)])
def test_the_work_limit_is_read_from_the_environment_in_any_number_form(
        given: str, limit: int, monkeypatch: pytest.MonkeyPatch) -> None:
    source = parse_text(threshold_base(5, 20), "big.spec").source
    assert source is not None
    base = k.normalise(next(i for i in source.items if isinstance(i, m.RuleBase)))
    monkeypatch.setenv(k.WORK_LIMIT_VARIABLE, given)
    if limit < k.compile_base(base, limit=10**7).tree_nodes:
        with pytest.raises(k.TooLarge) as refused:
            k.compile_base(base)
        assert refused.value.limit == limit
    else:
        assert k.compile_base(base).findings is not None


SYMBOL_ATTRIBUTES = {"s1": ("A", "B", "C"), "s2": ("A", "B"), "mid": ("M", "N", "O"), "out": ("X", "Y", "Z"),
                     "flag": ("P", "Q")}
NUMERIC_INPUTS = ("n1", "n2")


@st.composite
def random_base_texts(draw: st.DrawFn) -> str:
    """Small rule bases that exercise what the compiler reduces: numeric inputs split at several
    thresholds, intermediates deduced then tested, rules made useless by others (inert), or/not,
    `impossible` and `else` rules, assignments and calls."""

    def atom() -> str:
        name = draw(st.sampled_from([*SYMBOL_ATTRIBUTES, *NUMERIC_INPUTS, "total"]))
        if name in NUMERIC_INPUTS or name == "total":  # total: an intermediate some rule may assign
            return f"{name} {draw(st.sampled_from(['<', '<=', '>', '>=', '==', '!=']))} {draw(st.integers(0, 100))}"
        values = SYMBOL_ATTRIBUTES[name]
        if draw(st.booleans()):
            return f'{name} {draw(st.sampled_from(["==", "!="]))} "{draw(st.sampled_from(values))}"'
        chosen = ", ".join(f'"{v}"' for v in draw(st.lists(st.sampled_from(values), min_size=1, max_size=2,
                                                            unique=True)))
        return f"{name} {draw(st.sampled_from(['oneof', 'noneof']))} [{chosen}]"

    def condition(depth: int = 0) -> str:
        shape = draw(st.sampled_from(["atom", "atom", "and", "or", "not"] if depth < 2 else ["atom"]))
        if shape == "atom":
            return atom()
        if shape == "not":
            return f"!({condition(depth + 1)})"
        parts = [condition(depth + 1) for _ in range(draw(st.integers(2, 3)))]
        return f"({(' | ' if shape == 'or' else ', ').join(parts)})"

    def action() -> str:
        kind = draw(st.sampled_from(["restrict", "restrict", "restrict", "assign", "call"]))
        if kind == "assign":  # always the same value: two rules assigning two values is another matter
            return "do {total = n1 + 1}"
        if kind == "call":
            return "do {note(n2)}"
        name = draw(st.sampled_from(["mid", "out", "flag"]))
        return f'restrict {name} == "{draw(st.sampled_from(SYMBOL_ATTRIBUTES[name]))}"'

    lines = ['rules rnd {', '  inputs s1: {"A", "B", "C"}, s2: {"A", "B"}, n1: [0, 100], n2: [0, 100];',
             '  outputs out: {"X", "Y", "Z"}, flag: {"P", "Q"};', '  intermediate mid: {"M", "N", "O"};']
    for number in range(draw(st.integers(1, 9))):
        kind = draw(st.sampled_from(["when"] * 6 + ["impossible", "else"]))
        if kind == "impossible":
            lines.append(f"  r{number}: impossible {condition()};")
        elif kind == "else":
            lines.append(f"  r{number}: else {action()};")
        else:
            actions = ", ".join(action() for _ in range(draw(st.integers(1, 2))))
            lines.append(f"  r{number}: {condition()} ==> {actions};")
    return "\n".join(lines) + "\n}\n"


@settings(max_examples=150, deadline=None)
@given(random_base_texts())
def test_the_compiled_graph_of_random_bases_equals_the_reference_interpreter(text: str) -> None:
    """The compiler shares states that differ only on what no remaining rule reads, splits an
    input only where the remaining rules tell its values apart, and drops rules whose firing
    would change nothing: on every input combination it decides as forward chaining does."""
    result = parse_text(text, "random.spec")
    assert result.source is not None, [d.headline() for d in result.diagnostics]
    base = k.normalise(next(i for i in result.source.items if isinstance(i, m.RuleBase)))
    compiled = k.compile_base(base)
    for inputs in k.sample_inputs(base):
        found, expected = k.evaluate(compiled, inputs), k.interpret(base, inputs)
        if expected.inconsistent or found.inconsistent:
            # Left with no value, an attribute makes the rules testing it FALSE: what fires then
            # (an `impossible` rule too) depends on the order of deduction; the decision is not ok.
            assert bool(found.inconsistent or found.impossible) and bool(
                expected.inconsistent or expected.impossible), (text, inputs)
        elif expected.impossible or found.impossible:
            # Inputs that never occur (which `impossible` rule says so first, and what fired before, is moot).
            assert found.impossible and expected.impossible, (text, inputs)
        else:
            assert found.key() == expected.key(), (text, inputs)


def test_an_assigned_intermediate_is_tested_only_where_its_assignment_fired() -> None:
    """Two situations alike but for whether `x = b` ran: only where it ran may x be tested (else
    it has no value). The compiled graph must not share them (a review found it did)."""
    base = base_from("""rules assigned {
  inputs a: {"P", "Q"}, c: {"U", "V"}, b: [0, 10];
  outputs out: {"HI", "LO"}, flag: {"F", "G"};
  r1: a == "P" ==> do {x = b};
  r5: a == "P" ==> restrict flag == "F";
  r6: a == "Q" ==> restrict flag == "F";
  r2: c == "U", x > 5 ==> restrict out == "HI";
  r3: c == "U", x <= 5 ==> restrict out == "LO";
}""")
    compiled = k.compile_base(base)
    for inputs in k.sample_inputs(base):
        assert k.evaluate(compiled, inputs).key() == k.interpret(base, inputs).key(), inputs
    # out undetermined: a=Q (c either way) and a=P with c=V, listed as two cases (c=V merged).
    assert {f.witness for f in compiled.findings} == {(("a", ("P", "Q")), ("c", "V")), (("a", "Q"), ("c", "U"))}


def test_rules_of_one_name_in_two_joined_bases_are_two_rules() -> None:
    """An executive may join two bases that each name a rule r1: the compiler tells them apart."""
    first = base_from("""rules one {
  inputs s: {"A", "B"};
  outputs o: {"X", "Y"};
  r1: s == "A" ==> restrict o == "X";
}""")
    second = base_from("""rules two {
  inputs s: {"A", "B"};
  outputs o: {"X", "Y"};
  r1: s == "B" ==> restrict o == "Y";
}""")
    joined = k.Base("joined", first.attributes, first.rules + second.rules)
    compiled = k.compile_base(joined)
    assert compiled.findings == []
    assert k.evaluate(compiled, {"s": "A"}).outputs == {"o": "X"}
    assert k.evaluate(compiled, {"s": "B"}).outputs == {"o": "Y"}


def covering(base: k.Base, findings: list[k.Finding], inputs: dict[str, Any]) -> list[k.Finding]:
    """The findings whose witness holds for these inputs (a test of what is not an input, an
    intermediate a rule assigned, is taken to hold)."""
    def holds(attribute: str, element: Any) -> bool:
        if attribute not in inputs:
            return True
        return base.element(attribute, inputs[attribute]) in (element if isinstance(element, tuple) else (element,))

    return [f for f in findings if all(holds(a, e) for a, e in f.witness)]


def assert_findings_cover_the_unsettled_inputs(base: k.Base, compiled: k.Compiled) -> None:
    """Every input combination the decision leaves inconsistent or incomplete is one of the cases
    listed (exactly one, when the cases test inputs only), and no settled one is."""
    exact = all(a in base.inputs for f in compiled.findings for a, _ in f.witness)
    for inputs in k.sample_inputs(base):
        outcome = k.evaluate(compiled, inputs)
        if outcome.impossible:
            continue
        kind = "inconsistent" if outcome.inconsistent else "incomplete" if outcome.incomplete else None
        found = covering(base, compiled.findings, inputs)
        if kind is None:
            assert not found or not exact, (inputs, found)
        else:
            assert any(f.kind == kind for f in found), (inputs, kind)
            assert len(found) == 1 or not exact, (inputs, found)


SHARED_STATES = """
rules bms {
  inputs soc: [0, 100], temp: [-20, 80], charger: {"on", "off"}, estop: bool;
  outputs action: {"normal", "dock", "shutdown", "charge"};
  normal: soc >= 20, temp >= 0, charger == "off" ==> restrict action == "normal";
  low: soc < 20, soc >= 10, charger == "off" ==> restrict action == "dock";
  crit: soc < 10 ==> restrict action == "shutdown";
  charging: charger == "on", temp < 50 ==> restrict action == "charge";
  stop: estop ==> restrict action == "shutdown";
}
"""


def test_every_unsettled_input_is_listed_once_also_below_a_state_two_paths_share() -> None:
    # crit and charging conflict for temp below 0 and in [0, 50[: the compiled graph reaches that
    # state by two paths; both are listed (they used to be only the first), merged as one case.
    base = base_from(SHARED_STATES)
    compiled = k.compile_base(base)
    assert_findings_cover_the_unsettled_inputs(base, compiled)
    conflict = next(f for f in compiled.findings if set(f.fired) >= {"crit", "charging"})
    temperatures = dict(conflict.witness)["temp"]
    assert isinstance(temperatures, tuple) and len(temperatures) == 2  # [-20, 0[ | [0, 50[


@pytest.mark.parametrize("name", EXHAUSTIVE)
def test_the_cases_listed_for_the_example_bases_cover_their_unsettled_inputs(name: str) -> None:
    assert_findings_cover_the_unsettled_inputs(BASES[name], COMPILED[name])


@settings(max_examples=100, deadline=None)
@given(random_base_texts())
def test_the_cases_listed_for_random_bases_cover_their_unsettled_inputs(text: str) -> None:
    result = parse_text(text, "random.spec")
    assert result.source is not None
    base = k.normalise(next(i for i in result.source.items if isinstance(i, m.RuleBase)))
    assert_findings_cover_the_unsettled_inputs(base, k.compile_base(base))


TYPED_INPUTS = """
rules guard {
  inputs soc: [0, 100], estop: bool;
  outputs action: {"go", "stop"};
  stop: estop ==> restrict action == "stop";
  low: soc < 10 ==> restrict action == "stop";
  go: !estop, soc >= 10 ==> restrict action == "go";
}
"""


def test_a_generated_decision_refuses_what_its_inputs_cannot_be_and_names_the_input(tmp_path: Path) -> None:
    from tests.functional.conftest import compiled_module

    spec = tmp_path / "guard.spec"
    spec.write_text(TYPED_INPUTS)
    guard = compiled_module(spec, tmp_path / "out", "rules.guard")
    assert guard.decide({"soc": 50, "estop": False}).outputs == {"action": "go"}
    assert guard.decide({"soc": 50, "estop": 1}).outputs == {"action": "stop"}  # as the interpreter: 1 == True
    for wrong in ("no", None, 2):  # a truthy string used to read as True
        with pytest.raises(ValueError, match=f"estop={wrong!r} is outside its domain"):
            guard.decide({"soc": 50, "estop": wrong})
        with pytest.raises(ValueError):
            k.interpret(base_from(TYPED_INPUTS), {"soc": 50, "estop": wrong})
    with pytest.raises(TypeError, match=r"input soc='50': give a number"):
        guard.decide({"soc": "50", "estop": False})


STATEFUL = """
rules door {
  inputs request: bool;
  outputs command: {"open", "hold"};
  init @command = "hold";
  opening: request, @command == "hold" ==> restrict command == "open";
  held: else restrict command == "hold";
}
"""


def test_a_generated_decision_reads_the_init_of_a_previous_value_not_given(tmp_path: Path) -> None:
    """`init @command = "hold"` is what the first cycle reads as @command: the caller may leave it
    out, and the decision is the interpreter's with the init given."""
    from tests.functional.conftest import compiled_module

    spec = tmp_path / "door.spec"
    spec.write_text(STATEFUL)
    door = compiled_module(spec, tmp_path / "out", "rules.door")
    assert door.INITIAL == {"@command": "hold"}
    assert door.decide({"request": True}).outputs == {"command": "open"}
    assert door.decide({"request": True, "@command": "open"}).outputs == {"command": "hold"}
    base = base_from(STATEFUL)
    for request in (True, False):
        assert dict(door.decide({"request": request}).outputs) == k.interpret(
            base, {"request": request, "@command": "hold"}).outputs


def test_a_listing_of_unsettled_inputs_cut_at_its_limit_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    base = base_from(SHARED_STATES)
    full = k.compile_base(base)
    assert not full.findings_cut and full.findings_count() == str(len(full.findings))
    monkeypatch.setattr(k, "FINDINGS_LIMIT", 2)  # reached as shared states list their cases again
    cut = k.Compiler(base).compile()  # not compile_base: it keeps what it compiled
    assert cut.findings_cut and cut.findings_count() == f"at least {len(cut.findings)}"
    warning = k.unsettled_warning(cut, "rule base 'bms'", base.source or m.RuleBase(name="bms"))
    assert warning is not None and f"at least {len(cut.findings)} case(s)" in warning.message


def test_a_large_decision_graph_is_a_warning_with_its_figures(tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    # Under the work limit, 23,318 nodes made a 17 MB module (8 inputs x 50 rules): check says so.
    spec = tmp_path / "guard.spec"
    spec.write_text(TYPED_INPUTS)
    assert not any(d.code == "rules-large" for d in load([spec]).diagnostics)
    monkeypatch.setattr(k, "LARGE_DAG_NODES", 2)
    k._COMPILED.clear()
    (large,) = [d for d in load([spec]).diagnostics if d.code == "rules-large"]
    assert large.severity == "warning" and "rule base 'guard' compiles into a decision graph of" in large.message
    assert "split it into bases that each decide from fewer inputs" in large.message
