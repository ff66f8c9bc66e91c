"""Drawing Petri nets (specc.pictures.draw_net): the files it writes, what `only` keeps, the
marking it shows, and that a net of a couple of hundred places draws."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path
from types import SimpleNamespace

import pytest

from specc.analysis.petri import Arc, Net
from specc.pictures import draw_net
from tests.conftest import EXAMPLES

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def mutual_exclusion() -> Net:
    """Two KAs sharing one resource; KA1 also tests a flag without consuming it (a read arc)."""
    net = Net("mutex")
    net.place("mutex", initial=1)
    net.place("flag", initial=1)
    for ka, waiting in (("KA1", "ASKING"), ("KA2", "QUEUED")):
        net.place(f"{ka}.IDLE", initial=1)
        net.place(f"{ka}.{waiting}")
        net.place(f"{ka}.CRITICAL")
        net.transition(f"{ka} asks", [Arc(f"{ka}.IDLE")], [Arc(f"{ka}.{waiting}")], origin=f"{ka}:2")
        net.transition(f"{ka} enters", [Arc(f"{ka}.{waiting}"), Arc("mutex")], [Arc(f"{ka}.CRITICAL")],
                       origin=f"{ka}:3")
        net.transition(f"{ka} leaves", [Arc(f"{ka}.CRITICAL")], [Arc(f"{ka}.IDLE"), Arc("mutex")], origin=f"{ka}:4")
    net.transition("KA1 peeks", [Arc("flag"), Arc("KA1.ASKING")], [Arc("flag"), Arc("KA1.ASKING")])
    return net


def svg_texts(path: Path) -> list[str]:
    return [t.strip() for t in re.findall(r"<text[^>]*>([^<]*)", path.read_text(encoding="utf-8"))]


def test_draw_net_writes_a_png(tmp_path: Path) -> None:
    target = tmp_path / "pictures" / "mutex.png"
    assert draw_net(mutual_exclusion(), target, "mutual exclusion") == target
    data = target.read_bytes()
    assert data.startswith(PNG_MAGIC) and len(data) > 1000


def test_draw_net_writes_an_svg_with_short_labels_and_a_read_arc(tmp_path: Path) -> None:
    target = draw_net(mutual_exclusion(), tmp_path / "mutex.svg", "mutual exclusion")
    text = target.read_text(encoding="utf-8")
    assert text.lstrip().startswith("<?xml") and "<svg" in text
    labels = svg_texts(target)
    # "KA.SUFFIX" places show their suffix only; other places their whole name.
    assert {"ASKING", "QUEUED", "CRITICAL", "mutex", "flag"} <= set(labels)
    assert "KA1.ASKING" not in labels
    assert "KA1 enters" in labels and "KA2 leaves" in labels
    assert "stroke-dasharray" in text  # the read arc is dashed


def test_draw_net_writes_a_pdf(tmp_path: Path) -> None:
    target = draw_net(mutual_exclusion(), tmp_path / "mutex.pdf", "mutual exclusion")
    assert target.read_bytes().startswith(b"%PDF")


def test_draw_net_is_deterministic(tmp_path: Path) -> None:
    first = draw_net(mutual_exclusion(), tmp_path / "a.svg", "mutex").read_bytes()
    second = draw_net(mutual_exclusion(), tmp_path / "b.svg", "mutex").read_bytes()
    assert first == second
    assert draw_net(mutual_exclusion(), tmp_path / "a.png", "mutex").read_bytes() == \
        draw_net(mutual_exclusion(), tmp_path / "b.png", "mutex").read_bytes()


def test_only_keeps_one_kas_places_and_the_transitions_touching_them(tmp_path: Path) -> None:
    target = draw_net(mutual_exclusion(), tmp_path / "ka1.svg", "KA1", only=lambda place: place.startswith("KA1."))
    labels = svg_texts(target)
    assert {"ASKING", "CRITICAL", "IDLE", "KA1 asks", "KA1 enters", "KA1 leaves", "KA1 peeks"} <= set(labels)
    for absent in ("QUEUED", "KA2 asks", "KA2 enters", "KA2 leaves", "mutex", "flag"):
        assert absent not in labels
    assert any(label.startswith("3 places, 4 transitions") for label in labels)


def test_only_accepting_nothing_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="no place"):
        draw_net(mutual_exclusion(), tmp_path / "none.png", "nothing", only=lambda place: False)
    assert not (tmp_path / "none.png").exists()


def test_an_unknown_suffix_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"\.png"):
        draw_net(mutual_exclusion(), tmp_path / "mutex.gif", "mutex")
    with pytest.raises(ValueError):
        draw_net(mutual_exclusion(), tmp_path / "mutex", "mutex")


def test_marking_weights_and_where_are_shown(tmp_path: Path) -> None:
    net = mutual_exclusion()
    net.transition("KA2 takes two flags", [Arc("flag", weight=2)], [Arc("KA2.QUEUED")])
    where = {"KA1.CRITICAL": SimpleNamespace(line=17, what="use(arm)")}
    target = draw_net(net, tmp_path / "marked.svg", "marked", where=where, marking={"KA2.QUEUED": 7, "mutex": 0})
    labels = svg_texts(target)
    assert "7" in labels  # seven tokens in KA2.QUEUED
    assert "2" in labels  # the weight of the arc from flag
    assert "17: use(arm)" in labels


def test_a_long_name_is_cut_short(tmp_path: Path) -> None:
    net = Net("long")
    net.place("KA.START", initial=1)
    net.place("KA.END")
    net.transition("KA:12 action a_very_long_service_name_indeed(arg1, arg2, arg3)", [Arc("KA.START")],
                   [Arc("KA.END")])
    text = draw_net(net, tmp_path / "long.svg", "long").read_text(encoding="utf-8")
    assert "arg3" not in text and "…" in text


def chain(length: int, extra: int) -> Net:
    net = Net("chain")
    for i in range(length):
        net.place(f"K{i // 20}.P{i}", initial=1 if i == 0 else 0)
    for i in range(length - 1):
        net.transition(f"K{i // 20}:{i} step", [Arc(f"K{i // 20}.P{i}")], [Arc(f"K{(i + 1) // 20}.P{i + 1}")])
    for k in range(extra):  # skips forward, jumps back, a few read arcs
        i = (k * 7) % length
        j = (i + 3 + k % 5) % length if k % 3 else (i * 5) % length
        if k % 10 == 0:
            net.transition(f"K{i // 20}:{i} reads #{k}", [Arc(f"K{i // 20}.P{i}"), Arc(f"K{j // 20}.P{j}")],
                           [Arc(f"K{i // 20}.P{i}"), Arc(f"K{j // 20}.P{j}")])
        else:
            net.transition(f"K{i // 20}:{i} jumps #{k}", [Arc(f"K{i // 20}.P{i}")], [Arc(f"K{j // 20}.P{j}")])
    return net


def test_a_200_place_chain_draws_every_place(tmp_path: Path) -> None:
    net = chain(200, 51)
    assert len(net.places) == 200 and len(net.transitions) == 250
    target = draw_net(net, tmp_path / "chain.png", "a long chain")
    assert target.read_bytes().startswith(PNG_MAGIC)
    svg = draw_net(net, tmp_path / "chain.svg", "a long chain")
    labels = svg_texts(svg)
    assert "P0" in labels and "P199" in labels


def test_a_nets_without_marked_places_still_draws(tmp_path: Path) -> None:
    net = Net("cycle")  # nothing marked, every place has a producer: layers start at the first place
    for name in ("A", "B", "C"):
        net.place(name)
    net.transition("ab", [Arc("A")], [Arc("B")])
    net.transition("bc", [Arc("B")], [Arc("C")])
    net.transition("ca", [Arc("C")], [Arc("A")])
    net.place("LONELY")
    net.transition("from nowhere", [], [Arc("LONELY")])
    labels = svg_texts(draw_net(net, tmp_path / "cycle.svg", "cycle"))
    assert {"A", "B", "C", "LONELY", "ab", "bc", "ca", "from nowhere"} <= set(labels)


def test_the_incompatibility_graph_puts_each_group_together_in_a_colour_of_its_own(tmp_path: Path) -> None:
    """Twenty services in ten groups, declared interleaved: round the circle each group's services
    sit side by side, and no two groups share a colour (eight colours once made the ninth group
    look like the first); the picture is written."""
    from specc.analysis.incompat import build_graph
    from specc.pictures import draw_incompatibility_graph, incompatibility_layout
    from specc.pipeline import load

    pairs = [(f"A{k}", f"B{k}") for k in range(10)]
    request = "  request {} {{ type: exec; task: T; codel exec: go; incompatible_with: A, B; }}\n"
    modules = "\n".join(f"module m{k} {{\n" + request.format("A") + request.format("B")
                        + "  exec_task T { period: 100 ms; }\n}" for k in range(10))
    services = "\n".join(f"  service {a} {{ request: m{k}.A; }}" for k, (a, _) in enumerate(pairs)) + "\n" + "\n".join(
        f"  service {b} {{ request: m{k}.B; }}" for k, (_, b) in enumerate(pairs))
    spec = tmp_path / "robot.spec"
    spec.write_text(modules + f"\nexecutive e {{\n{services}\n}}\n")
    (tmp_path / "codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    loaded = load([spec], check=False)
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if type(i).__name__ == "Executive")
    graph = build_graph(loaded.program, executive)
    ordered, colour, group_colours = incompatibility_layout(graph)
    assert len(set(group_colours)) == len(group_colours) == 10
    for a, b in pairs:
        assert abs(ordered.index(a) - ordered.index(b)) == 1 and colour[a] == colour[b]
    assert draw_incompatibility_graph(graph, tmp_path / "incompat.png", "e").stat().st_size > 0


@pytest.mark.parametrize("robot", ["small", "hilare"])
def test_the_incompatibility_graph_keeps_its_labels_off_the_nodes_and_its_legend_lines_apart(
        robot: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A small executive (three groups and a control service, the smallest figure) and Hilare's
    21 services in six groups: measured in the figure as drawn, no service label starts on a node
    and no two legend lines overlap (on small figures both did: labels began inside their
    markers, and the legend's spacing was fixed in data units)."""
    import matplotlib.figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PathCollection
    from matplotlib.text import Text

    from specc.analysis.incompat import build_graph
    from specc.pictures import draw_incompatibility_graph
    from specc.pipeline import load

    if robot == "small":
        request = "  request {} {{ type: exec; task: T; codel exec: go; incompatible_with: {}; }}\n"
        (tmp_path / "robot.spec").write_text(
            "module arm {\n" + request.format("MoveToBed", "MoveToBed") + request.format("Image", "Image")
            + request.format("Spray", "Spray") + "  request Humidity { type: control; }\n"
            + "  exec_task T { period: 100 ms; }\n}\nexecutive e {\n"
            + "".join(f"  service {s.upper()} {{ request: arm.{s}; }}\n" for s in ("MoveToBed", "Image", "Spray",
                                                                                    "Humidity")) + "}\n")
        (tmp_path / "codels.py").write_text("def go(sdi, request):\n    return 'ether'\n")
    loaded = load([tmp_path / "robot.spec" if robot == "small" else EXAMPLES / "hilare"], check=False)
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if type(i).__name__ == "Executive")
    drawn: list[matplotlib.figure.Figure] = []
    save = matplotlib.figure.Figure.savefig
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig",
                        lambda self, *args, **kwargs: (drawn.append(self), save(self, *args, **kwargs))[1])
    graph = build_graph(loaded.program, executive)
    draw_incompatibility_graph(graph, tmp_path / "incompat.png", robot)
    figure = drawn[0]
    renderer = FigureCanvasAgg(figure).get_renderer()  # the figure is closed: a canvas of its own
    axes = figure.axes[0]
    texts = [t for t in axes.texts if isinstance(t, Text)]
    legend = [t.get_window_extent(renderer) for t in texts if ": " in t.get_text()]
    labels = [t for t in texts if ": " not in t.get_text()]
    assert len(legend) == (3 if robot == "small" else 6) and len(labels) == len(graph.services)
    assert not any(a.overlaps(b) for a, b in itertools.combinations(legend, 2))
    radius = (420 / math.pi) ** 0.5 * figure.dpi / 72  # the markers' radius in pixels
    centres = [axes.transData.transform(xy) for c in axes.collections if isinstance(c, PathCollection)
               for xy in c.get_offsets()]
    assert len(centres) == len(graph.services)
    # A label runs outwards along its node's radius from where it is anchored: that point is the
    # label's nearest to its node, and lies past the node's edge.
    for label in labels:
        anchor = axes.transData.transform(label.get_position())
        assert min(math.dist(anchor, centre) for centre in centres) > radius, label.get_text()
