"""Reading user Python modules (codels, bindings) without executing them."""

from __future__ import annotations

import ast
import functools
import keyword
import sys
from collections.abc import Mapping
from dataclasses import dataclass
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
    parts = dotted.split(".")
    if not all(part.isidentifier() for part in parts):
        return None
    relative = Path(*parts)
    for folder in (start, *start.parents):
        for candidate in (folder / relative.with_suffix(".py"), folder / relative / "__init__.py"):
            try:
                if candidate.is_file():
                    return candidate
            except OSError:  # a name longer than the file system allows is no file
                return None
    return None


@dataclass(frozen=True)
class FunctionShape:
    """What `specc check` reads of a user function without running it."""

    line: int
    least: int  # positional arguments it needs
    most: int | None  # positional arguments it accepts (None: *args)
    returns: tuple[tuple[str, int], ...] = ()  # the string constants it returns, with their lines

    def accepts(self, count: int) -> bool:
        return self.least <= count and (self.most is None or count <= self.most)


def shape_of(node: ast.FunctionDef | ast.AsyncFunctionDef) -> FunctionShape | None:
    """None for a decorated function: its decorator may change how it is called."""
    if node.decorator_list:
        return None
    arguments = node.args
    positional = len(arguments.posonlyargs) + len(arguments.args)
    required_keywords = any(default is None for default in arguments.kw_defaults)
    least = positional - len(arguments.defaults)
    most = None if arguments.vararg is not None else positional
    if required_keywords:  # a keyword-only argument without default: no positional call works
        most = -1
    returns: list[tuple[str, int]] = []
    stack: list[ast.AST] = list(node.body)
    while stack:
        current = stack.pop()
        if isinstance(current, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue  # a nested function's returns are its own
        if isinstance(current, ast.Return) and isinstance(current.value, ast.Constant) \
                and isinstance(current.value.value, str):
            returns.append((current.value.value, current.lineno))
        stack.extend(ast.iter_child_nodes(current))
    return FunctionShape(node.lineno, least, most, tuple(sorted(returns, key=lambda r: r[1])))


@functools.lru_cache(maxsize=256)
def top_level_functions(path: Path) -> Mapping[str, FunctionShape | None] | SyntaxError:
    """The names a module defines at top level, each with its shape when it is a plain function
    (None for an import, an assignment or a decorated function), or why it cannot be read."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    except SyntaxError as exc:
        exc.lineno = exc.lineno or 1  # a NUL byte is a SyntaxError of no line
        return exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:  # unreadable, not UTF-8, a NUL byte
        unreadable = SyntaxError(f"cannot read it as Python source: {exc}")
        unreadable.lineno = 1
        return unreadable
    names: dict[str, FunctionShape | None] = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names[node.name] = shape_of(node)
        elif isinstance(node, ast.ImportFrom):
            names.update((alias.asname or alias.name, None) for alias in node.names)
        elif isinstance(node, ast.Assign):
            names.update((t.id, None) for t in node.targets if isinstance(t, ast.Name))
    return names
