"""`make bench`: microseconds per evaluation of a compiled Kheops decision function, against
the reference forward-chaining interpreter (goal: 20x faster) and CLIPS running the same rules
(clipspy, bench only; goal: 50x faster), all measured in the same run, on the rule base of
Fig 3.8 and on the Hilare executive's resource controller (the rules generated from its conflicts
joined by those of Fig 5.6). CLIPS asserts the inputs and reads the outputs itself
(`cycle`), since clipspy leaks every fact object handed back to Python."""

from __future__ import annotations

import importlib
import random
import sys
import time
from pathlib import Path

import pytest

from specc.analysis import kheops as k
from specc.analysis.controller import executive_controller
from specc.model import nodes as m
from specc.pipeline import load
from tests.conftest import EXAMPLES
from tests.functional.conftest import compile_robot

pytestmark = pytest.mark.bench


def per_call_us(function, inputs: list[dict[str, object]], repeat: int = 3) -> float:  # type: ignore[no-untyped-def]
    best = float("inf")
    for _ in range(repeat):
        started = time.perf_counter()
        for values in inputs:
            function(values)
        best = min(best, (time.perf_counter() - started) / len(inputs))
    return best * 1e6


def rule_base(program: m.Program, kind: str, name: str) -> k.Base:
    if kind == "executive":
        executive = next(i for i in program.items if isinstance(i, m.Executive) and i.name == name)
        return executive_controller(program, executive).base
    return k.normalise(next(i for i in program.items if isinstance(i, m.RuleBase) and i.name == name))


@pytest.mark.parametrize("robot, kind, name", [("generic", "rules", "diagnosis"), ("hilare", "executive", "hilare")])
def test_decision_function_against_the_interpreter(robot: str, kind: str, name: str, tmp_path: Path) -> None:
    loaded = load([EXAMPLES / robot])
    assert loaded.program is not None
    base = rule_base(loaded.program, kind, name)
    package = compile_robot(EXAMPLES / robot, tmp_path)
    sys.path.insert(0, str(tmp_path))
    try:
        module = f"{package}.rules.{name}" if kind == "rules" else f"{package}.executive.{name}_resource_controller"
        generated = importlib.import_module(module)
        decide = generated.decide
    finally:
        sys.path.remove(str(tmp_path))
    rng = random.Random(7)
    samples = list(k.sample_inputs(base))
    inputs = [rng.choice(samples) for _ in range(2000)]
    compiled_us = per_call_us(decide, inputs)
    interpreted_us = per_call_us(lambda values: k.interpret(base, values), inputs[:300])
    clips = pytest.importorskip("clips", reason="make bench installs clipspy")
    from tests.bench import clips_kheops

    env = clips.Environment()
    for construct in clips_kheops.program(base):
        env.build(construct)
    cycles = [clips_kheops.call(base, values) for values in inputs[:500]]
    assert all(str(env.eval(c)) == clips_kheops.expected(base, v) for c, v in zip(cycles[:100], inputs, strict=False))
    clips_us = per_call_us(env.eval, cycles)
    print(f"\n{kind} {name} ({len(base.rules)} rules, depth {generated.DEPTH}):"
          f"\n  CLIPS 6.4 (clipspy)    {clips_us:9.2f} us/evaluation"
          f"\n  reference interpreter  {interpreted_us:9.2f} us/evaluation"
          f"\n  compiled decision      {compiled_us:9.2f} us/evaluation  "
          f"({clips_us / compiled_us:.0f}x faster than CLIPS, goal 50x; "
          f"{interpreted_us / compiled_us:.0f}x faster than the interpreter, goal 20x)")
    assert all(decide(v).outputs == {o: (str(x) if isinstance(x, k.Piece) else x)
                                     for o, x in k.interpret(base, v).outputs.items()} for v in inputs[:50])
