"""`specc table`: every mission x world x configuration x seed of a robot run, one run folder
each, and the table of their measures.

    table = sweep("tug", RunRequest(Path("examples/tug")), missions=["shuttle"], worlds=["hall", "crowded"])
    table.missions      # one MissionRow per mission x world x configuration
    table.failures      # the runs whose mission failed, with why and their folder

One row per mission x world x configuration over the seeds: how many were tried, how many
succeeded, the mean time of the successful ones, and the means of the run's figures (its
extension's too, e.g. the objects a hunt took). When every run's extension measured seed 004
§4.1.4's figures (`specc.run.measures.Measures`, as the rover's does), the table is theirs: the
means sigma-bar, nu-bar, kappa-bar, R-bar, T-bar, D-bar. Every run keeps its folder (log, report;
pictures on request) so each failure can be read in its log.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from specc.run import RunError
from specc.run.measures import MeanMeasures, Measures, markdown_table, measure_table
from specc.run.mission import brief_why, load_robot
from specc.run.session import RunCrashed, RunOutcome, RunRequest, plan_run, run_planned
from specc.runtime.ftplan import planner_processes_kept

Step = Callable[[int, int, str], None]  # runs done, runs in all, the run under way (or just ended)


@dataclass(frozen=True)
class Failure:
    name: str  # the run folder's name
    folder: Path
    why: str
    outcome: str = "failed"  # the report's: failed, horizon (still running at the horizon's end) or crashed


@dataclass(frozen=True)
class MissionRow:
    """A mission in a world over the seeds."""

    mission: str
    world: str
    configuration: str | None  # FTplan's, for a planned mission
    seeds: int
    succeeded: int
    simulated_time: float | None  # mean, s, over the successful runs (None: none succeeded)
    means: dict[str, float]  # the mean of each figure every run measured with a number

    @property
    def success_rate(self) -> float:
        return self.succeeded / self.seeds if self.seeds else 0.0

    def to_json(self) -> dict[str, Any]:
        return {**self.__dict__, "success_rate": self.success_rate}


@dataclass
class SweepResult:
    robot: str
    outcomes: list[RunOutcome] = field(default_factory=list)
    rows: list[MeanMeasures] = field(default_factory=list)  # seed 004's means, when the runs measured them
    missions: list[MissionRow] = field(default_factory=list)
    planned: int = 0  # the runs asked for: more than the outcomes when the table was interrupted

    @property
    def interrupted(self) -> bool:
        return len(self.outcomes) < self.planned

    @property
    def failures(self) -> list[Failure]:
        return [Failure(o.folder.name, o.folder, str(o.report.get("why", "")), str(o.report.get("outcome", "failed")))
                for o in self.outcomes if not o.succeeded]

    def markdown(self) -> str:
        if self.rows:
            text = markdown_table(self.rows)
        else:
            headings, cells = self.mission_cells()
            text = ("| " + " | ".join(headings) + " |\n" + "| --- " * len(headings) + "|\n"
                    + "".join(("| " + " | ".join(row) + " |").replace("|  |", "| |") + "\n" for row in cells))
        if self.interrupted:
            text += (f"\nInterrupted after {len(self.outcomes)} of {self.planned} run(s): the means above are over "
                     "those.\n")
        crashed = sum(o.report.get("outcome") == "crashed" for o in self.outcomes)
        if crashed:
            text += f"\n{crashed} run(s) crashed: they have no measures, so the means above leave them out.\n"
        if self.failures:
            text += "\nFailures (each run's log is in its folder, and the whole why in its report.json):\n\n" + "".join(
                f"- {f.name} ({f.outcome}): {brief_why(f.why)}\n" for f in self.failures)
        return text

    def mission_cells(self) -> tuple[list[str], list[list[str]]]:
        """The missions' table when the runs measured no seed 004 means: its headings, and each
        mission's cells (the mean of every figure a run measured with a number), for the Markdown
        file and the terminal alike."""
        figures = list(dict.fromkeys(name for row in self.missions for name in row.means))
        if all(row.means.get("goals", 0) == 0 for row in self.missions):
            # Goals posted to the supervisor: a planned mission posts none (FTplan's goals are the
            # planned_goals columns), and columns of zeros would read as goals failed.
            figures = [name for name in figures if name not in POSTED_GOALS]
        headings = ["mission", "world", "configuration", "seeds", "succeeded", "success rate", "time (s)", *figures]
        # A planned mission beside missions of posted goals posts none: "-", not goals failed.
        cells = [[row.mission, row.world, row.configuration or "-", str(row.seeds), str(row.succeeded),
                  f"{100 * row.success_rate:.0f} %", mean_time_text(row.simulated_time, ".1f"),
                  *("-" if n in POSTED_GOALS and not row.means.get("goals") else
                    f"{row.means[n]:.4g}" if n in row.means else "" for n in figures)] for row in self.missions]
        return headings, cells

    def to_json(self) -> dict[str, Any]:
        return {"robot": self.robot, "planned": self.planned, "interrupted": self.interrupted,
                "runs": [dict(o.report, folder=str(o.folder)) for o in self.outcomes],
                "rows": [row.to_json() for row in self.rows],
                "missions": [row.to_json() for row in self.missions]}


POSTED_GOALS = ("goals_succeeded", "goals")  # a run's measures of the goals posted to its supervisor


def sweep(robot: str, base: RunRequest, *, missions: Sequence[str] = (), worlds: Sequence[str] = (),
          configurations: Sequence[str] = (), seeds: Sequence[int] = (0,), step: Step | None = None) -> SweepResult:
    """Run `robot` (compiled into base.generated) on every combination, each run as `base` says
    otherwise (its folder under base.runs). Names are checked before the first run. No missions:
    every mission of the system (with configurations: every planned one); no worlds: each in its own;
    no configurations: FTplan's default. A mission without planning named beside configurations
    runs once, without any."""
    if not seeds:
        raise RunError("no seed to run: give at least one")
    declared = load_robot(base.generated, base.specs, robot).system.missions

    def is_planned(name: str) -> bool:
        mission = declared.get(name)
        return mission is None or mission.plan is not None  # an unknown name: plan_run says so

    # With configurations of FTplan and no mission named: the planned missions, which they are for.
    every = missions or tuple(name for name in declared if not configurations or is_planned(name))
    if configurations and not any(is_planned(name) for name in every):
        which = f"none of the missions named ({', '.join(every)})" if missions else f"no mission of robot {robot!r}"
        raise RunError(f"--config: {which} is planned (a mission with 'plan:'), and a configuration is FTplan's: "
                       "run without --config")
    requests = []
    for c, m, w, s in itertools.product(configurations or (None,), every, worlds or (None,), seeds):
        if c is not None and not is_planned(m):
            if c != configurations[0]:
                continue
            c = None  # a mission without planning runs without FTplan: once, whatever the configurations
        requests.append(replace(base, mission=m, world=w, configuration=c, seed=s))
    if not requests:
        raise RunError("nothing to run: give at least one mission, world and configuration")
    planned = [plan_run(robot, request) for request in requests]  # a typo stops the table before any run
    result = SweepResult(robot, planned=len(planned))
    with planner_processes_kept():  # the runs' planners start warm, one after another
        for done, run in enumerate(planned):
            if step is not None:
                step(done, len(requests), _label(robot, run.request))
            try:
                result.outcomes.append(run_planned(run))
            except RunCrashed as crash:  # one broken run is a failure of the table, not the end of it
                if crash.exit_code == 130:  # but a signal (Ctrl-C) stops the table: the runs before it make it
                    break
                result.outcomes.append(crash.outcome)
    if step is not None and not result.interrupted:
        step(len(requests), len(requests), "")
    result.missions = mission_rows(result.outcomes)
    measured = [o.report.get("measures") for o in result.outcomes if o.report.get("outcome") != "crashed"]
    if measured and all(isinstance(m, dict) and Measures.readable(m) for m in measured):
        result.rows = measure_table([Measures.from_json(m) for m in measured if m is not None])
    return result


def _label(robot: str, request: RunRequest) -> str:
    configuration = f"{request.configuration} " if request.configuration else ""
    world = f" {request.world}" if request.world else ""
    return f"{configuration}{request.mission}{world} seed {request.seed}"


def mission_rows(outcomes: Sequence[RunOutcome]) -> list[MissionRow]:
    """One row per mission x world, in the order first run."""
    def mean(values: Sequence[float]) -> float:
        return math.fsum(values) / len(values) if values else 0.0

    groups: dict[tuple[str, str, str | None], list[RunOutcome]] = {}
    for outcome in outcomes:
        key = (str(outcome.report.get("mission")), str(outcome.report.get("world")),
               outcome.report.get("configuration"))
        groups.setdefault(key, []).append(outcome)
    rows = []
    for (mission, world, configuration), group in groups.items():
        measured = [o.report["measures"] for o in group if isinstance(o.report.get("measures"), dict)]
        numeric = [name for name in dict.fromkeys(n for m in measured for n in m)
                   if measured and all(_is_number(m.get(name)) for m in measured)]
        succeeded = [o for o in group if o.succeeded]
        rows.append(MissionRow(mission, world, configuration, len(group), len(succeeded),
                               mean([o.report["simulated_time"] for o in succeeded]) if succeeded else None,
                               {name: mean([float(m[name]) for m in measured]) for name in numeric}))
    return rows


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def write_table(result: SweepResult, path: Path) -> list[Path]:
    """The table as Markdown at `path` and as JSON beside it (same name, .json)."""
    written = [path, path.with_suffix(".json")]
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(result.markdown(), encoding="utf-8")
        written[1].write_text(json.dumps(result.to_json(), indent=2, sort_keys=True) + "\n", encoding="utf-8")
    except OSError as error:
        raise RunError(f"cannot write the table '{path}': {error.strerror or error}") from None
    return written


def mean_time_text(value: float | None, spec: str = ".0f") -> str:
    """A mean time as a table shows it: "-" when there is none (no run succeeded)."""
    return "-" if value is None else format(value, spec)
