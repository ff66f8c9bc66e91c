"""The report of a campaign, from its results store alone (seed 004 §4.2.2.3, Fig 4.14).

The measures of §4.1.4 are averaged over sets of activities in the seed's notation: σ̄_p({W*, M*},
F*) is the mean quotient of goals of kind p (the rover's photos) met over every world and mission
and over F*, the kept mutants (∅: the original model). Each mean is given over every world and,
when the campaign sets worlds apart (`--set-apart W4`: the seed set W4 apart for its adversity),
without them, for each configuration; the headlines are the change of mission success ν̄ from the
first configuration to each other one under injected faults, absolute (points) and relative,
beside the fault-free figures."""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from specc.campaign.campaign import EQUIVALENT, KEPT, NEVER_PLANS, UNJUDGED, activity
from specc.campaign.experiments import ORIGINAL, Outcome
from specc.campaign.store import MutantRecord, ResultStore
from specc.run.measures import MeanMeasures, Measures, aggregate, kinds_of

FAULTY, FAULT_FREE = "F*", "∅"
# Below this many kept mutants the report says how much one mutant weighs in each mean.
FEW_MUTANTS = 10
# The seed's headline (§4.2.2.3, without W4): ν̄ up 19 points, "41 %" relative. The relative figure
# is on the failure rate (with W4, a 12-point communication gain is called 64 %: a base of 18.75 %,
# a failure rate), so the seed's Robot1 failed 0.19 / 0.41 = 46 % of its missions under faults.
SEED_HEADLINE = (0.19, 0.41)


@dataclass(frozen=True)
class Mean:
    configuration: str
    faults: str  # FAULTY or FAULT_FREE
    worlds: str  # "W*", or "W* \\ W4" without the worlds set apart
    experiments: int
    means: MeanMeasures | None  # None when no experiment is in the set


@dataclass(frozen=True)
class Headline:
    worlds: str
    first: str
    second: str
    faulty: tuple[float, float]  # ν̄(F*) of the first and of the second configuration
    fault_free: tuple[float, float]  # ν̄(∅)

    @property
    def absolute(self) -> float:
        return self.faulty[1] - self.faulty[0]

    @property
    def relative(self) -> float | None:
        """The change relative to the first configuration's ν̄ (None when that is 0)."""
        return self.absolute / self.faulty[0] if self.faulty[0] else None

    @property
    def failure_cut(self) -> float | None:
        """The seed's basis (§4.2.2.3): the cut in the failure rate 1 - ν̄, relative to the first
        configuration's (None when it never failed)."""
        failed = 1.0 - self.faulty[0]
        return self.absolute / failed if failed > 0 else None

    def text(self) -> str:
        below = "still below" if self.faulty[1] < self.fault_free[1] else "not below"
        relative = (f"{self.relative:+.0%} relative" if self.relative is not None
                    else "relative change undefined (from 0 %)")
        cut = (f"; failures cut from {1 - self.faulty[0]:.0%} to {1 - self.faulty[1]:.0%}, {self.failure_cut:.0%} "
               "relative (the seed's basis)") if self.failure_cut is not None else ""
        return (f"{self.worlds}: under injected faults, {self.second} succeeds in {self.faulty[1]:.0%} of missions "
                f"against {self.first}'s {self.faulty[0]:.0%}: {self.absolute * 100:+.0f} points "
                f"({relative}{cut}); {below} the fault-free {self.fault_free[1]:.0%} "
                f"({self.first} fault-free: {self.fault_free[0]:.0%})")


@dataclass(frozen=True)
class Coverage:
    """How much of a configuration's share of the campaign has run: the means cover that only."""

    configuration: str
    done: int
    expected: int  # the original and the mutants it runs (all for the first, else the kept or unjudged)

    @property
    def complete(self) -> bool:
        return self.done >= self.expected


