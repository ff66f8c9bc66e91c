"""Codels of module alpha (see the package docstring)."""

from scripted_codels import play


def play_start(sdi, request):
    return play("start", sdi, request)


def play_exec(sdi, request):
    return play("exec", sdi, request)


def play_named(sdi, request):
    return play("named", sdi, request)


def play_end(sdi, request):
    request.trace = request.trace + ",end"
    return "ether"


def play_inter(sdi, request):
    request.trace = request.trace + ",inter"
    return sdi.inter_outcome or "ether"


def check_script(sdi, request):
    return "BAD_SCRIPT" if "bad" in request.script else "end"


def set_value(sdi, request):
    if request.value < 0:
        return "NEGATIVE"
    sdi.value = request.value
    return "end"


def set_mode(sdi, request):
    sdi.mode = request.mode
    return "end"


def accept(sdi, request):
    return "end"


def init_perm(sdi):
    sdi.counter = 0
    return "exec"


def perm(sdi):
    sdi.counter += 1
    return "exec"


def get_value(sdi, request):
    request.value = sdi.value
    return "end"
