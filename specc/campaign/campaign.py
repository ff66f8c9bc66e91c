"""A fault-injection campaign as one command (seed 004 ch. 4): mutants of a planning model,
every configuration x mutant x mission x world x run, the filters of §4.2.2.1, the report.

It runs in two phases. The first configuration given (Robot1: the mutated model alone) runs the
original model and every mutant; then each mutant is judged on those results (`judge`): one
that never finds a plan in any mission, or whose every result equals the original's, is set
aside and reported apart, as the seed did. The other configurations (Robot1/2, ...) then run
the original and the mutants kept. Every result goes to the store as it comes, so a campaign
stopped anywhere resumes where it stopped (the verdicts are computed again from the store)."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from specc.campaign.engines import Engine
from specc.campaign.experiments import ORIGINAL, Experiment, Outcome, Setting
from specc.campaign.store import EQUIVALENT, KEPT, NEVER_PLANS, UNJUDGED, MutantRecord, ResultStore
from specc.run import RunError
from specc.runtime.planner import model as pm

Progress = Callable[[int, int, Outcome | None], None]  # (done, total, the outcome just recorded)


@dataclass(frozen=True)
class CampaignPlan:
    robot: Path  # the robot's spec folder
    setting: Setting
    domain: str  # the planning model faults are injected into
    mutants: int | None  # how many mutants to draw (None: every kept one)
    sample_seed: int
    missions: tuple[str, ...]  # planned missions of the robot's system block
    worlds: tuple[str, ...]  # the system's worlds (or world files)
    runs: int  # seeds 0 .. runs-1 of each activity
    configurations: tuple[str, ...]  # FTplan's (Robot1, Robot1/2...); the first judges the mutants
    set_apart: tuple[str, ...] = ()  # worlds the means are also given without (seed 004 set W4 apart)

    def description(self, mutant_ids: Sequence[str]) -> dict[str, Any]:
        """What makes two campaigns the same (the store refuses to mix two different ones): the
        options, and the robot's files and specc's sources (a digest: results of a changed robot
        or another specc are not added to those of the first)."""
        from specc.run.package import robot_digest

        return {"robot": self.robot.name, "domain": self.domain, "mutants": list(mutant_ids),
                "missions": list(self.missions), "worlds": list(self.worlds), "runs": self.runs,
                "configurations": list(self.configurations), "timing": self.setting.timing,
                "set_apart": list(self.set_apart), "files": robot_digest(self.robot)[:16]}

    def experiments(self, configuration: str, mutants: Iterable[str]) -> list[Experiment]:
        return [Experiment(configuration, mutant, mission, world, seed) for mutant in mutants
                for mission in self.missions for world in self.worlds for seed in range(self.runs)]


@dataclass(frozen=True)
class Verdict:
    mutant: str
    verdict: str  # KEPT, NEVER_PLANS, EQUIVALENT, or UNJUDGED while its results are incomplete
    detail: str = ""


def judge(outcomes: Iterable[Outcome], configuration: str, mutants: Sequence[str], expected: int
          ) -> dict[str, Verdict]:
    """The filters of seed 004 §4.2.2.1 on the results of `configuration` (the mutated model
    alone): a mutant that finds no plan in any mission never plans (every experiment a planner
    failure, κ = 1, before any action ran: a mutant whose first plan ran and whose replanning
    failed later did plan); one whose every experiment gives the original's measures exactly is
    equivalent (no influence on the system in these activities); the others are kept. A mutant
    with fewer than `expected` results is not judged yet."""
    mine: dict[str, list[Outcome]] = {}
    for outcome in outcomes:
        if outcome.experiment.configuration == configuration:
            mine.setdefault(outcome.experiment.mutant, []).append(outcome)
    original = {activity(o.experiment): o.measures for o in mine.get(ORIGINAL, []) if o.status == "done"}
    verdicts = {}
    for mutant in mutants:
        results = mine.get(mutant, [])
        if len(results) < expected or len(original) < expected:
            verdicts[mutant] = Verdict(mutant, UNJUDGED, f"{len(results)} of {expected} results")
            continue
        done = [o for o in results if o.status == "done" and o.measures is not None]
        if len(done) == len(results) and all(o.measures is not None and o.measures["kappa"] == 1
                                             and o.measures["activity_time"] == 0 for o in done):
            verdicts[mutant] = Verdict(mutant, NEVER_PLANS, "no plan in any mission (κ = 1 before any action, "
                                                            "in every experiment)")
        elif len(done) == len(results) and all(original.get(activity(o.experiment)) == o.measures for o in done):
            verdicts[mutant] = Verdict(mutant, EQUIVALENT, "every measure equals the original model's")
        else:
            differing = sum(1 for o in results if o.status != "done" or original.get(activity(o.experiment))
                            != o.measures)
            verdicts[mutant] = Verdict(mutant, KEPT, f"{differing} of {len(results)} experiments differ")
    return verdicts


def activity(e: Experiment) -> tuple[str, str, int]:
    """An experiment's activity: its mission, world and seed (what a mutant and the original share)."""
    return e.mission, e.world, e.seed


