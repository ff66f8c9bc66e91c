"""Corner cases of the functional level: reply order when several activities must give way,
codels that end their own activity while running, children that cannot be activated, several
ZOMBIEs, control request outputs, posters named by a request's codel, the exec task grid."""

from __future__ import annotations

import types
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from specc.runtime import functional as rt
from specc.runtime.functional import State, Status
from tests.functional.conftest import Robot

E, INIT, X, N, Z = State.ETHER, State.INIT, State.EXEC, State.INTER, State.ZOMBIE


def send(robot: Robot, request: str, script: str, log: list[rt.Reply] | None = None) -> tuple[int, list[rt.Reply]]:
    replies: list[rt.Reply] = [] if log is None else log
    record = getattr(robot.package.alpha, f"{request}Input")(script=script)
    return robot.alpha.submit(request, record, replies.append), replies


def test_a_newcomer_waits_for_every_activity_it_interrupts(robot: Robot) -> None:
    # A (INTER for a long time) holds up B (INIT); C runs. E conflicts with B and C, not A:
    # it must not start before C has left INTER, and C's final reply comes before E's
    # intermediate one, even though B (earlier in the module's list) gives way at once.
    robot.alpha.sdi.inter_outcome = "inter"
    log: list[rt.Reply] = []
    a, _ = send(robot, "A", "exec," * 50, log)
    robot.kernel.run_for(0.02)
    b, _ = send(robot, "B", "exec", log)
    c, _ = send(robot, "C", "exec," * 50, log)
    robot.kernel.run_for(0.02)
    assert robot.alpha.activities[b].state is INIT and robot.alpha.activities[c].state is X
    e, _ = send(robot, "E", "exec", log)
    assert robot.alpha.activities[e].state is INIT
    robot.alpha.sdi.inter_outcome = "ether"
    robot.kernel.run_for(0.1)
    order = [(r.rqst_id, r.final) for r in log if r.rqst_id in (c, e)]
    assert order == [(c, False), (c, True), (e, False), (e, True)]


def test_a_codel_that_sends_a_refused_child_and_returns_zombie_does_not_crash(robot: Robot) -> None:
    # alpha.Checked refuses a "bad" script in its validate codel: the parent ends at once with the
    # child's error chained, and what its codel returns afterwards is ignored (one final reply).
    for outcome in ("zombie", "ether", "OOPS", "exec"):
        rqst, replies = send(robot, "C", f"to:alpha.Checked:bad:{outcome}")
        robot.kernel.run_for(0.05)
        assert [r.final for r in replies] == [False, True], outcome
        assert replies[-1].status is Status.FINAL_ERROR and replies[-1].report.code == "CHILD_NOT_ACTIVATED"
        assert [(r.request, r.report.code) for r in replies[-1].report.chain()] == [("Checked", "BAD_SCRIPT")]
        assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, X), (X, E)]
        assert robot.alpha.zombie is None and not robot.alpha.activities


def transitions(module: rt.Module, rqst_id: int) -> list[tuple[State, State]]:
    return [(a, b) for i, a, b in module.transitions if i == rqst_id]


def test_a_codel_interrupting_its_own_activity_goes_through_inter(robot: Robot) -> None:
    # Reset (control, incompatible with A) sent by A's own codel interrupts A: whatever the codel
    # returns, A passes through INTER, runs its inter codel and ends INTERRUPTED.
    rqst, replies = send(robot, "A", "to:alpha.Reset:-:ether")
    robot.kernel.run_for(0.05)
    assert transitions(robot.alpha, rqst) == [(E, INIT), (INIT, X), (X, N), (N, E)]
    assert (replies[-1].status, replies[-1].report.code) == (Status.INTERRUPTED, "Reset")
    assert replies[-1].output.trace.endswith(",inter")


