"""`make bench`: the executive and the rule bases at a real robot's size (issue #24, item 2).

- `specc compile` of robots whose executive has 10, 25, 50 and 100 services with random
  conflicts (tests/scale.py, seeded), each in its own process: wall time and peak memory (the
  process's maximum resident set), the controller's states (the product of its groups' states)
  and the work of its compilation, and the growth from one size to the next. Goal: 50 services
  in under 10 s and 500 MB.
- The same controllers compiled as one decision over every group's state (what the compiler did
  before it split them per service), same run, under a work limit: the baseline the split is
  measured against, on Hilare's controller too (size of the generated file, work, time).
- A rule base of 8 numeric inputs x 50 threshold rules, compiled by `specc compile` in its own
  process (time, memory, work).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from specc.analysis import kheops as k
from specc.analysis.controller import executive_controller
from specc.analysis.incompat import state_count
from specc.backends.env import render
from specc.backends.rules import DecisionView
from specc.model import nodes as m
from specc.pipeline import load
from tests.conftest import EXAMPLES
from tests.scale import threshold_base, write_robot

pytestmark = pytest.mark.bench

SIZES = (10, 25, 50, 100)
SEED = 1
GOAL_SERVICES, GOAL_SECONDS, GOAL_MB = 50, 10.0, 500
ONE_DECISION_LIMIT = 100_000  # tree nodes: the unsplit baseline stops there (about 10 s)

# Runs `specc compile` in this process and prints its wall time and peak resident memory: the
# high-water mark of its own memory (VmHWM; ru_maxrss would count what the parent held at the fork).
MEASURED = """
import json, sys, time
from specc.cli import app
started = time.perf_counter()
try:
    app(sys.argv[1:], standalone_mode=False)
    code = 0
except SystemExit as exc:
    code = exc.code
wall = time.perf_counter() - started
status = open("/proc/self/status").read().splitlines()
peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024
print("MEASURED " + json.dumps({"code": code, "wall": wall, "mb": peak}))
"""


def measured_compile(spec: Path, out: Path) -> dict[str, float]:
    result = subprocess.run([sys.executable, "-c", MEASURED, "compile", str(spec), "-o", str(out)],
                            capture_output=True, text=True, timeout=900)
    line = next((x for x in result.stdout.splitlines() if x.startswith("MEASURED ")), None)
    assert line is not None, result.stdout + result.stderr
    figures: dict[str, float] = json.loads(line.removeprefix("MEASURED "))
    assert figures["code"] in (0, None), result.stdout + result.stderr
    return figures


def one_decision(base: k.Base) -> tuple[str, float]:
    """The controller compiled as one decision over every group's state, or how far it got."""
    started = time.perf_counter()
    try:
        compiled = k.compile_base(base, limit=ONE_DECISION_LIMIT)
    except k.TooLarge:
        return f"> {ONE_DECISION_LIMIT:,} nodes", time.perf_counter() - started
    return f"{compiled.tree_nodes:,} nodes", time.perf_counter() - started


