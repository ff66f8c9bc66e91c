"""Codels of the executive_rules case."""


def go(sdi, request):
    return "ether"


def back(sdi, request):
    return "ether"
