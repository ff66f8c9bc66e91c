"""Pictures people would rather look at than read (matplotlib, no display needed)."""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from specc.analysis import petri
from specc.analysis.incompat import Group, IncompatibilityGraph, service_groups, state_count

GROUP_COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860", "#da8bc3", "#8c8c8c")
# For the service groups of a large executive: twenty colours told apart, the first eight as above.
MANY_COLOURS = (*GROUP_COLOURS, "#ccb974", "#64b5cd", "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                "#8c564b", "#e377c2", "#bcbd22", "#17becf", "#393b79")


def incompatibility_layout(graph: IncompatibilityGraph, groups: list[Group] | None = None
                           ) -> tuple[list[str], dict[str, str], list[str]]:
    """The services in their order round the circle, each one's colour, and each group's colour.
    A group's services sit side by side (its arcs short, the group one stretch of the circle),
    the services of no group after them, each in the order the executive lists them; groups get
    colours of their own (twenty before one repeats). `groups`: the graph's, when worked out already."""
    groups = service_groups(graph) if groups is None else groups
    palette = GROUP_COLOURS if len(groups) <= len(GROUP_COLOURS) else MANY_COLOURS
    group_colour = [palette[i % len(palette)] for i in range(len(groups))]
    colour = {s: group_colour[i] for i, g in enumerate(groups) for s in g.services}
    rank = {s: i for i, g in enumerate(groups) for s in g.services}
    ordered = sorted(graph.services, key=lambda s: (rank.get(s, len(groups)), graph.services.index(s)))
    return ordered, colour, group_colour


def draw_incompatibility_graph(graph: IncompatibilityGraph, target: Path, title: str) -> Path:
    """Services on a circle; solid arcs interrupt, dashed arcs wait; groups share a colour."""
    from specc.runtime.sim.render import pyplot

    plt = pyplot()
    from matplotlib.patches import FancyArrowPatch

    groups = service_groups(graph)
    ordered, colour, group_colour = incompatibility_layout(graph, groups)
    count = len(ordered)
    radius = 1.0
    angle = {s: 2 * math.pi * i / count + math.pi / 2 for i, s in enumerate(ordered)}
    position = {s: (radius * math.cos(a), radius * math.sin(a)) for s, a in angle.items()}
    size = max(6.0, 0.45 * count + 4)
    labels = {s: s + (" (control)" if s in graph.control else "") for s in ordered}
    longest = max((len(label) for label in labels.values()), default=0)
    # Room for the labels along the radius: a 9 pt character is about 5.4 pt wide, in data units
    # that depend on the room itself (two rounds settle it).
    reach = 1.2 + 0.018 * longest
    for _ in range(2):
        reach = 1.15 + longest * 5.4 / 72 * (2 * reach + 0.1) / (0.75 * size)
    # Data units per point (the axes take about 3/4 of the width), for a node's marker radius (420
    # pt² markers) and a legend line (9 pt text, 13 pt apart).
    per_point = (2 * reach + 0.1) / (0.75 * size * 72)
    marker = math.sqrt(420 / math.pi) * per_point
    line_height = 13 * per_point
    figure, axes = plt.subplots(figsize=(size, size))
    for arc in graph.arcs:
        start, end = position[arc.source], position[arc.target]
        style = "-" if arc.policy == "interrupt" else "--"
        if arc.source == arc.target:  # a loop on the inner side of the node, touching its marker
            x, y = start
            ux, uy = x / radius, y / radius  # the node's direction from the centre
            tx, ty = -uy, ux
            inner = (x - 0.9 * marker * ux, y - 0.9 * marker * uy)
            axes.add_patch(FancyArrowPatch((inner[0] + 0.6 * marker * tx, inner[1] + 0.6 * marker * ty),
                                           (inner[0] - 0.6 * marker * tx, inner[1] - 0.6 * marker * ty),
                                           connectionstyle="arc3,rad=2.2", arrowstyle="-|>", mutation_scale=9,
                                           linestyle=style, color="#555555", zorder=2))
            continue
        axes.add_patch(FancyArrowPatch(start, end, connectionstyle="arc3,rad=0.08", arrowstyle="-|>",
                                       mutation_scale=12, shrinkA=14, shrinkB=14, linestyle=style,
                                       color="#555555", linewidth=0.9))
    for service, (x, y) in position.items():
        shade = colour.get(service, "#ffffff")
        axes.scatter([x], [y], s=420, color=shade, edgecolors="black", zorder=3)
        # Along the radius, outwards from its node: labels of neighbours never overlap.
        degrees = math.degrees(angle[service]) % 360
        left = 90 < degrees < 270
        # Past the marker's edge, not on it.
        away = 1 + (marker + 4 * per_point) / radius
        axes.text(x * away, y * away, labels[service], rotation=degrees - 180 if left else degrees,
                  rotation_mode="anchor", ha="right" if left else "left", va="center", fontsize=9)
    legend = [f"{g.name}: {' | '.join(g.states)}" for g in groups]
    plural = "" if len(groups) == 1 else "s"
    axes.set_title(f"{title}\n{len(groups)} service group{plural}, {state_count(groups)} controller states "
                   "(solid: interrupt, dashed: wait)", fontsize=11)
    for i, line in enumerate(legend):
        axes.text(-reach, -reach - line_height * i, line, fontsize=9, color=group_colour[i])
    axes.set_xlim(-reach - 0.05, reach + 0.05)
    axes.set_ylim(-reach - 0.1 - line_height * len(legend), reach)
    axes.set_aspect("equal")
    axes.axis("off")
    target.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(figure)
    return target


# ---------------------------------------------------------------------------------------- Petri nets
NET_FORMATS = (".png", ".svg", ".pdf")
_LABEL_WIDTH = 28  # characters a node label keeps
_COLUMN = 1.3  # layout units between two layers
_ROW = 0.8  # layout units between two nodes of a layer
_RADIUS = 0.2  # a place's circle
_BAR = (0.07, 0.44)  # a transition's rectangle
_MAX_INCHES = (40.0, 30.0)
_UNIT_INCHES = 0.75  # inches per layout unit when the picture fits


def draw_net(net: petri.Net, target: Path, title: str, where: Mapping[str, Any] | None = None,
             marking: Mapping[str, int] | None = None, only: Callable[[str], bool] | None = None) -> Path:
    """Draw a (coloured) Petri net in layers, left to right, into a PNG, SVG or PDF file.

    Places are circles holding their tokens (a dot for one, a number for more: `marking`,
    place -> count, or else the initial marking), transitions thin bars, arcs arrows; a place a
    transition both takes and puts back (a read arc) is one dashed double-headed line, and an
    arc's weight, when not 1, is written on it. `only` keeps the places it accepts and the
    transitions touching them (one KA's net: `only=lambda p: p.startswith("KA.")`). `where`,
    place -> an object with `line` and `what`, puts the statement under the place's name.
    The same net always makes the same file."""
    from specc.runtime.sim.render import pyplot

    plt = pyplot()
    from matplotlib.patches import Circle, FancyArrowPatch, Rectangle

    suffix = target.suffix.lower()
    if suffix not in NET_FORMATS:
        raise ValueError(f"cannot draw a net into a '{target.suffix or 'suffix-less'}' file: "
                         f"name it {', '.join('*' + s for s in NET_FORMATS)}")
    places = [name for name in net.places if only is None or only(name)]
    if not places:
        raise ValueError(f"net '{net.name}' has no place to draw")
    kept = set(places)
    tokens = {name: (sum(net.places[name].initial.values()) if marking is None else marking.get(name, 0))
              for name in places}
    transitions = [t for t in net.transitions.values()
                   if only is None or any(arc.place in kept for arc in (*t.inputs, *t.outputs))]
    arcs = _net_arcs(transitions, kept)
    layer, order = _net_layers(places, transitions, arcs, tokens)

    # Long thin nets (one KA's net is mostly a chain) fold into bands, like lines of text, when
    # one band would be long and more than three times as wide as high.
    widest = max(len(nodes) for nodes in order)
    bands = 1
    if len(order) > 20 and len(order) * _COLUMN > 3 * (widest + 1) * _ROW:
        bands = max(1, round(math.sqrt(len(order) * _COLUMN / (1.33 * (widest + 1) * _ROW))))
    per_band = math.ceil(len(order) / bands)
    position: dict[Node, tuple[float, float]] = {}
    top = 0.0
    for first in range(0, len(order), per_band):
        chunk = order[first:first + per_band]
        high = max(len(nodes) for nodes in chunk)
        for column, nodes in enumerate(chunk):
            offset = top + (high - len(nodes)) * _ROW / 2
            for row, node in enumerate(nodes):
                position[node] = (column * _COLUMN, -(offset + row * _ROW))
        top += (high + 1) * _ROW
    span_x = (per_band + 1) * _COLUMN
    span_y = top
    unit = min(_UNIT_INCHES, _MAX_INCHES[0] / span_x, _MAX_INCHES[1] / span_y)
    font = max(2.0, min(7.0, 7.0 * unit / _UNIT_INCHES))
    # The axes fill the figure under the title at `unit` inches a layout unit: no tight bounding
    # box to compute (that would draw everything twice).
    heading = max(6.0, min(11.0, font * 1.6))
    width, height = span_x * unit, span_y * unit
    banner = 3.2 * heading / 72 + 0.2
    figure = plt.figure(figsize=(max(width, 5.0), height + banner))
    axes = figure.add_axes((0.5 - width / max(width, 5.0) / 2, 0.0, width / max(width, 5.0),
                            height / (height + banner)))
    try:
        shade = _prefix_colours(places)
        for name in places:
            x, y = position[("p", name)]
            circle = Circle((x, y), _RADIUS, facecolor=shade[name], edgecolor="black", linewidth=0.8, zorder=3)
            axes.add_patch(circle)
            count = tokens[name]
            if count == 1:
                axes.add_patch(Circle((x, y), _RADIUS / 3.5, color="black", zorder=4))
            elif count:
                axes.text(x, y, str(count), ha="center", va="center", fontsize=font * 1.2, fontweight="bold",
                          zorder=4)
            label = _wrap(_short_place(name))
            spot = where.get(name) if where is not None else None
            if spot is not None:
                label += _wrap(_shorten(f"{getattr(spot, 'line', '?')}: {getattr(spot, 'what', '')}"))
            axes.text(x, y - _RADIUS - 0.04, "\n".join(label), ha="center", va="top", fontsize=font, zorder=5,
                      linespacing=1.0)
        for transition in transitions:
            x, y = position[("t", transition.name)]
            thin, tall = _BAR
            bar = Rectangle((x - thin / 2, y - tall / 2), thin, tall, facecolor="#333333", edgecolor="black",
                            linewidth=0.5, zorder=3)
            axes.add_patch(bar)
            axes.text(x, y + tall / 2 + 0.03, "\n".join(_wrap(_shorten(transition.name))), ha="center",
                      va="bottom", fontsize=font * 0.85, color="#333333", zorder=5, linespacing=1.0)
        for (source, sink), (weight, read) in arcs.items():
            start, end = position[source], position[sink]
            # Straight to the next layer, bent when skipping layers (not to run over the nodes
            # between) and more when going back; barely bent on to the next band.
            step = layer[sink] - layer[source]
            bend = 0.0 if step == 1 else 0.2 if step > 1 else 0.3
            if layer[sink] // per_band != layer[source] // per_band:
                bend = 0.05
            arrow = FancyArrowPatch(path=_arc_path(source, start, sink, end, bend),
                                    arrowstyle="<|-|>" if read else "-|>", mutation_scale=4 + font,
                                    linestyle="--" if read else "-", linewidth=0.7,
                                    color="#2a6f97" if read else "#555555", zorder=2)
            axes.add_patch(arrow)
            if weight != "1":
                axes.text((start[0] + end[0]) / 2, (start[1] + end[1]) / 2 + 0.06, weight, ha="center",
                          va="bottom", fontsize=font, color="#8b0000", zorder=5)
        figure.text(0.5, 1 - 0.4 * heading / 72 / (height + banner),
                    f"{title}\n{len(places)} places, {len(transitions)} transitions (dashed double arrow: read arc)",
                    ha="center", va="top", fontsize=heading)
        axes.set_xlim(-_COLUMN, span_x - _COLUMN)
        axes.set_ylim(-(span_y - _ROW), _ROW)
        axes.axis("off")
        target.parent.mkdir(parents=True, exist_ok=True)
        stamp: dict[str, Any] = {".png": {"Software": None}, ".svg": {"Date": None},
                                 ".pdf": {"CreationDate": None}}[suffix]
        with plt.rc_context({"svg.fonttype": "none", "svg.hashsalt": "specc"}):
            figure.savefig(target, dpi=120, metadata=stamp)
    finally:
        plt.close(figure)
    return target


Node = tuple[str, str]  # ("p", place) or ("t", transition)


def _net_arcs(transitions: Sequence[petri.Transition], kept: set[str]) -> dict[tuple[Node, Node], tuple[str, bool]]:
    """(source, sink) -> (weight shown, read arc?); a read arc is keyed place -> transition."""
    arcs: dict[tuple[Node, Node], tuple[str, bool]] = {}
    for transition in transitions:
        takes: dict[str, int] = {}
        puts: dict[str, int] = {}
        for arc in transition.inputs:
            takes[arc.place] = takes.get(arc.place, 0) + arc.weight
        for arc in transition.outputs:
            puts[arc.place] = puts.get(arc.place, 0) + arc.weight
        node = ("t", transition.name)
        for place, weight in takes.items():
            if place not in kept:
                continue
            if place in puts:
                back = puts[place]
                arcs[(("p", place), node)] = (str(weight) if weight == back else f"{weight}/{back}", True)
            else:
                arcs[(("p", place), node)] = (str(weight), False)
        for place, weight in puts.items():
            if place in kept and place not in takes:
                arcs[(node, ("p", place))] = (str(weight), False)
    return arcs


def _net_layers(places: Sequence[str], transitions: Sequence[petri.Transition],
                arcs: Mapping[tuple[Node, Node], tuple[str, bool]],
                tokens: Mapping[str, int]) -> tuple[dict[Node, int], list[list[Node]]]:
    """A layer for every node (breadth first from the marked places), then each layer's order."""
    nodes: list[Node] = [("p", p) for p in places] + [("t", t.name) for t in transitions]
    after: dict[Node, list[Node]] = {n: [] for n in nodes}
    before: dict[Node, list[Node]] = {n: [] for n in nodes}
    for source, sink in arcs:
        after[source].append(sink)
        before[sink].append(source)
    layer: dict[Node, int] = {}
    found: list[Node] = []

    def spread(seeds: list[Node]) -> None:
        queue = deque(seeds)
        while queue:
            node = queue.popleft()
            for successor in after[node]:
                if successor not in layer:
                    layer[successor] = layer[node] + 1
                    found.append(successor)
                    queue.append(successor)

    seeds = [("p", p) for p in places if tokens[p]] or [("p", p) for p in places if not before[("p", p)]]
    seeds = seeds or [("p", places[0])]
    while True:
        for seed in seeds:
            layer[seed] = 0 if seed[0] == "p" else 1
            found.append(seed)
        spread(seeds)
        rest = [n for n in nodes if n not in layer]
        if not rest:
            break
        seeds = [n for n in rest if not before[n]][:1] or [n for n in rest if n[0] == "p"][:1] or rest[:1]
    used = sorted(set(layer.values()))
    renumber = {old: new for new, old in enumerate(used)}
    layer = {n: renumber[k] for n, k in layer.items()}
    order: list[list[Node]] = [[] for _ in used]
    for node in found:
        order[layer[node]].append(node)

    # Barycentre sweeps, down then up, twice: each node goes where its neighbours already are.
    def place_of(node: Node) -> float:
        nodes_here = order[layer[node]]
        return index[node] - (len(nodes_here) - 1) / 2

    index = {n: i for nodes_here in order for i, n in enumerate(nodes_here)}
    for _ in range(2):
        for sweep, neighbours in ((range(1, len(order)), before), (range(len(order) - 2, -1, -1), after)):
            for k in sweep:
                def key(node: Node, k: int = k, neighbours: dict[Node, list[Node]] = neighbours) -> float:
                    near = [place_of(n) for n in neighbours[node] if layer[n] != k]
                    return sum(near) / len(near) if near else place_of(node)
                order[k] = sorted(order[k], key=key)
                index.update({n: i for i, n in enumerate(order[k])})
    return layer, order


def _arc_path(source: Node, start: tuple[float, float], sink: Node, end: tuple[float, float], bend: float) -> Any:
    """A straight or quadratic arc (like matplotlib's arc3) from node to node, cut at their edges.

    Matplotlib can clip an arrow to its end patches itself, but far too slowly for big nets."""
    from matplotlib.path import Path as Curve

    (x1, y1), (x2, y2) = start, end
    control = ((x1 + x2) / 2 + bend * (y2 - y1), (y1 + y2) / 2 - bend * (x2 - x1))
    head = _cut(source, start, control if bend else end)
    tail = _cut(sink, end, control if bend else start)
    if not bend:
        return Curve([head, tail], [Curve.MOVETO, Curve.LINETO])
    return Curve([head, control, tail], [Curve.MOVETO, Curve.CURVE3, Curve.CURVE3])


def _cut(node: Node, centre: tuple[float, float], toward: tuple[float, float]) -> tuple[float, float]:
    """Where the line from a node's centre toward a point leaves the node's shape."""
    dx, dy = toward[0] - centre[0], toward[1] - centre[1]
    length = math.hypot(dx, dy) or 1.0
    dx, dy = dx / length, dy / length
    if node[0] == "p":
        reach = _RADIUS
    else:
        reach = min(_BAR[0] / 2 / abs(dx) if dx else math.inf, _BAR[1] / 2 / abs(dy) if dy else math.inf)
    reach += 0.02
    return centre[0] + dx * reach, centre[1] + dy * reach


def _prefix_colours(places: Sequence[str]) -> dict[str, str]:
    prefixes = list(dict.fromkeys(p.split(".", 1)[0] for p in places if "." in p))
    light = {prefix: _lighter(GROUP_COLOURS[i % len(GROUP_COLOURS)]) for i, prefix in enumerate(prefixes)}
    return {p: light.get(p.split(".", 1)[0], "#ffffff") if "." in p else "#ffffff" for p in places}


def _lighter(colour: str) -> str:
    red, green, blue = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return "#" + "".join(f"{c + (255 - c) * 2 // 3:02x}" for c in (red, green, blue))


def _short_place(name: str) -> str:
    return _shorten(name.split(".", 1)[1] if "." in name and name.split(".", 1)[1] else name)


def _shorten(text: str) -> str:
    return text if len(text) <= _LABEL_WIDTH else text[:_LABEL_WIDTH - 1] + "…"


def _wrap(text: str, width: int = 15) -> list[str]:
    import textwrap

    return textwrap.wrap(text, width, break_long_words=True, break_on_hyphens=False) or [text]


def draw_timeline(plan: Any, problem: Any, target: Path) -> Path:
    """A Gantt chart of a plan: one row per task, each action a bar from its dispatch date to its
    shortest end, then a lighter bar to its longest (what nature may add); the windows of
    contingent events (visibility windows) as bands; the goal timepoints and the mission end."""
    from specc.runtime.sim.render import pyplot

    plt = pyplot()

    from specc.runtime.planner.plan import format_value

    tasks = sorted({a.task for a in plan.actions}, key=lambda t: min(a.dispatch for a in plan.actions if a.task == t))
    row = {task: i for i, task in enumerate(tasks)}
    colour = {task: GROUP_COLOURS[i % len(GROUP_COLOURS)] for i, task in enumerate(tasks)}
    figure, axes = plt.subplots(figsize=(12, 1.2 + 0.55 * max(1, len(tasks))))
    first = min([plan.now] + [a.dispatch for a in plan.actions])
    span = max(plan.makespan, plan.schedule.get(problem.end, 0.0)) - first + 1.0
    seconds_per_char = span / 230  # about 230 characters of 7-point text across the axes
    for action in plan.actions:
        y = row[action.task]
        low, high = action.duration
        axes.barh(y, low, left=action.dispatch, height=0.6, color=colour[action.task], edgecolor="black",
                  linewidth=0.5)
        if high > low:
            axes.barh(y, high - low, left=action.dispatch + low, height=0.6, color=colour[action.task], alpha=0.3,
                      edgecolor=colour[action.task], hatch="//", linewidth=0.5)
        label = ", ".join(format_value(a) for a in action.args)
        if len(label) * seconds_per_char < high:  # only labels that fit their bar
            axes.text(action.dispatch + 0.5, y, label, va="center", ha="left", fontsize=7, clip_on=True)
    # Contingent instants of the problem (window openings and closings): where nature may put them.
    openings = sorted((name, dates) for name, dates in plan.uncontrolled.items() if "." not in name)
    for name, (early, late) in openings:
        axes.axvspan(early, late, color="tab:gray", alpha=0.25, linewidth=0)
        axes.text((early + late) / 2, len(tasks) - 0.35, name, rotation=90, fontsize=6, ha="center", va="bottom")
    end = plan.schedule.get(problem.end)
    if end is not None:
        axes.axvline(end, color="black", linestyle="--", linewidth=1)
        axes.text(end, -0.7, f" {problem.end} = {end:.0f} s", fontsize=7, va="top")
    axes.set_yticks(range(len(tasks)), tasks)
    axes.invert_yaxis()
    axes.set_xlabel("mission time (s): solid = shortest duration, hatched = what nature may add")
    axes.set_xlim(left=first - 2)
    axes.set_title(f"plan for {plan.problem} ({plan.domain}): {len(plan.actions)} actions, "
                   f"{plan.controllability_text}, done by {plan.makespan:.0f} s at worst", fontsize=10)
    axes.grid(axis="x", alpha=0.3)
    figure.tight_layout()
    target.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(target, dpi=120)
    plt.close(figure)
    return target
