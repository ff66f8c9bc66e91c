"""The results store of a campaign: one SQLite file, one row per experiment, written as each
experiment finishes and committed at once. An interrupted campaign resumes from what the file
holds: an experiment already there is never run again, and the primary key refuses a second row
for it, so no result is lost or duplicated.

The file also records what the campaign is (robot, mutants and their diffs, missions, worlds,
runs, configurations, and the filters' verdicts), so that a report can be made from it alone and
a resumed campaign is refused when it would mix two different campaigns' results."""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from specc.campaign.experiments import STATUSES, Experiment, Outcome
from specc.run import RunError

# What a resumed campaign may add to (see ResultStore.describe), and whether the first must stay.
GROWING = {"configurations": True, "mutants": False}
# What only shapes the report (the worlds the means are also given without): a resume may change it.
REPORT_ONLY = {"set_apart"}


def _shown(value: Any) -> str:
    """A description's value as a message shows it: a list as its items, anything else as it is."""
    return ", ".join(map(str, value)) if isinstance(value, list) else "none" if value is None else str(value)


def _grows(key: str, stored: Any, given: Any) -> bool:
    return (isinstance(stored, list) and isinstance(given, list) and set(stored) <= set(given)
            and (not GROWING[key] or given[:1] == stored[:1]))
# The columns each table holds, in order (what SCHEMA creates).
EXPECTED_COLUMNS = {
    "campaign": ("name", "value"),
    "mutants": ("id", "kind", "description", "diff", "verdict", "detail"),
    "results": ("key", "configuration", "mutant", "mission", "world", "seed", "status", "measures", "seconds", "why",
                "finished"),
}
# The filters' verdicts on a mutant (seed 004 §4.2.2.1), UNJUDGED while its results are incomplete.
KEPT, NEVER_PLANS, EQUIVALENT, UNJUDGED = "kept", "never-plans", "equivalent", ""
VERDICTS = (UNJUDGED, KEPT, NEVER_PLANS, EQUIVALENT)
SCHEMA = """
CREATE TABLE IF NOT EXISTS campaign (name TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS mutants (
    id TEXT PRIMARY KEY, kind TEXT NOT NULL, description TEXT NOT NULL, diff TEXT NOT NULL,
    verdict TEXT NOT NULL DEFAULT '', detail TEXT NOT NULL DEFAULT '');
CREATE TABLE IF NOT EXISTS results (
    key TEXT PRIMARY KEY, configuration TEXT NOT NULL, mutant TEXT NOT NULL, mission TEXT NOT NULL,
    world TEXT NOT NULL, seed INTEGER NOT NULL, status TEXT NOT NULL, measures TEXT,
    seconds REAL NOT NULL, why TEXT NOT NULL, finished REAL NOT NULL);
"""


@dataclass(frozen=True)
class MutantRecord:
    id: str
    kind: str
    description: str
    diff: str
    verdict: str = ""  # "" (not judged yet), kept, never-plans, equivalent
    detail: str = ""