@dataclass(frozen=True)
class CampaignReport:
    description: dict[str, Any]
    mutants: tuple[MutantRecord, ...]
    outcomes: tuple[Outcome, ...]
    means: tuple[Mean, ...]
    per_mutant: tuple[tuple[MutantRecord, dict[str, MeanMeasures | None]], ...]  # kept ones, per configuration
    headlines: tuple[Headline, ...]
    coverage: tuple[Coverage, ...]
    # Activities (a mutant, or the original, in a mission, world and seed) left out of the means
    # because some configuration did not finish them: the means compare the same experiments.
    unpaired: int = 0
    ledger_judged: bool = False  # some experiment's goals were counted as FTplan's ledger believed them

    def with_verdict(self, verdict: str) -> list[MutantRecord]:
        return [m for m in self.mutants if m.verdict == verdict]

    @property
    def failed(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.status != "done"]



def build_report(store: ResultStore) -> CampaignReport:
    description = store.description()
    mutants = tuple(store.mutants())
    outcomes = tuple(store.outcomes())
    configurations: list[str] = list(description.get("configurations", []))
    kept = {m.id for m in mutants if m.verdict == KEPT}
    measures = [(o, Measures.from_json(o.measures)) for o in outcomes if o.status == "done" and o.measures]
    ledger_judged = any(not m.judged_by_robot for _, m in measures)
    # The configurations are compared on the same mutants and activities: an experiment one of
    # them did not finish (a timeout, a crash) leaves that activity out of every one's means,
    # instead of a failure left out of one side only.
    # A configuration that has run nothing yet (a campaign interrupted before it) is left out of
    # the pairing: the others' means stand, and it has none.
    finished: dict[tuple[str, str, str, int], set[str]] = {}
    for o, _ in measures:
        finished.setdefault(_paired(o), set()).add(o.experiment.configuration)
    started = set(configurations) & {o.experiment.configuration for o in outcomes}  # crashed ones too
    unpaired = {key for key, done_by in finished.items() if key[0] in kept | {ORIGINAL}
                and not done_by >= started}
    measures = [(o, m) for o, m in measures if _paired(o) not in unpaired]
    world_sets = world_subsets(description)
    means = []
    for configuration in configurations:
        for faults, wanted in ((FAULTY, kept), (FAULT_FREE, {ORIGINAL})):
            for label, left_out in world_sets:
                chosen = [m for o, m in measures if o.experiment.configuration == configuration
                          and o.experiment.mutant in wanted and o.experiment.world not in left_out]
                means.append(Mean(configuration, faults, label, len(chosen), aggregate(chosen) if chosen else None))
    per_mutant = []
    for mutant in (m for m in mutants if m.id in kept):
        row: dict[str, MeanMeasures | None] = {}
        for configuration in configurations:
            chosen = [m for o, m in measures if o.experiment.configuration == configuration
                      and o.experiment.mutant == mutant.id]
            row[configuration] = aggregate(chosen) if chosen else None
        per_mutant.append((mutant, row))
    headlines = []
    first = configurations[0] if configurations else ""
    for second in configurations[1:]:  # each other configuration against the first (the model alone)
        for label, _ in world_sets:
            faulty = tuple(_nu(means, c, FAULTY, label) for c in (first, second))
            free = tuple(_nu(means, c, FAULT_FREE, label) for c in (first, second))
            if all(v is not None for v in faulty + free):
                headlines.append(Headline(label, first, second, faulty, free))  # type: ignore[arg-type]
    return CampaignReport(description, mutants, outcomes, tuple(means), tuple(per_mutant), tuple(headlines),
                          coverage(description, mutants, outcomes), len(unpaired),
                          ledger_judged)


def _paired(o: Outcome) -> tuple[str, str, str, int]:
    """An experiment's mutant and activity: what the configurations are compared on."""
    return (o.experiment.mutant, *activity(o.experiment))


def world_subsets(description: dict[str, Any]) -> tuple[tuple[str, frozenset[str]], ...]:
    """The sets of worlds the means are taken over: every one (W*), and without those the
    campaign sets apart (W* \\ W4) when it does."""
    apart = frozenset(description.get("set_apart", []))
    every: tuple[tuple[str, frozenset[str]], ...] = (("W*", frozenset()),)
    return every + ((f"W* \\ {', '.join(sorted(apart))}", apart),) if apart else every


def quotients(report: CampaignReport) -> list[tuple[str, str]]:
    """(kind or "nu", label) of the quotients the report shows: σ̄ of each kind of goal, then ν̄."""
    kinds = kinds_of(m.means for m in report.means if m.means is not None)
    return [(kind, f"σ̄_{kind}") for kind in kinds] + [("nu", "ν̄")]


