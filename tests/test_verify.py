"""`specc verify`: the executive's reachable states, explored with abstract modules, prove the
four properties for the repository's executives and refute them, with a shortest trace, for
rule bases that break them."""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

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


def write_codels(folder: Path) -> None:
    """The codels every robot of these tests names: one that ends at once."""
    (folder / "arm_codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")


def robot(tmp_path: Path, rule: str, back: str = "", policy: str = "wait") -> list[Path]:
    write_codels(tmp_path)
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


def test_a_conflict_declared_one_way_is_said_with_the_verdict(tmp_path: Path) -> None:
    """BACK waits for GO, GO names no conflict with BACK: a GO asked for while BACK runs starts
    beside it, which exclusion (the arcs as written) allows; the verdict says so, and how to make
    them never run together."""
    result = run(robot(tmp_path, ""), "shop", 2)
    assert result.ok and result.one_way == (("BACK", "wait", "GO"),)
    said = list(describe(result))[-1]
    assert said.startswith("conflicts declared one way only, which the states explored show running together "
                           "(exclusion reads them as written): GO starts while BACK runs (BACK waits for GO, GO does "
                           "not name BACK)")
    # The controller's own rules may keep them apart all the same: then nothing is said.
    kept = tmp_path / "kept"
    kept.mkdir()
    rule = ('BackState: {"BACK", "IDLE"};\n  init @BackState = "IDLE";\n'
            '  goAfterBack: event == "START", service == "GO", @BackState == "BACK" ==> restrict status == "WAIT";')
    paths = robot(kept, "")
    paths[0].write_text(paths[0].read_text().replace('outputs status: {"OK", "WAIT", "REFUSE", "ERROR"};',
                                                     'outputs status: {"OK", "WAIT", "REFUSE", "ERROR"}, ' + rule))
    apart = run(paths, "shop", 2)
    assert apart.ok and apart.one_way == ()
    both = tmp_path / "both"
    both.mkdir()
    paths = robot(both, "")
    paths[0].write_text(paths[0].read_text().replace("service GO { request: arm.Go; }",
                                                     "service GO { request: arm.Go; conflicts { BACK: wait; } }"))
    assert run(paths, "shop", 2).one_way == ()
    # A control service takes no time, so nothing has an arc to it: its own arcs are not one-way
    # by omission (the rover's PTU-INIT and STOP-NAV interrupt what they stop).
    assert run([EXAMPLES / "atrv"], "atrv", 1).one_way == ()


def test_a_rule_keeping_a_service_waiting_starves_it_unless_it_has_a_start_timeout(tmp_path: Path) -> None:
    rule = 'backNever: event == "START", service == "BACK" ==> restrict status == "WAIT";'
    starving = run(robot(tmp_path, rule), "shop", 1)
    assert set(starving.violations) == {"no-starvation", "one-reply"}
    assert starving.violations["no-starvation"].trace == ["task: RQST EXEC BACK"]
    timed = run(robot(tmp_path, rule, back="timeout { start: 1 s; }"), "shop", 1)
    assert timed.ok
    # Every property holds, and BACK never runs (each request of it times out in WAIT): said.
    assert timed.never_started == ("BACK",)
    assert any(line.startswith("never started, in any state explored: BACK") for line in describe(timed))
    assert run(robot(tmp_path, ""), "shop", 1).never_started == ()


def test_a_rule_the_controller_cannot_follow_puts_the_executive_in_error(tmp_path: Path) -> None:
    rule = 'moveIsError: event == "START", service == "MOVE" ==> restrict status == "ERROR";'
    result = run(robot(tmp_path, rule), "shop", 1)
    assert "no-error" in result.violations
    assert "start of MOVE" in result.violations["no-error"].message
    assert result.violations["no-error"].trace == ["task: RQST EXEC MOVE"]


def test_every_property_is_named_and_explained() -> None:
    assert set(PROPERTIES) == {"exclusion", "one-reply", "no-starvation", "no-error", "settles"}


