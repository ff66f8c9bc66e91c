"""Codels of module beta (see the package docstring)."""

from scripted_codels import play


def play_exec(sdi, request):
    return play("exec", sdi, request)


def play_inter(sdi, request):
    request.trace = request.trace + ",inter"
    return "ether"