@dataclass
class Campaign:
    plan: CampaignPlan
    store: ResultStore
    engine: Engine
    domains: dict[str, pm.PlanningDomain]  # mutant id -> its planning domain
    records: list[MutantRecord] = field(default_factory=list)

    def start(self) -> list[str]:
        """Record what the campaign is, or check the store holds this very campaign (or one it
        grows, or one grown from it): returns what to say of the store."""
        notes = self.store.describe(self.plan.description(list(self.domains)))
        self.store.add_mutants(self.records)
        return notes

    def experiments(self, kept: Sequence[str]) -> list[Experiment]:
        """The whole campaign when the later configurations run the mutants `kept`: the first
        configuration runs the original and every mutant, to judge them."""
        first, others = self.plan.configurations[0], self.plan.configurations[1:]
        judging = self.plan.experiments(first, [ORIGINAL, *self.domains])
        return judging + [e for c in others for e in self.plan.experiments(c, [ORIGINAL, *kept])]

    def run(self, progress: Progress | None = None) -> dict[str, Verdict]:
        first, others = self.plan.configurations[0], self.plan.configurations[1:]
        mutants = list(self.domains)
        done = self.store.done()
        # The total as far as it is known: until judged, a mutant counts in the later configurations.
        judged = self.verdicts()
        everything = self.experiments([m for m in mutants if judged[m].verdict in (KEPT, UNJUDGED)])
        total, counted = len(everything), len(done & {e.key for e in everything})

        def go(experiments: list[Experiment]) -> None:
            nonlocal counted
            todo = [e for e in experiments if e.key not in done]
            tasks = ((e, self.domains.get(e.mutant)) for e in todo)
            if progress is not None:
                progress(counted, total, None)
            for outcome in self.engine.run(tasks):
                self.store.record(outcome)
                done.add(outcome.experiment.key)
                counted += 1
                if progress is not None:
                    progress(counted, total, outcome)

        go(self.plan.experiments(first, [ORIGINAL, *mutants]))
        judged = self.verdicts()
        kept = [m for m in mutants if judged[m].verdict == KEPT]
        total = len(self.experiments(kept))
        for configuration in others:
            go(self.plan.experiments(configuration, [ORIGINAL, *kept]))
        return judged

    def verdicts(self) -> dict[str, Verdict]:
        first = self.plan.configurations[0]
        expected = len(self.plan.experiments(first, [ORIGINAL]))
        verdicts = judge(self.store.outcomes(), first, list(self.domains), expected)
        self.store.judge((v.mutant, v.verdict, v.detail) for v in verdicts.values())
        return verdicts


@dataclass(frozen=True)
class Defaults:
    """What a campaign on a robot covers unless told otherwise."""

    domain: str  # the first planner's
    missions: tuple[str, ...]  # every planned mission of the system
    worlds: tuple[str, ...]  # every world of the system
    configurations: tuple[str, ...]  # the first planner alone, then all of them (successive)


