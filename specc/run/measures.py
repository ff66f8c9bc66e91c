"""The measures of seed 004 §4.1.4, from rover runs (`specc.run.rover`).

For one run (`measure(run)`):

- u_i of v_i goals met per kind i: photos (p), communications (c), the return home (h); the
  quotients sigma_i = u_i / v_i of goals met and phi_i = 1 - sigma_i of goals failed;
- mu, the mission's failure (1 when some goal was not met), and nu = 1 - mu, its success (the
  thesis' formula for mu has the cases the wrong way round; its text is followed);
- kappa, the planner's failure: 1 when planning could not give the system a plan in time (FTplan's
  mission exception: every planner failed in a row). A planner that crashed, hung or gave an
  invalid plan and was recovered from is counted apart (`planner_failures`);
- R, the replannings: planning rounds after the first (with FTplan, model switches too). A round
  is one request in successive planning (Fig 3.1 line 9), one request to every planner at once in
  concurrent planning (Fig 3.2 line 5);
- T, the physical activity time: how long at least one action ran (the planner's time is not
  counted, nor waiting for a window);
- D, the distance the robot travelled.

The goals are judged on what really happened in the simulation, as the thesis took its measures
from the simulator's logs, not on what FTplan believes (`believed`, counted apart): a photo is met
when an image CAMERA took shows its target, a communication when its window held one of ANTENNA's
links, the return when the robot really stands within HOME_TOLERANCE of home at the end.
The two differ when FTplan's state is wrong: a communication a faulty plan sent in another window
than its own, a robot whose odometry says home when it is not.

For many runs, the thesis' means (§4.1.4: sigma-bar_p(A, F) over n executions):
`aggregate(measures)` and `measure_table(measures, by=...)` (one row per configuration x mission x
world, or grouped over any of them: "*" stands for all, as the thesis' M*, W*), rendered by
`markdown_table` or `rich_table`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from specc.run import RunError

if TYPE_CHECKING:
    from rich.table import Table

    from specc.run.rover import MissionGoal, RoverRun

HOME_TOLERANCE = 0.5  # m: NDD stops within 0.3 m of its goal by odometry, which drifts (INVENTED)
GROUPS = ("configuration", "mission", "world")
ALL = "*"  # a dimension the row groups over


@dataclass(frozen=True)
class GoalCount:
    """u goals met of the v asked for, of one kind."""

    asked: int  # v
    met: int  # u

    @property
    def sigma(self) -> float:
        """The quotient of goals met (1 when none was asked for)."""
        return self.met / self.asked if self.asked else 1.0

    @property
    def phi(self) -> float:
        """The quotient of goals failed."""
        return 1.0 - self.sigma

    def text(self) -> str:
        return f"{self.met}/{self.asked}"


@dataclass(frozen=True)
class Measures:
    """The measures of one run (seed 004 §4.1.4)."""

    configuration: str
    mission: str
    world: str
    seed: int
    photos: GoalCount  # p
    communications: GoalCount  # c
    home: GoalCount  # h
    kappa: int  # 1: no plan could be given in time (the mission exception)
    replannings: int  # R
    activity_time: float  # T, s
    distance: float  # D, m
    mission_time: float  # s, when the mission ended
    planner_failures: int  # FTplan's detections: watchdog, crash, no plan, invalid plan
    believed: GoalCount  # every goal, as FTplan's ledger counted them

    @property
    def success(self) -> bool:
        return all(count.met == count.asked for count in (self.photos, self.communications, self.home))

    @property
    def nu(self) -> int:
        return int(self.success)

    @property
    def mu(self) -> int:
        return 1 - self.nu

    def to_json(self) -> dict[str, Any]:
        data = asdict(self)
        for kind, count in (("p", self.photos), ("c", self.communications), ("h", self.home)):
            data[f"sigma_{kind}"] = round(count.sigma, 6)
            data[f"phi_{kind}"] = round(count.phi, 6)
        data.update(mu=self.mu, nu=self.nu, activity_time=round(self.activity_time, 3),
                    distance=round(self.distance, 3), mission_time=round(self.mission_time, 3))
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Measures:
        """The measures `to_json` wrote (a run folder's report.json keeps them)."""
        try:
            counts = {name: GoalCount(int(data[name]["asked"]), int(data[name]["met"]))
                      for name in ("photos", "communications", "home", "believed")}
            return cls(configuration=str(data["configuration"]), mission=str(data["mission"]),
                       world=str(data["world"]), seed=int(data["seed"]), kappa=int(data["kappa"]),
                       replannings=int(data["replannings"]), activity_time=float(data["activity_time"]),
                       distance=float(data["distance"]), mission_time=float(data["mission_time"]),
                       planner_failures=int(data["planner_failures"]), **counts)
        except (KeyError, TypeError, ValueError) as error:
            raise RunError(f"not the measures of a rover run ({type(error).__name__}: {error})") from None

    def summary(self) -> str:
        outcome = "succeeded" if self.success else "failed"
        counts = ", ".join(f"{label} {count.text()} ({symbol} {_percent(count.sigma)})" for label, symbol, count in (
            ("photos", "sigma_p", self.photos), ("communications", "sigma_c", self.communications),
            ("return", "sigma_h", self.home)))
        return "\n".join([
            f"{self.configuration} on {self.mission} in {self.world} (seed {self.seed}): mission {outcome} "
            f"(nu = {self.nu}, mu = {self.mu})",
            f"  goals met: {counts}",
            f"  planner failure kappa = {self.kappa} ({self.planner_failures} failure(s) detected), "
            f"replannings R = {self.replannings}",
            f"  physical activity T = {self.activity_time:.1f} s of {self.mission_time:.1f} s, "
            f"distance D = {self.distance:.1f} m",
            f"  FTplan counted {self.believed.text()} goals met",
        ])


def measure(run: RoverRun) -> Measures:
    """The measures of one rover run, its goals judged on what happened in the simulation."""
    counts = {kind: GoalCount(0, 0) for kind in ("photo", "communication", "return")}
    for goal in run.goals:
        count = counts[goal.kind]
        counts[goal.kind] = GoalCount(count.asked + 1, count.met + achieved(run, goal))
    result = run.result
    return Measures(
        configuration=run.configuration, mission=run.mission, world=run.world, seed=run.seed,
        photos=counts["photo"], communications=counts["communication"], home=counts["return"],
        kappa=int(bool(result.failure)), replannings=run.result.replannings, activity_time=activity_time(run),
        distance=run.distance, mission_time=run.simulated_time, planner_failures=result.planner_failures,
        believed=GoalCount(len(result.met) + len(result.missed), len(result.met)))


def achieved(run: RoverRun, goal: MissionGoal) -> bool:
    """Whether the goal was really met in the simulation."""
    if goal.kind == "photo":
        return any(photo.ok and goal.name in photo.seen for photo in run.photos)
    if goal.kind == "communication":
        return any(link.ok and link.link == goal.name for link in run.communications)
    if goal.kind == "return":
        x, y = run.final_position
        home = goal.point or (0.0, 0.0)
        return math.hypot(x - home[0], y - home[1]) <= HOME_TOLERANCE
    raise ValueError(f"no judgement for goals of kind '{goal.kind}'")


def activity_time(run: RoverRun) -> float:
    """How long at least one action ran: the union of the actions' intervals."""
    total, reached = 0.0, -math.inf
    for start, end in sorted((a.start, a.end) for a in run.actions):
        if end > reached:
            total += end - max(start, reached)
            reached = end
    return total


# ---------------------------------------------------------------- many runs


@dataclass(frozen=True)
class MeanMeasures:
    """The means of the measures over runs (seed 004 §4.1.4): sigma-bar, phi-bar, mu-bar, nu-bar,
    kappa-bar, R-bar, T-bar, D-bar. A dimension the runs differ in reads ALL."""

    configuration: str
    mission: str
    world: str
    runs: int
    sigma_p: float
    sigma_c: float
    sigma_h: float
    nu: float
    kappa: float
    replannings: float  # R-bar
    activity_time: float  # T-bar, s
    distance: float  # D-bar, m

    @property
    def phi_p(self) -> float:
        return 1.0 - self.sigma_p

    @property
    def phi_c(self) -> float:
        return 1.0 - self.sigma_c

    @property
    def phi_h(self) -> float:
        return 1.0 - self.sigma_h

    @property
    def mu(self) -> float:
        return 1.0 - self.nu

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {k: round(v, 6) if isinstance(v, float) else v for k, v in asdict(self).items()}
        data.update(phi_p=round(self.phi_p, 6), phi_c=round(self.phi_c, 6), phi_h=round(self.phi_h, 6),
                    mu=round(self.mu, 6))
        return data


def aggregate(measures: Sequence[Measures]) -> MeanMeasures:
    """The means of `measures` (the arithmetic means of the thesis, quotient by quotient)."""
    if not measures:
        raise RunError("no run to take the means of")

    def label(name: str) -> str:
        values = {getattr(m, name) for m in measures}
        return values.pop() if len(values) == 1 else ALL

    def mean(values: Iterable[float]) -> float:
        listed = list(values)
        return math.fsum(listed) / len(listed)

    return MeanMeasures(
        configuration=label("configuration"), mission=label("mission"), world=label("world"), runs=len(measures),
        sigma_p=mean(m.photos.sigma for m in measures), sigma_c=mean(m.communications.sigma for m in measures),
        sigma_h=mean(m.home.sigma for m in measures), nu=mean(m.nu for m in measures),
        kappa=mean(m.kappa for m in measures), replannings=mean(m.replannings for m in measures),
        activity_time=mean(m.activity_time for m in measures), distance=mean(m.distance for m in measures))


def measure_table(measures: Iterable[Measures], by: Sequence[str] = GROUPS) -> list[MeanMeasures]:
    """One row of means per group of runs with the same values of `by` (configuration, mission,
    world), in the order the groups first appear."""
    unknown = [name for name in by if name not in GROUPS]
    if unknown:
        raise RunError(f"cannot group runs by {', '.join(unknown)} (only by {', '.join(GROUPS)})")
    groups: dict[tuple[str, ...], list[Measures]] = {}
    for m in measures:
        groups.setdefault(tuple(getattr(m, name) for name in by), []).append(m)
    return [aggregate(runs) for runs in groups.values()]


COLUMNS = ("configuration", "mission", "world", "runs", "ν", "φ_p", "φ_c", "φ_h", "κ", "R", "T (s)", "D (m)")


def _cells(row: MeanMeasures) -> list[str]:
    return [row.configuration, row.mission, row.world, str(row.runs), _percent(row.nu), _percent(row.phi_p),
            _percent(row.phi_c), _percent(row.phi_h), _percent(row.kappa), f"{row.replannings:.2f}",
            f"{row.activity_time:.0f}", f"{row.distance:.1f}"]


def markdown_table(rows: Iterable[MeanMeasures]) -> str:
    """The rows as a Markdown table: mission success nu and failed-goal quotients phi (the
    measures of Fig 4.5) in %, kappa in %, R, T and D (Fig 4.6) as means."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "|".join(" --- " for _ in COLUMNS) + "|"]
    lines += ["| " + " | ".join(_cells(row)) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def rich_table(rows: Iterable[MeanMeasures], title: str = "Measures of seed 004 §4.1.4 (means)") -> Table:
    """The rows as a rich Table, for a terminal."""
    from rich.table import Table

    table = Table(title=title)
    for k, column in enumerate(COLUMNS):
        table.add_column(column, justify="left" if k < 3 else "right")
    for row in rows:
        table.add_row(*_cells(row), style=None if row.nu == 1.0 else "yellow")
    return table


def _percent(value: float) -> str:
    return f"{100.0 * value:.0f} %"