RESTARTED = """
module ptu {
  codels: "ptu_codels";
  request Point { type: exec; task: Axes; incompatible_with: Point, Sweep; codel exec: sweep; }
  request Sweep { type: exec; task: Axes; incompatible_with: Point, Sweep; codel exec: sweep; }
  exec_task Axes { period: 100 ms; }
}
module camera {
  codels: "ptu_codels";
  request Panorama { type: exec; task: Grab; incompatible_with: Panorama; sends: ptu.Sweep; codel exec: sweep; }
  exec_task Grab { period: 100 ms; }
}
executive e {
  service SWEEP { request: ptu.Sweep; conflicts { SWEEP: interrupt; } }
  service PANORAMA { request: camera.Panorama; conflicts { PANORAMA: wait; } }
  reflex again on reply SWEEP => start SWEEP;
}
"""


def test_a_reaction_loop_outside_time_is_a_finding_not_a_verifier_that_never_ends(tmp_path: Path) -> None:
    """A reflex restarting SWEEP on every reply, and its module frozen by a ZOMBIE: the module
    refuses each start at once, the refusal is a reply, the reflex starts SWEEP again, with no
    time passing (the robot would stand at that instant for ever). The exploration ends, and
    `settles` is refuted with the events that lead there."""
    (tmp_path / "ptu_codels.py").write_text("def sweep(sdi, request):\n    return 'exec'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(RESTARTED)
    result = run([spec], "e", 2)
    assert result.complete and "settles" in result.violations
    violation = result.violations["settles"]
    # Each restart sends the module a request: their count stops the event first.
    assert "sent 1,000 requests to the modules (the last: ptu.Sweep) with no time passing" in violation.message
    assert "ptu: Sweep goes ZOMBIE" in violation.trace


REQUESTED_AGAIN = """
module cam {
  codels: "cam_codels";
  request Snap { type: exec; task: Grab; codel exec: grab; }
  exec_task Grab { period: 100 ms; }
}
executive e {
  service SNAP { request: cam.Snap; }
  reflex again on reply cam.Snap => request cam.Snap;
}
"""


def test_a_reflex_requesting_a_frozen_module_again_is_a_finding_and_the_executive_does_not_hang(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same loop through a module request, which takes no decision: the frozen module
    refuses each request at once. The verifier used to run that event for ever; it counts the
    requests now, and `settles` is refuted. The executive itself, on a robot, ends in its ERROR
    state after CYCLES_PER_INSTANT cycles: in it no reflex fires, where it used to go on at that
    instant for ever."""
    from specc.analysis import verify as v
    from specc.runtime import executive as rx

    (tmp_path / "cam_codels.py").write_text("def grab(sdi, request):\n    return 'exec'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(REQUESTED_AGAIN)
    program = load([spec]).program
    assert program is not None
    executive = next(i for i in program.items if isinstance(i, m.Executive))
    result = v.verify(program, executive, 1, limit=60)
    assert "settles" in result.violations, result.violations
    violation = result.violations["settles"]
    assert "sent 1,000 requests to the modules (the last: cam.Snap)" in violation.message
    assert "cam: Snap goes ZOMBIE" in violation.trace

    # The runtime alone: a frozen module, the reflex, a request; no cap of the verifier's.
    monkeypatch.setattr(v, "REQUESTS_PER_EVENT", 10**9)
    monkeypatch.setattr(rx, "CYCLES_PER_INSTANT", 2_000)
    world = v.explorer_for(program, executive, 1).initial()
    frozen = world.registry.modules["cam"]
    frozen.zombies.add(999)
    world.executive.request("SNAP", 1)
    assert world.executive.error is not None and "2,000 cycles" in world.executive.error
    assert frozen.registry.submitted < 2_100  # it stopped soon after the limit


CHAIN = """
module arm {
  codels: "chain_codels";
  request Pick { type: exec; task: T; sends: gripper.Close; codel start: pick; codel exec: work; }
  exec_task T { period: 100 ms; }
}
module gripper {
  codels: "chain_codels";
  request Close { type: exec; task: T; sends: camera.Snap; codel start: close; codel exec: work; }
  exec_task T { period: 100 ms; }
}
module camera {
  codels: "chain_codels";
  request Snap { type: exec; task: T; incompatible_with: Snap; codel exec: work; }
  exec_task T { period: 100 ms; }
}
executive e {
  service PICK { request: arm.Pick; }
  service SNAP { request: camera.Snap; }
}
"""


def test_a_request_sent_by_a_codel_ends_with_its_sender_and_sends_nothing_after(tmp_path: Path) -> None:
    """PICK's codel sends gripper.Close, whose codel sends camera.Snap, which would interrupt
    SNAP behind the executive's back: the controller keeps PICK and SNAP apart (sends are
    followed through). The runtime interrupts a request's children when it ends, so Close never
    sends once Pick is over; the model let it ("Pick ends; Close sends camera.Snap; Snap is
    interrupted") and refuted no-error for a robot on which that cannot happen."""
    (tmp_path / "chain_codels.py").write_text(
        "def pick(sdi, request):\n    sdi.send_request('gripper.Close')\n    return 'exec'\n\n"
        "def close(sdi, request):\n    sdi.send_request('camera.Snap')\n    return 'exec'\n\n"
        "def work(sdi, request):\n    return 'end'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(CHAIN)
    result = run([spec], "e", 2)
    assert result.ok, describe(result)
    # Close is sent, and sends, while Pick runs: those states are there.
    assert result.states > 100


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
    write_codels(tmp_path)
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


LISTENED = """
module m1 {
  codels: "arm_codels";
  request Rs { type: exec; task: T; codel exec: go; sends: n.Y; }
  request Rp { type: exec; task: T; codel exec: go; incompatible_with: Rp; }
  request Rq { type: exec; task: T; codel exec: go; }
  request Rk { type: exec; task: T; codel exec: go; incompatible_with: Rk; }
  exec_task T { period: 10 ms; }
}
module n {
  codels: "arm_codels";
  request W { type: exec; task: T; codel exec: go; }
  request Y { type: exec; task: T; codel exec: go; }
  exec_task T { period: 10 ms; }
}
executive shop {
  rules: policy;
  service S { request: m1.Rs; }
  service P { request: m1.Rp; }
  service Q { request: m1.Rq; }
  service K { request: m1.Rk; }
  reflex both on interm S => start P, start Q;
  reflex never on reply n.W => abort P;
}
rules policy {
  inputs service: {"S", "P", "Q", "K"}, event: {"START", "INTERM", "END", "ABORT", "ZOMBIE"};
  outputs status: {"OK", "WAIT", "REFUSE", "ERROR"}, Kstate: {"K", "IDLE"}, Pstate: {"P", "IDLE"};
  init @Kstate = "IDLE";
  init @Pstate = "IDLE";
  kRef: event == "START", service == "K", @Kstate == "K" ==> restrict status == "REFUSE";
  pWait: event == "START", service == "P", @Kstate == "IDLE" ==> restrict status == "WAIT";
  qRef: event == "START", service == "Q" ==> restrict status == "REFUSE", restrict Kstate == "K";
  sReset: event != "START", service == "S" ==> restrict Kstate == "IDLE";
  sEndErr: event == "END", service == "S", @Pstate == "P" ==> restrict status == "ERROR";
}
"""


def test_a_send_to_a_module_a_reflex_listens_to_is_kept_though_the_reflex_never_fires(tmp_path: Path) -> None:
    # Found by review: the executive hears every reply of a module some reflex takes as its source
    # (here n, for n.W, which nothing runs): each runs a cycle, and the WAIT activities ask again.
    # Leaving n.Y out hid the ERROR that extra cycle leads to (S ending while P runs): the
    # explorer now sees that such a pass changes a state, and keeps n.Y.
    write_codels(tmp_path)
    spec = tmp_path / "listened.spec"
    spec.write_text(LISTENED)
    from specc.analysis.verify import explorer_for

    loaded = load([spec])
    assert loaded.program is not None
    explorer = explorer_for(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive)), 1)
    assert explorer.left_out == ("m1.Rs sends n.Y",)  # n.Y's replies taken to change nothing, at first
    result = explorer.explore()
    assert explorer.passes_matter and result.left_out == ()  # a pass did change something: n.Y kept
    assert result.violations["no-error"].trace == ["task: RQST EXEC S", "m1: Rs sends n.Y", "m1: Rs ends"]
    assert "(groups: " in result.violations["no-error"].message  # the controller's state it failed in


def test_a_state_limit_refutes_no_liveness_property_it_could_not_explore_to_the_end(tmp_path: Path) -> None:
    # Stopped early, the states at the limit have successors nobody looked at: they are no
    # evidence that a request can never get its reply (stopped at 40 states, this executive was
    # once reported "one-reply: REFUTED ... stuck with GO in EXEC"; so was Hilare's at 500,000).
    write_codels(tmp_path)
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
    write_codels(tmp_path)
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


def split_and_whole(paths: list[Path], executive: str, requests: int) -> tuple[Verification, Verification]:
    """The exploration as `specc verify` runs it (part by part when it can), and the same one
    over the whole executive at once."""
    from specc.analysis.verify import explorer_for

    loaded = load(paths)
    assert loaded.program is not None and not loaded.errors
    chosen = next(i for i in loaded.program.items if isinstance(i, m.Executive) and i.name == executive)
    whole = explorer_for(loaded.program, chosen, requests)
    whole.parts = ()
    return explorer_for(loaded.program, chosen, requests).explore(), whole.explore()


@pytest.mark.parametrize("rule, split", [
    # MOVE (module base) shares nothing with GO and BACK (module arm): two parts.
    ('moveOk: event == "START", service == "MOVE" ==> restrict status == "OK";', True),
    # A part's own fault is found with the trace the whole exploration finds.
    ('backNever: event == "START", service == "BACK" ==> restrict status == "WAIT";', True),
    # A decision for MOVE that names GO ties them: one part.
    ('moveStopsGo: event == "START", service == "MOVE" ==> do {sendAbortRequest("GO")};', False),
    # So does one that reads GO's group state.
    ('moveAfterGo: event == "START", service == "MOVE", @GOstate == "GO" ==> restrict status == "WAIT";'
     '\n  outputs GOstate: {"GO", "IDLE"};\n  init @GOstate = "IDLE";', False),
    # The general ERROR state reaches every part: explored whole once a part enters it.
    ('moveIsError: event == "START", service == "MOVE" ==> restrict status == "ERROR";', False),
])
def test_services_that_share_nothing_are_explored_part_by_part_with_the_whole_s_verdicts(
        tmp_path: Path, rule: str, split: bool) -> None:
    parted, whole = split_and_whole(robot(tmp_path, rule), "shop", 3)
    assert parted.complete and whole.complete and not whole.parts
    assert bool(parted.parts) == split
    if split:
        assert sorted(parted.parts) == [("GO", "BACK"), ("MOVE",)]
        assert parted.states < whole.states / 3  # the parts' states, not their products
        assert any(line.startswith("explored as 2 independent parts") for line in describe(parted))
    assert {p: (v.message, v.trace) for p, v in parted.violations.items()} == {
        p: (v.message, v.trace) for p, v in whole.violations.items()}


RULES = ('r: event == "START", service == "{a}" ==> restrict status == "WAIT";',
         'r: event == "START", service == "{a}" ==> restrict status == "REFUSE";',
         'r: event == "START", service == "{a}" ==> restrict status == "ERROR";',
         'r: event == "INTERM", service == "{a}" ==> restrict status == "ERROR";',
         'r: event == "START", service == "{a}" ==> do {{sendAbortRequest("{b}")}};',
         'r: event == "START", service == "{a}" ==> restrict status == "OK";')


def random_robot(folder: Path, seed: int) -> Path:
    """Three modules of two requests (incompatible in their module half the time), one service
    per request, a conflict for one service in five, and one hand-written rule of RULES (or none)."""
    rng = random.Random(seed)
    services = [f"S{i}" for i in range(6)]
    lines = []
    for module in range(3):
        lines += [f"module m{module} {{", '  codels: "arm_codels";']
        for i in (2 * module, 2 * module + 1):
            clash = f" incompatible_with: R{i ^ 1};" if rng.random() < 0.5 else ""
            lines.append(f"  request R{i} {{ type: exec; task: T; codel exec: go;{clash} }}")
        lines += ["  exec_task T { period: 10 ms; }", "}"]
    lines += ["executive shop {", "  rules: policy;"]
    for i, name in enumerate(services):
        conflicts = ""
        if rng.random() < 0.2:
            other = rng.choice([s for s in services if s != name])
            conflicts = f" conflicts {{ {other}: {rng.choice(['interrupt', 'wait'])}; }}"
        lines.append(f"  service {name} {{ request: m{i // 2}.R{i};{conflicts} }}")
    lines.append("}")
    a, b = rng.sample(services, 2)
    rule = rng.choice(RULES + ("",)).format(a=a, b=b)
    lines += ["rules policy {", f"  inputs service: {{{', '.join(map(repr, services))}}}, ".replace("'", '"')
              + 'event: {"START", "INTERM", "END", "ABORT", "ZOMBIE"};',
              '  outputs status: {"OK", "WAIT", "REFUSE", "ERROR"};', f"  {rule}", "}"]
    write_codels(folder)
    spec = folder / f"robot{seed}.spec"
    spec.write_text("\n".join(lines) + "\n")
    return spec


def test_part_by_part_and_whole_explorations_agree_on_random_robots(tmp_path: Path) -> None:
    split = refuted = 0
    for seed in range(30):
        spec = random_robot(tmp_path, seed)
        parted, whole = split_and_whole([spec], "shop", 2)
        assert parted.complete and whole.complete, spec.read_text()
        # A property two parts refute has two shortest traces: the one of either is a shortest one.
        assert {p: len(v.trace) for p, v in parted.violations.items()} == {
            p: len(v.trace) for p, v in whole.violations.items()}, spec.read_text()
        split += bool(parted.parts)
        refuted += bool(whole.violations)
    assert split >= 10 and refuted >= 5  # parts were compared with wholes, refutations too


def reachable(explorer: Any) -> set[Any]:
    """Every state key the explorer reaches (breadth first, as `explore` goes)."""
    start = explorer.key(explorer.initial())
    seen, queue = {start}, [start]
    while queue:
        key = queue.pop()
        for event in explorer.events(explorer.world(key)):
            after = explorer.key(explorer.step(explorer.world(key), event))
            if after not in seen:
                seen.add(after)
                queue.append(after)
    return seen


def projected(key: Any, part: frozenset[str], modules: set[str], groups: list[tuple[str, tuple[str, ...]]]) -> Any:
    """A state of the whole executive as its part `part` sees it: the part's activities (ranked
    again by age), its modules' entries, its groups' states (the others idle), its ZOMBIEs."""
    activities, entries, states, zombies, error = key
    ranks = {old: new for new, old in enumerate(i for i, a in enumerate(activities) if a[0] in part)}
    return (tuple(a for a in activities if a[0] in part),
            tuple((name, tuple((ranks.get(entry[0], -1),) + entry[1:] for entry in listed))
                  for name, listed in entries if name in modules),
            tuple(state if set(members) <= part else "IDLE"
                  for state, (_, members) in zip(states, groups, strict=True)),
            tuple((module, ranks[rank]) for module, rank in zombies if module in modules), error)


def test_each_part_reaches_exactly_what_the_whole_executive_shows_of_it(tmp_path: Path) -> None:
    # The split's claim itself, on random robots: the states a part reaches alone are the
    # states of the whole executive seen from that part (with as many requests outstanding),
    # for every robot whose executive never enters its ERROR state (one that does is explored
    # whole: that state reaches every part).
    from specc.analysis.verify import explorer_for

    compared = 0
    for seed in range(30):
        loaded = load([random_robot(tmp_path, seed)])
        assert loaded.program is not None
        explorer = explorer_for(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive)), 2)
        if not explorer.parts:
            continue
        whole = reachable(explorer)
        if any(key[4] for key in whole):  # the ERROR state reaches every part: explored whole
            assert explorer.explore().parts == ()
            continue
        groups = list(explorer.spec.groups.items())
        for part in map(frozenset, explorer.parts):
            explorer.asked = part
            modules = {explorer.spec.services[s].module for s in part}
            assert {projected(k, part, modules, groups) for k in whole} == reachable(explorer), seed
            explorer.asked = None
        compared += 1
    assert compared >= 10


