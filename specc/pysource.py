"""Reading user Python modules (codels, bindings) without executing them."""

from __future__ import annotations

import ast
import functools
import keyword
import sys
from pathlib import Path


def python_name(base: str) -> str:
    """The Python name a spec name becomes in the generated package (`a-b` -> `a_b`)."""
    return "".join(c if c.isalnum() else "_" for c in base)


def camel(name: str) -> str:
    """A module's, request's or poster's name as the generated module capitalises it for a class."""
    return name[:1].upper() + name[1:]


def python_name_problem(name: str) -> str | None:
    """Why the spec name `name` cannot name something of the generated package (None when it can):
    a Python keyword, or a dunder (Python's own names: `__init__`, `__dict__`...)."""
    generated = python_name(name)
    if keyword.iskeyword(generated):
        return f"'{generated}' is a Python keyword"
    if generated.startswith("__") and generated.endswith("__"):
        return f"'{generated}' is one of Python's own (dunder) names"
    if not generated.isidentifier():
        return f"'{generated}' is not a Python identifier"
    return None


def shadowed_by_the_standard_library(package: str) -> bool:
    """A package named like a standard module (`os`) is never imported: the standard one is."""
    return package in sys.stdlib_module_names


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
