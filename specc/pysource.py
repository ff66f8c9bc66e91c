"""Reading user Python modules (codels, bindings) without executing them."""

from __future__ import annotations

import ast
import dataclasses
import functools
import keyword
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from specc import disk_cache


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
    defined_in: str = ""  # where a re-exported function is written (its package's folder / file)
    posters: tuple[tuple[str, int], ...] = ()  # the names it reads posters by (`x.read_poster("m.P")`), with lines
    sends: tuple[tuple[str, int], ...] = ()  # the requests it sends by name (`x.send_request("m.R")`), with lines
    computed_sends: tuple[int, ...] = ()  # the lines sending a request whose name is computed (`"m." + r`)
    # What the name holds when it is no function (`step = "exec"`: "a str"): nothing calls it.
    not_callable: str = ""

    def accepts(self, count: int) -> bool:
        return not self.not_callable and self.least <= count and (self.most is None or count <= self.most)


# Assigned values that are no function, and how to say what they are.
_NOT_CALLABLE = {ast.List: "a list", ast.Tuple: "a tuple", ast.Dict: "a dict", ast.Set: "a set",
                 ast.JoinedStr: "a str", ast.ListComp: "a list", ast.DictComp: "a dict", ast.SetComp: "a set"}


def assigned_shape(value: ast.expr, line: int) -> FunctionShape | None:
    """`name = value` at a module's top level: a lambda's shape, what a literal is (no function),
    or None when only running it would tell (another function's name, a call's result)."""
    if isinstance(value, ast.Lambda):
        least, most = _arity(value.args)
        return FunctionShape(line, least, most, tuple((v, line) for v in _strings_returned(value.body)))
    if isinstance(value, ast.Constant):
        return FunctionShape(line, 0, 0, not_callable=f"a {type(value.value).__name__}")
    kind = _NOT_CALLABLE.get(type(value))
    return FunctionShape(line, 0, 0, not_callable=kind) if kind is not None else None


def _arity(arguments: ast.arguments) -> tuple[int, int | None]:
    """The positional arguments a function needs and accepts (None: any number; -1: none works,
    a keyword-only argument has no default)."""
    positional = len(arguments.posonlyargs) + len(arguments.args)
    if any(default is None for default in arguments.kw_defaults):
        return positional - len(arguments.defaults), -1
    return positional - len(arguments.defaults), None if arguments.vararg is not None else positional