def test_children_that_cannot_be_activated_end_the_parent(robot: Robot) -> None:
    cases: dict[str, tuple[Status, str] | None] = {
        "to:beta.Nope:x:exec": (Status.CS_ERROR, "UNKNOWN_REQUEST"),
        "to:gamma.Child:x:exec": (Status.CS_ERROR, "UNKNOWN_MODULE"),
        "to:beta.Child:exec;exec:exec": None,  # accepted: the parent runs on (reference case)
    }
    for script, expected in cases.items():
        status, code = expected or (None, "")
        _, replies = send(robot, "C", script + "," + "exec," * 20)
        robot.kernel.run_for(0.3)
        final = replies[-1]
        if status is None:
            assert final.status is Status.END, script
            continue
        assert (final.status, final.report.code) == (Status.FINAL_ERROR, "CHILD_NOT_ACTIVATED"), script
        assert [(r.status, r.report.code) for r in final.report.chain()] == [(status, code)], script
    # A control request is no child: its refusal (Reset takes no input) is the codel's to handle.
    _, replies = send(robot, "C", "to:alpha.Reset:x:exec,exec")
    robot.kernel.run_for(0.05)
    assert replies[-1].status is Status.END


def test_a_child_refused_by_a_frozen_module_ends_the_parent(robot: Robot) -> None:
    zombie = robot.beta.submit("Child", robot.package.beta.ChildInput(script="zombie"), lambda reply: None)
    robot.kernel.run_for(0.05)
    assert robot.beta.zombie is not None and robot.beta.zombie.id == zombie
    _, replies = send(robot, "Parent", "send:exec," + "exec," * 20)
    robot.kernel.run_for(0.05)
    assert (replies[-1].status, replies[-1].report.code) == (Status.FINAL_ERROR, "CHILD_NOT_ACTIVATED")
    (cause,) = replies[-1].report.chain()
    assert (cause.module, cause.status, cause.report.code) == ("beta", Status.ZOMBIE, "MODULE_FROZEN")


def test_a_child_that_goes_zombie_ends_its_parent_with_server_error(robot: Robot) -> None:
    _, replies = send(robot, "Parent", "send:exec;zombie," + "exec," * 20)
    robot.kernel.run_for(0.1)
    assert (replies[-1].status, replies[-1].report.code) == (Status.SERVER_ERROR, "CHILD_ERROR")
    (cause,) = replies[-1].report.chain()
    assert (cause.module, cause.status) == ("beta", Status.ZOMBIE)
    assert robot.beta.zombie is not None and not robot.alpha.activities


def test_the_module_stays_frozen_while_any_activity_is_zombie(robot: Robot) -> None:
    first, _ = send(robot, "C", "zombie")
    second, _ = send(robot, "C", "zombie")
    robot.kernel.run_for(0.05)
    assert robot.client().abort(second).status is Status.END
    _, refused = send(robot, "B", "exec")
    assert [(r.status, r.report.code) for r in refused] == [(Status.ZOMBIE, "MODULE_FROZEN")]
    assert robot.client().abort(first).status is Status.END
    _, accepted = send(robot, "B", "exec")
    assert accepted[0].status is Status.WAITING


def test_an_activity_waiting_in_init_does_not_start_once_the_module_is_frozen(robot: Robot) -> None:
    robot.alpha.sdi.inter_outcome = "zombie"
    old, _ = send(robot, "A", "exec," * 50)
    robot.kernel.run_for(0.02)
    new, replies = send(robot, "B", "exec")  # waits for A's interruption, which goes ZOMBIE
    robot.kernel.run_for(0.05)
    assert robot.alpha.activities[old].state is Z
    assert transitions(robot.alpha, new) == [(E, INIT), (INIT, E)]
    assert [(r.final, r.status, r.report.code) for r in replies] == [(True, Status.ZOMBIE, "MODULE_FROZEN")]


def test_a_control_request_validate_codel_fills_its_output(robot: Robot) -> None:
    client = robot.client()
    client.call("Set", robot.package.alpha.SetInput(value=4.5))
    reply = client.call("Get")
    assert reply.status is Status.END and reply.output.value == 4.5


