"""The executive at run time (seed 000 §3.3-3.5, §3.9) over the scripted robot: the activity
graph of Fig 3.3, the request and reply managers, timeouts, ZOMBIE, the ERROR state, reflexes,
parameters, input and output functions."""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import pytest

from specc.runtime import executive as rx
from specc.runtime import functional as rt


@dataclass
class Shop:
    registry: rt.Registry
    executive: rx.Executive
    moves: list[tuple[str, int, rx.Phase, rx.Phase]] = field(default_factory=list)

    @property
    def kernel(self) -> Any:
        return self.registry.kernel

    def queue(self, *scripts: str) -> None:
        self.executive.context.vars.setdefault("next", []).extend(scripts)

    def ask(self, service: str, ident: int, script: str | None = None) -> int:
        if script is not None:
            self.queue(script)
        return self.executive.request(service, ident)

    def run(self, seconds: float) -> None:
        self.kernel.run_for(seconds)

    def facts(self) -> list[tuple[Any, ...]]:
        return [m.fact for m in self.executive.messages]

    def state(self, ident: int) -> rx.Phase:
        activity = self.executive.activities.get(ident)
        return rx.Phase.ETHER if activity is None else activity.state

    def path(self, ident: int) -> list[str]:
        found = [str(source) for _, i, source, _ in self.moves if i == ident]
        last = [str(target) for _, i, _, target in self.moves if i == ident][-1:]
        return found + last


@pytest.fixture
def shop(shop_package: ModuleType) -> Shop:
    registry = rt.Registry()
    importlib.import_module("shop.modules").create_all(registry)
    executive = importlib.import_module("shop.executive.shop").create(registry)
    made = Shop(registry, executive)
    executive.observers.append(lambda a, s, t: made.moves.append((a.service.name, a.id, s, t)))
    return made


LONG = ",".join(["exec"] * 100)  # one second at the 10 ms period of task T


def test_an_executive_on_a_registry_without_its_modules_is_refused_at_once(shop_package: ModuleType) -> None:
    """Not a KeyError of a module's name at the first request: the modules it needs, named."""
    with pytest.raises(ValueError, match=r"executive 'shop': its services run requests of module\(s\) alpha, "
                                         r"beta, which the registry does not have: create the modules"):
        importlib.import_module("shop.executive.shop").create(rt.Registry())


def test_a_service_runs_through_wait_init_exec_and_replies_ok(shop: Shop) -> None:
    shop.ask("FREE", 1, "exec,exec")
    shop.run(1)
    assert shop.facts() == [("REPLY", 1, "OK")]
    assert shop.path(1) == ["ETHER", "WAIT", "INIT", "EXEC", "ETHER"]
    assert shop.executive.activities == {}


def test_an_intrinsic_failure_is_a_normal_end_with_the_module_report(shop: Shop) -> None:
    shop.ask("FREE", 1, "exec,OOPS")  # §3.4.1: REPLY END with the bilan
    shop.run(1)
    assert ("REPLY", 1, "OOPS") in shop.facts()


def test_unknown_service_and_reused_id_are_answered_at_once(shop: Shop) -> None:
    shop.ask("FLY", 1)
    shop.ask("FREE", 2, LONG)
    shop.ask("FREE", 2)
    assert shop.facts() == [("REPLY", 1, "BAD-SERVICE"), ("WARNING", "FREE", 2, "BAD-ID")]


def test_a_waiting_service_starts_when_what_it_waits_for_ends(shop: Shop) -> None:
    shop.ask("MOVE", 1, "exec,exec,exec")
    shop.run(0.005)
    shop.ask("WAITER", 2, "exec")
    shop.run(0.005)
    assert shop.state(1) is rx.Phase.EXEC and shop.state(2) is rx.Phase.WAIT
    shop.run(1)
    assert shop.facts() == [("REPLY", 1, "OK"), ("REPLY", 2, "OK")]
    assert shop.path(2) == ["ETHER", "WAIT", "INIT", "EXEC", "ETHER"]


def test_a_start_timeout_answers_timeout_and_drops_the_activity(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.005)
    shop.ask("TIMED", 2)
    shop.run(0.2)
    assert shop.facts() == [("REPLY", 2, "TIMEOUT")]
    assert shop.path(2) == ["ETHER", "WAIT", "ETHER"]


def test_a_service_of_the_same_group_interrupts_the_running_one_through_its_module(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.05)
    shop.ask("MOVE2", 2, "exec")
    shop.run(0.5)
    assert shop.facts() == [("REPLY", 1, "INT"), ("REPLY", 2, "OK")]
    assert shop.path(1) == ["ETHER", "WAIT", "INIT", "EXEC", "INTER", "ETHER"]
    assert shop.executive.groups == {"MOVE_MOVE2state": "IDLE"}