class ResultStore:
    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            self.db = sqlite3.connect(path)
            # WAL: a commit per result stays cheap, and a reader (a report) never blocks the writer.
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.executescript(SCHEMA)
        except (OSError, sqlite3.Error) as error:
            raise RunError(f"cannot open the results store '{path}': {error} (is it a results store? give "
                           "another --store)") from None
        self._check_schema()

    def _check_schema(self) -> None:
        """A file made by something else than specc (or an older specc) is refused by name."""
        for table, columns in EXPECTED_COLUMNS.items():
            found = tuple(row[1] for row in self._rows(f"PRAGMA table_info({table})"))
            if found != columns:
                self.db.close()
                raise RunError(f"'{self.path}' is not a specc results store: its table '{table}' has the columns "
                               f"({', '.join(found)}), not ({', '.join(columns)}); give another --store")

    def _rows(self, query: str, *args: Any) -> list[Any]:
        """The rows of `query`; RunError when the file is damaged (what SQLite says, in one line)."""
        try:
            return list(self.db.execute(query, args))
        except sqlite3.Error as error:
            raise RunError(f"the results store '{self.path}' is damaged ({error}): its results cannot be read; "
                           "restore it or give another --store") from None

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        self.db.close()

    # ------------------------------------------------------------ what the campaign is
    def describe(self, description: dict[str, Any]) -> list[str]:
        """Record the campaign's description, or check that the store already holds this one (a
        resumed campaign): RunError naming what differs otherwise. A list under one of GROWING
        may hold more than the stored one if it holds all of it (more configurations compared after
        the same first one, which judges the mutants; more mutants drawn, as a larger draw_kept
        sample holds the smaller one): the stored description grows. It may hold part of a stored
        one that grew so (the command the campaign was first run with): the store stays as it is.
        Returns what to tell the user of either."""
        stored = self.description()
        notes: list[str] = []
        if stored:
            differs = sorted(k for k in set(stored) | set(description) if stored.get(k) != description.get(k))
            # A list of the same items (configurations in another order after the same first): the same.
            same = [k for k in differs if k in GROWING and _grows(k, stored.get(k), description.get(k))
                    and _grows(k, description.get(k), stored.get(k))]
            grows = [k for k in differs if k not in same and (k in REPORT_ONLY or k in GROWING
                                                              and _grows(k, stored.get(k), description.get(k)))]
            part = [k for k in differs if k not in same and k in GROWING
                    and _grows(k, description.get(k), stored.get(k))]
            if set(differs) - set(same) - set(grows) - set(part):
                said = "; ".join(f"{k}: {_shown(stored.get(k))} stored, {_shown(description.get(k))} asked"
                                 for k in differs)
                files = (" (files: the robot's specs, codels and worlds, or specc itself, changed since: a "
                         "campaign's results all come from one robot and one specc)") if "files" in differs else ""
                raise RunError(f"'{self.path}' holds another campaign ({said}){files}: give another --store, or "
                               "the options it was run (or last grown) with to resume it")
            for k in grows:
                if k in GROWING:
                    added = [item for item in description[k] if item not in stored[k]]
                    notes.append(f"the campaign in '{self.path}' grows by {len(added)} {k}: {_shown(added)}")
            for k in part:
                notes.append(f"'{self.path}' holds {len(stored[k])} {k} (it grew by a later command), "
                             f"{len(description[k])} of them asked: theirs are resumed, the report covers all "
                             f"{len(stored[k])}")
            with self.db:
                self.db.executemany("UPDATE campaign SET value = ? WHERE name = ?",
                                    [(json.dumps(description[k]), k) for k in grows])
            return notes
        with self.db:
            self.db.executemany("INSERT INTO campaign VALUES (?, ?)",
                                [(name, json.dumps(value)) for name, value in description.items()])
        return notes

    def description(self) -> dict[str, Any]:
        return {name: self._json(value, f"the campaign's '{name}'")
                for name, value in self._rows("SELECT name, value FROM campaign")}

    def _json(self, text: Any, what: str) -> Any:
        try:
            return json.loads(text)
        except (TypeError, ValueError) as error:
            raise RunError(f"the results store '{self.path}' is damaged: {what} is not JSON ({error}); restore it "
                           "or give another --store") from None

    def add_mutants(self, mutants: Iterable[MutantRecord]) -> None:
        with self.db:
            self.db.executemany("INSERT OR IGNORE INTO mutants (id, kind, description, diff) VALUES (?, ?, ?, ?)",
                                [(m.id, m.kind, m.description, m.diff) for m in mutants])

    def judge(self, verdicts: Iterable[tuple[str, str, str]]) -> None:
        """Record (mutant, verdict, detail) for each judged mutant, in one transaction."""
        with self.db:
            self.db.executemany("UPDATE mutants SET verdict = ?, detail = ? WHERE id = ?",
                                [(verdict, detail, mutant) for mutant, verdict, detail in verdicts])

    def mutants(self) -> list[MutantRecord]:
        records = [MutantRecord(*row) for row in
                   self._rows("SELECT id, kind, description, diff, verdict, detail FROM mutants ORDER BY id")]
        for record in records:
            if record.verdict not in VERDICTS:
                raise RunError(f"the results store '{self.path}' is damaged: mutant {record.id} has the verdict "
                               f"'{record.verdict}' (known: {', '.join(v or 'none yet' for v in VERDICTS)})")
        return records

    # ------------------------------------------------------------ results
    def record(self, outcome: Outcome) -> None:
        """Store one experiment's outcome, committed at once; a second outcome for the same
        experiment is an error (a campaign runs each experiment once), but for one that timed
        out, which a resumed campaign runs again (`done`) and whose new outcome replaces it."""
        e = outcome.experiment
        measures = json.dumps(outcome.measures, sort_keys=True) if outcome.measures is not None else None
        try:
            with self.db:
                self.db.execute("DELETE FROM results WHERE key = ? AND status = 'timeout'", (e.key,))
                self.db.execute("INSERT INTO results VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                                (e.key, e.configuration, e.mutant, e.mission, e.world, e.seed, outcome.status,
                                 measures, outcome.seconds, outcome.why, time.time()))
        except sqlite3.IntegrityError:
            raise RunError(f"experiment {e.key} is already in '{self.path}'") from None

    def done(self) -> set[str]:
        """The experiments a resumed campaign need not run again: all but those that timed out (a
        wall-clock limit, which a busy machine or a small --timeout may have hit)."""
        return {key for (key,) in self._rows("SELECT key FROM results WHERE status != 'timeout'")}

    def outcomes(self) -> Iterator[Outcome]:
        rows = self._rows("SELECT key, configuration, mutant, mission, world, seed, status, measures, seconds, why "
                          "FROM results ORDER BY key")
        for key, configuration, mutant, mission, world, seed, status, measures, seconds, why in rows:
            if status not in STATUSES:
                raise RunError(f"the results store '{self.path}' is damaged: experiment {key} has the status "
                               f"'{status}' (known: {', '.join(STATUSES)}); restore it or give another --store")
            yield Outcome(Experiment(configuration, mutant, mission, world, seed), status,
                          self._json(measures, f"the measures of experiment {key}") if measures is not None
                          else None, seconds, why)

    def count(self) -> int:
        ((n,),) = self._rows("SELECT COUNT(*) FROM results")
        return int(n)
