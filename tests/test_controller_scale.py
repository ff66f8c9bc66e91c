"""The resource controller at a real robot's size (issue #24, item 2): one decision per service,
deciding only the group states it may change, so that it grows with the conflicts and not with
the product of every group's states; and deciding exactly as the whole rule base does (the
reference interpreter runs every rule, frame rules included)."""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from specc.analysis import kheops as k
from specc.analysis.controller import Controller, executive_controller
from specc.analysis.incompat import state_count
from specc.model import nodes as m
from specc.pipeline import load
from tests.functional.conftest import compiled_module
from tests.scale import write_robot


def controller(folder: Path, services: int, seed: int) -> Controller:
    loaded = load([write_robot(folder, services, seed)])
    assert loaded.program is not None, [d.headline() for d in loaded.diagnostics]
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    return executive_controller(loaded.program, executive)


def random_inputs(base: k.Base, rng: random.Random) -> dict[str, Any]:
    return {name: rng.choice([v for v in base.attributes[name].values if v != k.OTHER]) for name in base.inputs}


def test_the_controller_grows_with_the_conflicts_not_their_product(tmp_path: Path) -> None:
    built = {n: controller(tmp_path / str(n), n, seed=3) for n in (10, 20, 40)}
    nodes = {n: c.compile().tree_nodes for n, c in built.items()}
    # Twice the services, about twice the work (each decision tests the few groups of its service's conflicts) ...
    assert nodes[20] < 3 * nodes[10] and nodes[40] < 3 * nodes[20], nodes
    # ... where the controller's states multiply: 40 services have more than 10^9 of them.
    assert state_count(built[40].groups) > 10**9
    # One decision over every group's states does not fit in the work the split one needs many times over.
    with pytest.raises(k.TooLarge):
        k.compile_base(built[20].base, limit=20 * nodes[20])
    compiled = built[40].compile()
    assert compiled.findings == []  # complete and consistent by construction, at any size
    assert max(compiled.part_depths().values()) < len(compiled.base.inputs) / 4


def test_the_split_controller_decides_as_the_whole_base(tmp_path: Path) -> None:
    built = controller(tmp_path, 15, seed=5)
    compiled = built.compile()
    assert any(compiled.kept.values())  # the split leaves states out of decisions: the case this test is about
    rng = random.Random(11)
    for _ in range(3000):
        inputs = random_inputs(built.base, rng)
        assert k.evaluate(compiled, inputs).key() == k.interpret(built.base, inputs).key(), inputs


def test_the_generated_split_controller_decides_as_the_whole_base(tmp_path: Path) -> None:
    folder = write_robot(tmp_path / "robot", 15, seed=5)
    module = compiled_module(folder, tmp_path / "out", "executive.scale15_resource_controller")
    base = controller(tmp_path / "again", 15, seed=5).base
    assert module.SPLIT == "service" and set(module.KEPT) == set(base.attributes["service"].values)
    rng = random.Random(13)
    for _ in range(2000):
        inputs = random_inputs(base, rng)
        calls: list[tuple[str, tuple[Any, ...]]] = []
        decision = module.decide(inputs, lambda f, args: calls.append((f, args)))
        expected = k.interpret(base, inputs)
        assert dict(decision.outputs) == expected.outputs, inputs
        assert sorted(calls, key=repr) == sorted(expected.calls, key=repr)
        assert (list(decision.inconsistent), list(decision.incomplete)) == (expected.inconsistent, expected.incomplete)