def campaign_defaults(generated: Path, folder: Path, robot_name: str) -> Defaults:
    """The defaults of a campaign on the compiled robot; RunError when it plans nothing."""
    from specc.run.mission import load_robot

    robot = load_robot(generated, folder, robot_name)
    system = robot.system
    planned = tuple(name for name, mission in system.missions.items() if mission.plan is not None)
    if system.planning is None or not planned:
        raise RunError(f"robot '{robot.name}' has no planned mission: a campaign injects faults into the planning "
                       "model FTplan plans its missions in (give its system 'planning: <ftplan block>;' and a "
                       "mission with 'plan: ...;')")
    block = robot.part("ftplan").FTPLANS[system.planning]
    planners = block.CONFIG.planners
    configurations = ("Robot1",) + (("Robot" + "/".join(str(k) for k in range(1, len(planners) + 1)),)
                                    if len(planners) > 1 else ())
    return Defaults(planners[0].domain, planned, tuple(system.worlds), configurations)


def check_names(plan: CampaignPlan) -> list[str]:
    """Every configuration, mission and world named, checked before anything runs (RunError).
    Returns notes: a configuration whose planners share the mutated model, so that each mutant
    reaches them all (a common-mode fault: seed 004 diversifies models, §3.1, §4.1.2.2)."""
    from specc.run.mission import check_mission, load_robot

    if plan.runs < 1:
        raise RunError(f"--runs {plan.runs}: give at least 1")
    for name, values in (("--configs", plan.configurations), ("--missions", plan.missions),
                         ("--worlds", plan.worlds)):
        if not values:
            raise RunError(f"{name}: give at least one")
    unknown = sorted(set(plan.set_apart) - set(plan.worlds))
    if unknown:
        raise RunError(f"--set-apart {', '.join(unknown)}: not among the campaign's worlds ({', '.join(plan.worlds)})")
    robot = load_robot(plan.setting.generated, plan.setting.example, plan.setting.robot)
    notes: dict[str, str] = {}
    for configuration in plan.configurations:
        for name in plan.missions:
            mission = robot.mission(name)
            if mission.plan is None:
                raise RunError(f"mission {mission.name} of robot '{robot.name}' is not planned: a campaign injects "
                               "faults into the planning model of planned missions")
            for world in plan.worlds:
                setup = check_mission(robot, mission, world, 0, None, configuration).planning
                if plan.domain not in setup.planned_in:
                    raise RunError(f"configuration {configuration} does not plan in '{plan.domain}' (it plans in "
                                   f"{', '.join(sorted(setup.planned_in))}): a campaign injects faults into the model "
                                   "its configurations use")
                sharing = [p.name for p in setup.config.planners if p.domain == plan.domain]
                if len(sharing) > 1:
                    notes[configuration] = (
                        f"configuration {configuration}: planners {', '.join(sharing)} all plan in '{plan.domain}', "
                        "so each mutant reaches them all (a fault common to them): their diversity is measured "
                        "against model faults only with a model of their own each (seed 004 §3.1; §4.1.2.2: "
                        "Modele1 and Modele2). With one model written once, give the other planner a copy of the "
                        "domain under another name (its own problems for it), and the mutants reach one planner "
                        "only")
    return list(notes.values())


@dataclass(frozen=True)
class Selection:
    """The mutants a campaign injects: drawn among those that pass the checks."""

    records: list[MutantRecord]
    domains: dict[str, pm.PlanningDomain]
    generated: int  # mutants enumerated


def select_mutants(plan: CampaignPlan, workers: int = 1,
                   progress: Callable[[int, int], None] | None = None) -> Selection:
    """Enumerate the domain's mutants, keep those that pass specc check, draw `plan.mutants` of
    them (stratified by class, with `plan.sample_seed`; all when None) and lower each to the
    planner's domain. RunError when the robot or the domain cannot be mutated."""
    from specc.mutation import MutationError, draw_kept, enumerate_mutants, keep_valid, mutant_domain, mutation_target

    try:
        target = mutation_target(plan.robot, plan.domain)
        enumerated = enumerate_mutants(target)
        if plan.mutants is None:
            chosen = keep_valid(enumerated, workers=workers, progress=progress).kept
        else:  # only what is drawn gets checked (specc mutants --sample draws the same ones)
            chosen = draw_kept(enumerated, plan.mutants, plan.sample_seed)
        domains = {x.id: mutant_domain(x) for x in chosen}
    except MutationError as error:
        raise RunError(str(error)) from None
    records = [MutantRecord(x.id, x.kind, x.description, x.diff) for x in chosen]
    return Selection(records, domains, len(enumerated))
