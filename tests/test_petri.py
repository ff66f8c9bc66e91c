"""The coloured Petri net engine (seed 000 §4.3): unfolding, full state-space exploration and
the reports a designer reads — deadlocks with their firing sequence, bounds and unbounded
places, dead transitions, eternal cycles, home markings — and PNML export."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest

from specc.analysis.petri import PNML, Arc, Net, NetError, analyse, explore, to_pnml

PHILOSOPHERS = range(3)


def philosophers(polite: bool) -> Net:
    """Dijkstra's dining philosophers; a polite one takes both forks at once."""
    net = Net("philosophers")
    net.place("think", PHILOSOPHERS, {i: 1 for i in PHILOSOPHERS})
    net.place("fork", PHILOSOPHERS, {i: 1 for i in PHILOSOPHERS})
    net.place("left", PHILOSOPHERS)
    net.place("eat", PHILOSOPHERS)
    i = {"i": PHILOSOPHERS}
    left = Arc("fork", lambda b: b["i"])
    right = Arc("fork", lambda b: (b["i"] + 1) % 3)
    if polite:
        net.transition("takeBoth", [Arc("think", lambda b: b["i"]), left, right], [Arc("eat", lambda b: b["i"])], i,
                       origin="KA Philosopher, line 3")
    else:
        net.transition("takeLeft", [Arc("think", lambda b: b["i"]), left], [Arc("left", lambda b: b["i"])], i,
                       origin="KA Philosopher, line 3")
        net.transition("takeRight", [Arc("left", lambda b: b["i"]), right], [Arc("eat", lambda b: b["i"])], i)
    net.transition("release", [Arc("eat", lambda b: b["i"])], [Arc("think", lambda b: b["i"]), left, right], i)
    return net


def test_a_deadlock_is_reported_with_its_shortest_firing_sequence() -> None:
    report = analyse(philosophers(polite=False))
    deadlocks = [f for f in report.findings if f.kind == "deadlock"]
    assert len(deadlocks) == 1
    assert [str(s) for s in deadlocks[0].trace] == ["takeLeft(i=0)", "takeLeft(i=1)", "takeLeft(i=2)"]
    assert deadlocks[0].trace[0].origin == "KA Philosopher, line 3"
    assert deadlocks[0].marking == "left(0) + left(1) + left(2)"


def test_without_deadlock_every_marking_can_come_home() -> None:
    report = analyse(philosophers(polite=True))
    assert report.space.states == 4 and report.home  # nobody eats, or one of three does
    assert report.bounds == {"think": 3, "fork": 3, "left": 0, "eat": 1}
    # The philosophers dine forever: the whole graph is one terminal component.
    assert [f.kind for f in report.findings] == ["eternal-cycle"]


def test_an_expected_end_is_not_a_deadlock() -> None:
    net = Net("job")
    net.place("todo", initial=2)
    net.place("done")
    net.transition("work", [Arc("todo")], [Arc("done")])
    assert [f.kind for f in analyse(net).findings] == ["deadlock"]
    assert analyse(net, expected_end=lambda tokens: tokens("done") == 2).findings == []


def test_an_unbounded_place_is_found_with_the_sequence_that_repeats() -> None:
    net = Net("recursion")
    net.place("running", initial=1)
    net.place("posted")
    net.place("idle", initial=1)
    net.transition("start", [Arc("idle")], [Arc("running")])
    net.transition("post", [Arc("running")], [Arc("running"), Arc("posted")], origin="KA Loop, line 2")
    (finding,) = [f for f in analyse(net).findings if f.kind == "unbounded"]
    assert "posted" in finding.message and [str(s) for s in finding.trace] == ["post"]
    assert not analyse(net).space.complete


def test_a_transition_that_can_never_fire_is_dead() -> None:
    net = Net("dead")
    net.place("a", initial=1)
    net.place("b")
    net.place("never")
    net.transition("go", [Arc("a")], [Arc("b")])
    net.transition("stuck", [Arc("never")], [Arc("a")], origin="KA Never, line 7")
    dead = [f for f in analyse(net, expected_end=lambda tokens: tokens("b") == 1).findings]
    assert [f.kind for f in dead] == ["dead-transition"] and "KA Never, line 7" in dead[0].message


def test_guards_and_colours_unfold_to_one_step_per_binding() -> None:
    net = Net("guarded")
    net.place("n", range(4), {0: 1})
    net.transition("inc", [Arc("n", lambda b: b["x"])], [Arc("n", lambda b: b["x"] + 1)], {"x": range(4)},
                   guard=lambda b: b["x"] < 3)
    space = explore(net)
    assert len(space.unfolded.steps) == 3 and space.states == 4 and len(space.deadlocks()) == 1
    with pytest.raises(NetError, match="colour 4"):
        bad = Net("bad")
        bad.place("n", range(4), {0: 1})
        bad.transition("inc", [Arc("n", lambda b: b["x"])], [Arc("n", lambda b: b["x"] + 1)], {"x": range(4)})
        bad.unfold()


def test_pnml_export_is_a_place_transition_net_with_every_place_arc_and_marking() -> None:
    net = philosophers(polite=False)
    root = ET.fromstring(to_pnml(net))
    ns = {"p": PNML}
    (element,) = root.findall("p:net", ns)
    assert element.get("type", "").endswith("ptnet")
    places = element.findall("p:page/p:place", ns)
    transitions = element.findall("p:page/p:transition", ns)
    arcs = element.findall("p:page/p:arc", ns)
    assert len(places) == 12 and len(transitions) == 9
    assert len(arcs) == 3 * (2 + 1) + 3 * (2 + 1) + 3 * (1 + 3)
    marked = [p for p in places if p.find("p:initialMarking", ns) is not None]
    assert len(marked) == 6  # three thinking philosophers, three forks
    ids = {p.get("id") for p in places} | {t.get("id") for t in transitions}
    assert all(a.get("source") in ids and a.get("target") in ids for a in arcs)
