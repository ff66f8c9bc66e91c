"""`specc verify`: the executive's reachable states, explored with abstract modules, prove the
four properties for the repository's executives and refute them, with a shortest trace, for
rule bases that break them."""

from __future__ import annotations

from pathlib import Path

import pytest

from specc.analysis.verify import PROPERTIES, Verification, describe, verify
from specc.model import nodes as m
from specc.pipeline import load
from tests.conftest import EXAMPLES, ROOT

SCRIPTED = ROOT / "tests" / "functional"


def run(paths: list[Path], executive: str, requests: int) -> Verification:
    loaded = load(paths)
    assert loaded.program is not None and not loaded.errors
    chosen = next(i for i in loaded.program.items if isinstance(i, m.Executive) and i.name == executive)
    return verify(loaded.program, chosen, requests)


@pytest.mark.parametrize("paths, executive, requests", [
    ([EXAMPLES / "generic"], "generic", 1),
    ([EXAMPLES / "generic"], "fig35", 1),
    ([EXAMPLES / "hilare"], "hilare", 1),
    ([SCRIPTED / "scripted.spec", SCRIPTED / "executive.spec"], "shop", 2),
])
def test_the_repositorys_executives_satisfy_every_property(paths: list[Path], executive: str,
                                                           requests: int) -> None:
    result = run(paths, executive, requests)
    assert result.complete and result.violations == {}, result.violations
    assert result.states > 100  # requests, replies, timeouts and ZOMBIEs really were explored


@pytest.mark.slow
def test_the_generic_executive_with_two_outstanding_requests() -> None:
    result = run([EXAMPLES / "generic"], "generic", 2)
    assert result.ok and result.states > 10_000


ROBOT = """
module arm {
  codels: "arm_codels";
  request Go { type: exec; task: T; codel exec: go; incompatible_with: Go; }
  request Back { type: exec; task: T; codel exec: go; incompatible_with: Back; }
  exec_task T { period: 10 ms; }
}
module base {
  codels: "arm_codels";
  request Move { type: exec; task: T; codel exec: go; incompatible_with: Move; }
  exec_task T { period: 10 ms; }
}
executive shop {
  rules: policy;
  service GO { request: arm.Go; }
  service BACK { request: arm.Back; %(back)s conflicts { GO: %(policy)s; } }
  service MOVE { request: base.Move; }
}
rules policy {
  inputs service: {"GO", "BACK", "MOVE"}, event: {"START", "INTERM", "END", "ABORT", "ZOMBIE"};
  outputs status: {"OK", "WAIT", "REFUSE", "ERROR"};
  %(rule)s
}
"""


