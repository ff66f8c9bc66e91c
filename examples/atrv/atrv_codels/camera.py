"""Codels of CAMERA (seed 004 §4.1.1): photographs of the mission's targets.

An image shows the photo targets (the world's `[[targets]]`) the camera sees when it is taken:
looking ahead, those in the camera's field and range and not hidden by an obstacle (the
simulated camera's `in_view`); looking at the robot's feet (tilt at or below FEET_TILT, annex A's
AT_MY_FEET), those on the patch of ground in front of the robot. The photo succeeds when the
target asked for (or, asked for none, any target) is in it. Without a simulator every photo
succeeds, as the thesis' CAMERA did.
"""

from __future__ import annotations

import math

PERIOD = 0.1  # s, ShotTask period
EXPOSURE = 2.0  # s per image: annex A's TAKE_PICTURE lasts [2, 6] s (INVENTED within it)
FEET_TILT = -0.5  # rad: at or below this tilt the camera looks at the ground near the robot
CAMERA_HEIGHT = 1.0  # m above the ground (INVENTED)
# m: the patch of ground an image at the robot's feet covers, around the point the camera aims at
# (INVENTED). It holds the robot's own position at both models' AT_MY_FEET: the codels' tilt
# (platine.AT_MY_FEET, aimed 0.39 m ahead) and Modele2's 45 degrees (annex A.2, aimed 1 m ahead),
# where a mission's first photo is taken (M1's target under the lander); not at Modele2's moving
# tilt of 30 degrees (aimed 1.73 m ahead), so a photo taken with the camera there still misses.
FEET_RADIUS = 1.2


def initCamera(sdi):
    """ShotTask init: no photo yet."""
    sdi.last.count, sdi.last.targets, sdi.last.date = 0, "", 0.0
    return "exec"


def startExposure(sdi, request):
    """TakePicture start: the pan-tilt unit must be still."""
    hardware = sdi.hardware
    if hardware is not None and hardware.pan_tilt.moving:
        _log(sdi, request, [], "PTU_MOVING")
        return "PTU_MOVING"
    sdi.exposure = 0.0
    return "exec"


def expose(sdi, request):
    """TakePicture exec: after the exposure time, the targets in the image decide."""
    sdi.exposure += PERIOD
    if sdi.exposure < EXPOSURE - 1e-9:
        return "exec"
    hardware = sdi.hardware
    names = targets_in_image(hardware) if hardware is not None else [request.target or "target"]
    wanted = request.target
    ok = wanted in names if wanted else bool(names)
    return _log(sdi, request, names, "ether" if ok else "NO_TARGET_IN_VIEW")


def abortExposure(sdi, request):
    """TakePicture inter: the image is dropped."""
    return "ether"


def targets_in_image(hardware):
    """The names of the photo targets the camera's image shows now."""
    targets = hardware.world.targets
    points = [(t.x, t.y) for t in targets]
    if hardware.pan_tilt.tilt.position <= FEET_TILT:
        x, y, heading = hardware.camera.axis()
        ahead = CAMERA_HEIGHT / math.tan(-hardware.pan_tilt.tilt.position)
        cx, cy = x + ahead * math.cos(heading), y + ahead * math.sin(heading)
        return [t.name for t, (px, py) in zip(targets, points, strict=True)
                if math.hypot(px - cx, py - cy) <= FEET_RADIUS]
    return [targets[s.index].name for s in hardware.camera.in_view(points)]


def _log(sdi, request, names, outcome):
    hardware = sdi.hardware
    now = hardware.now if hardware is not None else sdi.last.date + sdi.exposure
    ok = outcome == "ether"
    if hardware is not None:
        if ok:
            hardware.trace.photos.extend((now, name, True) for name in names)
        else:
            hardware.trace.photos.append((now, request.target, False))
    if ok:
        sdi.last.count += 1
        sdi.last.targets, sdi.last.date = ",".join(names), now
        request.photo.count, request.photo.targets, request.photo.date = sdi.last.count, sdi.last.targets, now
    return outcome