def test_the_rovers_four_subsystems_are_verified_apart_where_the_whole_takes_minutes() -> None:
    # The ATRV's motion, pan-tilt unit, camera and radio: with 3 outstanding requests, 16,306
    # states explored whole (9 s), a few hundred part by part; the same verdicts.
    parted, whole = split_and_whole([EXAMPLES / "atrv"], "atrv", 3)
    assert parted.ok and whole.ok
    assert len(parted.parts) == 4 and parted.states * 20 < whole.states
    # The state limit counts the parts' states together, and stops at it.
    loaded = load([EXAMPLES / "atrv"])
    assert loaded.program is not None
    stopped = verify(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive)), 3, limit=100)
    assert not stopped.complete and stopped.states <= 100 and stopped.parts == parted.parts


def test_hilare_splits_where_its_hand_written_rules_do_not_reach() -> None:
    # Fig 5.6's two rules tie CALC-TRAJ-OBJ and ARM-OBJ to the motion group; the generated rules
    # that step aside for them name those services, so they tie nothing else: the camera and
    # vision services (module visual) are a part of their own.
    from specc.analysis.verify import explorer_for

    loaded = load([EXAMPLES / "hilare"])
    assert loaded.program is not None
    parts = explorer_for(loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Executive))).parts
    assert [set(p) for p in parts][1:] == [{"INIT-MODEL", "READ-OBST", "TURN-CAMERA", "TAKE-IMAGE", "SEARCH-OBJ",
                                            "GET-NEAR-OBJ"}]
    assert {"CALC-TRAJ-OBJ", "ARM-OBJ", "EXEC-TRAJ-GOAL"} <= set(parts[0])


