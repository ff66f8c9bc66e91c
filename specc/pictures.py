"""Pictures people would rather look at than read (matplotlib, no display needed)."""

from __future__ import annotations

import math
from pathlib import Path

from specc.analysis.incompat import IncompatibilityGraph, service_groups, state_count

GROUP_COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860", "#da8bc3", "#8c8c8c")


def draw_incompatibility_graph(graph: IncompatibilityGraph, target: Path, title: str) -> Path:
    """Services on a circle; solid arcs interrupt, dashed arcs wait; groups share a colour."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyArrowPatch

    groups = service_groups(graph)
    colour = {s: GROUP_COLOURS[i % len(GROUP_COLOURS)] for i, g in enumerate(groups) for s in g.services}
    count = len(graph.services)
    radius = 1.0
    position = {s: (radius * math.cos(2 * math.pi * i / count + math.pi / 2),
                    radius * math.sin(2 * math.pi * i / count + math.pi / 2))
                for i, s in enumerate(graph.services)}
    size = max(6.0, 0.45 * count + 4)
    figure, axes = plt.subplots(figsize=(size, size))
    for arc in graph.arcs:
        start, end = position[arc.source], position[arc.target]
        style = "-" if arc.policy == "interrupt" else "--"
        if arc.source == arc.target:
            x, y = start
            axes.add_patch(FancyArrowPatch((x + 0.04, y + 0.05), (x - 0.04, y + 0.05),
                                           connectionstyle="arc3,rad=-2.5", arrowstyle="-|>",
                                           mutation_scale=10, linestyle=style, color="#555555"))
            continue
        axes.add_patch(FancyArrowPatch(start, end, connectionstyle="arc3,rad=0.08", arrowstyle="-|>",
                                       mutation_scale=12, shrinkA=14, shrinkB=14, linestyle=style,
                                       color="#555555", linewidth=0.9))
    for service, (x, y) in position.items():
        shade = colour.get(service, "#ffffff")
        kind = " (control)" if service in graph.control else ""
        axes.scatter([x], [y], s=420, color=shade, edgecolors="black", zorder=3)
        axes.annotate(service + kind, (x, y), xytext=(x * 1.18, y * 1.18), ha="center", va="center", fontsize=9)
    legend = [f"{g.name}: {' | '.join(g.states)}" for g in groups]
    axes.set_title(f"{title}\n{len(groups)} service groups, {state_count(groups)} controller states "
                   "(solid: interrupt, dashed: wait)", fontsize=11)
    for i, line in enumerate(legend):
        axes.text(-1.45, -1.35 - 0.09 * i, line, fontsize=9, color=GROUP_COLOURS[i % len(GROUP_COLOURS)])
    axes.set_xlim(-1.5, 1.5)
    axes.set_ylim(-1.45 - 0.09 * len(legend), 1.4)
    axes.set_aspect("equal")
    axes.axis("off")
    target.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(target, dpi=110, bbox_inches="tight")
    plt.close(figure)
    return target