def test_executives_of_10_to_100_services_compile_with_the_conflicts(tmp_path: Path) -> None:
    rows = []
    for services in SIZES:
        folder = write_robot(tmp_path / f"robot{services}", services, SEED)
        figures = measured_compile(folder, tmp_path / f"out{services}")
        loaded = load([folder])
        assert loaded.program is not None
        executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
        controller = executive_controller(loaded.program, executive)
        split = controller.compile()
        generated = next((tmp_path / f"out{services}").glob("*/executive/*_resource_controller.py"))
        whole, whole_wall = one_decision(controller.base)
        rows.append((services, len(controller.groups), state_count(controller.groups), figures["wall"],
                     figures["mb"], split.tree_nodes, generated.stat().st_size, whole, whole_wall))
    print(f"\nexecutives with random conflicts (seed {SEED}, tests/scale.py): `specc compile` in its own process; "
          f"the controller as one decision per service, against one decision over every group's state (same run, "
          f"stopped at {ONE_DECISION_LIMIT:,} nodes)")
    print(f"  {'services':>8s} {'groups':>6s} {'states':>12s} {'compile':>8s} {'peak':>7s} {'growth':>14s} "
          f"{'split work':>11s} {'controller':>11s}   {'one decision':>18s}")
    previous = None
    for services, groups, states, wall, mb, nodes, size, whole, whole_wall in rows:
        growth = "" if previous is None else f"x{wall / previous[0]:.1f} t x{mb / previous[1]:.1f} m"
        print(f"  {services:8d} {groups:6d} {states:12.3g} {wall:7.2f}s {mb:5.0f}MB {growth:>14s} {nodes:11,d} "
              f"{size / 1024:9.0f}KB   {whole:>14s} {whole_wall:5.1f}s")
        previous = (wall, mb)
    at_goal = next(r for r in rows if r[0] == GOAL_SERVICES)
    met = at_goal[3] < GOAL_SECONDS and at_goal[4] < GOAL_MB
    print(f"  goal: {GOAL_SERVICES} services in under {GOAL_SECONDS:.0f} s and {GOAL_MB} MB: "
          f"{at_goal[3]:.1f} s, {at_goal[4]:.0f} MB, {'met' if met else 'NOT MET'}")


def test_hilare_controller_split_per_service_against_one_decision(tmp_path: Path) -> None:
    loaded = load([EXAMPLES / "hilare"])
    assert loaded.program is not None
    executive = next(i for i in loaded.program.items if isinstance(i, m.Executive))
    controller = executive_controller(loaded.program, executive)
    started = time.perf_counter()
    split = controller.compile()
    split_wall = time.perf_counter() - started
    started = time.perf_counter()
    whole = k.compile_base(controller.base)
    whole_wall = time.perf_counter() - started
    sources = controller.executive.span.file
    split_size = len(render("rules/decision.py.j2", view=DecisionView(split, sources)))
    whole_size = len(render("rules/decision.py.j2", view=DecisionView(whole, sources)))
    groups = len(controller.groups)
    print(f"\nHilare's resource controller ({len(controller.graph.services)} services, {groups} groups, "
          f"{state_count(controller.groups)} states), same run:")
    for label, compiled, size, wall in (("one decision over every group's state", whole, whole_size, whole_wall),
                                        ("one decision per service", split, split_size, split_wall)):
        print(f"  {label:38s} {compiled.tree_nodes:8,d} tree nodes {compiled.dag_nodes:6,d} shared  depth "
              f"{compiled.depth}  {size / 1024:6.0f} KB generated  {wall:5.2f} s")
    print(f"  ({whole_size / split_size:.0f}x smaller, {whole_wall / split_wall:.0f}x faster to compile)")
    # The same decisions: every domain combination of the inputs, both ways.
    for inputs in k.sample_inputs(controller.base):
        assert k.evaluate(split, inputs).key() == k.evaluate(whole, inputs).key()


def test_rule_base_of_8_inputs_and_50_rules(tmp_path: Path) -> None:
    spec = tmp_path / "policy.spec"
    spec.write_text(threshold_base(8, 50))
    figures = measured_compile(spec, tmp_path / "out")
    source = load([spec]).program
    assert source is not None
    bound, _ = k.paths_bound(k.normalise(next(i for i in source.items if isinstance(i, m.RuleBase))))
    generated = next((tmp_path / "out").glob("*/rules/big.py")).read_text()
    depth = re.search(r"^DEPTH = (\d+)$", generated, re.MULTILINE)
    assert depth is not None
    print(f"\nrule base of 8 numeric inputs x 50 threshold rules (tests/scale.py): `specc compile` in its own "
          f"process {figures['wall']:.1f} s, peak {figures['mb']:.0f} MB; a decision graph of depth {depth[1]}, "
          f"{len(generated) / 1024:.0f} KB generated (the inputs' values combine in {bound:,} ways)")
