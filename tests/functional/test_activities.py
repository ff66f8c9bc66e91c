"""The activity control graph of seed 000 Fig. 2.3 (every arc), the codel sub-states of
Fig. 2.4, and every status of Table 2.1, on a generated module whose codels play scripts."""

from __future__ import annotations

import re

from specc.runtime import functional as rt
from specc.runtime.functional import State, Status
from tests.functional.conftest import Robot

E, INIT, X, N, Z = State.ETHER, State.INIT, State.EXEC, State.INTER, State.ZOMBIE


def transitions(module: rt.Module, rqst_id: int) -> list[tuple[State, State]]:
    return [(a, b) for i, a, b in module.transitions if i == rqst_id]


def send(robot: Robot, request: str, script: str) -> tuple[int, list[rt.Reply]]:
    """Submit through a recording sink: the replies in the order the module sent them."""
    replies: list[rt.Reply] = []
    record = getattr(robot.package.alpha, f"{request}Input")(script=script)
    return robot.alpha.submit(request, record, replies.append), replies


def test_nominal_life_ether_init_exec_ether(robot: Robot) -> None:
    rqst, replies = send(robot, "C", "exec,exec,ether")
    robot.kernel.run_for(0.1)
    assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, X), (X, E)]
    assert [(r.final, r.status) for r in replies] == [(False, Status.WAITING), (True, Status.END)]
    assert replies[0].report.code == "final" and replies[1].report.code == "OK"
    assert replies[1].output.step == 3


def test_refused_by_validation_init_ether(robot: Robot) -> None:
    rqst, replies = send(robot, "Checked", "bad")
    assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, E)]
    assert [(r.status, r.report.code) for r in replies] == [(Status.FINAL_ERROR, "BAD_SCRIPT")]


def test_interrupted_while_waiting_in_init(robot: Robot) -> None:
    first, _ = send(robot, "A", "exec," * 20)
    robot.kernel.run_for(0.03)
    waiting, replies = send(robot, "B", "exec")  # waits in INIT for A's interruption codel
    newest, _ = send(robot, "A", "exec")  # interrupts B before it ever started
    assert transitions(robot.alpha, waiting) == [(E, INIT), (INIT, E)]
    assert [(r.status, r.report.code) for r in replies] == [(Status.INTERRUPTED, "A")]
    robot.kernel.run_for(0.1)
    assert transitions(robot.alpha, first)[-2:] == [(X, N), (N, E)]
    assert transitions(robot.alpha, newest) == [(E, INIT), (INIT, X), (X, E)]


def test_failed_exec_zombie_freezes_module_until_abort(robot: Robot) -> None:
    rqst, replies = send(robot, "C", "exec,zombie")
    robot.kernel.run_for(0.05)
    assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, X), (X, Z)]
    assert replies[-1].status is Status.ZOMBIE
    refused, refusal = send(robot, "B", "exec")
    assert [(r.status, r.report.code) for r in refusal] == [(Status.ZOMBIE, "MODULE_FROZEN")]
    assert robot.client().abort(rqst).status is Status.END
    assert transitions(robot.alpha, rqst)[-1] == (Z, E)
    accepted, replies = send(robot, "B", "exec")
    robot.kernel.run_for(0.05)
    assert [r.status for r in replies] == [Status.WAITING, Status.END]


def test_abort_exec_inter_ether_reports_abort(robot: Robot) -> None:
    rqst, replies = send(robot, "A", "exec," * 50)
    robot.kernel.run_for(0.05)
    assert robot.client().abort(rqst).status is Status.END
    robot.kernel.run_for(0.05)
    assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, X), (X, N), (N, E)]
    assert (replies[-1].status, replies[-1].report.code) == (Status.INTERRUPTED, "ABORT")
    assert replies[-1].output.trace.endswith(",inter")


