from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
EXAMPLE_ROBOTS = ("hilare", "generic", "atrv", "tug")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
HUNT_SEED = 0  # five objects taken; its first exploration move is interrupted by a detection (§5.5, t2)


def is_png(path: Path) -> bool:
    return path.read_bytes()[:8] == PNG_MAGIC


@pytest.fixture(scope="session", autouse=True)
def _stamps_in_a_temporary_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Compile-if-stale stamps (specc.run.package) go to a cache of the test session's own, the
    commands the tests start included, not to the user's."""
    before = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if before is None:
        del os.environ["XDG_CACHE_HOME"]
    else:
        os.environ["XDG_CACHE_HOME"] = before


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture
def no_planner_left_behind() -> Iterator[None]:
    """Every planner process FTplan started is gone when the test ends."""
    import multiprocessing

    yield
    assert multiprocessing.active_children() == []


@pytest.fixture(scope="session")
def hunt_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, Path, list[Any]]:
    """One full hunt of seed HUNT_SEED (about 4 s) through the generic runner, its log file and its
    progress reports, shared by the tests of the hunt and of its pictures."""
    from specc.run.events import EventLog
    from specc.run.mission import run_mission

    robot = hilare()
    path = tmp_path_factory.mktemp("hunt") / "hunt.jsonl"
    reports: list[Any] = []
    with EventLog(path) as log:
        result = run_mission(robot, robot.mission("hunt"), HUNT_SEED, log=log, progress=reports.append)
    return result, path, reports


def hilare() -> Any:
    """The compiled Hilare of generated/, with its codels (and its extension) importable."""
    from specc.run.mission import load_robot

    return load_robot(ROOT / "generated", EXAMPLES / "hilare", "hilare")


def tug_with(tmp_path: Path, planner: str, line: str) -> tuple[Any, Any, dict[str, Any]]:
    """examples/tug copied into `tmp_path`, `line` (`repair: on;`) added to its planner block
    `planner`: the program, its ftplan configuration and its planning domains (by name)."""
    import shutil

    from specc.analysis.ftplan import ftplan_config
    from specc.analysis.planning import domain_model
    from specc.model import nodes as m
    from specc.pipeline import load

    tug = tmp_path / "tug"
    shutil.copytree(EXAMPLES / "tug", tug)
    spec = (tug / "ftplan.spec").read_text()
    block = f"planner {planner} {{\n"
    assert block in spec
    (tug / "ftplan.spec").write_text(spec.replace(block, f"{block}    {line}\n"))
    loaded = load([tug])
    assert not loaded.errors and loaded.program is not None
    ftplan = next(i for i in loaded.program.items if isinstance(i, m.FtPlan))
    domains = {d.name: domain_model(loaded.program, d) for d in loaded.program.items if isinstance(d, m.Domain)}
    return loaded.program, ftplan_config(ftplan, loaded.program), domains
