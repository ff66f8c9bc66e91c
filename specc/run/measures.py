"""The measures of seed 004 §4.1.4 for a planned mission, and their means over runs.

A robot's extension measures one run from its log (its `measure(events)` returns
`Measures(...).to_json()`, e.g. seed 004's rover, beside its codels), with
`activity_time(events)` for T. The figures:

- u_i of v_i goals met per kind i: photos (p), communications (c), the return home (h); the
  quotients sigma_i = u_i / v_i of goals met and phi_i = 1 - sigma_i of goals failed;
- mu, the mission's failure (1 when some goal was not met), and nu = 1 - mu, its success (the
  thesis' formula for mu has the cases the wrong way round; its text is followed);
- kappa, the planner's failure: 1 when planning could not give the system a plan in time (FTplan's
  mission exception: every planner failed in a row). A planner that crashed, hung or gave an
  invalid plan and was recovered from is counted apart (`planner_failures`);
- R, the replannings: planning rounds after the first (with FTplan, model switches too). A round
  is one request in successive planning (Fig 3.1 line 9), one request to every planner at once in
  concurrent planning (Fig 3.2 line 5). A plan repair (`repair: on` planners, IxTeT's) is not one,
  as the thesis counts R (§4.2.1.2: R-bar 0.3 for Robot1 with repair, 8.3 for Robot1* without):
  `repairs` and `repaired` count them apart;
- T, the physical activity time: how long at least one action ran (the planner's time is not
  counted, nor waiting for a window);
- D, the distance the robot travelled.

The goals are judged on what really happened in the simulation, as the thesis took its measures
from the simulator's logs, not on what FTplan believes (`believed`, counted apart). The two
differ when FTplan's state is wrong: a communication a faulty plan sent in another window than
its own, a robot whose odometry says home when it is not.

For many runs, the thesis' means (§4.1.4: sigma-bar_p(A, F) over n executions):
`aggregate(measures)` and `measure_table(measures, by=...)` (one row per configuration x mission x
world, or grouped over any of them: "*" stands for all, as the thesis' M*, W*), rendered by
`markdown_table` or `rich_table`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from specc.run import RunError

if TYPE_CHECKING:
    from rich.table import Table

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
    """The measures of one run (seed 004 §4.1.4). The goals are counted by kind, each kind named
    as the robot's measures name it (the rover's: p photos, c communications, h the return home;
    without an extension of its own, each of FTplan's goal attributes is a kind)."""

    configuration: str
    mission: str
    world: str
    seed: int
    goals: tuple[tuple[str, GoalCount], ...]  # (kind, u of v), in the robot's order
    kappa: int  # 1: no plan could be given in time (the mission exception)
    replannings: int  # R
    activity_time: float  # T, s
    distance: float  # D, m
    mission_time: float  # s, when the mission ended
    planner_failures: int  # FTplan's detections: watchdog, crash, no plan, invalid plan
    believed: GoalCount  # every goal, as FTplan's ledger counted them
    repairs: int = 0  # plan repairs asked after an action failure (not replannings: seed 004 §4.2.1.2)
    repaired: int = 0  # of them, those whose plan was carried out
    # The goals were judged by the robot's own judgement of the world (its extension's `measure`),
    # not as FTplan's ledger believed them: a fault in FTplan's model cannot count a goal met.
    judged_by_robot: bool = False
    # FTplan's detections by mechanism (seed 004 §3.1.1), counted from its log: (mechanism, count).
    detected: tuple[tuple[str, int], ...] = ()

    def count(self, kind: str) -> GoalCount:
        """The goals of `kind` (none asked when the run had none)."""
        return dict(self.goals).get(kind, GoalCount(0, 0))

    @property
    def success(self) -> bool:
        return all(count.met == count.asked for _, count in self.goals)

    @property
    def nu(self) -> int:
        return int(self.success)

    @property
    def mu(self) -> int:
        return 1 - self.nu

    def to_json(self) -> dict[str, Any]:
        data = asdict(self)
        # a list, not an object: the kinds keep the robot's order through JSON with sorted keys
        data["goals"] = [{"kind": kind, **asdict(count)} for kind, count in self.goals]
        for kind, count in self.goals:
            data[f"sigma_{kind}"] = round(count.sigma, 6)
            data[f"phi_{kind}"] = round(count.phi, 6)
        data.update(mu=self.mu, nu=self.nu, activity_time=round(self.activity_time, 3),
                    distance=round(self.distance, 3), mission_time=round(self.mission_time, 3))
        return data

    @staticmethod
    def readable(data: Mapping[str, Any]) -> bool:
        """Whether `data` holds the measures `to_json` writes (a robot's extension may not)."""
        try:
            Measures.from_json(data)
        except RunError:
            return False
        return True

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Measures:
        """The measures `to_json` wrote (a run folder's report.json keeps them)."""
        try:
            goals = tuple((str(c["kind"]), GoalCount(int(c["asked"]), int(c["met"]))) for c in data["goals"])
            believed = GoalCount(int(data["believed"]["asked"]), int(data["believed"]["met"]))
            return cls(configuration=str(data["configuration"]), mission=str(data["mission"]),
                       world=str(data["world"]), seed=int(data["seed"]), goals=goals, kappa=int(data["kappa"]),
                       replannings=int(data["replannings"]), activity_time=float(data["activity_time"]),
                       distance=float(data["distance"]), mission_time=float(data["mission_time"]),
                       planner_failures=int(data["planner_failures"]), believed=believed,
                       repairs=int(data.get("repairs", 0)), repaired=int(data.get("repaired", 0)),
                       judged_by_robot=bool(data.get("judged_by_robot", False)),
                       detected=tuple((str(name), int(count)) for name, count in data.get("detected", ())))
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise RunError(f"not the measures of seed 004 §4.1.4 ({type(error).__name__}: {error})") from None

    def summary(self) -> str:
        outcome = "succeeded" if self.success else "failed"
        counts = ", ".join(f"{kind} {count.text()} (sigma_{kind} {_percent(count.sigma)})"
                           for kind, count in self.goals) or "none asked"
        return "\n".join([
            f"{self.configuration} on {self.mission} in {self.world} (seed {self.seed}): mission {outcome} "
            f"(nu = {self.nu}, mu = {self.mu})",
            f"  goals met: {counts}",
            f"  planner failure kappa = {self.kappa} ({self.planner_failures} failure(s) detected), "
            f"replannings R = {self.replannings}"
            + (f", plan repairs {self.repairs} ({self.repaired} carried out)" if self.repairs else ""),
            f"  physical activity T = {self.activity_time:.1f} s of {self.mission_time:.1f} s, "
            f"distance D = {self.distance:.1f} m",
            f"  FTplan counted {self.believed.text()} goals met",
        ])


