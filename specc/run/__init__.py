"""Running a compiled robot end to end, on the simulated kernel (issue #9, `specc run`).

- `specc.run.events`: the JSONL event log every run writes, stamped with simulated time.
- `specc.run.mission`: any robot's mission, from its system block (`load_robot`, `run_mission`),
  with the robot's own extension hooks; `specc.run.plans`: FTplan's plans carried out as the
  system's bindings say.
- `specc.run.measures`: the measures of seed 004 §4.1.4 of a planned mission and their tables.
- `specc.run.render`: every picture of a run, drawn from its event log alone (`render_run`);
  `specc.run.pictures`: the state of Fig 5.11.
- `specc.run.session`: `specc run` (compile if stale, run, write the run folder);
  `specc.run.replay` and `specc.run.sweep`: `specc replay` and `specc table`.
- `specc.run.package`: compile-if-stale and the import of the generated package.

What a user can get wrong (a bad seed, an unreadable log, a package that is not compiled) is a
`RunError`, whose message the command line prints as it is.
"""

from __future__ import annotations

import os
from pathlib import Path


class RunError(ValueError):
    """A run that cannot start or a log that cannot be read: the message says why and what to do."""


def writable_folder(folder: Path, what: str, option: str = "--output") -> None:
    """RunError unless `folder` is, or can be made, a folder this process may write in: checked
    before long work (a table's runs, a campaign's experiments) whose results would otherwise
    have nowhere to go at the end."""
    if folder.exists() and not folder.is_dir():
        raise RunError(f"{what} '{folder}' is a file, not a folder: give a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RunError(f"cannot make {what} '{folder}': {error.strerror or error}") from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise RunError(f"{what} '{folder}' is not writable: give another ({option})")
