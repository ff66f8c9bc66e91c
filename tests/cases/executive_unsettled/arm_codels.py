"""Codels of the executive_unsettled case."""


def go(sdi, request):
    return "ether"


def back(sdi, request):
    return "ether"
