"""Check passes over the model. The pipeline is this tuple: one module per pass.

The semantic analysis comes first (`symbols.py`): every name of every layer is resolved once into
symbol tables (blocks by kind and name, each module's requests and posters, the module of each
request, each executive's services, a service's request, what a request sends), which the passes
read through the Context, and the analyses and back ends through `symbols_of(program)`: nothing
resolves a `module.request` by hand again. Each pass then reads the model and the tables and
reports into the shared Context; passes never stop early, so every diagnostic of a run comes out
at once. Only the CLI decides the exit code. Diagnostics that need an analysis (how an executive's
rule bases name its service groups, what its controller leaves unsettled) come from
`specc.pipeline`, after these passes: the checks never import an analysis.
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