def test_a_poster_named_after_a_request_codel_is_updated_by_its_cycles(robot: Robot) -> None:
    client = robot.client()
    client.call("Set", robot.package.alpha.SetInput(value=7.0))
    # The poster exists from the module's start with the initialised SDI; Set does not update it.
    initial = client.poster("Named")
    assert initial is not None and initial.data.copied == 0.0 and initial.date == 0.0
    send(robot, "A", "copy,named,exec,exec")
    robot.kernel.run_for(0.1)
    snapshot = client.poster("Named")
    assert snapshot is not None and snapshot.data.copied == 7.0
    assert abs(snapshot.date - 0.02) < 1e-9  # start at 0, exec (copy) at 10 ms, named at 20 ms


def test_a_poster_named_after_a_control_request_is_updated_when_it_runs(robot: Robot) -> None:
    # A control request's one cycle is its validate codel: the poster shows what it wrote, by the
    # time the client has its reply.
    client = robot.client()
    robot.kernel.run_for(0.05)
    reply = client.call("Set", robot.package.alpha.SetInput(value=2.5))
    snapshot = client.poster("Settings")
    assert reply.status is Status.END and snapshot is not None
    assert snapshot.data.value == 2.5 and abs(snapshot.date - robot.kernel.now) < 1e-9 and snapshot.date > 0
    # A refused one (its validate codel returned a fail message) leaves the poster as it was.
    robot.kernel.run_for(0.05)
    refused = client.call("Set", robot.package.alpha.SetInput(value=-1.0))
    assert refused.report.code == "NEGATIVE" and client.poster("Settings") == snapshot


def test_a_codel_setting_an_enum_field_to_no_value_of_its_enum_is_a_codel_error(robot: Robot) -> None:
    # A value's name (or the member itself) is one of its values; a misspelt one fails the
    # activity at once, naming the field, the values and the codel, and the field keeps its value.
    _, replies = send(robot, "C", "mode:BUSY,ether")
    robot.kernel.run_for(0.05)
    # The name given became the member, which equals its name too: codels may compare either way.
    mode = robot.alpha.sdi.mode
    busy = type(mode).BUSY
    assert replies[-1].status is Status.END and mode is busy and mode == "BUSY" and "BUSY" == mode
    _, replies = send(robot, "C", "mode:BUSSY,exec")
    robot.kernel.run_for(0.05)
    final = replies[-1]
    assert final.status is Status.FINAL_ERROR and final.report.code == "CODEL_ERROR"
    assert "field 'mode' was left holding 'BUSSY' (in " in final.report.detail
    assert "(IDLE, BUSY)" in final.report.detail
    assert "did you mean 'BUSY'?" in final.report.detail and "scripted_codels" in final.report.detail
    assert robot.alpha.sdi.mode == "BUSY"


def test_a_client_may_give_an_enum_input_by_its_name_and_a_misspelt_one_is_refused(robot: Robot) -> None:
    # The typed client's `SetMode("BUSY")`, as a codel's `sdi.mode = "BUSY"`: the module takes the
    # name for its member; a misspelt name is BAD_INPUT naming the values, before any codel runs.
    typed = robot.package.alpha.client(robot.alpha)
    reply = typed.final(typed.SetMode("BUSY"))
    mode = robot.alpha.sdi.mode
    assert reply.status is Status.END and mode is type(mode).BUSY
    refused = typed.final(typed.SetMode("IDEL"))
    assert refused.status is Status.FINAL_ERROR and refused.report.code == "BAD_INPUT"
    assert refused.report.detail == "mode: 'IDEL' is not a Mode (IDLE, BUSY) (did you mean 'IDLE'?)"
    assert robot.alpha.sdi.mode is mode
    record = robot.package.alpha.SetModeInput(mode="IDLE")  # a record built by hand, through the plain client
    assert robot.client().call("SetMode", record).status is Status.END and robot.alpha.sdi.mode == "IDLE"