def test_failed_during_inter_goes_zombie(robot: Robot) -> None:
    robot.alpha.sdi.inter_outcome = "zombie"
    rqst, replies = send(robot, "A", "exec," * 50)
    robot.kernel.run_for(0.03)
    robot.client().abort(rqst)
    robot.kernel.run_for(0.03)
    assert transitions(robot.alpha, rqst)[-2:] == [(X, N), (N, Z)]
    assert replies[-1].status is Status.ZOMBIE and robot.alpha.zombie is not None


def test_every_arc_of_fig_2_3_is_exercised_by_the_tests_above(robot: Robot) -> None:
    # One run touching every arc, checked against the runtime's own list of the nine arcs.
    robot.alpha.sdi.inter_outcome = ""
    a, _ = send(robot, "A", "exec," * 20)
    send(robot, "Checked", "bad")
    robot.kernel.run_for(0.03)
    send(robot, "B", "exec")
    send(robot, "A", "exec")
    robot.kernel.run_for(0.1)
    z, _ = send(robot, "C", "zombie")
    robot.kernel.run_for(0.03)
    robot.client().abort(z)
    robot.alpha.sdi.inter_outcome = "zombie"
    c, _ = send(robot, "C", "exec," * 20)
    robot.kernel.run_for(0.03)
    robot.client().abort(c)
    robot.kernel.run_for(0.03)
    seen = {(a_, b_) for _, a_, b_ in robot.alpha.transitions}
    assert seen == {(source, target) for source, _, target in rt.ARCS}
    assert len(rt.ARCS) == 9


def test_codel_sub_states_follow_what_each_codel_returns(robot: Robot) -> None:
    rqst, replies = send(robot, "A", "named,exec,named,end")
    robot.kernel.run_for(0.1)
    assert replies[-1].output.trace == "start,named,exec,named,end"
    assert replies[-1].status is Status.END


def test_intrinsic_failure_runs_the_end_codel_and_reports_the_fail_message(robot: Robot) -> None:
    rqst, replies = send(robot, "A", "exec,OOPS")
    robot.kernel.run_for(0.1)
    assert (replies[-1].status, replies[-1].report.code) == (Status.END, "OOPS")
    assert replies[-1].output.trace == "start,exec,end"


def test_extrinsic_failures_are_final_errors_not_crashes(robot: Robot) -> None:
    outcomes = {}
    for script in ("raise", "exit", "none", "NOT_A_STATE", "end2"):
        _, replies = send(robot, "C", script)
        robot.kernel.run_for(0.05)
        outcomes[script] = (replies[-1].status, replies[-1].report.code)
    assert outcomes == {  # a codel's sys.exit() is its bug too: the run goes on
        "raise": (Status.FINAL_ERROR, "CODEL_ERROR"), "exit": (Status.FINAL_ERROR, "CODEL_ERROR"),
        "none": (Status.FINAL_ERROR, "UNDECLARED_STATE"),
        "NOT_A_STATE": (Status.FINAL_ERROR, "UNDECLARED_STATE"), "end2": (Status.FINAL_ERROR, "UNDECLARED_STATE")}
    _, replies = send(robot, "C", "raise")  # where the codel raised, as file:line
    robot.kernel.run_for(0.05)
    assert re.search(r"raised ValueError: scripted failure \(.*scripted_codels/__init__\.py:\d+\)$",
                     replies[-1].report.detail), replies[-1].report.detail
    _, replies = send(robot, "Checked", "end")  # declared `-> exec, ether`: `end` is not allowed
    robot.kernel.run_for(0.05)
    assert (replies[-1].status, replies[-1].report.code) == (Status.FINAL_ERROR, "UNDECLARED_STATE")
    assert "declared" in replies[-1].report.detail


