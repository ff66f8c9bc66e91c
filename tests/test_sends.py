"""A request a codel sends to another module (`sends:`) can interrupt there a service the
executive runs: the incompatibility analysis sees it, so the controller aborts that service
and waits for its end before it starts the sender (issue #24, item 1)."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from specc.analysis.incompat import Arc, build_graph
from specc.analysis.verify import verify
from specc.backends import generate_all
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime import executive as rx
from specc.runtime import functional as rt

SPEC = """\
module mapper {
  number: 1;
  codels: "sends_codels";
  request Build { type: exec; task: T; codel exec: build; incompatible_with: Pause; }
  request Pause { type: exec; task: T; codel exec: pause; }
  exec_task T { period: 10 ms; }
}
module pilot {
  number: 2;
  codels: "sends_codels";
  request Go { type: exec; task: P; codel start: go_start_long; codel exec: go; sends: mapper.Pause; }
  exec_task P { period: 10 ms; }
}
executive yard {
  service MAP { request: mapper.Build; }
  service DRIVE { request: pilot.Go; }
}
"""

CODELS = '''\
def build(sdi, request):
    return "exec"  # maps until it is interrupted


def pause(sdi, request):
    return "ether"


def go_start(sdi, request):
    sdi.send_request("mapper.Pause")  # the mapper stops whatever Pause is incompatible with
    return "exec"


CYCLES = {"left": 0}


def go(sdi, request):
    CYCLES["left"] -= 1  # drives for a few cycles (0.05 s) after its start
    return "exec" if CYCLES["left"] > 0 else "ether"


def go_start_long(sdi, request):
    CYCLES["left"] = 5
    return go_start(sdi, request)
'''


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> Iterator[m.Program]:
    folder = tmp_path_factory.mktemp("yard")
    (folder / "yard.spec").write_text(SPEC)
    (folder / "sends_codels.py").write_text(CODELS)
    loaded = load([folder / "yard.spec"])
    assert loaded.program is not None and not loaded.errors, [d.headline() for d in loaded.diagnostics]
    generate_all(loaded.program, "yard").write(folder / "out" / "yard")
    sys.path[:0] = [str(folder / "out"), str(folder)]
    yield loaded.program
    sys.path[:2] = []


def executive_of(program: m.Program) -> m.Executive:
    return next(i for i in program.items if isinstance(i, m.Executive))


def test_a_sent_request_incompatible_with_a_service_s_request_is_an_arc_both_ways(yard: m.Program) -> None:
    graph = build_graph(yard, executive_of(yard))
    # Logical arcs: DRIVE aborts MAP before it starts, MAP waits while DRIVE runs (it may send).
    assert set(graph.arcs) == {Arc("DRIVE", "MAP", "interrupt", False), Arc("MAP", "DRIVE", "wait", False)}


def started(program: m.Program) -> tuple[rt.Registry, rx.Executive]:
    registry = rt.Registry()
    importlib.import_module("yard.modules").create_all(registry)
    return registry, importlib.import_module("yard.executive.yard").create(registry)


def test_the_service_a_running_sender_could_interrupt_waits_for_its_end(yard: m.Program) -> None:
    registry, executive = started(yard)
    executive.request("DRIVE", 1)
    registry.kernel.run_for(0.001)
    executive.request("MAP", 2)
    registry.kernel.run_for(0.001)
    assert executive.activities[2].state is rx.Phase.WAIT
    registry.kernel.run_for(0.2)
    assert executive.error is None and executive.activities[2].state is rx.Phase.EXEC
    assert [m.fact for m in executive.messages] == [("REPLY", 1, "OK")]


def test_the_sender_starts_once_the_service_its_request_would_interrupt_has_ended(yard: m.Program) -> None:
    registry, executive = started(yard)
    executive.request("MAP", 1)
    registry.kernel.run_for(0.05)
    executive.request("DRIVE", 2)
    registry.kernel.run_for(0.001)
    assert executive.activities[1].state is rx.Phase.INTER and executive.activities[2].state is rx.Phase.WAIT
    registry.kernel.run_for(1)
    # Without the arc, DRIVE started at once and its Pause interrupted MAP, which the executive
    # had not decided: its general ERROR state (§3.4.2).
    assert executive.error is None
    assert [m.fact for m in executive.messages] == [("REPLY", 1, "INT"), ("REPLY", 2, "OK")]


def test_verify_proves_the_yard_s_executive(yard: m.Program) -> None:
    result = verify(yard, executive_of(yard), 2)
    assert result.ok and result.complete, result.violations


def test_verify_finds_a_hand_written_rule_that_lets_the_sent_request_interrupt_a_service(
        tmp_path: Path) -> None:
    # A rule of the executive's own starting DRIVE at once takes over the generated abort-and-wait:
    # the modules' requests (`sends:`) are in verify's model, so the interference is found.
    (tmp_path / "sends_codels.py").write_text(CODELS)
    spec = tmp_path / "yard.spec"
    spec.write_text(SPEC.replace("executive yard {", "executive yard {\n  rules: eager;") + """
rules eager {
  inputs service: {"MAP", "DRIVE"}, event: {"START", "INTERM", "END", "ABORT", "ZOMBIE"};
  outputs status: {"OK", "WAIT", "REFUSE", "ERROR"};
  driveAtOnce: event == "START", service == "DRIVE" ==> restrict status == "OK";
}
""")
    loaded = load([spec])
    assert loaded.program is not None and not loaded.errors, [d.headline() for d in loaded.diagnostics]
    result = verify(loaded.program, executive_of(loaded.program), 2)
    assert "no-error" in result.violations
    trace = result.violations["no-error"].trace
    assert "pilot: Go sends mapper.Pause" in trace and "task: RQST EXEC MAP" in trace, trace
    assert "MAP" in result.violations["no-error"].message


def test_two_services_whose_requests_interrupt_each_other_get_the_same_arcs_in_any_order(tmp_path: Path) -> None:
    # Each of GO and BACK sends the other's module a request incompatible with the other's: both
    # interrupt (by an abort) whichever is declared first; no wait arc hides an interrupt one.
    module = """
module %s {
  number: %d;
  request Run { type: exec; task: T; codel exec: run; sends: %s.Halt; }
  request Halt { type: exec; task: T; codel exec: run; incompatible_with: Run; }
  exec_task T { period: 10 ms; }
}"""
    spec = (module % ("a", 1, "b") + module % ("b", 2, "a")).replace("%", "%%") + "\nexecutive ex { %s }\n"
    services = ["service GO { request: a.Run; }", "service BACK { request: b.Run; }"]
    found = []
    for order in (services, services[::-1]):
        (tmp_path / "x.spec").write_text(spec % " ".join(order))
        loaded = load([tmp_path / "x.spec"], check=False)
        assert loaded.program is not None
        found.append(set(build_graph(loaded.program, executive_of(loaded.program)).arcs))
    assert found[0] == found[1] == {Arc("GO", "BACK", "interrupt", False), Arc("BACK", "GO", "interrupt", False)}