def _quotient(mean: MeanMeasures, name: str) -> float:
    return mean.nu if name == "nu" else mean.sigma_of(name)


def coverage(description: dict[str, Any], mutants: Iterable[MutantRecord],
             outcomes: Iterable[Outcome]) -> tuple[Coverage, ...]:
    """Each configuration's experiments run against those it has to run: the first runs the
    original and every mutant, the others the original and the mutants kept (or not judged yet).
    One that timed out is still to run: a resumed campaign runs it again."""
    configurations: list[str] = list(description.get("configurations", []))
    activities = len(description.get("missions", [])) * len(description.get("worlds", [])) * description.get("runs", 0)
    mutants = list(mutants)
    runs_later = {m.id for m in mutants if m.verdict in (KEPT, UNJUDGED)}
    done: dict[str, int] = {}
    for outcome in outcomes:
        if outcome.status != "timeout":
            done[outcome.experiment.configuration] = done.get(outcome.experiment.configuration, 0) + 1
    return tuple(Coverage(c, done.get(c, 0), activities * (1 + (len(mutants) if k == 0 else len(runs_later))))
                 for k, c in enumerate(configurations))


def _nu(means: Iterable[Mean], configuration: str, faults: str, worlds: str) -> float | None:
    for mean in means:
        if (mean.configuration, mean.faults, mean.worlds) == (configuration, faults, worlds) and mean.means:
            return mean.means.nu
    return None


# ---------------------------------------------------------------- writing