def test_status_dictionary_of_table_2_1(robot: Robot) -> None:
    client = robot.client()
    seen: dict[Status, rt.Reply] = {}
    seen[Status.CS_ERROR] = client.call("NoSuchRequest")
    pending = client.send("C", robot.package.alpha.CInput(script="exec," * 30))
    seen[Status.WAITING] = client.reply(pending)
    assert seen[Status.WAITING].report.code == "final"  # accepted at once: the final reply is awaited
    seen[Status.TIMEOUT] = client.final(pending, timeout=0.05)
    seen[Status.END] = client.final(pending)
    seen[Status.FINAL_ERROR] = client.call("Set", robot.package.alpha.SetInput(value="fast"))
    running = client.send("A", robot.package.alpha.AInput(script="exec," * 30))
    client.interm(running)
    client.abort(running)
    seen[Status.INTERRUPTED] = client.final(running)
    seen[Status.ZOMBIE] = client.call("C", robot.package.alpha.CInput(script="zombie"))
    robot.client().abort(seen[Status.ZOMBIE].rqst_id)
    seen[Status.SERVER_ERROR] = client.call("Parent", robot.package.alpha.ParentInput(script="send:raise,exec,exec"))
    assert {status: reply.status for status, reply in seen.items()} == {status: status for status in Status}
    assert seen[Status.TIMEOUT].report.code == "final"
    assert not seen[Status.TIMEOUT].final and seen[Status.END].final  # the client gave up; the request went on
    assert seen[Status.FINAL_ERROR].report.code == "BAD_INPUT"
    assert seen[Status.INTERRUPTED].report.code == "ABORT"
    chain = seen[Status.SERVER_ERROR].report.chain()
    assert [(r.module, r.request, r.status, r.report.code) for r in chain] == [
        ("beta", "Child", Status.FINAL_ERROR, "CODEL_ERROR")]


def test_control_requests_answer_at_once_and_may_interrupt(robot: Robot) -> None:
    client = robot.client()
    before = robot.kernel.now
    reply = client.call("Set", robot.package.alpha.SetInput(value=2.5))
    assert reply.status is Status.END and robot.kernel.now == before and robot.alpha.sdi.value == 2.5
    assert client.call("Set", robot.package.alpha.SetInput(value=-1.0)).report.code == "NEGATIVE"
    running = client.send("A", robot.package.alpha.AInput(script="exec," * 30))
    client.interm(running)
    assert client.call("Reset").status is Status.END
    interrupted = client.final(running)
    assert (interrupted.status, interrupted.report.code) == (Status.INTERRUPTED, "Reset")


def test_most_recent_incompatible_request_wins_and_replies_are_ordered(robot: Robot) -> None:
    log: list[tuple[int, bool, Status]] = []

    def sink(reply: rt.Reply) -> None:
        log.append((reply.rqst_id, reply.final, reply.status))

    old = robot.alpha.submit("A", robot.package.alpha.AInput(script="exec," * 30), sink)
    robot.kernel.run_for(0.03)
    new = robot.alpha.submit("B", robot.package.alpha.BInput(script="exec"), sink)
    robot.kernel.run_for(0.05)
    assert log == [(old, False, Status.WAITING), (old, True, Status.INTERRUPTED),
                   (new, False, Status.WAITING), (new, True, Status.END)]


def test_compatible_activities_run_together(robot: Robot) -> None:
    client = robot.client()
    ids = [client.send(r, getattr(robot.package.alpha, f"{r}Input")(script="exec," * 5)) for r in ("A", "C", "C")]
    robot.kernel.run_for(0.02)
    assert sorted(a.state for a in robot.alpha.activities.values()) == [State.EXEC] * 3
    assert [client.final(i).status for i in ids] == [Status.END] * 3


