"""Check passes over the model. The pipeline is this tuple: one module per pass.

Each pass reads the model and reports into the shared Context; passes never stop early, so
every diagnostic of a run comes out at once. Only the CLI decides the exit code.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from specc.check import codels, executive, ftplan, modules, names, planning, procedures, rules, system
from specc.check.context import Context
from specc.diagnostics import Diagnostic, sort_key
from specc.model import nodes as m

Pass = Callable[[Context], None]

PASSES: tuple[Pass, ...] = (
    names.check,
    modules.check,
    codels.check,
    executive.check,
    rules.check,
    procedures.check,
    planning.check,
    ftplan.check,
    system.check,
)


def check_program(program: m.Program, base_dirs: dict[str, Path] | None = None) -> list[Diagnostic]:
    ctx = Context(program, base_dirs or {})
    for run in PASSES:
        run(ctx)
    unique = {(d.code, d.span, d.message): d for d in ctx.diagnostics}
    return sorted(unique.values(), key=sort_key)
