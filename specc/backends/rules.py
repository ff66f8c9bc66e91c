"""Back end `rules`: each Kheops rule base becomes a plain Python decision function.

The compiled decision DAG is unrolled into nested tests; a node reached by several paths
becomes a function of its own, so the code stays as small as the DAG. No inference engine
runs at run time: a decision costs at most DEPTH tests.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Any

from specc.analysis import kheops as k
from specc.backends.env import Code, render
from specc.backends.manifest import Output, header
from specc.model import nodes as m
from specc.pysource import python_name

BACKEND = "rules"
INDENT = "    "


@dataclass
class DecisionView:
    compiled: k.Compiled
    source: str

    def __post_init__(self) -> None:
        self.base = self.compiled.base
        counts: Counter[int] = Counter()
        self.nodes: dict[int, k.Node] = {}

        def count(node: k.Node) -> None:
            counts[id(node)] += 1
            if counts[id(node)] > 1:
                return
            self.nodes[id(node)] = node
            for child in children(node):
                count(child)

        count(self.compiled.root)
        # A leaf is a constant: every path returns it directly, only inner nodes become functions.
        self.shared = {key for key, n in counts.items() if n > 1 and not isinstance(self.nodes[key], k.Leaf)}
        self.numbers = {key: i for i, key in enumerate(sorted(self.shared, key=list(self.nodes).index))}
        self.leaves: dict[k.Leaf, str] = {}
        for node in self.nodes.values():
            if isinstance(node, k.Leaf) and node not in self.leaves:
                self.leaves[node] = f"_LEAF_{len(self.leaves)}"

    @property
    def header(self) -> str:
        return header(self.source)

    @property
    def name(self) -> str:
        return self.base.name

    @property
    def inputs(self) -> list[str]:
        return self.base.inputs

    @property
    def outputs(self) -> list[str]:
        return self.base.outputs

    @property
    def part_depths(self) -> dict[Any, int]:
        return self.compiled.part_depths()

    @property
    def kept(self) -> dict[Any, tuple[str, ...]]:
        """For each part of a base compiled in parts, the outputs it keeps as they were (it decides
        the others), in the base's order of outputs."""
        return {value: tuple(o for o in self.outputs if o in kept) for value, kept in self.compiled.kept.items()}

    @property
    def copies_inputs(self) -> bool:
        return any(isinstance(n, k.Do) and any(isinstance(a, k.Assign) for a in n.actions)
                   for n in self.nodes.values())

    @property
    def leaf_constants(self) -> list[Code]:
        lines = []
        for leaf, name in self.leaves.items():
            # Every output of the base (or of its part) the leaf was compiled from; a decision
            # compiled in parts copies in the outputs its part keeps as they were.
            shown = ", ".join(f"{o!r}: {literal(v)}" for o, v in leaf.outputs)
            lines.append(Code(f"{name} = Decision(MappingProxyType({{{shown}}}), {leaf.inconsistent!r}, "
                              f"{leaf.incomplete!r}, {leaf.impossible!r})"))
        return lines

    @property
    def root_body(self) -> list[Code]:
        """The decision function's lines: Python the compiler wrote from the rules' names and
        their values written as literals (`repr`)."""
        return [Code(line) for line in self.body(self.compiled.root, 2, root=True)]  # under `try:`

    @property
    def initial(self) -> dict[str, Any]:
        """The previous-cycle values (`@x`) the base's `init` gives: what `decide` reads when the
        caller gives none (the first cycle)."""
        return {name: a.init for name, a in self.base.attributes.items() if a.role == "previous" and a.init is not None}

    def read(self, attribute: str) -> str:
        """The Python reading `attribute` in the inputs: with its `init` when the caller may leave it out."""
        if attribute in self.initial:
            return f"a.get({attribute!r}, {literal(self.initial[attribute])})"
        return f"a[{attribute!r}]"

    @property
    def numeric_inputs(self) -> list[str]:
        return [name for name in self.base.inputs if self.base.attributes[name].kind == "number"]

    @property
    def shared_functions(self) -> list[tuple[Code, list[Code]]]:
        return [(Code(f"_node_{self.numbers[key]}"), [Code(line) for line in self.body(self.nodes[key], 1, root=True)])
                for key in sorted(self.shared, key=self.numbers.__getitem__)]

    @property
    def findings(self) -> list[str]:
        return [k.describe(f) for f in self.compiled.findings]

    def body(self, node: k.Node, depth: int, root: bool = False) -> list[str]:
        pad = INDENT * depth
        if not root and id(node) in self.shared:
            return [f"{pad}return _node_{self.numbers[id(node)]}(a, calls)"]
        if isinstance(node, k.Leaf):
            return [f"{pad}return {self.leaves[node]}"]
        if isinstance(node, k.Do):
            lines = []
            for action in node.actions:
                if isinstance(action, k.Assign):
                    lines.append(f"{pad}a[{action.target!r}] = {action.expr.python(self.read)}")
                else:
                    args = ", ".join(arg.python(self.read) for arg in action.args)
                    lines.append(f"{pad}calls({action.function!r}, ({args}{',' if len(action.args) == 1 else ''}))")
            return lines + self.body(node.next, depth)
        assert isinstance(node, k.Test)
        attribute = self.base.attributes[node.attribute]
        lines = [f"{pad}v = {self.read(node.attribute)}"]
        # Values leading to the same subgraph share one test: `if v in ('A', 'B'):`.
        grouped: dict[int, tuple[k.Node, list[Any]]] = {}
        for value, child in node.branches:
            grouped.setdefault(id(child), (child, []))[1].append(value)
        keyword = "if"
        otherwise: list[str] | None = None
        for child, values in grouped.values():
            if k.OTHER in values:  # the values nobody mentions: whatever the other tests leave
                otherwise = self.body(child, depth + 1)
                continue
            lines.append(f"{pad}{keyword} {conditions(attribute, values)}:")
            lines += self.body(child, depth + 1)
            keyword = "elif"
        lines.append(f"{pad}else:")
        if otherwise is not None:
            lines += otherwise
        else:
            # The domain as a literal of its own (repr), outside the f-string: its values are the spec's text.
            lines.append(f"{pad}{INDENT}raise ValueError(f\"{node.attribute}={{v!r}} is outside its domain, \" + "
                         f"{domain_text(attribute)!r})")
        return lines


