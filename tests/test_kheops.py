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


def repository_bases() -> dict[str, k.Base]:
    """Every rule base of the examples, and every executive's resource controller (its generated
    rules joined by its own)."""
    bases = {}
    for robot in ("generic", "hilare"):
        loaded = load([EXAMPLES / robot])
        assert loaded.program is not None
        for item in loaded.program.items:
            if isinstance(item, m.RuleBase):
                bases[item.name] = k.normalise(item)
            elif isinstance(item, m.Executive):
                controller = executive_controller(loaded.program, item)
                bases[controller.name] = controller.base
    return bases


BASES = repository_bases()
COMPILED = {name: k.compile_base(base) for name, base in BASES.items()}
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


def threshold_base(inputs: int, rules: int) -> str:
    """Numeric inputs tested against many thresholds, pairwise: the decision graph multiplies."""
    lines = [f"rules big {{\n  inputs {', '.join(f'x{i}: [0, 100]' for i in range(inputs))};",
             '  outputs level: {"LOW", "HIGH"};']
    for r in range(rules):
        a, b = r % inputs, (r * 3 + 1) % inputs
        lines.append(f'  r{r}: x{a} > {(r * 37) % 97 + 1}, x{b} < {(r * 53) % 89 + 5} ==> restrict level == '
                     f'"{"LOW" if r % 2 else "HIGH"}";')
    return "\n".join(lines) + "\n}\n"


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
    small = {**os.environ, k.WORK_LIMIT_VARIABLE: "500"}
    for args in (["compile", str(spec), "-o", str(tmp_path / "out")], ["rules", str(spec)],
                 ["compile", str(EXAMPLES / "hilare"), "-o", str(tmp_path / "out")],
                 ["verify", str(EXAMPLES / "hilare"), "--requests", "1"]):
        result = subprocess.run([sys.executable, "-m", "specc.cli", *args], capture_output=True, text=True,
                                timeout=120, env=small)
        shown = result.stdout + result.stderr
        assert result.returncode == 1 and "Traceback" not in shown, shown
        headline = next(line for line in shown.splitlines() if line.endswith("[rules-too-large]"))
        if "hilare" in args[1]:
            assert "executive.spec:" in headline and "resource controller of executive 'hilare'" in headline
            assert "service groups: 432 controller states x 21 services x 5 events" in headline
        else:
            assert headline.startswith(f"{spec}:1:1: error: rule base 'big' needs more than 500")


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