def test_interrupting_a_parent_interrupts_its_children_first(robot: Robot) -> None:
    order: list[tuple[str, State, State]] = []
    for module in (robot.alpha, robot.beta):
        module.observers.append(lambda mod, activity, a, b: order.append((activity.spec.name, a, b)))
    replies: list[rt.Reply] = []
    parent = robot.alpha.submit("Parent", robot.package.alpha.ParentInput(
        script="send:" + "exec;" * 50 + "," + "exec," * 50), replies.append)
    robot.kernel.run_for(0.05)
    assert [a.spec.name for a in robot.beta.activities.values()] == ["Child"]
    robot.alpha.abort(parent)
    robot.kernel.run_for(0.1)
    child_ended = order.index(("Child", N, E))
    parent_inter = order.index(("Parent", X, N))
    parent_ended = order.index(("Parent", N, E))
    assert parent_inter < child_ended < parent_ended
    assert (replies[-1].status, replies[-1].report.code) == (Status.INTERRUPTED, "ABORT")
    assert not robot.beta.activities and not robot.alpha.activities


def test_a_parent_that_ends_waits_for_its_children(robot: Robot) -> None:
    client = robot.client()
    reply = client.call("Parent", robot.package.alpha.ParentInput(script="send:" + "exec;" * 10 + ",ether"))
    assert reply.status is Status.END
    (child_end,) = [t for t in robot.beta.transitions if t[2] is E]
    assert not robot.beta.activities and child_end is not None


def test_posters_are_dated_copies_updated_by_their_activity(robot: Robot) -> None:
    client = robot.client()
    assert client.poster("Status") is None or client.poster("Status").data.counter >= 0
    robot.kernel.run_for(0.1)
    snapshot = client.poster("Status")
    assert snapshot is not None and snapshot.data.counter == robot.alpha.sdi.counter
    assert abs(snapshot.date - 0.09) < 1e-9  # the Perm task ticks at 10 ms + k * 20 ms
    snapshot.data.counter = -1
    assert client.poster("Status").data.counter == robot.alpha.sdi.counter


def test_control_poster_lists_activities_and_states(robot: Robot) -> None:
    client = robot.client()
    rqst = client.send("C", robot.package.alpha.CInput(script="exec," * 10))
    client.interm(rqst)
    (info,) = robot.alpha.control_poster().data
    assert (info.rqst_id, info.request, info.state) == (rqst, "C", State.EXEC)


def test_client_timeout_on_the_intermediate_reply(robot: Robot) -> None:
    client = robot.client()
    client.send("A", robot.package.alpha.AInput(script="exec," * 50))
    robot.kernel.run_for(0.02)
    robot.alpha.sdi.inter_outcome = "inter"  # the interruption codel asks for more cycles...
    waiting = client.send("B", robot.package.alpha.BInput(script="exec"), interm_timeout=0.05)
    assert (client.reply(waiting).status, client.reply(waiting).report.code) == (Status.WAITING, "interm")
    reply = client.final(waiting, timeout=0.2)
    assert (reply.status, reply.report.code) == (Status.TIMEOUT, "interm")


def test_exec_tasks_run_by_period_delay_and_priority(scripted_package) -> None:  # type: ignore[no-untyped-def]
    import scripted_codels.alpha as codels  # type: ignore[import-not-found]

    registry = rt.Registry()
    calls: list[tuple[float, str]] = []

    class Logged:
        """The alpha codels, each call logged with the simulated time."""

        def __getattr__(self, name: str):  # type: ignore[no-untyped-def]
            function = getattr(codels, name)

            def logged(*args):  # type: ignore[no-untyped-def]
                calls.append((round(registry.kernel.now, 6), name))
                return function(*args)
            return logged

    made = scripted_package.create_all(registry, {"alpha": Logged()})
    made["alpha"].submit("C", scripted_package.alpha.CInput(script="exec," * 10), lambda reply: None)
    registry.kernel.run_for(0.035)
    # Perm: period 20 ms, delay 10 ms, priority 1; T: period 10 ms, priority 2 (runs after Perm).
    # Perm's init codel runs as the module starts, before any request is served.
    assert calls == [(0.0, "init_perm"), (0.0, "play_exec"), (0.01, "perm"), (0.01, "play_exec"),
                     (0.02, "play_exec"), (0.03, "perm"), (0.03, "play_exec")]
