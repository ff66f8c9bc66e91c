"""Codels of LIFT: the hook that hitches the cart standing behind the tug.

A cart is one of the world's objects; it is behind the tug when it lies within REACH of the
tug's centre. Hitched, it travels with the tug; unhitched, it stands where the tug left it.
"""

from __future__ import annotations

import math

REACH = 0.6  # m from the tug's centre
HOOK_CYCLES = 20  # of the 100 ms task: the hook takes 2 s to move


def initHook(sdi):
    sdi.cart = -1


def startHitch(sdi, request):
    if sdi.cart >= 0:
        return "ALREADY_HITCHED"
    sim = sdi.hardware
    x, y, _ = sim.pose
    near = [k for k, (cx, cy) in enumerate(sim.objects) if math.hypot(cx - x, cy - y) <= REACH]
    if not near:
        return "NO_CART"
    sdi.cart = near[0]
    sdi.cycles = 0
    return "exec"


def raiseHook(sdi, request):
    sdi.cycles += 1
    if sdi.cycles < HOOK_CYCLES:
        return "exec"
    sdi.hardware.trace.taken.add(sdi.cart)  # on the tug (the simulator's own pictures draw it taken)
    return "end"


def startUnhitch(sdi, request):
    if sdi.cart < 0:
        return "NO_CART"
    sdi.cycles = 0
    return "exec"


def lowerHook(sdi, request):
    sdi.cycles += 1
    if sdi.cycles < HOOK_CYCLES:
        return "exec"
    sim = sdi.hardware
    x, y, _ = sim.pose
    sim.objects[sdi.cart] = (round(x, 3), round(y, 3))  # the cart stands where it was left
    sim.trace.taken.discard(sdi.cart)
    sdi.cart = -1
    return "end"
