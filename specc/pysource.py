"""Reading user Python modules (codels, bindings) without executing them."""

from __future__ import annotations

import ast
import functools
from pathlib import Path


def find_module(dotted: str, start: Path) -> Path | None:
    """The source file of `dotted`, looked up from the spec's folder and its parents."""
    relative = Path(*dotted.split("."))
    for folder in (start, *start.parents):
        for candidate in (folder / relative.with_suffix(".py"), folder / relative / "__init__.py"):
            if candidate.is_file():
                return candidate
    return None


@functools.lru_cache(maxsize=256)
def top_level_functions(path: Path) -> frozenset[str] | SyntaxError:
    """Names of the functions a module defines at top level, or the SyntaxError it has."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    except SyntaxError as exc:
        return exc
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            names.update(alias.asname or alias.name for alias in node.names)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return frozenset(names)
