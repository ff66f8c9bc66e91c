"""Codels of the executive_rules case."""


def go(record):
    return "ether"


def back(record):
    return "ether"