def robot(tmp_path: Path, rule: str, back: str = "", policy: str = "wait") -> list[Path]:
    (tmp_path / "arm_codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    spec = tmp_path / "shop.spec"
    spec.write_text(ROBOT % {"rule": rule, "back": back, "policy": policy})
    return [spec]


def test_a_rule_starting_a_service_before_the_one_it_interrupts_has_stopped_breaks_exclusion(
        tmp_path: Path) -> None:
    # GO and BACK are not incompatible in their module: interrupting GO takes an abort request,
    # and the generated rules WAIT for it; this rule answers OK at once, so no abort is sent.
    rule = 'backAnyway: event == "START", service == "BACK" ==> restrict status == "OK";'
    result = run(robot(tmp_path, rule, policy="interrupt"), "shop", 2)
    assert set(result.violations) == {"exclusion"}
    trace = result.violations["exclusion"].trace
    # Shortest: GO starts and runs, then BACK is let in beside it.
    assert trace == ["task: RQST EXEC GO", "task: RQST EXEC BACK"]


def test_a_rule_cannot_start_a_service_beside_the_one_it_is_declared_to_wait_for(tmp_path: Path) -> None:
    # The same rule against `GO: wait`: where the declared wait applies the rule steps aside.
    rule = 'backAnyway: event == "START", service == "BACK" ==> restrict status == "OK";'
    assert run(robot(tmp_path, rule), "shop", 2).ok


def test_a_rule_keeping_a_service_waiting_starves_it_unless_it_has_a_start_timeout(tmp_path: Path) -> None:
    rule = 'backNever: event == "START", service == "BACK" ==> restrict status == "WAIT";'
    starving = run(robot(tmp_path, rule), "shop", 1)
    assert set(starving.violations) == {"no-starvation", "one-reply"}
    assert starving.violations["no-starvation"].trace == ["task: RQST EXEC BACK"]
    timed = run(robot(tmp_path, rule, back="timeout { start: 1 s; }"), "shop", 1)
    assert timed.ok


def test_a_rule_the_controller_cannot_follow_puts_the_executive_in_error(tmp_path: Path) -> None:
    rule = 'moveIsError: event == "START", service == "MOVE" ==> restrict status == "ERROR";'
    result = run(robot(tmp_path, rule), "shop", 1)
    assert "no-error" in result.violations
    assert "start of MOVE" in result.violations["no-error"].message
    assert result.violations["no-error"].trace == ["task: RQST EXEC MOVE"]


def test_every_property_is_named_and_explained() -> None:
    assert set(PROPERTIES) == {"exclusion", "one-reply", "no-starvation", "no-error"}


def test_a_refusing_rule_is_answered_refused_and_keeps_every_property(tmp_path: Path) -> None:
    from specc.analysis.verify import explorer_for

    rule = 'moveRefused: event == "START", service == "MOVE" ==> restrict status == "REFUSE";'
    paths = robot(tmp_path, rule)
    assert run(paths, "shop", 2).ok
    loaded = load(paths)
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    world = explorer_for(loaded.program, executive).initial()
    world.executive.request("MOVE", 7)
    assert [msg.fact for msg in world.executive.messages] == [("REPLY", 7, "REFUSED")]


SHARED = """
module m {
  codels: "arm_codels";
  request R { type: exec; task: T; codel exec: go; }
  request Q { type: exec; task: T; codel exec: go; }
  exec_task T { period: 10 ms; }
}
executive ex {
  service S { request: m.R; }
  service W { request: m.Q; conflicts { S: wait; } }
}
"""


def test_two_instances_of_a_grouped_service_that_does_not_exclude_itself_stay_safe(tmp_path: Path) -> None:
    """S runs in several instances, yet W waits for it, so it has a group whose state names one
    running S: a second S waits for the first rather than drive the controller to ERROR."""
    (tmp_path / "arm_codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    (tmp_path / "shared.spec").write_text(SHARED)
    result = run([tmp_path / "shared.spec"], "ex", 2)
    assert result.ok, result.violations
    from specc.analysis.verify import explorer_for

    loaded = load([tmp_path / "shared.spec"])
    assert loaded.program is not None
    world = explorer_for(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive))).initial()
    world.executive.request("S", 1)
    world.executive.request("S", 2)
    assert [str(a.state) for a in world.executive.activities.values()] == ["EXEC", "WAIT"]


def test_a_hand_written_refusal_interrupts_nothing(tmp_path: Path) -> None:
    rule = ('backNotNow: event == "START", service == "MOVE", @GOstate == "GO" ==> restrict status == "REFUSE";'
            '\n  outputs GOstate: {"GO", "IDLE"};\n  init @GOstate = "IDLE";')
    spec = robot(tmp_path, rule)[0]
    spec.write_text(spec.read_text().replace("service MOVE { request: base.Move; }",
                                             "service MOVE { request: base.Move; conflicts { GO: interrupt; } }"))
    result = run([spec], "shop", 2)
    assert result.ok, result.violations
    from specc.analysis.verify import explorer_for

    loaded = load([spec])
    assert loaded.program is not None
    world = explorer_for(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive))).initial()
    world.executive.request("GO", 1)
    world.executive.request("MOVE", 2)
    assert [msg.fact for msg in world.executive.messages] == [("REPLY", 2, "REFUSED")]
    assert [str(a.state) for a in world.executive.activities.values()] == ["EXEC"]  # GO untouched


