"""Random storms of task requests, interruptions, module outcomes (ends, intrinsic failures,
codel errors, ZOMBIEs) and timeouts against the executive over real modules: the properties
`specc verify` proves on the abstract model hold at run time too."""

from __future__ import annotations

import importlib
from collections import Counter
from types import ModuleType
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.analysis.incompat import build_graph
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime import executive as rx
from specc.runtime import functional as rt
from tests.functional.conftest import HERE

SERVICES = ["MOVE", "MOVE2", "WAITER", "TIMED", "REMOTE", "FREE", "SLOW", "RESET", "MEASURE", "NOPE"]
OUTCOMES = ["exec", "exec", "exec", "ether", "OOPS", "zombie", "raise"]

requests = st.tuples(st.just("request"), st.sampled_from(SERVICES), st.lists(st.sampled_from(OUTCOMES), max_size=8))
interrupts = st.tuples(st.just("interrupt"), st.integers(0, 40), st.just([]))
runs = st.tuples(st.just("run"), st.sampled_from([0.0, 0.01, 0.05, 0.2]), st.just([]))
storms = st.lists(st.one_of(requests, interrupts, runs), min_size=1, max_size=40)


def arcs() -> set[tuple[str, str]]:
    loaded = load([HERE / "scripted.spec", HERE / "executive.spec"])
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    return {(a.source, a.target) for a in build_graph(loaded.program, executive).arcs}


ARCS = arcs()


def play(storm: list[tuple[str, Any, list[str]]]) -> tuple[rx.Executive, list[int], list[str]]:
    registry = rt.Registry()
    importlib.import_module("shop.modules").create_all(registry)
    executive = importlib.import_module("shop.executive.shop").create(registry)
    violations: list[str] = []

    def watch(activity: rx.Activity, source: rx.Phase, target: rx.Phase) -> None:
        if target is not rx.Phase.EXEC:
            return
        for other in executive.activities.values():
            if other is not activity and other.state is rx.Phase.EXEC and (
                    activity.service.name, other.service.name) in ARCS:
                violations.append(f"{activity.service.name} entered EXEC beside {other.service.name}")

    executive.observers.append(watch)
    asked: list[int] = []
    for kind, value, script in storm:
        if kind == "request":
            executive.context.vars.setdefault("next", []).append(",".join(script))
            asked.append(len(asked) + 1)
            executive.request(value, asked[-1])
        elif kind == "interrupt" and asked:
            executive.interrupt(asked[value % len(asked)])
        elif kind == "run":
            registry.kernel.run_for(value)
    for _ in range(4):  # the task level's side of the protocol: acknowledge every ZOMBIE, then wait
        for activity in list(executive.activities.values()):
            if activity.state is rx.Phase.ZOMBIE:
                executive.interrupt(activity.id)
        registry.kernel.run_for(2.0)
    return executive, asked, violations


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(storms)
def test_executive_invariants_hold_under_random_storms(shop_package: ModuleType, storm: list[Any]) -> None:
    executive, asked, violations = play(storm)
    assert violations == []
    replies = Counter(m.id for m in executive.messages if m.kind == "REPLY")
    for ident in asked:
        assert replies[ident] == 1, f"request {ident}: {replies[ident]} final replies"
    assert executive.error is None, executive.error
    assert executive.activities == {}  # nothing starves, nothing is left behind
    assert set(executive.groups.values()) == {"IDLE"} and executive.zombies == {}
