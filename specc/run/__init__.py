"""Running a compiled robot end to end, on the simulated kernel (issue #9, `specc run`).

- `specc.run.events`: the JSONL event log every run writes, stamped with simulated time.
- `specc.run.hunt`: Hilare's object hunt of seed 000 ch. 5 (`run_hunt`) and the §5.5 checks
  read from its log.
- `specc.run.pictures`: the hunt's picture and the state of Fig 5.11 (`draw_hunt`).

What a user can get wrong (a bad seed, an unreadable log, a package that is not compiled) is a
`RunError`, whose message the command line prints as it is.
"""

from __future__ import annotations


class RunError(ValueError):
    """A run that cannot start or a log that cannot be read: the message says why and what to do."""
