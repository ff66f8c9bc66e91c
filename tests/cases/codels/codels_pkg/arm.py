"""Codels of the test module `arm`."""

raise RuntimeError("codel modules must never be executed by `specc check`")


def checkGrab(sdi, request):
    return "ok"


def openGripper(sdi, request):
    return "exec"


def closeGripper(sdi, request):
    return "end"
