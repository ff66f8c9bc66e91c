"""The rover missions of seed 004 (§4.1, §4.2) on the simulated ATRV: what specc's runner needs
beyond the specs (the system block's `extension:`, see docs/run.md).

- `prepare`: the mission's photo targets, checked in the world where the mission asks for them and
  named as the plans name them (M1_OBJ2 in the world file is OBJ2 during M1), and the visibility
  windows of the antenna, drawn with the seed;
- `attach`: a `photo` event for every image CAMERA takes and a `communication` event for every
  link ANTENNA tries, from the modules' replies;
- `measure`: the measures of §4.1.4 (`specc.run.measures.Measures`: p photos, c communications,
  h the return home), the goals judged on what happened in the simulation, from the log alone;
- `judge`: the mission succeeded when every goal was really met (not only in FTplan's ledger).

Where the thesis is silent (INVENTED): the windows' real opening and closing instants are drawn
uniformly in the bounds of the mission's contingent events (missions.md: "W1 [125..127,
154..156]"); the robot is home when it stands within HOME_TOLERANCE of the lander at the end.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from specc.run.measures import Measures, PlannedGoal, believed, planned_goals, planned_measures
from specc.runtime.ftplan.state import SystemState, constant, constant_key
from specc.runtime.planner import model as pm
from specc.runtime.sim import Target, Window, WorldError

WINDOW_STREAM = 0x57A7E11  # mixed with the seed for the windows' instants, apart from the simulator's streams
HOME_TOLERANCE = 0.5  # m: NDD stops within 0.3 m of its goal by odometry, which drifts (INVENTED)

# FTplan's goal attributes (ftplan.spec's state): a photo, a communication, the return home.
PICTURE, COMMUNICATION = "PICTURE", "COMMUNICATION"
ROBOT_X, ROBOT_Y = "AT_ROBOT_X", "AT_ROBOT_Y"


# ---------------------------------------------------------------- before the run


def prepare(world: Any, setup: Any) -> Any:
    """The world of a planned mission: its photo targets under the plans' names, its windows drawn."""
    if setup.planning is None:  # goals posted by hand (`--goal`): the world as written
        return world
    problem = setup.planning.problem
    mission = setup.mission.plan
    return dataclasses.replace(world, targets=mission_targets(world, problem, mission),
                               windows=mission_windows(problem, setup.seed))


def mission_targets(world: Any, problem: pm.Problem, mission: str) -> tuple[Target, ...]:
    """The world's targets, the mission's own (`<mission>_<object>`) renamed as its plans name
    them; WorldError when one the mission photographs is not where it asks for it."""
    in_world = {t.name: t for t in world.targets}
    renamed: dict[str, Target] = {}
    for goal in SystemState.from_problem(problem).goals:
        if goal.attribute != PICTURE or len(goal.args) != 3:
            continue
        obj, x, y = goal.args
        name = f"{mission}_{obj}"
        target = in_world.get(name)
        if target is None or not (math.isclose(target.x, float(x), abs_tol=1e-6)
                                  and math.isclose(target.y, float(y), abs_tol=1e-6)):
            raise WorldError(f"world {world.name} ({world.source or 'no file'}) has no photo target {name} at "
                             f"({float(x):g}, {float(y):g}), which mission {mission} photographs")
        renamed[name] = Target(str(obj), target.x, target.y)
    return tuple(renamed.get(t.name, t) for t in world.targets)


def mission_windows(problem: pm.Problem, seed: int) -> tuple[Window, ...]:
    """The visibility windows of the mission, each opening and closing at an instant nature draws
    (with the seed) uniformly within the bounds of its contingent events."""
    dates = SystemState.from_problem(problem).dates
    opening: dict[str, tuple[float, float]] = {}
    closing: dict[str, tuple[float, float]] = {}
    for a in problem.assertions:
        if not (isinstance(a, pm.Event) and a.kind == "contingent" and a.attribute == "VISIBILITY_WINDOW"):
            continue
        key, before, after = constant_key(a.attribute, a.args), constant(a.before), constant(a.after)
        if key is None or a.time == problem.start or a.time not in dates or len(key[1]) != 1:
            continue
        if (before, after) == ("OUT", "IN"):
            opening[str(key[1][0])] = dates[a.time]
        elif (before, after) == ("IN", "OUT"):
            closing[str(key[1][0])] = dates[a.time]
    rng = np.random.default_rng([WINDOW_STREAM, seed])
    windows = []
    for name in sorted(opening, key=lambda n: opening[n]):
        if name not in closing or not (_drawable(opening[name]) and _drawable(closing[name])):
            continue  # an inconsistent problem leaves nature no instant: no window, and no plan either
        start = round(float(rng.uniform(*opening[name])), 3)
        end = round(float(rng.uniform(*closing[name])), 3)
        windows.append(Window(name, start, max(end, start)))
    return tuple(windows)


