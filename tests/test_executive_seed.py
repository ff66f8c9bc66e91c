"""The seed's executive examples at run time, on the committed generated packages: the rules of
§3.8.1 (generic system of Table 3.1) driving real modules, and the two rules of Fig 5.6 taking
over from the generated ones in Hilare's controller."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import pytest

from specc.runtime import executive as rx
from specc.runtime import functional as rt
from tests.conftest import EXAMPLES, ROOT
from tests.storm import blow, hilare_executive


@pytest.fixture(scope="module")
def packages() -> Iterator[None]:
    added = [str(ROOT / "generated"), str(EXAMPLES / "generic"), str(EXAMPLES / "hilare")]
    sys.path[:0] = added
    yield
    for path in added:
        sys.path.remove(path)


def generic(packages: None) -> tuple[rt.Registry, rx.Executive]:
    registry = rt.Registry()
    importlib.import_module("generic.modules").create_all(registry)
    return registry, importlib.import_module("generic.executive.generic").create(registry)


def states(executive: rx.Executive) -> dict[str, str]:
    return {a.service.name: str(a.state) for a in executive.activities.values()}


def facts(executive: rx.Executive) -> list[tuple[Any, ...]]:
    return [m.fact for m in executive.messages]


def test_c_waits_for_the_end_of_the_abc_group(packages: None) -> None:
    registry, executive = generic(packages)
    executive.request("A", 1)
    registry.kernel.run_for(0.5)
    executive.request("C", 2)  # CstartWhenNotIdle
    registry.kernel.run_for(0.5)
    assert states(executive) == {"A": "EXEC", "C": "WAIT"}
    registry.kernel.run_for(5)
    assert facts(executive) == [("REPLY", 1, "OK"), ("REPLY", 2, "OK")]


def test_i_interrupts_efg_in_its_own_module_and_waits_for_abc(packages: None) -> None:
    registry, executive = generic(packages)
    executive.request("E", 1)
    registry.kernel.run_for(0.5)
    executive.request("I", 2)  # IstartWhenABCidleEFGnotIdle: E goes INTER, mod2 interrupts it
    registry.kernel.run_for(0.5)
    assert facts(executive) == [("REPLY", 2, "OK"), ("REPLY", 1, "INT")]
    executive.request("B", 3)
    registry.kernel.run_for(0.5)
    executive.request("I", 4)  # IstartWhenABCnotIdle
    registry.kernel.run_for(0.5)
    assert states(executive) == {"B": "EXEC", "I": "WAIT"}
    registry.kernel.run_for(5)
    assert facts(executive)[2:] == [("REPLY", 3, "OK"), ("REPLY", 4, "OK")]


def test_j_aborts_abc_in_the_other_module_and_waits_for_the_interruption(packages: None) -> None:
    registry, executive = generic(packages)
    executive.request("A", 1)
    registry.kernel.run_for(0.5)
    executive.request("J", 2)  # JstartWhenABCnotIdle
    assert states(executive) == {"A": "INTER", "J": "WAIT"}
    assert executive.activities[1].abort_sent
    registry.kernel.run_for(1)
    assert facts(executive) == [("REPLY", 1, "INT"), ("REPLY", 2, "OK")]
    assert executive.groups == {"ABCstate": "IDLE", "EFGstate": "IDLE"}


def test_d_conflicts_with_nothing_and_always_starts(packages: None) -> None:
    registry, executive = generic(packages)
    for ident, service in enumerate("ABD", start=1):
        executive.request(service, ident)
    registry.kernel.run_for(0.5)
    assert states(executive)["D"] == "EXEC"


@pytest.fixture(scope="module")
def resource_controller(packages: None) -> ModuleType:
    return importlib.import_module("hilare.executive.hilare_resource_controller")


def decide(controller: ModuleType, service: str, event: str = "START", **groups: str) -> tuple[Any, list[Any]]:
    inputs = {name: "IDLE" for name in controller.INPUTS if name.startswith("@")}
    inputs |= {"service": service, "event": event} | {f"@{k}": v for k, v in groups.items()}
    calls: list[Any] = []
    decision = controller.decide(inputs, lambda f, args: calls.append((f, args)))
    assert decision.ok
    return decision.outputs["status"], sorted(calls)


def test_fig_5_6_rules_take_over_where_they_apply(resource_controller: ModuleType) -> None:
    # Fig 5.6 names the pilo group; the generated controller uses that name.
    assert "@ExecTrajState" in resource_controller.INPUTS and resource_controller.FINDINGS == 0
    abort_goal = [("changeInterState", ("EXEC-TRAJ-GOAL",)), ("sendAbortRequest", ("EXEC-TRAJ-GOAL",))]
    # CalcTrajObjWhenExecTrajGoal: abort the exploration trajectory and start at once (the
    # generated rule would have waited for the abort: the conflict is only one of efficiency).
    assert decide(resource_controller, "CALC-TRAJ-OBJ", ExecTrajState="EXEC-TRAJ-GOAL") == ("OK", abort_goal)
    # ArmGoWhenExecTrajGoal: abort it too, but WAIT for the robot to stand still.
    assert decide(resource_controller, "ARM-OBJ", ExecTrajState="EXEC-TRAJ-GOAL") == ("WAIT", abort_goal)
    # Where Fig 5.6 says nothing, the generated rules decide.
    assert decide(resource_controller, "CALC-TRAJ-OBJ") == ("OK", [])
    assert decide(resource_controller, "CALC-GOAL", ExecTrajState="EXEC-TRAJ-OBJ")[0] == "WAIT"
    assert decide(resource_controller, "EXEC-TRAJ-GOAL", ExecTrajState="EXEC-TRAJ-OBJ")[0] == "WAIT"


def test_fig_5_6_rules_do_not_take_over_a_declared_wait(resource_controller: ModuleType) -> None:
    # CALC-TRAJ-OBJ is declared to wait for READ-MODEL (same module, `READ-MODEL: wait`): Fig 5.6's
    # rule tests only the pilo group, so while READ-MODEL runs it steps aside and nothing is aborted;
    # starting at once would let the planner's module interrupt READ-MODEL, which nobody decided.
    plan_group = next(name[1:] for name in resource_controller.INPUTS if "READ_MODEL" in name)
    assert decide(resource_controller, "CALC-TRAJ-OBJ", ExecTrajState="EXEC-TRAJ-GOAL",
                  **{plan_group: "READ-MODEL"}) == ("WAIT", [])
    assert decide(resource_controller, "CALC-TRAJ-OBJ", **{plan_group: "READ-MODEL"}) == ("WAIT", [])


def test_a_storm_of_task_level_events_never_reaches_the_error_state(packages: None) -> None:
    # Seeded random requests (up to six outstanding), interruptions and time, on the real modules
    # (PILO's start codel sends AVOID a request of its own once AVOID-ON ran). Before the declared
    # waits held against Fig 5.6, this storm reached ERROR at its 1,493rd cycle.
    storm = hilare_executive()
    blow(storm, 20_000)
    assert storm.executive.error is None
    live = set(storm.executive.activities)
    assert storm.requests > 1_000
    assert all(storm.finals[ident] == 1 for ident in range(1, storm.requests + 1) if ident not in live), \
        "every ended request has exactly one final reply"
    assert not any(storm.finals[ident] for ident in live)