ZOMBIE_REFLEX = """
module cam {
  codels: "arm_codels";
  request Scan { type: exec; task: T; codel exec: go; incompatible_with: Scan; }
  exec_task T { period: 10 ms; }
}
executive eye {
  service SCAN { request: cam.Scan; }
  reflex bump on warning %s => abort SCAN;
}
"""


@pytest.mark.parametrize("source", ["cam.Scan", "SCAN"])
def test_a_reflex_aborting_a_service_gone_zombie_frees_it_whichever_the_source_named(tmp_path: Path,
                                                                                     source: str) -> None:
    # Found by a user trial: on the module request's warning, the reflex used to act before the
    # executive had recorded the ZOMBIE; its abort's reply was lost and SCAN stayed ZOMBIE for good.
    # The module's client hears a reply before the reflexes do, as for the service's own warning.
    write_codels(tmp_path)
    spec = tmp_path / "eye.spec"
    spec.write_text(ZOMBIE_REFLEX % source)
    result = run([spec], "eye", 1)
    assert result.complete and result.violations == {}, result.violations


REFUSED_AGAIN = """
module ptu {
  codels: "ptu_codels";
  request Sweep { type: exec; task: Axes; fail: NO; validate: refuse; incompatible_with: Sweep; codel exec: sweep; }
  exec_task Axes { period: 100 ms; }
}
executive e {
  service SWEEP { request: ptu.Sweep; conflicts { SWEEP: interrupt; } }
  reflex again on reply SWEEP => start SWEEP;
}
"""