def test_an_output_of_the_wrong_type_is_the_codel_s_error_and_whole_numbers_of_doubles_become_floats(
        robot: Robot) -> None:
    """`request.trace = 7` into a string output: the activity ends with CODEL_ERROR naming the
    output, as an input of the wrong type is refused, not with END and a number its client reads
    as text. A whole number written into a double is the float the type says."""
    from specc.runtime.functional import as_declared

    _, replies = send(robot, "A", "badtrace")
    robot.kernel.run_for(0.05)
    final = replies[-1]
    assert final.status is Status.FINAL_ERROR and final.report.code == "CODEL_ERROR"
    assert final.report.detail == "the output of A: trace: expected str, got int"
    output = robot.package.alpha.GetOutput(value=3)
    as_declared(output)
    assert output.value == 3.0 and isinstance(output.value, float)


def test_manual_posters_are_written_by_codels_and_unknown_ones_are_codel_errors(robot: Robot) -> None:
    client = robot.client()
    client.call("Set", robot.package.alpha.SetInput(value=3.0))
    send(robot, "C", "write:Manual")
    robot.kernel.run_for(0.05)
    snapshot = client.poster("Manual")
    assert snapshot is not None and snapshot.data.value == 3.0 and snapshot.date == 0.0
    _, replies = send(robot, "C", "write:Nope")
    robot.kernel.run_for(0.05)
    assert (replies[-1].status, replies[-1].report.code) == (Status.FINAL_ERROR, "CODEL_ERROR")
    assert "no poster 'Nope'" in replies[-1].report.detail


def test_waiting_for_the_intermediate_reply_can_time_out(robot: Robot) -> None:
    client = robot.client()
    robot.alpha.sdi.inter_outcome = "inter"
    client.send("A", robot.package.alpha.AInput(script="exec," * 50))
    robot.kernel.run_for(0.02)
    waiting = client.send("B", robot.package.alpha.BInput(script="exec"))
    reply = client.interm(waiting, timeout=0.05)
    assert (reply.status, reply.report.code) == (Status.TIMEOUT, "interm")
    assert client.reply(waiting).status is Status.WAITING  # only this wait gave up


def test_final_listeners_hear_each_final_reply_once_a_client_timeout_included(robot: Robot) -> None:
    client = robot.client()
    heard: list[rt.Reply] = []
    client.final_listeners.append(heard.append)
    ended = client.send("C", robot.package.alpha.CInput(script="exec"))
    late = client.send("A", robot.package.alpha.AInput(script="exec," * 50), final_timeout=0.05)
    robot.kernel.run_for(0.02)
    assert [(r.rqst_id, r.status) for r in heard] == [(ended, Status.END)]  # no intermediate reply
    robot.kernel.run_for(1.0)
    assert [(r.rqst_id, r.status) for r in heard] == [(ended, Status.END), (late, Status.TIMEOUT)]
    assert late not in robot.alpha.activities  # A ended meanwhile: its own final reply is not heard
    assert heard[-1] is client.reply(late)


@dataclass
class _Data(rt.InternalData):
    pass


def test_tasks_due_at_the_same_instant_run_in_priority_order_despite_rounding() -> None:
    # 3 x 0.1 s is 0.30000000000000004 in floating point: the 100 ms and 300 ms grids still meet.
    registry = rt.Registry()
    calls: list[tuple[float, str]] = []
    codels = types.SimpleNamespace(
        fast=lambda sdi: calls.append((registry.kernel.now, "fast")),
        slow=lambda sdi: calls.append((registry.kernel.now, "slow")))
    spec = rt.ModuleSpec(name="grid", number=0, codel_module="", sdi_type=_Data, requests={}, tasks=(
        rt.ExecTaskSpec(name="Slow", period=0.3, priority=2, permanent="slow"),
        rt.ExecTaskSpec(name="Fast", period=0.1, priority=1, permanent="fast")))
    registry.add(spec, codels)
    registry.kernel.run_for(0.65)
    at = {round(t, 6): [n for u, n in calls if round(u, 6) == round(t, 6)] for t, _ in calls}
    assert at[0.0] == at[0.3] == at[0.6] == ["fast", "slow"]
    assert len(calls) == 7 + 3