def markdown(report: CampaignReport) -> str:
    d = report.description
    lines = [f"# Campaign: faults injected into {d.get('domain')} of {d.get('robot')}", ""]
    counts = {v: len(report.with_verdict(v)) for v in (KEPT, NEVER_PLANS, EQUIVALENT, UNJUDGED)}
    lines += [f"- missions {', '.join(d.get('missions', []))} x worlds {', '.join(d.get('worlds', []))} x "
              f"{d.get('runs')} run(s); configurations {', '.join(d.get('configurations', []))}",
              f"- mutants drawn: {len(report.mutants)}; kept (F*): {counts[KEPT]}; never plan: "
              f"{counts[NEVER_PLANS]}; equivalent to the original: {counts[EQUIVALENT]}"
              + (f"; not judged yet (the first configuration has not run all of their experiments): "
                 f"{counts[UNJUDGED]}" if counts[UNJUDGED] else ""),
              f"- experiments: {len(report.outcomes)} ({len(report.failed)} crashed or timed out): "
              + "; ".join(f"{c.configuration} {c.done:,} of {c.expected:,}" for c in report.coverage)]
    if report.ledger_judged:
        lines.append("- **goals counted as FTplan believed them:** the robot's extension judges no goal in the "
                     "world (a `measure` hook, docs/your-robot.md §8), so a goal counts as met when FTplan's "
                     "ledger says so. A mutant that corrupts FTplan's model of the world (a wrong effect) can "
                     "make it believe a goal met that the robot missed: σ and ν then count it met. Judge the "
                     "goals on what the log shows happened to trust them under faults")
    unfinished = [c.configuration for c in report.coverage if not c.complete]
    if unfinished:
        timed_out = sum(o.status == "timeout" for o in report.outcomes)
        lines.append(f"- **not finished: {', '.join(unfinished)}.** The means cover the experiments every "
                     "configuration started has run so far (one not started has none); the same command resumes "
                     "the campaign"
                     + (f" and runs again the {timed_out} that timed out (a larger --timeout if they keep doing so)"
                        if timed_out else ""))
    elif report.unpaired:
        lines.append(f"- {report.unpaired} activit{'y' if report.unpaired == 1 else 'ies'} (a mutant or the original "
                     "in a mission, world and seed) left out of every configuration's means: some configuration did "
                     "not finish it (it timed out or crashed, below), and the configurations are compared on the "
                     "same experiments")
    lines.append("")
    if report.headlines:
        lines += ["## Headline", ""]
        lines += [f"- {h.text()}" for h in report.headlines]
        kept = len(report.per_mutant)
        if 0 < kept < FEW_MUTANTS:
            lines.append(f"- **few mutants:** the means under faults are over {kept} kept mutant(s); one mutant's "
                         f"runs weigh {1 / kept:.0%} of each, so a difference of that size may be one mutant's doing "
                         "(seed 004 kept 28 of 38, §4.2.2.1; `--mutants N` draws more)")
        seed_abs, seed_rel = SEED_HEADLINE
        seed_failed = seed_abs / seed_rel
        lines += [f"- for reference, seed 004's own campaign (§4.2.2.3, W* \\ W4, its rover and missions): "
                  f"+{seed_abs * 100:.0f} points of mission success, failures cut by {seed_rel:.0%} relative: "
                  f"its Robot1 succeeded in about {1 - seed_failed:.0%} of missions under faults, its Robot1/2 in "
                  f"about {1 - seed_failed + seed_abs:.0%}, still below fault-free. Its FTplan had no plan "
                  "analyzer, and its IxTeT repaired plans before replanning: configurations named "
                  "`-noanalyzer` (and `-repair`) are the seed's (docs/campaign.md)", ""]
    shown = quotients(report)
    header = [label for _, label in shown] + ["κ̄", "R̄", "T̄ (s)", "D̄ (m)"]
    lines += ["## Means over sets of activities", "",
              "| configuration | faults | worlds | experiments | " + " | ".join(header) + " |",
              "| --- | --- | --- | --- | " + " | ".join("---" for _ in header) + " |"]
    for mean in report.means:
        m = mean.means
        cells = ["-"] * len(header) if m is None else [_pct(_quotient(m, name)) for name, _ in shown] + [
            _pct(m.kappa), f"{m.replannings:.2f}", f"{m.activity_time:.0f}", f"{m.distance:.1f}"]
        lines.append(f"| {mean.configuration} | {mean.faults} | {mean.worlds} | {mean.experiments} | "
                     + " | ".join(cells) + " |")
    lines += ["", "What the columns say (seed 004 §4.1.4; `specc/run/measures.py`): faults F* are the kept "
              "mutants, ∅ the original model; worlds W* every world, W* \\ X without those set apart (`--set-apart`); "
              "σ̄_X the share of goals of kind X met, ν̄ of missions with every goal met; κ̄ of missions "
              "where planning gave no plan in time (a planner whose plans leave every goal aside is not counted: "
              "the robot then simply stays); R̄ the replannings per mission; T̄ the physical activity time, how "
              "long at least one action ran (neither planning nor waiting counts, so a recovery's cost shows in "
              "R̄ and in each result's `mission_time`, not here); D̄ the distance travelled."]
    mechanisms = list(dict.fromkeys(name for mean in report.means if mean.means is not None
                                    for name, _ in mean.means.detected))
    if mechanisms:
        lines += ["", "## Detections per experiment, by mechanism (FTplan's log; seed 004 §3.1.1)", "",
                  "| configuration | faults | worlds | " + " | ".join(mechanisms) + " |",
                  "| --- | --- | --- | " + " | ".join("---" for _ in mechanisms) + " |"]
        for mean in report.means:
            if mean.means is None:
                continue
            detected: dict[str, float] = dict(mean.means.detected)
            lines.append(f"| {mean.configuration} | {mean.faults} | {mean.worlds} | "
                         + " | ".join(f"{detected.get(name, 0.0):.2f}" for name in mechanisms) + " |")
        lines += ["", "Each a mean count per experiment: the watchdog on planning time, the plan analyzer "
                  "(`-noanalyzer` configurations have none), an action's failure reported by the executive, the "
                  "check of the goals once a plan has ended. A fault detected is followed by a replanning (R̄) or "
                  "ends the mission (κ̄)."]
    configurations = list(d.get("configurations", []))
    lines += ["", "## Kept mutants (F*): mission success ν̄ over every activity", "",
              "| mutant | class | mutation | " + " | ".join(configurations) + " |",
              "| --- | --- | --- | " + " | ".join("---" for _ in configurations) + " |"]
    for mutant, row in report.per_mutant:
        cells = [_pct(row[c].nu) if row.get(c) is not None else "-" for c in configurations]  # type: ignore[union-attr]
        lines.append(f"| {mutant.id} | {mutant.kind} | {_cell(mutant.description)} | " + " | ".join(cells) + " |")
    for verdict, title in ((NEVER_PLANS, "Set aside: never find a plan"),
                           (EQUIVALENT, "Set aside: results equal the original's")):
        listed = report.with_verdict(verdict)
        if listed:
            lines += ["", f"## {title} ({len(listed)})", ""]
            lines += [f"- {m.id} ({m.kind}): {_cell(m.description)}" for m in listed]
    if report.failed:
        lines += ["", f"## Experiments that crashed or timed out ({len(report.failed)})", ""]
        lines += [f"- {o.experiment.key}: {o.status}: {o.why}" for o in report.failed[:50]]
    return "\n".join(lines) + "\n"