def test_a_reaction_loop_at_run_time_ends_in_the_error_state(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A reflex starting SWEEP again on every reply, and a module whose validate codel refuses
    it at once: each refusal is a reply, each reply a new start, at one instant. Instead of
    holding the robot at that instant for ever, the running executive enters its ERROR state,
    which refuses every request and so ends the loop, saying why. (`specc verify` finds the
    same loop: the next test.)"""
    import importlib

    from specc.runtime import executive as rx
    from specc.runtime import functional as rt
    from tests.functional.conftest import compile_robot

    (tmp_path / "ptu_codels.py").write_text("def sweep(sdi, request):\n    return 'ether'\n\n\n"
                                            "def refuse(sdi, request):\n    return 'NO'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(REFUSED_AGAIN)
    name = compile_robot(spec, tmp_path / "generated", "looping")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(tmp_path / "generated"))
    monkeypatch.setattr(rx, "CYCLES_PER_INSTANT", 500)
    registry = rt.Registry()
    importlib.import_module(f"{name}.modules").create_all(registry)
    executive = importlib.import_module(f"{name}.executive.e").create(registry)
    executive.request("SWEEP", 1)
    registry.kernel.run_for(0.5)
    assert executive.error is not None and "500 cycles at 0 s with no time passing" in executive.error


def test_verify_sees_a_validate_codel_refuse_and_finds_the_loop_it_makes(tmp_path: Path) -> None:
    """The robot of the test above: `specc verify`'s modules accept or refuse each request with a
    validate codel, as the running ones may, so the loop the running executive ends in ERROR is
    a refuted `settles`, with the refusals in its trace."""
    (tmp_path / "ptu_codels.py").write_text("def sweep(sdi, request):\n    return 'ether'\n\n\n"
                                            "def refuse(sdi, request):\n    return 'NO'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(REFUSED_AGAIN)
    result = run([spec], "e", 1)
    assert result.complete and set(result.violations) == {"settles"}, result.violations
    violation = result.violations["settles"]
    assert violation.trace[0].startswith("task: RQST EXEC SWEEP (ptu.Sweep refused by its validate codel with NO")
    assert "requests to validate codels" in violation.message


def test_a_refusal_interrupts_nothing_in_verify_as_at_run_time(tmp_path: Path) -> None:
    """A validate codel's refusal comes before the module interrupts what the request conflicts
    with (specc.runtime.functional): in the model too, a refused Point leaves Sweep running."""
    from specc.analysis.verify import Choices, explorer_for

    (tmp_path / "ptu_codels.py").write_text("def sweep(sdi, request):\n    return 'exec'\n\n\n"
                                            "def check(sdi, request):\n    return 'end'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text("""
module ptu {
  codels: "ptu_codels";
  request Point { type: exec; task: Axes; validate: check; incompatible_with: Sweep; codel exec: sweep; }
  request Sweep { type: exec; task: Axes; incompatible_with: Point; codel exec: sweep; }
  exec_task Axes { period: 100 ms; }
}
executive e {
  service POINT { request: ptu.Point; }
  service SWEEP { request: ptu.Sweep; }
}
""")
    loaded = load([spec])
    assert loaded.program is not None and not loaded.errors
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    states = {}
    for refused in (0, 1):
        explorer = explorer_for(loaded.program, executive)
        world = explorer.initial()
        world.executive.request("SWEEP", 1)
        world.registry.choices = Choices((refused,))
        world.executive.request("POINT", 2)
        module = world.registry.modules["ptu"]
        states[refused] = sorted((a.spec.name, a.state) for a in module.activities.values())
    assert states[0] == [("Point", "INIT"), ("Sweep", "INTER")]
    assert states[1] == [("Sweep", "EXEC")]


RESTARTED_CONTROL = """
module ptu {
  codels: "ptu_codels";
  request Home { type: control; validate: check; }
}
executive e {
  service HOME { request: ptu.Home; }
  reflex again on reply HOME => start HOME;
}
"""


def test_a_loop_through_a_validate_codel_on_every_answer_ends_refuted_and_incomplete(tmp_path: Path) -> None:
    """Accepted or refused, every reply starts HOME again: each sequence of answers loops, and
    there are 2^CHOICES_PER_EVENT of them. The exploration ends: `settles` refuted, the event's
    other sequences left out and said (incomplete, so nothing else is claimed proved)."""
    from specc.analysis.verify import SEQUENCES_PER_EVENT, describe

    (tmp_path / "ptu_codels.py").write_text("def check(sdi, request):\n    return 'end'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text(RESTARTED_CONTROL)
    result = run([spec], "e", 1)
    assert "settles" in result.violations and not result.complete and not result.limited
    assert result.cut and result.cut[0] == "task: RQST EXEC HOME"
    said = "\n".join(describe(result))
    assert f"not every way they may answer was explored ({SEQUENCES_PER_EVENT} at most)" in said
    assert "exclusion: holds in the states explored" in said
