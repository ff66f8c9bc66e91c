"""The five mutation classes of seed 004 §4.1.3, as edits of the model of one `domain` block.

Each edit names one node by its path from the file's root and what takes its place (or nothing:
a deletion). Only the domain block's own members are mutated (its tasks, and any macro or
attribute written in it); the fragments it includes are read for their values, constants and
attribute domains but stay as they are, since the problems include them too.

1. numeric: each numeric literal (a number, `oo`, or one of them with its sign) replaced by every
   other value of the pool: the values written in the domain and its fragments, the special
   values 0, 1 and -1, and a few values drawn from a seeded generator (the same for every site).
2. variable: in each task, a `?variable` replaced by every other variable of the same kind
   (numeric, or symbolic: constrained `in` a set of symbols) and a timepoint by every other
   timepoint of the task. The seed's table mixes ?obj with ?x and ?y; a symbol standing in for a
   number only makes a mutant the planner rejects outright, so kinds are kept apart.
3. value: a symbolic value of an attribute (or of a symbolic attribute argument) replaced by every
   other value of the attribute's declared domain.
4. operator: a comparison by every other (`=.` and `==` are one), an arithmetic operator by the
   three others of its notation (dotted or not), `min` and `max` swapped, a sign flipped on a
   non-literal operand (signed literals are the numeric class's), `contingent` dropped, a task's
   preemption among latePreemptive / nonPreemptive / none (the seed's table), and an interval's
   bounds swapped, or opened to -oo or +oo.
5. deletion: each constraint of a task or macro removed (an `in` domain, a relation, an
   implication, a macro call such as `distance(...)`); assertions and events are not constraints.
"""

from __future__ import annotations

import random
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from pathlib import PurePath
from typing import Any, Literal

from specc.analysis.planning import VALUE_VAR, members
from specc.model import nodes as m
from specc.model.span import Span
from specc.model.visitor import walk
from specc.mutation.tree import Path, nodes_with_paths
from specc.syntax.printer import ixexpr, tstmt

MutationClass = Literal["numeric", "variable", "value", "operator", "deletion"]
CLASSES: tuple[MutationClass, ...] = ("numeric", "variable", "value", "operator", "deletion")

SPECIAL_VALUES: tuple[float, ...] = (0, 1, -1)
RANDOM_RANGE = (-100.0, 100.0)  # the seed's drawn values (-4, 26.3) are of this order

COMPARISONS = ("=.", "!=", "<", "<=", ">", ">=")
EQUALITIES = ("=.", "==")  # one relation: both lower to `=`
ARITHMETIC = (("+.", "-.", "*.", "/."), ("+", "-", "*", "/"))
SWAPPED_FUNCTIONS = {"min": "max", "max": "min"}
PREEMPTIONS: tuple[str | None, ...] = ("latePreemptive", "nonPreemptive", None)
CONSTRAINTS = (m.InConstraint, m.RelConstraint, m.Implication, m.MacroCall)


@dataclass(frozen=True)
class Edit:
    """One mutation: the node at `path` (from the file's root) becomes `new`, or goes if None."""

    kind: MutationClass
    path: Path
    new: m.Node | None
    span: Span  # where the mutated node is written
    scope: str  # the task (macro, attribute) it belongs to
    what: str  # e.g. "numeric 2 -> 10"

    def describe(self) -> str:
        """`model1.spec:34:12: numeric 2 -> 10 in MOVE`: the file's name only, so a description
        does not depend on the folder the robot was loaded from."""
        return f"{PurePath(self.span.file).name}:{self.span.line}:{self.span.column}: {self.what} in {self.scope}"


@dataclass(frozen=True)
class Scope:
    """A member of the domain block that mutations stay inside of."""

    node: m.Task | m.Macro | m.Attribute | m.Resource
    path: Path

    @property
    def name(self) -> str:
        return self.node.name


