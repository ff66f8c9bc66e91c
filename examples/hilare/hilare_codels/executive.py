"""Input and output functions of the Hilare 2 executive's services (seed 000 §3.3.1, §5.3).

§5.3: input functions "servent essentiellement à faire des lectures de données exportées et des
conversions mineures de format: en aucun cas elles ne doivent exécuter des algorithmes complexes";
an output function "prépare le résultat d'exécution à être envoyé au client du service".

Interface assumed from the runtime: ``ctx.vars`` is a dict of executive variables that persists
across services, ``ctx.read_poster("module.Poster")`` reads a poster, ``ctx.world`` is the path of
the system's world file. An input function returns the request's inputs as a dict (struct values
as dicts); an output function receives the request's outputs and returns the result sent to the
task level in (REPLY id result).
"""

from __future__ import annotations

import math
import pathlib
import tomllib

CAMERA_STEP = math.radians(30)  # §5.3: "une valeur constante" - not given, invented


def default_dynamic(ctx):
    """SET-DYNAMIC: PILO's default maximum speeds and accelerations (invented values)."""
    return {"dynamic": {"vmax": 0.3, "wmax": 0.6, "amax": 0.3, "dwmax": 0.6}}


def room_box(ctx):
    """SET-BOX: the planner's environment bounds, from the world file's [room] table."""
    if "room" not in ctx.vars:  # the world file does not change while the robot runs: read it once
        ctx.vars["room"] = tomllib.loads(pathlib.Path(ctx.world).read_text()).get("room", {})
    room = ctx.vars["room"]
    return {
        "box": {
            "xmin": 0.0,
            "ymin": 0.0,
            "xmax": float(room.get("width", 20.0)),
            "ymax": float(room.get("height", 20.0)),
        }
    }


def path_to_goal(ctx):
    """CALC-TRAJ-GOAL: from the robot's position to EXPLOR's last exploration position."""
    return {"start": _robot(ctx), "goal": _posit(ctx.read_poster("explor.Goals").goal)}


def path_to_object(ctx):
    """CALC-TRAJ-OBJ: from the robot's position to EXPLOR's last grasping position."""
    return {"start": _robot(ctx), "goal": _posit(ctx.read_poster("explor.Goals").graspPos)}


def object_to_grasp(ctx):
    """CALC-OBJ: the object kept by GET-NEAR-OBJ."""
    return {"object": dict(ctx.vars["object"])}


def object_for_arm(ctx):
    """ARM-OBJ: the kept object, in the robot's frame (the arm base is at the robot's centre)."""
    robot = ctx.read_poster("loco.Robot").robot
    obj = ctx.vars["object"]
    dx, dy = obj["x"] - robot.x, obj["y"] - robot.y
    c, s = math.cos(robot.theta), math.sin(robot.theta)
    return {"object": {"x": c * dx + s * dy, "y": -s * dx + c * dy, "z": 0.0}}


def next_camera_orientation(ctx):
    """TURN-CAMERA: the previous orientation plus a constant step (§5.3)."""
    pan = ctx.vars.get("pan", 0.0) + CAMERA_STEP
    ctx.vars["pan"] = math.atan2(math.sin(pan), math.cos(pan))
    return {"pan": ctx.vars["pan"]}


def objects_found(ctx, outputs):
    """SEARCH-OBJ: pass the number of objects detected to the task level (§5.3)."""
    return outputs.nbFound


def keep_nearest_object(ctx, outputs):
    """GET-NEAR-OBJ: keep the object in an executive variable for CALC-OBJ and ARM-OBJ."""
    o = outputs.object
    ctx.vars["object"] = {"x": o.x, "y": o.y, "i": o.i, "j": o.j}
    return "OK"


def _robot(ctx):
    return _posit(ctx.read_poster("loco.Robot").robot)


def _posit(p):
    return {"x": p.x, "y": p.y, "theta": p.theta}
