"""The tasks of seed 004's planning models (Modele1, Modele2) by kind, and an action as a plan
writes it: what `specc.run.rover` executes and what `specc.run.render` draws on a rover's
timeline, kept apart from both so the runner can draw its run through render.
"""

from __future__ import annotations

from collections.abc import Sequence

from specc.runtime.planner.plan import Value, format_value

# What each task of Modele1 and Modele2 is, for the executor and the timeline.
MOVE, PAN_TILT, PHOTO, LINK, PTU_INIT, MOTION_INIT = "move", "pan-tilt", "photo", "communication", \
    "pan-tilt init", "motion init"
TASK_KINDS = {
    "MOVE": MOVE, "MOVE_NOMINAL": MOVE, "MOVE_RECOV": MOVE,
    "MOVE_PAN_TILT_UNIT": PAN_TILT, "MOVE_PTU": PAN_TILT,
    "TAKE_PICTURE": PHOTO, "TAKE_SHOT": PHOTO,
    "COMMUNICATE": LINK, "COMMUNICATE_ANTENNA": LINK,
    "INIT_PTU_DRIVER": PTU_INIT, "INIT_PTU": PTU_INIT,
    "INIT_MVT_GENERATION": MOTION_INIT, "INIT_FRAME": MOTION_INIT,
}


def task_text(task: str, args: Sequence[Value]) -> str:
    """An action as a plan writes it, TASK(arg, ...) (as `Action.text`)."""
    return f"{task}({', '.join(format_value(a) for a in args)})"