@dataclass(frozen=True)
class PlannedGoal:
    """A goal FTplan was given (the log's mission-start `planned_goals`), and whether its ledger
    counted it met at the end (mission-figures' `planned_goals_met_each`)."""

    attribute: str
    args: tuple[Any, ...]
    value: Any
    believed: bool


# What a robot's judgement makes of one of FTplan's goals: its kind and whether it was really met,
# or None to leave it out (a goal counted with another, as the rover's return home is two).
Judgement = Callable[[PlannedGoal], "tuple[str, bool] | None"]


def planned_goals(events: Sequence[Mapping[str, Any]]) -> list[PlannedGoal]:
    """FTplan's goals of a planned run, from its log."""
    start = events[0]
    figures: Mapping[str, Any] = next((e for e in reversed(events) if e["kind"] == "mission-figures"), {})
    met = list(figures.get("planned_goals_met_each", []))
    return [PlannedGoal(str(attribute), tuple(args), value, bool(met[k]) if k < len(met) else False)
            for k, (attribute, args, value) in enumerate(start.get("planned_goals", []))]


def believed(goal: PlannedGoal) -> tuple[str, bool]:
    """The judgement of a robot without one of its own: the goal's attribute is its kind, and it
    was met when FTplan's ledger says so."""
    return goal.attribute, goal.believed


