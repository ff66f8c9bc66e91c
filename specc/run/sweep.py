"""`specc table`: every mission x world x configuration x seed of a robot run, one run folder
each, and the table of their measures.

    table = sweep(Path("examples/atrv"), missions=["M1", "M2"], worlds=["W1"], configurations=["Robot1"])
    table.rows          # specc.run.measures.MeanMeasures, one per configuration x mission x world
    table.failures      # the runs whose mission failed, with why and their folder

For the rover the rows are the means of seed 004 §4.1.4 (`specc.run.measures`); for the Hilare
hunt, one row over the seeds: how many were tried, how many succeeded, and the means. Every run
keeps its folder (log, report; pictures on request) so each failure can be read in its log.
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
from specc.run.session import RunCrashed, RunOutcome, RunRequest, plan_run, run_planned
from specc.runtime.ftplan import planner_processes_kept

MISSIONS = ("M1", "M2", "M3", "M4")
WORLDS = ("W1", "W2", "W3", "W4")
CONFIGURATIONS = ("Robot1", "Robot2", "Robot1/2", "Robot1/2c")

Step = Callable[[int, int, str], None]  # runs done, runs in all, the run under way (or just ended)


@dataclass(frozen=True)
class Failure:
    name: str  # the run folder's name
    folder: Path
    why: str


@dataclass(frozen=True)
class HuntRow:
    seeds: int
    succeeded: int
    objects_taken: float  # mean
    simulated_time: float  # mean, s, over the successful hunts
    distance: float  # mean, m

    @property
    def success_rate(self) -> float:
        return self.succeeded / self.seeds if self.seeds else 0.0


@dataclass
class SweepResult:
    robot: str
    outcomes: list[RunOutcome] = field(default_factory=list)
    rows: list[MeanMeasures] = field(default_factory=list)  # the rover's
    hunt: HuntRow | None = None  # the hunt's

    @property
    def failures(self) -> list[Failure]:
        return [Failure(o.folder.name, o.folder, str(o.report.get("why", ""))) for o in self.outcomes
                if not o.succeeded]

    def markdown(self) -> str:
        if self.hunt is not None:
            h = self.hunt
            text = ("| seeds | succeeded | success rate | objects taken | time (s) | distance (m) |\n"
                    "| --- | --- | --- | --- | --- | --- |\n"
                    f"| {h.seeds} | {h.succeeded} | {100 * h.success_rate:.0f} % | {h.objects_taken:.2f} | "
                    f"{h.simulated_time:.0f} | {h.distance:.1f} |\n")
        else:
            text = markdown_table(self.rows)
        crashed = sum(o.report.get("outcome") == "crashed" for o in self.outcomes)
        if crashed:
            text += f"\n{crashed} run(s) crashed: they have no measures, so the means above leave them out.\n"
        if self.failures:
            text += "\nFailures (each run's log is in its folder):\n\n" + "".join(
                f"- {f.name}: {f.why}\n" for f in self.failures)
        return text

    def to_json(self) -> dict[str, Any]:
        return {"robot": self.robot, "runs": [dict(o.report, folder=str(o.folder)) for o in self.outcomes],
                "rows": [row.to_json() for row in self.rows],
                "hunt": None if self.hunt is None else {**self.hunt.__dict__, "success_rate": self.hunt.success_rate}}


def sweep(robot: str, base: RunRequest, *, missions: Sequence[str] = MISSIONS, worlds: Sequence[str] = WORLDS,
          configurations: Sequence[str] = CONFIGURATIONS, seeds: Sequence[int] = (0,),
          step: Step | None = None) -> SweepResult:
    """Run `robot` (compiled into base.generated) on every combination, each run as `base` says
    otherwise (its folder under base.runs). Names are checked before the first run."""
    if not seeds:
        raise RunError("no seed to run: give at least one")
    if robot == "atrv":
        requests = [replace(base, mission=m, world=w, configuration=c, seed=s)
                    for c, m, w, s in itertools.product(configurations, missions, worlds, seeds)]
    else:
        requests = [replace(base, seed=s) for s in seeds]
    if not requests:
        raise RunError("nothing to run: give at least one mission, world and configuration")
    planned = [plan_run(robot, request) for request in requests]  # a typo stops the table before any run
    result = SweepResult(robot)
    with planner_processes_kept():  # the runs' planners start warm, one after another
        for done, run in enumerate(planned):
            if step is not None:
                step(done, len(requests), _label(robot, run.request))
            try:
                result.outcomes.append(run_planned(run))
            except RunCrashed as crash:  # one broken run is a failure of the table, not the end of it
                result.outcomes.append(crash.outcome)
    if step is not None:
        step(len(requests), len(requests), "")
    if robot == "atrv":
        result.rows = measure_table([Measures.from_json(o.report["measures"]) for o in result.outcomes
                                     if "measures" in o.report])
    else:
        result.hunt = _hunt_row(result.outcomes)
    return result


def _label(robot: str, request: RunRequest) -> str:
    if robot == "atrv":
        return f"{request.configuration} {request.mission} {request.world} seed {request.seed}"
    return f"hunt seed {request.seed}"


def _hunt_row(outcomes: Sequence[RunOutcome]) -> HuntRow:
    def mean(values: Sequence[float]) -> float:
        return math.fsum(values) / len(values) if values else 0.0

    measures = [o.report["measures"] for o in outcomes if "measures" in o.report]
    succeeded = [o for o in outcomes if o.succeeded]
    return HuntRow(seeds=len(outcomes), succeeded=len(succeeded),
                   objects_taken=mean([m["objects_taken"] for m in measures]),
                   simulated_time=mean([o.report["simulated_time"] for o in succeeded]),
                   distance=mean([m["distance"] for m in measures]))


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