class DomainTables:
    """What the mutations read: the domain's constant sets and attributes, includes expanded."""

    def __init__(self, program: m.Program, domain: m.Domain):
        expanded = list(members(program, domain.members))
        self.constants = {c.name: c for c in expanded if isinstance(c, m.Constant)}
        self.attributes = {a.name: a for a in expanded if isinstance(a, (m.Attribute, m.Resource))}
        self.expanded = expanded

    def symbols(self, union: m.SetUnion, seen: tuple[str, ...] = ()) -> tuple[str, ...]:
        """The set's symbols in the order written (constants spelled out); () when unknown."""
        found: list[str] = []
        for part in union.parts:
            if isinstance(part, m.SetLiteral):
                found.extend(part.values)
            elif part.name in self.constants and part.name not in seen:
                found.extend(self.symbols(self.constants[part.name].value, seen + (part.name,)))
        return tuple(dict.fromkeys(found))

    def symbolic_domain(self, body: Iterable[Any], variable: str) -> tuple[str, ...]:
        """The symbols `variable` is constrained to (`?v in SET;` in `body`), or ()."""
        for statement in body:
            if (isinstance(statement, m.InConstraint) and isinstance(statement.expr, m.IxVar)
                    and statement.expr.name == variable and isinstance(statement.domain, m.SetUnion)):
                return self.symbols(statement.domain)
        return ()

    def value_domain(self, attribute: str) -> tuple[str, ...]:
        declared = self.attributes.get(attribute)
        return () if declared is None else self.symbolic_domain(declared.body, VALUE_VAR)

    def argument_domain(self, attribute: str, index: int) -> tuple[str, ...]:
        declared = self.attributes.get(attribute)
        if declared is None or index >= len(declared.params):
            return ()
        return self.symbolic_domain(declared.body, declared.params[index].name)


def domain_edits(program: m.Program, file_index: int, item_index: int, *, random_values: int = 3,
                 seed: int = 0) -> list[Edit]:
    """Every edit of the domain block `program.files[file_index].items[item_index]`, class by
    class (CLASSES' order), then in source order: a deterministic list."""
    domain = program.files[file_index].items[item_index]
    assert isinstance(domain, m.Domain)
    tables = DomainTables(program, domain)
    scopes = [Scope(member, (("items", item_index), ("members", k))) for k, member in enumerate(domain.members)
              if isinstance(member, (m.Task, m.Macro, m.Attribute, m.Resource))]
    pool = value_pool(tables.expanded, random_values, seed)
    edits: list[Edit] = []
    for scope in scopes:
        edits.extend(numeric_edits(scope, pool))
    for scope in scopes:
        edits.extend(variable_edits(scope, tables))
    for scope in scopes:
        edits.extend(value_edits(scope, tables))
    for scope in scopes:
        edits.extend(operator_edits(scope))
    for scope in scopes:
        edits.extend(deletion_edits(scope))
    return edits


def _inside(scope: Scope) -> Iterator[tuple[Path, m.Node]]:
    """The nodes below the scope's member, with their paths from the file's root."""
    for path, node in nodes_with_paths(scope.node):
        if path:
            yield scope.path + path, node


# ---------------------------------------------------------------- 1. numeric values


def literal_value(node: m.Node) -> float | None:
    """The value of a numeric literal: a number, `oo`, or either with its sign."""
    if isinstance(node, m.Number):
        return node.value
    if isinstance(node, m.Infinity):
        return float("inf")
    if isinstance(node, m.IxUnary) and isinstance(node.operand, (m.Number, m.Infinity)):
        inner = literal_value(node.operand)
        assert inner is not None
        return -inner if node.op == "-" else inner
    return None


def literal(value: float, span: Span) -> m.IxExpr:
    """The literal of `value` as the grammar writes it: numbers carry no sign, so -1 is `-1`
    (a sign and 1), and infinities are written `+oo` and `-oo` as in the seed's models."""
    if value in (float("inf"), float("-inf")):
        return m.IxUnary(op="+" if value > 0 else "-", operand=m.Infinity(span=span), span=span)
    if value < 0:
        return m.IxUnary(op="-", operand=m.Number(value=-value, span=span), span=span)
    return m.Number(value=value, span=span)