def with_codels(robot: Robot, **replaced: object) -> Robot:
    """The scripted robot on a fresh registry, some alpha codels replaced."""
    import scripted_codels.alpha as alpha  # type: ignore[import-not-found]

    codels = types.SimpleNamespace(**{n: getattr(alpha, n) for n in dir(alpha) if not n.startswith("_")})
    for name, function in replaced.items():
        setattr(codels, name, function)
    registry = rt.Registry()
    made = robot.package.create_all(registry, {"alpha": codels})
    return Robot(registry, made["alpha"], made["beta"], robot.package)


def test_a_control_codel_writing_no_output_is_a_codel_error(robot: Robot) -> None:
    def get_value(sdi, request):  # type: ignore[no-untyped-def]
        request.valeu = sdi.value
        return "end"

    reply = with_codels(robot, get_value=get_value).client().call("Get")
    assert (reply.status, reply.report.code) == (Status.FINAL_ERROR, "CODEL_ERROR")
    assert "no output 'valeu'" in reply.report.detail


def test_a_codel_writing_a_field_the_sdi_does_not_declare_is_a_codel_error_naming_it(robot: Robot) -> None:
    def get_value(sdi, request):  # type: ignore[no-untyped-def]
        sdi.valeu = 3  # a typo: without the check, a new field nobody reads and the reply OK
        return "end"

    reply = with_codels(robot, get_value=get_value).client().call("Get")
    assert (reply.status, reply.report.code) == (Status.FINAL_ERROR, "CODEL_ERROR")
    assert "module alpha's SDI has no field 'valeu' (did you mean 'value'?" in reply.report.detail
    line = get_value.__code__.co_firstlineno + 1  # where the codel wrote it
    assert reply.report.detail.endswith(f"internal_data) (tests/functional/test_edge_cases.py:{line})"), \
        reply.report.detail


def test_a_request_sent_by_a_validate_codel_is_nobody_s_child(robot: Robot) -> None:
    def check_script(sdi, request):  # type: ignore[no-untyped-def]
        sdi.send_request("beta.Child", script="exec")
        return "end"

    other = with_codels(robot, check_script=check_script)
    parent, _ = send(other, "C", "to:alpha.Checked:exec:exec,exec,exec")
    other.kernel.run_for(0.005)
    (child,) = other.alpha.activities[parent].children
    assert child.spec.name == "Checked" and not child.children
    (sent,) = other.beta.activities.values()
    assert sent.parent is None


@pytest.mark.parametrize(("body", "said"), [
    ("from greenhouse.rules.waterin import decide\n", "its codels 'broken_codels_{n}.arm' import what cannot be found"
                                                      ": No module named 'greenhouse'"),
    ("x = 1\nundefined_name()\n", "importing its codels 'broken_codels_{n}.arm' failed: NameError"),
])
def test_codels_that_fail_to_import_are_told_apart_from_codels_not_found(tmp_path: Path, monkeypatch: Any,
                                                                         body: str, said: str) -> None:
    from specc.runtime.functional import load_codels

    n = len(body)  # a package name of its own per case: nothing cached from the other
    package = tmp_path / f"broken_codels_{n}"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "arm.py").write_text(body)
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ImportError) as raised:
        load_codels(types.SimpleNamespace(name="arm", codel_module=f"broken_codels_{n}.arm"))  # type: ignore[arg-type]
    message = str(raised.value)
    assert said.format(n=n) in message and "sys.path" not in message
    assert f"{package / 'arm.py'}:{body.count(chr(10))}" in message  # where: the line that failed
    with pytest.raises(ImportError, match="put the folder holding them on sys.path"):
        load_codels(types.SimpleNamespace(name="arm", codel_module="no_such_codels_anywhere.arm"))  # type: ignore[arg-type]


