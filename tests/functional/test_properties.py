"""Random storms of requests, aborts, control requests and codel outcomes: the module
invariants of seed 000 ch. 2 hold whatever happens."""

from __future__ import annotations

from collections import Counter
from types import ModuleType
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.runtime import functional as rt
from specc.runtime.functional import State, Status

OUTCOMES = ["exec", "exec", "ether", "OOPS", "zombie", "raise", "end", "named"]
CHILD_SCRIPTS = ["send:exec;exec", "send:exec;raise", "send:zombie", "send:exec;exec;exec;exec"]

sends = st.tuples(st.just("send"), st.sampled_from(["A", "B", "C", "Parent"]),
                  st.lists(st.sampled_from(OUTCOMES + CHILD_SCRIPTS), max_size=6))
aborts = st.tuples(st.just("abort"), st.integers(0, 50), st.just([]))
runs = st.tuples(st.just("run"), st.sampled_from([0, 1, 3]), st.just([]))
resets = st.tuples(st.just("reset"), st.just(0), st.just([]))
storms = st.lists(st.one_of(sends, aborts, runs, resets), min_size=1, max_size=30)


def play(package: ModuleType, storm: list[tuple[str, Any, list[str]]]) -> dict[str, Any]:
    registry = rt.Registry()
    made = package.create_all(registry)
    alpha, beta = made["alpha"], made["beta"]
    replies: Counter[tuple[int, bool]] = Counter()
    frozen_submits: list[int] = []
    violations: list[str] = []
    sent: list[int] = []

    def sink(reply: rt.Reply) -> None:
        replies[(reply.rqst_id, reply.final)] += 1

    def watch(module: rt.Module, activity: rt.Activity, source: State, target: State) -> None:
        running = [a for a in module.activities.values() if a.state is State.EXEC]
        for i, first in enumerate(running):
            for second in running[i + 1:]:
                if first.spec.conflicts_with(second.spec):
                    violations.append(f"{first.spec.name} and {second.spec.name} both in EXEC")
        if target in (State.ETHER, State.ZOMBIE) and activity.live_children:
            violations.append(f"{activity.spec.name} ended before its children")

    alpha.observers.append(watch)
    beta.observers.append(watch)
    for kind, value, script in storm:
        if kind == "send":
            record = getattr(package.alpha, f"{value}Input")(script=",".join(script))
            if alpha.zombie is not None:
                frozen_submits.append(alpha.submit(value, record, sink))
            else:
                sent.append(alpha.submit(value, record, sink))
        elif kind == "abort" and sent:
            alpha.abort(sent[value % len(sent)])
        elif kind == "run":
            registry.kernel.run_for(value * 0.01)
        elif kind == "reset":
            alpha.submit("Reset", None, sink)
    for _ in range(3):  # wind down: abort whatever is left, zombies included, and let it end
        for module in (alpha, beta):
            for activity in list(module.activities.values()):
                module.abort(activity.id)
        registry.kernel.run_for(0.5)
    return {"replies": replies, "frozen": frozen_submits, "violations": violations, "sent": sent,
            "alpha": alpha, "beta": beta}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(storms)
def test_module_invariants_hold_under_random_storms(scripted_package: ModuleType, storm: list[Any]) -> None:
    run = play(scripted_package, storm)
    replies = run["replies"]
    assert run["violations"] == []
    for rqst in run["sent"]:
        assert replies[(rqst, True)] == 1, f"request {rqst}: {replies[(rqst, True)]} final replies"
        assert replies[(rqst, False)] <= 1
    for rqst in run["frozen"]:
        assert replies[(rqst, False)] == 0 and replies[(rqst, True)] == 1
    assert not run["alpha"].activities and not run["beta"].activities


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.sampled_from(["exec", "ether", "OOPS", "raise"]), max_size=5))
def test_an_accepted_exec_request_gets_one_intermediate_and_one_final_reply(scripted_package: ModuleType,
                                                                              script: list[str]) -> None:
    registry = rt.Registry()
    alpha = scripted_package.create_all(registry)["alpha"]
    log: list[rt.Reply] = []
    alpha.submit("C", scripted_package.alpha.CInput(script=",".join(script)), log.append)
    registry.kernel.run_for(1.0)
    assert [r.final for r in log] == [False, True]
    assert log[0].status is Status.WAITING and log[1].status in (Status.END, Status.FINAL_ERROR)


def test_a_zombie_module_refuses_exec_requests_until_aborted(scripted_package: ModuleType) -> None:
    registry = rt.Registry()
    alpha = scripted_package.create_all(registry)["alpha"]
    log: list[rt.Reply] = []
    zombie = alpha.submit("C", scripted_package.alpha.CInput(script="zombie"), log.append)
    registry.kernel.run_for(0.05)
    for request in ("A", "B", "C", "Parent"):
        alpha.submit(request, getattr(scripted_package.alpha, f"{request}Input")(script=""), log.append)
    assert [r.status for r in log[2:]] == [Status.ZOMBIE] * 4
    assert alpha.submit("Set", scripted_package.alpha.SetInput(value=1.0), log.append)
    assert log[-1].status is Status.END  # control requests still answer
    alpha.abort(zombie)
    alpha.submit("C", scripted_package.alpha.CInput(script=""), log.append)
    assert log[-1].status is Status.WAITING
