"""Every top-level name once per kind, and no two items of different kinds sharing one
(a system refers to its blocks by name only)."""

from __future__ import annotations

from specc.check.context import KIND_WORDS, Context
from specc.model import nodes as m


def check(ctx: Context) -> None:
    seen: dict[str, m.Item] = {}
    for item in ctx.program.items:
        previous = seen.get(item.name)
        if previous is None:
            seen[item.name] = item
            continue
        if type(previous) is type(item):
            message = f"{KIND_WORDS[type(item)]} '{item.name}' is defined twice"
        else:
            message = (f"'{item.name}' names both a {KIND_WORDS[type(previous)]} and a "
                       f"{KIND_WORDS[type(item)]}; rename one")
        ctx.report("duplicate-definition", message, item.span, (previous.span, "first defined here"))
