"""The incompatibility graph reduced to service groups reproduces seed 000 §3.6.1, §3.8 and Table 5.7."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from specc.analysis.incompat import build_graph, reduce, service_groups, state_count
from specc.model import nodes as m
from specc.pipeline import load
from tests.conftest import EXAMPLES


def executive(robot: str, name: str) -> tuple[m.Program, m.Executive]:
    loaded = load([EXAMPLES / robot])
    assert loaded.program is not None
    found = {e.name: e for e in loaded.program.items if isinstance(e, m.Executive)}
    return loaded.program, found[name]


def groups_of(robot: str, name: str) -> list[set[str]]:
    graph = build_graph(*executive(robot, name))
    return [set(g.services) for g in service_groups(graph)]


def test_figs_3_5_and_3_6_give_groups_b_def_g_hi_j_and_96_states() -> None:
    graph = build_graph(*executive("generic", "fig35"))
    groups = service_groups(graph)
    assert [g.name for g in groups] == ["B", "DEF", "G", "HI", "J"]
    assert state_count(groups) == 96
    assert ("D", "E", "F") in reduce(graph) and ("H", "I") in reduce(graph)
    assert ("C", "E") in {(a.source, a.target) for a in graph.arcs}  # "le service C interrompt le service E"


def test_generic_system_of_table_3_1_needs_groups_abc_and_efg() -> None:
    assert groups_of("generic", "generic") == [{"A", "B", "C"}, {"E", "F", "G"}]


def test_wait_arcs_are_kept_apart_from_interrupt_arcs() -> None:
    graph = build_graph(*executive("generic", "generic"))
    policies = {(a.source, a.target): a.policy for a in graph.arcs}
    assert policies[("C", "A")] == "wait" and policies[("I", "A")] == "wait"
    assert policies[("I", "E")] == "interrupt" and policies[("J", "A")] == "interrupt"
    assert not any(a.target in graph.control for a in graph.arcs)  # nothing interrupts a control request


def test_hilare_gives_the_six_groups_of_table_5_7() -> None:
    expected = [{"ARM-BACK", "ARM-OBJ"}, {"READ-MODEL", "CALC-TRAJ-OBJ", "CALC-TRAJ-GOAL"},
                {"EXEC-TRAJ-OBJ", "EXEC-TRAJ-GOAL"}, {"READ-OBST", "SEARCH-OBJ"}, {"CALC-OBJ"}, {"CALC-GOAL"}]
    found = groups_of("hilare", "hilare")
    assert sorted(map(sorted, found)) == sorted(map(sorted, expected))
    graph = build_graph(*executive("hilare", "hilare"))
    assert state_count(service_groups(graph)) == 3 * 4 * 3 * 3 * 2 * 2


def test_specc_graph_draws_the_picture_and_prints_the_groups(tmp_path: Path) -> None:
    picture = tmp_path / "fig35.png"
    result = subprocess.run([sys.executable, "-m", "specc.cli", "graph", "--incompat", str(EXAMPLES / "generic"),
                             "--executive", "fig35", "-o", str(picture)], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "5 group(s), 96 resource-controller states" in result.stdout
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and picture.stat().st_size > 10_000
    several = subprocess.run([sys.executable, "-m", "specc.cli", "graph", "--incompat", str(EXAMPLES / "generic"),
                              "-o", str(picture)], capture_output=True, text=True, timeout=120)
    assert several.returncode == 2 and "pick one with --executive" in several.stderr
