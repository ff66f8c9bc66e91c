"""Deterministic Python source for the runtime records a back end writes into a module (the KA
library of a supervisor, the tasks of a planning domain): `Record(field=value, ...)` with the
fields left at their default omitted, laid out one item per line when it does not fit."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from specc.backends.env import Code

WIDTH = 110


def literal(value: Any, positional: tuple[type, ...] = (), indent: int = 0, prefix: int = 0) -> Code:
    """Source for `value` on a line indented by `indent` whose first `prefix` characters are
    taken; records of a `positional` type are written without field names. Every value inside
    is written by `repr`, so the source holds no text of the spec's that is not a literal."""
    return Code(_literal(value, positional, indent, prefix))


def _literal(value: Any, positional: tuple[type, ...], indent: int, prefix: int) -> str:
    flat = _flat(value, positional)
    if indent + prefix + len(flat) <= WIDTH:
        return flat
    pad = " " * (indent + 4)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        items = [f"{name}={_literal(v, positional, indent + 4, len(name) + 1)}" for name, v in _fields(value)]
        return f"{type(value).__name__}(\n" + "".join(f"{pad}{item},\n" for item in items) + " " * indent + ")"
    if isinstance(value, tuple) and value and all(_scalar(v) for v in value):
        # A long run of plain values (a domain's 30 symbols) fills its lines rather than taking one each.
        lines = [""]
        for item in (f"{_flat(v, positional)}," for v in value):
            if lines[-1] and len(pad) + len(lines[-1]) + 1 + len(item) > WIDTH:
                lines.append(item)
            else:
                lines[-1] = f"{lines[-1]} {item}" if lines[-1] else item
        return "(\n" + "".join(f"{pad}{line}\n" for line in lines) + " " * indent + ")"
    if isinstance(value, tuple) and value:
        return "(\n" + "".join(f"{pad}{_literal(v, positional, indent + 4, 0)},\n" for v in value) + " " * indent + ")"
    return flat


def _scalar(value: Any) -> bool:
    return value is None or isinstance(value, (str, int, float, bool))


def _fields(record: Any) -> list[tuple[str, Any]]:
    shown = []
    for f in dataclasses.fields(record):
        value = getattr(record, f.name)
        factory = f.default_factory
        default = f.default if factory is dataclasses.MISSING else factory()
        if default is not dataclasses.MISSING and value == default:
            continue
        shown.append((f.name, value))
    return shown


def _flat(value: Any, positional: tuple[type, ...]) -> str:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = _fields(value)
        if isinstance(value, positional):
            return f"{type(value).__name__}({', '.join(_flat(v, positional) for _, v in fields)})"
        return f"{type(value).__name__}({', '.join(f'{n}={_flat(v, positional)}' for n, v in fields)})"
    if isinstance(value, tuple):
        inner = ", ".join(_flat(v, positional) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, float) and math.isinf(value):
        return "INF" if value > 0 else "-INF"  # the module imports INF: repr() would write `inf`
    return repr(value)