def planned_measures(events: Sequence[Mapping[str, Any]], judge: Judgement = believed,
                     kinds: Sequence[str] = ()) -> Measures:
    """The measures of a planned run from its log alone: the goals as `judge` counts them (by
    default, as FTplan believed them; `kinds` first, in that order, then the others as met),
    FTplan's figures, T from the actions, D."""
    start = events[0]
    figures = next((e for e in reversed(events) if e["kind"] == "mission-figures"), None)
    if start.get("kind") != "mission-start" or figures is None or "planned_goals" not in start:
        raise RunError("not the log of a planned mission: it needs mission-start's planned_goals and "
                       "mission-figures")
    counts: dict[str, GoalCount] = {}
    goals = planned_goals(events)
    for goal in goals:
        judged = judge(goal)
        if judged is None:
            continue
        kind, met = judged
        count = counts.get(kind, GoalCount(0, 0))
        counts[kind] = GoalCount(count.asked + 1, count.met + int(met))
    return Measures(
        configuration=str(start.get("configuration", "")), mission=str(start["mission"]), world=str(start["world"]),
        seed=int(start["seed"]), goals=tuple(sorted(counts.items(), key=lambda item: _rank(item[0], kinds))),
        kappa=int(bool(figures.get("planning_failure"))),
        replannings=int(figures.get("replannings", 0)), activity_time=activity_time(events),
        distance=float(figures.get("distance", 0.0)), mission_time=float(figures["t"]),
        planner_failures=int(figures.get("planner_failures", 0)),
        believed=GoalCount(len(goals), sum(g.believed for g in goals)),
        repairs=int(figures.get("repairs", 0)), repaired=int(figures.get("repaired", 0)),
        judged_by_robot=judge is not believed,
        detected=tuple((mechanism, sum(1 for e in events if e["kind"] == "ftplan" and e.get("event") == event))
                       for event, mechanism in DETECTIONS))


# FTplan's events that are a detection (seed 004 §3.1.1), and the mechanism each is: the watchdog on
# planning, the plan analyzer, an action's failure, the on-line check of the goals.
DETECTIONS = (("watchdog", "watchdog"), ("invalid-plan", "analyzer"), ("action-failed", "action failure"),
              ("goals-open", "goal check"))


def _rank(kind: str, kinds: Sequence[str]) -> int:
    return kinds.index(kind) if kind in kinds else len(kinds)


def activity_time(events: Iterable[Mapping[str, Any]]) -> float:
    """How long at least one action of a plan ran (the log's `action` events): the union of the
    actions' intervals, from each start to its end, failure or stop (or the log's end)."""
    began: dict[tuple[int, str], float] = {}
    intervals = []
    last = 0.0
    for event in events:
        last = event["t"]
        if event["kind"] != "action":
            continue
        key = (event["plan"], event["id"])
        if event["status"] == "started":
            began[key] = event["t"]
        elif key in began:
            intervals.append((began.pop(key), event["t"]))
    intervals += [(start, last) for start in began.values()]
    total, reached = 0.0, -math.inf
    for start, end in sorted(intervals):
        if end > reached:
            total += end - max(start, reached)
            reached = end
    return total


# ---------------------------------------------------------------- many runs