def shape_of(node: ast.FunctionDef | ast.AsyncFunctionDef) -> FunctionShape | None:
    """None for a decorated function: its decorator may change how it is called."""
    if node.decorator_list:
        return None
    arguments = node.args
    least, most = _arity(arguments)
    returns: list[tuple[str, int]] = []
    named: dict[str, list[tuple[str, int]]] = {"read_poster": [], "send_request": []}
    computed: list[int] = []
    stack: list[ast.AST] = list(node.body)
    while stack:
        current = stack.pop()
        if isinstance(current, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue  # a nested function's returns are its own
        if isinstance(current, ast.Return) and current.value is not None:
            returns += [(value, current.lineno) for value in _strings_returned(current.value)]
        if (isinstance(current, ast.Call) and isinstance(current.func, ast.Attribute)
                and current.func.attr in named and current.args):
            if isinstance(current.args[0], ast.Constant) and isinstance(current.args[0].value, str):
                named[current.func.attr].append((current.args[0].value, current.lineno))
            elif current.func.attr == "send_request":
                computed.append(current.lineno)
        stack.extend(ast.iter_child_nodes(current))
    return FunctionShape(node.lineno, least, most, tuple(sorted(returns, key=lambda r: r[1])),
                         posters=tuple(sorted(named["read_poster"], key=lambda r: r[1])),
                         sends=tuple(sorted(named["send_request"], key=lambda r: r[1])),
                         computed_sends=tuple(sorted(computed)))


def _strings_returned(value: ast.expr) -> list[str]:
    """The string constants a returned expression may be: the constant itself, or either side of
    a conditional (`"exec" if moving else "ether"`)."""
    if isinstance(value, ast.Constant) and isinstance(value.value, str):
        return [value.value]
    if isinstance(value, ast.IfExp):
        return _strings_returned(value.body) + _strings_returned(value.orelse)
    return []


@dataclass(frozen=True)
class _Imported:
    """`from module import name` at a module's top level (level: the leading dots)."""

    module: str
    level: int
    name: str


PYTHON_NAMES = "python"  # the disk cache's kind of entry: a module's top-level names


def _top_level(path: Path) -> Mapping[str, FunctionShape | _Imported | None] | SyntaxError | OSError:
    """The names a module defines at top level: a plain function's shape, where a `from ... import`
    takes a name from, or None (an assignment, a decorated function); or why it cannot be read
    (OSError: the file; SyntaxError: its text). Read back from the disk cache when this code read
    the same file before: parsing the codels is most of a `specc check` of a robot whose specs are
    cached."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        return exc
    return _names_in(data, str(path))


@functools.lru_cache(maxsize=256)
def _names_in(data: bytes, filename: str) -> Mapping[str, FunctionShape | _Imported | None] | SyntaxError:
    key = disk_cache.key(_own_digest(), filename, data)
    kept = disk_cache.read(PYTHON_NAMES, key, (dict, _Unreadable))
    found = _read_names(data, filename) if kept is disk_cache.MISSING else kept
    if kept is disk_cache.MISSING:
        disk_cache.keep(PYTHON_NAMES, key, found)
    return found.error() if isinstance(found, _Unreadable) else found


@functools.lru_cache(maxsize=1)
def _own_digest() -> str:
    """This code's digest and the interpreter's version: what `ast.parse` accepts is the
    interpreter's (3.12's `type X = ...` is a syntax error to 3.11), and the cache is shared."""
    return disk_cache.source_digest([Path(__file__)]) + sys.implementation.cache_tag + sys.version


@dataclass(frozen=True)
class _Unreadable:
    """Why a module cannot be read, as kept on disk (plain data: an exception's attributes do not all
    survive pickling once a library has changed how exceptions pickle)."""

    message: str
    filename: str
    line: int
    offset: int = 1
    text: str | None = None

    def error(self) -> SyntaxError:
        return SyntaxError(self.message, (self.filename, self.line, self.offset, self.text))


def _unreadable(path: Path | str, exc: Exception) -> _Unreadable:
    return _Unreadable(f"cannot read it as Python source: {exc}", str(path), 1)


def _read_names(data: bytes, filename: str) -> dict[str, FunctionShape | _Imported | None] | _Unreadable:
    try:
        tree = ast.parse(data.decode("utf-8"), filename=filename)
    except SyntaxError as exc:  # a NUL byte is a SyntaxError of no line
        return _Unreadable(exc.msg, filename, exc.lineno or 1, exc.offset or 1, exc.text)
    except (UnicodeDecodeError, ValueError) as exc:  # not UTF-8, a NUL byte
        return _unreadable(filename, exc)
    names: dict[str, FunctionShape | _Imported | None] = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names[node.name] = shape_of(node)
        elif isinstance(node, ast.ImportFrom):
            names.update((alias.asname or alias.name, _Imported(node.module or "", node.level, alias.name))
                         for alias in node.names if alias.name != "*")
        elif isinstance(node, ast.Import):
            names.update(((alias.asname or alias.name).split(".")[0], None) for alias in node.names)
        elif isinstance(node, ast.Assign):
            names.update((t.id, assigned_shape(node.value, node.lineno)) for t in node.targets
                         if isinstance(t, ast.Name))
    return names


def _source_of(imported: _Imported, path: Path) -> Path | None:
    """The file an import reads from: relative to the importing module's package, or looked up
    from its folder as the spec's modules are (`find_module`); None outside the robot's folders
    (the standard library, an installed package: not checked)."""
    if imported.level:
        package = path.parent
        for _ in range(imported.level - 1):
            package = package.parent
        parts = [p for p in imported.module.split(".") if p]
        if not all(part.isidentifier() for part in parts):
            return None
        base = package.joinpath(*parts) if parts else package
        for candidate in (base.with_suffix(".py") if parts else base / "__init__.py", base / "__init__.py"):
            if candidate.is_file():
                return candidate
        return None
    return find_module(imported.module, path.parent) if imported.module else None


def top_level_functions(path: Path) -> Mapping[str, FunctionShape | None] | SyntaxError | OSError:
    """The names a module defines at top level, each with its shape when it is a plain function
    (None for an assignment, a decorated function or an import from outside the robot's
    folders), or why it cannot be read. A name a `from ... import` re-exports from a module of
    the robot (`from .drive import stop`, `from tug_codels.drive import stop`) has the shape of
    the function it names there."""
    found = _top_level(path)
    if isinstance(found, (SyntaxError, OSError)):
        return found
    return {name: _follow(entry, path, 0) for name, entry in found.items()}


IMPORT_DEPTH = 8  # re-exports followed before giving up (an import circle ends there)


def _follow(entry: FunctionShape | _Imported | None, path: Path, depth: int) -> FunctionShape | None:
    if not isinstance(entry, _Imported) or depth >= IMPORT_DEPTH:
        return entry if isinstance(entry, FunctionShape) else None
    source = _source_of(entry, path)
    if source is None:
        return None
    names = _top_level(source)
    if isinstance(names, (SyntaxError, OSError)):
        return None
    found = _follow(names.get(entry.name), source, depth + 1)
    if found is None or found.defined_in:
        return found
    return dataclasses.replace(found, defined_in=f"{source.parent.name}/{source.name}")