def test_another_modules_service_aborts_the_conflicting_one_and_waits_for_its_end(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.05)
    shop.ask("REMOTE", 2, "exec")
    shop.run(0.001)
    assert shop.state(1) is rx.Phase.INTER and shop.state(2) is rx.Phase.WAIT
    assert shop.executive.activities[1].abort_sent
    shop.run(1)
    assert shop.facts() == [("REPLY", 1, "INT"), ("REPLY", 2, "OK")]


def test_a_control_service_interrupts_what_its_request_excludes(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.05)
    shop.ask("RESET", 2)
    shop.run(0.1)
    assert shop.facts() == [("REPLY", 2, "OK"), ("REPLY", 1, "INT")]


def test_rqst_int_of_a_waiting_and_of_a_running_service(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.05)
    shop.ask("WAITER", 2)
    shop.run(0.001)
    shop.executive.interrupt(2)
    shop.executive.interrupt(1)
    shop.executive.interrupt(99)
    shop.run(0.1)
    assert shop.facts() == [("REPLY", 2, "INT"), ("WARNING", "INT", 99, "BAD-ID"), ("REPLY", 1, "INT")]
    assert shop.executive.groups == {"MOVE_MOVE2state": "IDLE"}


def test_zombie_warns_refuses_the_module_until_interrupted_then_replies_error(shop: Shop) -> None:
    shop.ask("FREE", 1, "exec,zombie")
    shop.run(0.1)
    assert shop.facts() == [("WARNING", "FREE", 1, "ZOMBIE")]
    assert shop.state(1) is rx.Phase.ZOMBIE
    shop.ask("WAITER", 2)  # same module: REFUSED while the ZOMBIE stands (§3.4.1)
    shop.ask("REMOTE", 3, "exec")  # another module: unaffected
    shop.run(0.1)
    assert ("REPLY", 2, "REFUSED") in shop.facts() and ("REPLY", 3, "OK") in shop.facts()
    shop.executive.interrupt(1)  # the task level acknowledges: abort, then the final reply
    shop.run(0.1)
    assert shop.facts()[-1] == ("REPLY", 1, "ZOMBIE")
    assert shop.path(1)[-2:] == ["ZOMBIE", "ETHER"]
    shop.ask("FREE", 4, "exec")
    shop.run(0.1)
    assert shop.facts()[-1] == ("REPLY", 4, "OK")


def test_a_final_timeout_answers_timeout_once_and_aborts_the_activity(shop: Shop) -> None:
    shop.ask("SLOW", 1, LONG)
    shop.run(0.5)
    assert shop.facts() == [("REPLY", 1, "TIMEOUT")]
    assert shop.state(1) is rx.Phase.ETHER  # its module's INT reply let it go, silently
    assert shop.path(1)[-3:] == ["EXEC", "INTER", "ETHER"]


def test_an_interruption_nobody_decided_puts_the_executive_in_its_error_state(shop: Shop) -> None:
    shop.ask("FREE", 1, LONG)
    shop.ask("MOVE", 2, LONG)
    shop.run(0.05)
    alpha = shop.registry.modules["alpha"]
    alpha.abort(shop.executive.activities[1].module_id)  # behind the executive's back (§3.4.2)
    shop.run(0.05)
    assert shop.executive.error is not None
    assert ("WARNING", "EXECUTIVE", 0, "ERROR") in shop.facts()
    shop.ask("REMOTE", 3)
    shop.run(0.5)
    # Every request is refused and the running activities are brought to an end.
    assert ("REPLY", 3, "REFUSED") in shop.facts() and ("REPLY", 2, "INT") in shop.facts()
    assert shop.executive.activities == {}


def test_reflexes_start_services_and_send_requests(shop: Shop) -> None:
    shop.ask("FREE", 1, "exec,OOPS")
    shop.run(0.1)
    started = [m for m in shop.executive.messages if m.service == "MEASURE"]
    assert len(started) == 1 and started[0].kind == "REPLY" and started[0].id < 0
    shop.ask("FREE", 2, "exec,zombie")
    shop.run(0.1)
    assert [(r.request, r.status) for r in shop.executive.reflex_replies] == [("Get", rt.Status.END)]