def test_service_groups_do_not_depend_on_string_hashing(tmp_path: Path) -> None:
    import os
    import subprocess
    import sys

    (tmp_path / "c.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    (tmp_path / "tie.spec").write_text("""
module m {
  codels: "c";
  request R0 { type: exec; task: T; codel exec: go; incompatible_with: R0, R3; }
  request R1 { type: exec; task: T; codel exec: go; incompatible_with: R1, R3; }
  request R3 { type: exec; task: T; codel exec: go; incompatible_with: R0, R1, R3; }
  exec_task T { period: 10 ms; }
}
executive ex { service S0 { request: m.R0; } service S1 { request: m.R1; } service S3 { request: m.R3; } }
""")
    script = ("import sys; from pathlib import Path; from specc.pipeline import load; from specc.model import nodes"
              " as m; from specc.analysis.incompat import build_graph, service_groups; p = load([Path(sys.argv[1])])"
              ".program; e = next(i for i in p.items if isinstance(i, m.Executive)); "
              "print([g.services for g in service_groups(build_graph(p, e))])")
    found = {subprocess.run([sys.executable, "-c", script, str(tmp_path / "tie.spec")], capture_output=True,
                            text=True, env={**os.environ, "PYTHONHASHSEED": str(seed)}, check=True).stdout
             for seed in range(1, 9)}
    assert found == {"[('S0', 'S3'), ('S1',)]\n"}


def test_a_service_that_takes_inputs_is_explored_like_any_other(tmp_path: Path) -> None:
    """`takes: x;` (inputs the task level gives with each request): the explorer's requests give
    one for each, so a rule that breaks exclusion between two such services is found, where a
    request without its inputs would be refused before it ever ran."""
    paths = robot(tmp_path, 'backAnyway: event == "START", service == "BACK" ==> restrict status == "OK";',
                  policy="interrupt")
    spec = paths[0]
    text = spec.read_text()
    spec.write_text(text.replace("request Go { type: exec;", "request Go { type: exec; input: x: double;")
                    .replace("request Back { type: exec;", "request Back { type: exec; input: y: double;")
                    .replace("service GO { request: arm.Go; }", "service GO { request: arm.Go; takes: x; }")
                    .replace("service BACK { request: arm.Back;", "service BACK { request: arm.Back; takes: y;"))
    result = run(paths, "shop", 2)
    assert "exclusion" in result.violations, result
    assert any("BACK" in step for step in result.violations["exclusion"].trace)


def test_a_state_limit_refutes_no_liveness_property_it_could_not_explore_to_the_end(tmp_path: Path) -> None:
    # Stopped early, the states at the limit have successors nobody looked at: they are no
    # evidence that a request can never get its reply (stopped at 40 states, this executive was
    # once reported "one-reply: REFUTED ... stuck with GO in EXEC"; so was Hilare's at 500,000).
    (tmp_path / "arm_codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    spec = tmp_path / "shop.spec"
    spec.write_text(SENDING % "service HEAR { request: ear.Hear; }")
    assert run([spec], "shop", 2).ok
    loaded = load([spec])
    assert loaded.program is not None
    stopped = verify(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive)), 2,
                     limit=40)
    assert not stopped.complete and stopped.states == 40
    assert stopped.violations == {}


def test_a_stuck_state_explored_to_the_end_refutes_even_when_the_limit_stops_the_rest(tmp_path: Path) -> None:
    rule = 'backNever: event == "START", service == "BACK" ==> restrict status == "WAIT";'
    loaded = load(robot(tmp_path, rule))
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    whole = verify(loaded.program, executive, 2)
    stopped = verify(loaded.program, executive, 2, limit=whole.states // 2)
    assert not stopped.complete
    assert stopped.violations["no-starvation"].trace == whole.violations["no-starvation"].trace == [
        "task: RQST EXEC BACK"]


SENDING = """
module arm {
  codels: "arm_codels";
  request Go { type: exec; task: T; codel exec: go; incompatible_with: Go; sends: eye.Look; }
  exec_task T { period: 10 ms; }
}
module eye {
  codels: "arm_codels";
  request Look { type: exec; task: T; codel exec: go; sends: ear.Listen; }
  exec_task T { period: 10 ms; }
}
module ear {
  codels: "arm_codels";
  request Listen { type: exec; task: T; codel exec: go; }
  request Hear { type: exec; task: T; codel exec: go; }
  exec_task T { period: 10 ms; }
}
executive shop {
  service GO { request: arm.Go; }
  %s
}
"""


@pytest.mark.parametrize("addition, left_out", [
    ("", ("arm.Go sends eye.Look",)),  # Look and what it sends reach nothing the executive sees
    ("service HEAR { request: ear.Hear; }", ()),  # Listen shares a module with a service: it may freeze it
    ("reflex heard on reply ear.Listen == OK => abort GO;", ()),  # Listen's reply triggers a reflex
])
def test_a_sent_request_the_executive_cannot_observe_is_left_out_and_said(
        tmp_path: Path, addition: str, left_out: tuple[str, ...]) -> None:
    (tmp_path / "arm_codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    spec = tmp_path / "shop.spec"
    spec.write_text(SENDING % addition)
    result = run([spec], "shop", 2)
    assert result.ok and result.left_out == left_out
    lines = list(describe(result))
    assert any("left out" in line and "arm.Go sends eye.Look" in line for line in lines) == bool(left_out)
    # Left out, the sends change no state: the same states as without them.
    spec.write_text((SENDING % addition).replace(" sends: eye.Look;", ""))
    alone = run([spec], "shop", 2)
    assert (result.states == alone.states) == bool(left_out)
