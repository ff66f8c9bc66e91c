"""A program whose spans name its files otherwise, every node else the same.

`specc compile` records where each generated thing comes from (a header, a planning problem's
source, a procedure's file), by its spans. The spans name files as the command line showed them,
relative to where it ran; the package names them relative to the robot's folder, so that what
it writes does not depend on the folder a compilation ran from."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, TypeVar

from specc.model import nodes as m
from specc.model.span import Span

T = TypeVar("T")


def with_files_renamed(program: m.Program, names: Mapping[str, str]) -> m.Program:
    """`program` with each span's and source file's name found in `names` replaced by its value.
    Nodes that hold no renamed span are kept as they are (shared, not copied)."""
    done: dict[int, Any] = {}

    def renamed(value: T) -> T:
        if isinstance(value, Span):
            new = names.get(value.file)
            return value if new is None else dataclasses.replace(value, file=new)  # type: ignore[return-value]
        if isinstance(value, tuple):
            items = tuple(renamed(item) for item in value)
            return items if any(a is not b for a, b in zip(items, value, strict=True)) else value  # type: ignore[return-value]
        if not dataclasses.is_dataclass(value) or isinstance(value, type):
            return value
        known = done.get(id(value))
        if known is not None:
            return known  # type: ignore[no-any-return]
        changes = {f.name: new for f in dataclasses.fields(value) if f.init
                   and (new := renamed(old := getattr(value, f.name))) is not old}
        if isinstance(value, m.SourceFile) and value.path in names:
            changes["path"] = names[value.path]
        result = dataclasses.replace(value, **changes) if changes else value  # type: ignore[type-var]
        done[id(value)] = result
        return result

    return renamed(program)