def test_parameters_and_output_functions(shop: Shop) -> None:
    assert shop.executive.set_param("VALUE", 2.5) == "OK"
    assert shop.executive.set_param("VALUE", -1.0) == "NEGATIVE"
    shop.run(0.1)  # the Status poster follows at the next cycle of its permanent activity
    assert shop.executive.get_param("VALUE") == 2.5
    shop.ask("MEASURE", 1)
    shop.run(0.01)
    assert shop.facts() == [("REPLY", 1, 2.5)]  # value_of(ctx, outputs) made the result
    with pytest.raises(LookupError, match="no parameter 'SPEED'"):
        shop.executive.get_param("SPEED")


def test_an_input_function_failure_is_answered_not_raised(shop: Shop) -> None:
    shop.queue(123)  # not a script: the request's input does not fit
    shop.ask("FREE", 1)
    shop.run(0.1)
    assert shop.facts() == [("REPLY", 1, "ERROR")]
    assert "script" in shop.executive.messages[0].detail


def test_every_move_follows_an_arc_of_fig_3_3(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.ask("WAITER", 2)
    shop.ask("REMOTE", 3, LONG)
    shop.ask("FREE", 4, "exec,zombie")
    shop.run(0.2)
    shop.executive.interrupt(4)
    shop.executive.interrupt(3)
    shop.run(2)
    arcs = {(a, b) for a, _, b in rx.ARCS}
    assert shop.moves and all((s, t) in arcs for _, _, s, t in shop.moves)
    assert {i for _, i, _, t in shop.moves if t is rx.Phase.ETHER} == {1, 2, 3, 4}


def test_an_interruption_the_executive_causes_itself_is_decided_not_an_error(shop: Shop) -> None:
    shop.ask("MOVE", 1, LONG)
    shop.run(0.05)
    assert shop.executive.set_param("RESET-ALL", None) == "OK"  # alpha.Reset excludes MOVE's request
    shop.run(0.1)
    assert shop.executive.error is None and shop.facts() == [("REPLY", 1, "INT")]
    assert shop.path(1)[-3:] == ["EXEC", "INTER", "ETHER"]


def test_a_module_stays_frozen_until_every_zombie_is_released(shop: Shop) -> None:
    shop.ask("FREE", 1, "exec,zombie")
    shop.ask("FREE", 2, "exec,zombie")
    shop.run(0.1)
    shop.executive.interrupt(2)
    shop.run(0.1)
    shop.ask("WAITER", 3)
    shop.run(0.1)
    assert ("REPLY", 3, "REFUSED") in shop.facts()  # activity 1 still freezes alpha
    shop.executive.interrupt(1)
    shop.ask("FREE", 4, "exec")
    shop.run(0.1)
    assert ("REPLY", 4, "OK") in shop.facts() and shop.executive.zombies == {}


def test_a_listener_that_raises_is_recorded_and_the_executive_goes_on(shop: Shop) -> None:
    def broken(message: rx.Message) -> None:
        raise RuntimeError("listener bug")

    shop.executive.listeners.append(broken)
    shop.ask("FREE", 1, "exec")
    shop.run(0.1)
    assert shop.facts() == [("REPLY", 1, "OK")] and shop.executive.activities == {}
    assert shop.executive.incidents and "listener bug" in shop.executive.incidents[0]


def test_a_reflex_on_a_module_request_s_warning_acts_once_the_executive_has_heard_the_zombie(
        shop_package: ModuleType) -> None:
    # `on warning alpha.C` (the module's request) as `on warning FREE` (the service): the abort the
    # reflex sends finds FREE already ZOMBIE in the executive, and frees it. Acting first, it used
    # to be lost, and FREE stayed ZOMBIE with its module refusing every request.
    import dataclasses

    registry = rt.Registry()
    importlib.import_module("shop.modules").create_all(registry)
    generated = importlib.import_module("shop.executive.shop")
    free = rx.ReflexSpec("freeIt", "warning", "alpha.C", actions=(("abort", "FREE"),))
    spec = dataclasses.replace(generated.SPEC, reflexes=(free,))
    executive = rx.Executive(spec, generated.decide, registry, rx.load_codels(spec))
    shop = Shop(registry, executive)
    shop.ask("FREE", 1, "exec,zombie")
    shop.run(0.2)
    assert ("WARNING", "FREE", 1, "ZOMBIE") in shop.facts() and shop.facts()[-1] == ("REPLY", 1, "ZOMBIE")
    assert shop.state(1) is rx.Phase.ETHER and not registry.modules["alpha"].zombies
    shop.ask("FREE", 2, "exec")
    shop.run(0.1)
    assert shop.facts()[-1] == ("REPLY", 2, "OK")
