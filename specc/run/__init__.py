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


def writable_file(path: Path, option: str, file: str, folder: str, example: str, picture: bool = False) -> None:
    """RunError unless the file `path` (given by `option`) can be written: not a folder, a picture
    format matplotlib writes when `picture`, in a folder that can be made and written in. Checked
    before the work whose result it receives (a plan, a table's runs). `file` and `folder` name
    what is asked for ("the table's file", "the table's folder"); `example` a file name to give."""
    if path.is_dir():
        raise RunError(f"{option} '{path}' is a folder: give {file}, e.g. {path / example}")
    if picture and not path.suffix:  # matplotlib would write NAME.png, not the file named
        raise RunError(f"{option} '{path}': end the picture's name with .png, .svg or .pdf, e.g. "
                       f"{path.with_name(path.name + '.png')}")
    if picture:
        from matplotlib.backend_bases import FigureCanvasBase

        formats = FigureCanvasBase.get_supported_filetypes()
        if path.suffix[1:].lower() not in formats:
            raise RunError(f"{option} '{path}': matplotlib writes no '{path.suffix}' picture; end the name with "
                           f".png, .svg or .pdf (or {', '.join('.' + f for f in sorted(formats))})")
    writable_folder(path.parent, folder, option)
