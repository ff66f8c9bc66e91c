"""Codels of ARM (seed 000 §5.2.3, Table 5.3): a simulated manipulator arm (the simulator's
arm when one is attached, else joints integrated here)."""

from __future__ import annotations

import math

N_JOINTS = 6
JOINT_SPEED = 0.5  # rad/s (invented)
PERIOD = 0.05  # s, ArmTask period
REACH = 1.0  # m, invented reach from the arm base
REST = [0.0, -1.2, 2.0, 0.0, 0.8, 0.0]  # rest pose, above the robot's deck


def initArm(sdi):
    """ArmTask init: arm at rest, gripper open."""
    sdi.config.q = list(REST)
    sdi.target.q = list(REST)
    sdi.grip = "OPEN"
    if sdi.hardware is not None and sdi.hardware.arm is not None:
        sdi.hardware.arm.reset(REST)
    return "exec"


def planArmToObject(sdi, request):
    """goObject start: a placeholder inverse kinematics towards the object."""
    o = request.object
    dist = math.hypot(o.x, o.y)
    if dist > REACH:
        return "UNREACHABLE_OBJECT"
    sdi.object = o
    sdi.target.q = [math.atan2(o.y, o.x), 0.3, 0.9 * dist, 0.0, -0.5, 0.0]
    return "exec"


def planArmToRest(sdi, request):
    """goBack start: head for the rest pose (putting the object on the robot)."""
    sdi.target.q = list(REST)
    return "exec"


def moveArm(sdi, request):
    """goObject/goBack exec: move every joint towards the target at bounded speed (the
    simulated arm's joints when a simulator is attached)."""
    arm = sdi.hardware.arm if sdi.hardware is not None else None
    if arm is not None:
        arm.move_to(list(sdi.target.q))
        sdi.config.q = arm.q
        return "exec" if arm.moving else "ether"
    step = JOINT_SPEED * PERIOD
    done = True
    for i in range(N_JOINTS):
        error = sdi.target.q[i] - sdi.config.q[i]
        if abs(error) > step:
            sdi.config.q[i] += math.copysign(step, error)
            done = False
        else:
            sdi.config.q[i] = sdi.target.q[i]
    return "ether" if done else "exec"


def stopArm(sdi, request):
    """Inter phase: stop where the arm is."""
    if sdi.hardware is not None and sdi.hardware.arm is not None:
        sdi.hardware.arm.move_to(sdi.hardware.arm.q)
        sdi.config.q = sdi.hardware.arm.q
    sdi.target.q = list(sdi.config.q)
    return "ether"


def setGrip(sdi, request):
    """gripState: open or close the gripper."""
    sdi.grip = request.grip
    if sdi.hardware is not None and sdi.hardware.arm is not None:
        sdi.hardware.arm.grip = getattr(request.grip, "name", request.grip)  # "CLOSE", not "GripState.CLOSE"
    return "end"