def domain_text(attribute: k.Attribute) -> str:
    """An input's declared domain as its error says it: `[0, 100]`, or `one of 'on', 'off'`."""
    values = attribute.values
    pieces = [v for v in values if isinstance(v, k.Piece)]
    if pieces and len(pieces) == len(values):
        first, last = min(pieces, key=lambda p: p.low), max(pieces, key=lambda p: p.high)
        return str(k.Piece(first.low, last.high, first.low_closed, last.high_closed))
    return "one of " + ", ".join(repr(v) for v in values)


def children(node: k.Node) -> list[k.Node]:
    if isinstance(node, k.Test):
        return [child for _, child in node.branches]
    if isinstance(node, k.Do):
        return [node.next]
    return []


def literal(value: Any) -> str:
    if isinstance(value, k.Piece):
        return repr(str(value))
    return repr(value)


def conditions(attribute: k.Attribute, values: list[Any]) -> str:
    if len(values) == 1:
        return condition(attribute, values[0])
    if attribute.kind == "symbol":
        return f"v in {tuple(values)!r}"
    return " or ".join(f"({condition(attribute, v)})" for v in values)


def condition(attribute: k.Attribute, value: Any) -> str:
    if isinstance(value, k.Piece):
        if value.low == value.high:
            return f"v == {value.low!r}"
        parts = []
        if not math.isinf(value.low):
            parts.append(f"{value.low!r} {'<=' if value.low_closed else '<'} v")
        if not math.isinf(value.high):
            parts.append(f"v {'<=' if value.high_closed else '<'} {value.high!r}")
        return " and ".join(parts) or "True"
    if attribute.kind == "bool":  # as the interpreter's membership test: "no" or None is no bool
        return "v in (True,)" if value else "v in (False,)"
    return f"v == {value!r}"


def generate(program: m.Program, output: Output, robot: str = "") -> list[k.Compiled]:
    compiled_all = []
    bases = sorted((i for i in program.items if isinstance(i, m.RuleBase)), key=lambda b: b.name)
    # What a stand-alone base leaves unsettled, `specc check` says (specc.pipeline); an executive's
    # own bases only decide where they apply: the generated controller completes them.
    for base in bases:
        compiled = k.compile_base(k.normalise(base))
        compiled_all.append(compiled)
        view = DecisionView(compiled, base.span.file)
        output.add(BACKEND, f"rules/{python_name(base.name)}.py", render("rules/decision.py.j2", view=view))
    if bases:
        output.add(BACKEND, "rules/__init__.py", render(
            "rules/__init__.py.j2", names=[python_name(b.name) for b in bases],
            header=header("the rule bases")))
    return compiled_all
