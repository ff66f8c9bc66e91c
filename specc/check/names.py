"""Every top-level name once per kind. Kinds have separate namespaces: a system refers to each
block through a typed property (`executive: tug`), so robot and executive may share a name."""

from __future__ import annotations

from specc.check.context import KIND_WORDS, Context


def check(ctx: Context) -> None:
    for kind, word in KIND_WORDS.items():
        ctx.duplicates(list(ctx.items(kind)), word)