def value_pool(expanded: Iterable[Any], random_values: int, seed: int) -> tuple[float, ...]:
    """The replacement values, ascending: each written in the domain or its fragments (a signed
    literal gives both its values: `-oo` brings -oo and +oo), 0, 1, -1, and `random_values` values
    drawn with `seed` (one decimal). The first spelling of a value is kept (10.0 stays 10.0)."""
    written: dict[float, float] = {}
    for member in expanded:
        for node in walk(member):
            value = literal_value(node)
            if value is not None:
                written.setdefault(value, value)
    drawn = random.Random(seed)
    extra = list(SPECIAL_VALUES) + [round(drawn.uniform(*RANDOM_RANGE), 1) for _ in range(random_values)]
    for value in extra:
        written.setdefault(value, value)
    return tuple(sorted(written.values()))


def numeric_edits(scope: Scope, pool: tuple[float, ...]) -> Iterator[Edit]:
    signed: set[Path] = set()
    for path, node in _inside(scope):
        if path[:-1] in signed:
            continue  # the operand of a signed literal: the literal is the site
        value = literal_value(node)
        if value is None:
            continue
        if isinstance(node, m.IxUnary):
            signed.add(path)
        shown = ixexpr(literal(value, node.span))  # as written, up to the spelling of -oo and +oo
        for candidate in pool:
            if candidate == value:
                continue
            new = literal(candidate, node.span)
            yield Edit("numeric", path, new, node.span, scope.name, f"numeric {shown} -> {ixexpr(new)}")


# ---------------------------------------------------------------- 2. variables


def task_variables(task: m.Task, tables: DomainTables) -> dict[str, list[str]]:
    """The task's variables by kind, in declaration order: numeric, symbolic, and timepoints."""
    declared = [p.name for p in task.params] + [v.name for s in task.body if isinstance(s, m.VariableDecl)
                                                 for v in s.names]
    kinds: dict[str, list[str]] = {"numeric": [], "symbolic": [], "timepoint": []}
    for name in dict.fromkeys(declared):
        kinds["symbolic" if tables.symbolic_domain(task.body, name) else "numeric"].append(name)
    timepoints = [task.start, task.end] + [n for s in task.body if isinstance(s, m.TimepointDecl) for n in s.names]
    kinds["timepoint"] = list(dict.fromkeys(timepoints))
    return kinds


def variable_edits(scope: Scope, tables: DomainTables) -> Iterator[Edit]:
    task = scope.node
    if not isinstance(task, m.Task):
        return  # a macro's parameters stand for whatever its call passes: no kind to keep
    kinds = task_variables(task, tables)
    kind_of = {name: kind for kind, names in kinds.items() for name in names}
    for index, statement in enumerate(task.body):
        if isinstance(statement, m.VariableDecl):
            continue  # a declaration is not a use
        for inner, node in nodes_with_paths(statement):
            if isinstance(node, m.IxVar) and kind_of.get(node.name) in ("numeric", "symbolic"):
                word = "variable"
            elif isinstance(node, m.IxName) and kind_of.get(node.name) == "timepoint":
                word = "timepoint"
            else:
                continue
            path = scope.path + (("body", index),) + inner
            for other in kinds[kind_of[node.name]]:
                if other != node.name:
                    yield Edit("variable", path, replace(node, name=other), node.span, scope.name,
                               f"{word} {node.name} -> {other}")


# ---------------------------------------------------------------- 3. symbolic attribute values


