"""Codels of the test module `hand`: read by `specc check` for their signatures and the strings
they return, never run."""

raise RuntimeError("codel modules must never be executed by `specc check`")


def check_grip(sdi):  # a validate codel is called with (sdi, request)
    return "end"


def squeeze(sdi, request, force=1.0):  # a default third argument is fine
    if force > 2:
        return "SLIPPED"  # no such fail message
    if force > 1:
        return "exce"  # a typo of a codel state
    return "exec"


def hold(sdi, request, *rest):
    def inner():
        return "anything"  # a nested function's returns are its own
    if sdi.read_poster("arm.State") is None or sdi.read_poster("hnad.Grip") is None:  # arm exports none; a typo
        return "exec"
    if sdi.stuck:
        sdi.send_request("arm.Grab")  # a request Grip's `sends:` does not list
        sdi.send_request("arm.Grap")  # no module has it
        sdi.send_request("arm." + sdi.next)  # a name no analysis can follow
        return "exec" if sdi.busy else "ehter"  # a typo on one side of a conditional
    return "SLIP" if inner() else "ether"


def watch(sdi, request):  # an exec task's codel is called with (sdi)
    return "exec"


def release(sdi, request):
    return "ether"


loosen = "exec"  # a codel state where the function should be: no function at all
relax = lambda sdi: "ether"  # noqa: E731 - called with (sdi, request)
settle = lambda sdi, request: "etehr"  # noqa: E731 - a lambda's returned string is checked too