def test_a_permanent_codel_that_raises_leaves_its_poster_s_date_alone(robot: Robot) -> None:
    import scripted_codels.alpha as codels  # the fixture put tests/functional on sys.path

    unplugged = False

    def perm(sdi: Any) -> str:
        if unplugged:
            raise RuntimeError("sensor unplugged")
        return str(codels.perm(sdi))

    registry = rt.Registry()
    robot.package.create_all(registry, {"alpha": types.SimpleNamespace(**{**vars(codels), "perm": perm})})
    registry.kernel.run_for(0.1)
    before = registry.read_poster("alpha.Status")
    assert before is not None and before.data.counter > 0
    unplugged = True
    registry.kernel.run_for(0.1)
    assert any("permanent codel 'perm' raised" in i for i in registry.incidents)
    after = registry.read_poster("alpha.Status")
    assert after is not None and after.date == before.date  # not published as fresh
    # Raising on every cycle (20 ms) for 2.5 s: the first raise, then the 10th and the 100th, then
    # the recovery with the count; not an incident a cycle.
    registry.kernel.run_for(2.4)
    unplugged = False
    registry.kernel.run_for(0.1)
    said = [i.partition(" alpha: permanent codel 'perm' ")[2] for i in registry.incidents]
    assert [text.split(" in a row")[0] for text in said] == [
        "raised RuntimeError: sensor unplugged" + said[0].partition("sensor unplugged")[2],
        "has raised 10 times", "has raised 100 times", "ran again after raising 125 times"]
    assert said[1].endswith("the last: " + said[0].removeprefix("raised "))


def test_modules_created_twice_on_one_registry_are_refused(robot: Robot) -> None:
    with pytest.raises(ValueError, match="module 'alpha' is already on this registry"):
        robot.package.create_all(robot.registry)


def test_executive_inputs_that_are_no_tuple_are_refused_before_anything_is_sent() -> None:
    from specc.runtime import executive as rx

    sent: list[Any] = []
    executive = types.SimpleNamespace(_post=lambda *args: sent.append(args), _internal_ids=iter([-1]),
                                      spec=types.SimpleNamespace(services={}))
    with pytest.raises(TypeError, match=r"inputs of GOTO: give a tuple .* not dict \{'x': 3.0\}"):
        rx.Executive.request(executive, "GOTO", inputs={"x": 3.0})  # type: ignore[arg-type]
    assert not sent


def test_codels_given_by_their_module_s_dotted_name_are_imported(robot: Robot) -> None:
    registry = rt.Registry()
    made = robot.package.create_all(registry, {"alpha": "scripted_codels.alpha"})
    import scripted_codels.alpha as codels

    assert made["alpha"].codels is codels
    with pytest.raises(ImportError, match="cannot import its codels 'no_such_codels.alpha'"):
        robot.package.create_all(rt.Registry(), {"alpha": "no_such_codels.alpha"})


def test_codels_given_as_an_object_without_a_codel_are_named_in_the_error(scripted_package: types.ModuleType) -> None:
    """`create(registry, codels=SimpleNamespace(...))` lacking a codel: the error names the codels
    given, not the module the spec would have imported, and no place inside specc."""
    from types import SimpleNamespace

    registry = rt.Registry()
    alpha = scripted_package.alpha.create(registry, SimpleNamespace())
    replies: list[rt.Reply] = []
    alpha.submit("A", scripted_package.alpha.AInput(script="exec"), replies.append)
    registry.kernel.run_for(0.05)
    final = replies[-1]
    assert final.report.code == "CODEL_ERROR"
    assert final.report.detail.endswith("is not defined in the codels given to module 'alpha' (SimpleNamespace)")
    assert "functional.py" not in final.report.detail


def _opens_nothing(path: Any) -> None:
    Path(path)  # the user's line: pathlib refuses the None given to it


def test_an_error_raised_inside_python_s_library_is_placed_at_the_user_s_line() -> None:
    """What `specc run` and the executive say of a user function that passed a wrong value to the
    standard library (an input function's `Path(None)`): the line of the user's call, not
    pathlib's own."""
    with pytest.raises(TypeError) as raised:
        _opens_nothing(None)
    place = rt.where_raised(raised.value)
    assert place.endswith(f"test_edge_cases.py:{_opens_nothing.__code__.co_firstlineno + 1})"), place
