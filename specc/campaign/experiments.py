"""One experiment of a campaign (seed 004 §4.1.1): a robot configuration runs a mission in a world
with a planning model that may hold an injected fault, for one seed. It is a pure function of
those five values: the same experiment gives the same measures wherever it runs."""

from __future__ import annotations

import functools
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from specc.run import RunError
from specc.runtime.planner import model as pm

ORIGINAL = "original"  # the mutant name of the model without an injected fault (the seed's ∅)
STATUSES = ("done", "crashed", "timeout")


@dataclass(frozen=True, order=True)
class Experiment:
    configuration: str  # Robot1, Robot1/2, ...
    mutant: str  # a mutant id (model1-0042), or ORIGINAL
    mission: str
    world: str
    seed: int

    @property
    def key(self) -> str:
        """The experiment's name in the results store: one row per key, ever."""
        return f"{self.configuration}|{self.mutant}|{self.mission}|{self.world}|{self.seed}"

    @property
    def activity(self) -> str:
        return f"{self.mission}{self.world}"


@dataclass(frozen=True)
class Outcome:
    """What an experiment gave: its measures when it ran to its end (whatever the mission's
    outcome), else why not (the experiment crashed, or overran its hard timeout)."""

    experiment: Experiment
    status: str  # one of STATUSES
    measures: dict[str, Any] | None  # specc.run.measures.Measures.to_json() when done
    seconds: float  # wall time
    why: str = ""


@dataclass(frozen=True)
class Setting:
    """Where every experiment of a campaign finds the robot: the compiled package's parent folder,
    the robot's spec folder (codels, worlds) and its package name, plus FTplan's planning charge."""

    generated: Path
    example: Path
    robot: str
    timing: str = "model"


@functools.cache
def _robot(setting: Setting) -> Any:
    """The compiled robot, imported once per process."""
    from specc.run.mission import load_robot

    return load_robot(setting.generated, setting.example, setting.robot)


def run_experiment(experiment: Experiment, domain: pm.PlanningDomain | None, setting: Setting) -> Outcome:
    """Run the experiment with `domain` (the mutant's planning domain; None: the original model)
    in place of the generated domain of the same name. Its measures are those of seed 004 §4.1.4:
    the robot's extension's when it measures them, else FTplan's goals as its ledger counted them
    (`specc.run.measures.planned_measures`). Never raises: a failure is the outcome."""
    from specc.run.measures import Measures, planned_measures
    from specc.run.mission import run_mission

    started = time.perf_counter()
    try:
        robot = _robot(setting)
        run = run_mission(robot, robot.mission(experiment.mission), experiment.seed, world=experiment.world,
                          configuration=experiment.configuration, timing=setting.timing,
                          domains={domain.name: domain} if domain is not None else None)
        measured = dict(run.extension_measures)
        measures = measured if Measures.readable(measured) else planned_measures(run.events).to_json()
    except RunError as error:
        return Outcome(experiment, "crashed", None, time.perf_counter() - started, str(error))
    except Exception as error:  # an experiment must never take the campaign with it
        last = traceback.extract_tb(error.__traceback__)[-1]
        where = f" ({Path(last.filename).name}:{last.lineno})"
        return Outcome(experiment, "crashed", None, time.perf_counter() - started,
                       f"{type(error).__name__}: {error}{where}")
    return Outcome(experiment, "done", measures, time.perf_counter() - started)