@dataclass(frozen=True)
class MeanMeasures:
    """The means of the measures over runs (seed 004 §4.1.4): sigma-bar (per kind of goal),
    phi-bar, mu-bar, nu-bar, kappa-bar, R-bar, T-bar, D-bar. A dimension the runs differ in reads ALL."""

    configuration: str
    mission: str
    world: str
    runs: int
    sigma: tuple[tuple[str, float], ...]  # (kind, sigma-bar): the mean quotient of its goals met
    nu: float
    kappa: float
    replannings: float  # R-bar
    activity_time: float  # T-bar, s
    distance: float  # D-bar, m
    detected: tuple[tuple[str, float], ...] = ()  # detections per run, by mechanism (FTplan's log)

    def sigma_of(self, kind: str) -> float:
        """sigma-bar of `kind` (1: no run asked for any)."""
        return dict(self.sigma).get(kind, 1.0)

    def phi_of(self, kind: str) -> float:
        return 1.0 - self.sigma_of(kind)

    @property
    def mu(self) -> float:
        return 1.0 - self.nu

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {k: round(v, 6) if isinstance(v, float) else v for k, v in asdict(self).items()
                                if k not in ("sigma", "detected")}
        data["detected"] = {mechanism: round(value, 6) for mechanism, value in self.detected}
        for kind, value in self.sigma:
            data[f"sigma_{kind}"] = round(value, 6)
            data[f"phi_{kind}"] = round(1.0 - value, 6)
        data.update(mu=round(self.mu, 6))
        return data


def aggregate(measures: Sequence[Measures]) -> MeanMeasures:
    """The means of `measures` (the arithmetic means of the thesis, quotient by quotient; a kind
    of goal a run did not ask for counts as met in it, sigma = 1)."""
    if not measures:
        raise RunError("no run to take the means of")

    def label(name: str) -> str:
        values = {getattr(m, name) for m in measures}
        return values.pop() if len(values) == 1 else ALL

    def mean(values: Iterable[float]) -> float:
        listed = list(values)
        return math.fsum(listed) / len(listed)

    kinds = list(dict.fromkeys(kind for m in measures for kind, _ in m.goals))
    return MeanMeasures(
        configuration=label("configuration"), mission=label("mission"), world=label("world"), runs=len(measures),
        sigma=tuple((kind, mean(m.count(kind).sigma for m in measures)) for kind in kinds),
        nu=mean(m.nu for m in measures), kappa=mean(m.kappa for m in measures),
        replannings=mean(m.replannings for m in measures),
        activity_time=mean(m.activity_time for m in measures), distance=mean(m.distance for m in measures),
        detected=tuple((mechanism, mean(dict(m.detected).get(mechanism, 0) for m in measures))
                       for mechanism in dict.fromkeys(name for m in measures for name, _ in m.detected)))


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


def kinds_of(rows: Iterable[MeanMeasures]) -> list[str]:
    """The kinds of goal the rows count, in the order first met."""
    return list(dict.fromkeys(kind for row in rows for kind, _ in row.sigma))


def columns(kinds: Sequence[str]) -> list[str]:
    return ["configuration", "mission", "world", "runs", "ν", *(f"φ_{kind}" for kind in kinds), "κ", "R", "T (s)",
            "D (m)"]


def _cells(row: MeanMeasures, kinds: Sequence[str]) -> list[str]:
    return [row.configuration, row.mission, row.world, str(row.runs), _percent(row.nu),
            *(_percent(row.phi_of(kind)) for kind in kinds), _percent(row.kappa), f"{row.replannings:.2f}",
            f"{row.activity_time:.0f}", f"{row.distance:.1f}"]


def markdown_table(rows: Iterable[MeanMeasures]) -> str:
    """The rows as a Markdown table: mission success nu and failed-goal quotients phi per kind
    (the measures of Fig 4.5) in %, kappa in %, R, T and D (Fig 4.6) as means."""
    listed = list(rows)
    kinds = kinds_of(listed)
    header = columns(kinds)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    lines += ["| " + " | ".join(_cells(row, kinds)) + " |" for row in listed]
    return "\n".join(lines) + "\n"


def rich_table(rows: Iterable[MeanMeasures], title: str = "Measures of seed 004 §4.1.4 (means)") -> Table:
    """The rows as a rich Table, for a terminal."""
    from rich.table import Table

    listed = list(rows)
    kinds = kinds_of(listed)
    table = Table(title=title)
    for k, column in enumerate(columns(kinds)):
        table.add_column(column, justify="left" if k < 3 else "right")
    for row in listed:
        table.add_row(*_cells(row, kinds), style=None if row.nu == 1.0 else "yellow")
    return table


def _percent(value: float) -> str:
    return f"{100.0 * value:.0f} %"
