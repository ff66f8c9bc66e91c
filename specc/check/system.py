"""A system names the blocks that make one robot; each must exist and be of the right kind."""

from __future__ import annotations

from specc.check.context import Context
from specc.model import nodes as m


def check(ctx: Context) -> None:
    for system in ctx.items(m.System):
        for ref in system.modules:
            ctx.lookup(m.Module, ref, ref.span, "undefined-module")
        single: tuple[tuple[m.Ref | None, type, str], ...] = (
            (system.executive, m.Executive, "undefined-executive"),
            (system.supervisor, m.Procedures, "undefined-procedures"),
            (system.planning, m.FtPlan, "undefined-ftplan"))
        for reference, kind, code in single:
            if reference is not None:
                ctx.lookup(kind, reference, reference.span, code)
        for ref in system.missions:
            ctx.lookup(m.Problem, ref, ref.span, "undefined-problem")
        if not system.modules:
            ctx.report("missing-property", f"system '{system.name}' needs 'modules: ...;'", system.span)
        if system.world is not None:
            path = ctx.base_dir(system.world.span) / system.world.value
            if not path.is_file():
                ctx.warn("missing-world", f"world file '{system.world.value}' not found (looked at {path})",
                         system.world.span)
