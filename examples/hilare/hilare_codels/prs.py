"""Primitive actions and evaluable predicates of the Hilare 2 task level (seed 000 §4.1, §4.2).

Interface assumed from the supervisor runtime: each function receives ``ctx`` first, with
``ctx.send(message)`` to send a message to the executive, ``ctx.new_id()`` for a unique request
identifier, ``ctx.log(text)`` for the operator, and ``ctx.read_param(name)`` for GET-PARAM.
"""

from __future__ import annotations

import math

SHORT_RANGE = 2.0  # m, invented limit between long and short displacements


def send_request(ctx, request):
    """SEND-REQUEST (Fig 4.2): give the request a unique identifier, send both, return the id."""
    request_id = ctx.new_id()
    ctx.send((request, request_id))
    return request_id


def send_interrupt(ctx, request_id):
    """SEND-INTERRUPT: the INT request of §3.9, whose identifier names the service to interrupt."""
    ctx.send(("INT", request_id))


def warn_operator(ctx, request, request_id):
    """WARN-OPERATOR: tell the operator that a service is frozen in ZOMBIE (§4.2.1)."""
    ctx.log(f"service {request} ({request_id}) is ZOMBIE: interrupting it")


def is_long_range_displacement(ctx):
    """IS-LONG-RANGE-DISPLACEMENT (Fig 4.1): is the goal still too far for a short displacement?"""
    robot = ctx.read_param("ROBOT-POSITION")
    goal = ctx.read_param("GOAL-POSITION")
    return math.hypot(goal.x - robot.x, goal.y - robot.y) > SHORT_RANGE