def value_edits(scope: Scope, tables: DomainTables) -> Iterator[Edit]:
    for path, node in _inside(scope):
        if not isinstance(node, m.AttrValue):
            continue
        sites: list[tuple[Path, m.Node, tuple[str, ...], str]] = []  # path, node, domain, whose value
        for index, arg in enumerate(node.args):
            sites.append((path + (("args", index),), arg, tables.argument_domain(node.attribute, index),
                          f"of {node.attribute} (argument {index + 1})"))
        allowed = tables.value_domain(node.attribute)
        if isinstance(node.value, m.Transition):
            sites.append((path + (("value", None), ("before", None)), node.value.before, allowed,
                          f"of {node.attribute} (before)"))
            sites.append((path + (("value", None), ("after", None)), node.value.after, allowed,
                          f"of {node.attribute} (after)"))
        else:
            sites.append((path + (("value", None),), node.value, allowed, f"of {node.attribute}"))
        for site, value, domain, role in sites:
            if not isinstance(value, m.IxName) or value.name not in domain:
                continue
            for other in domain:
                if other != value.name:
                    yield Edit("value", site, replace(value, name=other), value.span, scope.name,
                               f"value {value.name} -> {other} {role}")


# ---------------------------------------------------------------- 4. operators


def operator_edits(scope: Scope) -> Iterator[Edit]:
    if isinstance(scope.node, m.Task):
        # The preemption is written after the task's closing brace; the task's span starts it.
        for other in PREEMPTIONS:
            if other != scope.node.preemption:
                new_task = replace(scope.node, preemption=other)
                yield Edit("operator", scope.path, new_task, scope.node.span, scope.name,
                           f"preemption {scope.node.preemption or 'none'} -> {other or 'none'}")
    for path, node in _inside(scope):
        yield from _node_operator_edits(scope, path, node)


def _node_operator_edits(scope: Scope, path: Path, node: m.Node) -> Iterator[Edit]:
    def edit(new: m.Node, what: str) -> Edit:
        return Edit("operator", path, new, node.span, scope.name, what)

    if isinstance(node, (m.InConstraint, m.RelConstraint)) and node.contingent:
        yield edit(replace(node, contingent=False), "contingent dropped")
    if isinstance(node, m.Event) and node.kind == "contingent":
        yield edit(replace(node, kind=None), "contingent dropped")
    if isinstance(node, m.RelConstraint):
        current = "=." if node.op in EQUALITIES else node.op
        for other in COMPARISONS:
            if other != current:
                spelled = "==" if other == "=." and node.op == "!=" else other
                yield edit(replace(node, op=spelled), f"comparison {node.op} -> {spelled}")
    elif isinstance(node, m.IxBinary):
        family = next((ops for ops in ARITHMETIC if node.op in ops), ())
        for other in family:
            if other != node.op:
                yield edit(replace(node, op=other), f"operator {node.op} -> {other}")
    elif isinstance(node, m.IxUnary) and literal_value(node) is None:
        flipped = "+" if node.op == "-" else "-"
        yield edit(replace(node, op=flipped), f"sign {node.op} -> {flipped}")
    elif isinstance(node, m.IxCall) and node.function in SWAPPED_FUNCTIONS:
        other = SWAPPED_FUNCTIONS[node.function]
        yield edit(replace(node, function=other), f"function {node.function} -> {other}")
    elif isinstance(node, m.Interval):
        shown = f"[{ixexpr(node.low)}, {ixexpr(node.high)}]"
        if node.low != node.high:
            yield edit(replace(node, low=node.high, high=node.low), f"interval {shown} bounds swapped")
        if literal_value(node.low) != float("-inf"):
            yield edit(replace(node, low=literal(float("-inf"), node.low.span)), f"interval {shown} opened below")
        if literal_value(node.high) != float("inf"):
            yield edit(replace(node, high=literal(float("inf"), node.high.span)), f"interval {shown} opened above")


# ---------------------------------------------------------------- 5. deletions


def deletion_edits(scope: Scope) -> Iterator[Edit]:
    if not isinstance(scope.node, (m.Task, m.Macro)):
        return
    for index, statement in enumerate(scope.node.body):
        if isinstance(statement, CONSTRAINTS):
            yield Edit("deletion", scope.path + (("body", index),), None, statement.span, scope.name,
                       f"deleted `{tstmt(statement)}`")