def _pct(value: float) -> str:
    return f"{value:.0%}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def to_json(report: CampaignReport) -> dict[str, Any]:
    return {
        "description": report.description,
        "mutants": [{"id": m.id, "kind": m.kind, "description": m.description, "verdict": m.verdict,
                     "detail": m.detail} for m in report.mutants],
        "means": [{"configuration": m.configuration, "faults": m.faults, "worlds": m.worlds,
                   "experiments": m.experiments, **(m.means.to_json() if m.means else {})} for m in report.means],
        "headlines": [{"worlds": h.worlds, "first": h.first, "second": h.second, "nu_faulty": list(h.faulty),
                       "nu_fault_free": list(h.fault_free), "absolute": h.absolute, "relative": h.relative}
                      for h in report.headlines],
        "experiments": len(report.outcomes), "failed": len(report.failed),
        "coverage": [{"configuration": c.configuration, "done": c.done, "expected": c.expected}
                     for c in report.coverage],
    }


def draw(report: CampaignReport, path: Path) -> Path:
    """Fig 4.14: the mean quotients of each configuration, without and with injected faults,
    over every world and without W4."""
    from matplotlib.ticker import PercentFormatter

    from specc.runtime.sim.render import pyplot

    plt = pyplot()

    panels = tuple(label for label, _ in world_subsets(report.description))
    shown = quotients(report)
    series = [(c, f) for c in dict.fromkeys(m.configuration for m in report.means) for f in (FAULT_FREE, FAULTY)]
    figure, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4.2), sharey=True, squeeze=False)
    axes = axes[0]
    width = 0.8 / max(1, len(series))
    for axis, worlds in zip(axes, panels, strict=True):
        for k, (configuration, faults) in enumerate(series):
            mean = next((m.means for m in report.means if (m.configuration, m.faults, m.worlds)
                         == (configuration, faults, worlds)), None)
            values = [_quotient(mean, name) if mean is not None else 0.0 for name, _ in shown]
            xs = [i + (k - (len(series) - 1) / 2) * width for i in range(len(shown))]
            bars = axis.bar(xs, values, width, label=f"{configuration}, {faults}",
                            hatch="//" if faults == FAULTY else None, edgecolor="black", linewidth=0.5)
            axis.bar_label(bars, labels=[f"{v:.0%}" for v in values], fontsize=6, padding=1)
        axis.set_xticks(range(len(shown)), [label for _, label in shown])
        axis.set_ylim(0, 1.1)
        axis.set_title(f"{{{worlds}, M*}}")
        axis.yaxis.set_major_formatter(PercentFormatter(1.0))
    # Below the panels: inside one, the legend would hide its bars.
    columns = min(4, len(series))
    handles, labels = axes[0].get_legend_handles_labels()
    figure.legend(handles, labels, loc="lower center", ncol=columns, fontsize=8, frameon=False)
    # Wrapped to the figure: one panel (no world set apart) is too narrow for it on one line.
    figure.suptitle("Goals met and missions succeeded, without faults (∅) and with injected faults (F*)", wrap=True)
    figure.tight_layout(rect=(0, 0.02 + 0.06 * -(-len(series) // columns), 1, 1))
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path


def write_report(report: CampaignReport, folder: Path, stem: str = "campaign") -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    written = [folder / f"{stem}.md", folder / f"{stem}.json"]
    written[0].write_text(markdown(report), encoding="utf-8")
    written[1].write_text(json.dumps(to_json(report), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    if any(m.means is not None for m in report.means):
        written.append(draw(report, folder / f"{stem}.png"))
    return written
