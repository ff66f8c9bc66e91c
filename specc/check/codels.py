"""Codel names exist in the module's declared Python codel module (read, never executed)."""

from __future__ import annotations

from specc.check.context import Context
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.span import Span
from specc.pysource import find_module, top_level_functions


def check(ctx: Context) -> None:
    for module in ctx.items(m.Module):
        used: list[tuple[str, Span]] = []
        for request in module.requests:
            used += [(c.function, c.span) for c in request.codels]
            if request.validate is not None:
                used.append((request.validate.text, request.validate.span))
        for task in module.exec_tasks:
            used += [(c.function, c.span) for c in task.codels]
        if module.codel_module is None:
            if used:
                ctx.report("missing-property",
                           f"module '{module.name}' names codels but no 'codels: \"python.module\";' to find them",
                           module.span)
            continue
        functions = python_functions(ctx, module.codel_module)
        if functions is None:
            continue
        for name, span in used:
            if name not in functions:
                ctx.report("undefined-codel",
                           f"codel '{name}' is not defined in {module.codel_module.value}"
                           f"{did_you_mean(name, functions)}; `specc skeleton` can write a stub for it", span)


def python_functions(ctx: Context, dotted: m.String) -> frozenset[str] | None:
    """The functions of a user Python module named in the spec; None (reported) if unreadable."""
    path = find_module(dotted.value, ctx.base_dir(dotted.span))
    if path is None:
        ctx.report("missing-python-module",
                   f"Python module '{dotted.value}' not found next to the spec (looked for "
                   f"{dotted.value.replace('.', '/')}.py from {ctx.base_dir(dotted.span)} upwards)", dotted.span)
        return None
    functions = top_level_functions(path)
    if isinstance(functions, SyntaxError):
        ctx.report("python-syntax-error",
                   f"{path}:{functions.lineno}: Python syntax error in '{dotted.value}': {functions.msg}",
                   dotted.span)
        return None
    return functions
