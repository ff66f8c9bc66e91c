"""Addressing and rewriting one node of a frozen model tree.

Nodes compare by meaning (spans aside), so two `t_start` of one task are equal and cannot be
told apart by value: a mutation names its node by its path from the root instead, and the tree
is rebuilt along that path with `dataclasses.replace` (the rest is shared, untouched).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from typing import Any, TypeVar

from specc.model import nodes as m
from specc.model.visitor import child_steps

# One step down: the field's name and, when the field holds a tuple, the element's index.
Step = tuple[str, int | None]
Path = tuple[Step, ...]
N = TypeVar("N", bound=m.Node)


def nodes_with_paths(node: m.Node, path: Path = ()) -> Iterator[tuple[Path, m.Node]]:
    """`node` and every node below it with their paths, depth first, in field (= source) order."""
    yield path, node
    for name, index, child in child_steps(node):
        yield from nodes_with_paths(child, path + ((name, index),))


def node_at(root: m.Node, path: Path) -> m.Node:
    """The node at `path` below `root`."""
    node: Any = root
    for name, index in path:
        node = getattr(node, name) if index is None else getattr(node, name)[index]
    assert isinstance(node, m.Node)
    return node


def replace_at(root: N, path: Path, new: m.Node | None) -> N:
    """`root` with the node at `path` replaced by `new`; None removes it from its tuple."""
    if not path:
        raise ValueError("cannot replace the root itself")
    (name, index), rest = path[0], path[1:]
    value = getattr(root, name)
    changed: Any
    if index is None:
        if rest:
            changed = replace_at(value, rest, new)
        elif new is None:
            raise ValueError(f"'{name}' holds one node, not a list: it cannot be removed")
        else:
            changed = new
    else:
        elements = list(value)
        if rest:
            elements[index] = replace_at(elements[index], rest, new)
        elif new is None:
            del elements[index]
        else:
            elements[index] = new
        changed = tuple(elements)
    updates: dict[str, Any] = {name: changed}
    return replace(root, **updates)