def _drawable(bounds: tuple[float, float]) -> bool:
    low, high = bounds
    return math.isfinite(low) and math.isfinite(high) and low <= high


# ---------------------------------------------------------------- during the run


def attach(run: Any) -> None:
    """Log what CAMERA and ANTENNA answer: each photo (the targets in the image, where the robot
    truly stood, the pan-tilt unit's true angles) and each communication (the window that held it)."""
    camera, antenna = run.registry.modules["camera"], run.registry.modules["antenna"]
    asked: dict[tuple[str, int], Any] = {}  # the activities under way, for their inputs and start

    def started(module: Any, activity: Any, source: Any, target: Any) -> None:
        if source == "ETHER":
            asked[(module.name, activity.id)] = activity

    def photo(reply: Any) -> None:
        if not reply.final or reply.request != "TakePicture":
            return
        activity = asked.pop(("camera", reply.rqst_id), None)
        x, y, _ = run.sim.pose
        unit = run.sim.pan_tilt
        seen = [t for t in reply.output.photo.targets.split(",") if t] if reply.ok else []
        why = {} if reply.ok else {"why": _reply_text(reply)}
        run.emit("photo", target=activity.input.target if activity is not None else "", ok=reply.ok, seen=seen,
                 x=round(x, 3), y=round(y, 3), pan=round(unit.pan.position, 4), tilt=round(unit.tilt.position, 4),
                 **why)

    def link(reply: Any) -> None:
        if not reply.final or reply.request != "Communicate":
            return
        activity = asked.pop(("antenna", reply.rqst_id), None)
        why = {} if reply.ok else {"why": _reply_text(reply)}
        run.emit("communication", ok=reply.ok, start=round(activity.started, 6) if activity is not None else None,
                 link=reply.output.window if reply.ok else "", **why)

    for module, listener in ((camera, photo), (antenna, link)):
        module.observers.append(started)
        module.reply_listeners.append(listener)


def _reply_text(reply: Any) -> str:
    detail = f" ({reply.report.detail})" if reply.report.detail else ""
    return f"{reply.status.value} {reply.report.code}{detail}"


# ---------------------------------------------------------------- after the run


def measure(events: list[dict[str, Any]]) -> dict[str, Any]:
    """The measures of §4.1.4 (`specc.run.measures`), each goal judged on what happened: a photo
    is met when an image CAMERA took shows its target, a communication when its window held one
    of ANTENNA's links, the return (FTplan's two goals AT_ROBOT_X, AT_ROBOT_Y: one goal h) when the
    robot truly stands within HOME_TOLERANCE of home at the end."""
    if "planned_goals" not in events[0]:  # goals posted by hand (`--goal`): no mission of §4.1.2 to measure
        return {}
    seen = {name for e in events if e["kind"] == "photo" and e["ok"] for name in e["seen"]}
    links = {e["link"] for e in events if e["kind"] == "communication" and e["ok"]}
    x, y = next((e["x"], e["y"]) for e in reversed(events) if e["kind"] == "pose")
    goals = planned_goals(events)
    home = {g.attribute: float(g.value) for g in goals if g.attribute in (ROBOT_X, ROBOT_Y)}

    def really(goal: PlannedGoal) -> tuple[str, bool] | None:
        if goal.attribute == PICTURE:
            return "p", str(goal.args[0]) in seen
        if goal.attribute == COMMUNICATION:
            return "c", str(goal.args[0]) in links
        if goal.attribute == ROBOT_X:
            return "h", math.hypot(x - home[ROBOT_X], y - home.get(ROBOT_Y, 0.0)) <= HOME_TOLERANCE
        if goal.attribute == ROBOT_Y and ROBOT_X in home:
            return None  # counted with AT_ROBOT_X: one return home
        return believed(goal)

    return planned_measures(events, really, kinds=("p", "c", "h")).to_json()


def judge(events: list[dict[str, Any]], measures: dict[str, Any], outcome: str, why: str) -> tuple[str, str]:
    """Succeeded when every goal was really met; what FTplan believed is kept in `why`."""
    if not Measures.readable(measures):  # nothing measured: the goals' own outcome stands
        return outcome, why
    judged = Measures.from_json(measures)
    if judged.success:
        return "succeeded", why
    named = {"p": "photos", "c": "communications", "h": "return"}
    missed = [f"{named.get(kind, kind)} {count.text()}" for kind, count in judged.goals if count.met < count.asked]
    # A run FTplan already judged (failed, or stopped at its horizon) keeps its outcome.
    return "failed" if outcome == "succeeded" else outcome, f"goals really met: {', '.join(missed)}" + (
        f"; {why}" if outcome != "succeeded" else "")
