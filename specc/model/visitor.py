"""Walking the model: `visit_<NodeClass>` methods with a `generic_visit` fallback."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import fields
from typing import Any

from specc.model.nodes import Node

_CHILD_FIELDS: dict[type, tuple[str, ...]] = {}


def _child_fields(node_class: type) -> tuple[str, ...]:
    """The fields of a node class that may hold child nodes: all but its span. Computed once per
    class, as every check walks every node."""
    found = _CHILD_FIELDS.get(node_class)
    if found is None:
        found = _CHILD_FIELDS[node_class] = tuple(f.name for f in fields(node_class) if f.name != "span")
    return found


def child_steps(node: Node) -> Iterator[tuple[str, int | None, Node]]:
    """The direct child nodes of `node`, in field order, with where each sits: the field's name
    and, in a field holding a tuple, its index there (None otherwise)."""
    for name in _child_fields(type(node)):
        value = getattr(node, name)
        if isinstance(value, Node):
            yield name, None, value
        elif isinstance(value, tuple):
            for index, element in enumerate(value):
                if isinstance(element, Node):
                    yield name, index, element


def children(node: Node) -> list[Node]:
    """The direct child nodes of `node`, in field order. A list built in one loop, not through
    `child_steps`: every check walks every node, and the walk is most of a check's time."""
    found: list[Node] = []
    for name in _child_fields(type(node)):
        value = getattr(node, name)
        if isinstance(value, Node):
            found.append(value)
        elif isinstance(value, tuple):
            found.extend(element for element in value if isinstance(element, Node))
    return found


def walk(node: Node) -> Iterator[Node]:
    """`node` and all its descendants, depth first, in source order."""
    stack = [node]
    while stack:
        current = stack.pop()
        yield current
        stack.extend(reversed(children(current)))


class Visitor:
    """Dispatches on the node's class name; unhandled nodes visit their children."""

    def visit(self, node: Node) -> Any:
        method = getattr(self, "visit_" + type(node).__name__, None)
        if method is None:
            return self.generic_visit(node)
        return method(node)

    def generic_visit(self, node: Node) -> None:
        for child in children(node):
            self.visit(child)
