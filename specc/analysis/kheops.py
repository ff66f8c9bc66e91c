"""Kheops rule bases (seed 000 §3.7, annex A): normalisation, a reference interpreter, and the
compiler into a decision DAG whose depth bounds the reaction time.

Semantics (annex A.1): every attribute has a finite set of possible values — symbols, booleans,
or, for numeric attributes, the intervals cut by the constants they are compared with. Inputs
are known; an attribute nobody determined yet may still take every value of its domain. A
condition is TRUE when it holds for every value still possible, FALSE when for none, and
UNDETERMINED otherwise; a rule fires only when its condition is TRUE. Firing restricts
attributes (set intersection, so reasoning is monotone and the firing order does not matter)
and runs `do` actions (an assignment makes an intermediate attribute known from then on).
When nothing more fires: `else` rules fire if an output is still undetermined; an output left
with several values is *incomplete*, an attribute left with none is *inconsistent*; an
`impossible` rule whose condition is TRUE marks the input combination as one that never occurs.

Symbolic attributes without a declared domain take the constants they are compared with plus
OTHER (any value the rules do not mention), so an undeclared intermediate such as Fig. 3.8's
`diagn` stays undetermined until a rule restricts it.
"""

from __future__ import annotations

import itertools
import math
import os
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Union

from specc.diagnostics import Diagnostic, error
from specc.model import nodes as m

OTHER = "*other*"  # the values of an undeclared symbolic domain that no rule mentions
NUMERIC_OPS = ("<", "<=", ">", ">=", "==", "!=")


class KheopsError(Exception):
    """A rule base outside the propositional subset (carries the offending node's span)."""

    code = "not-propositional"

    def __init__(self, message: str, node: m.Node):
        super().__init__(message)
        self.node = node

    def diagnostic(self) -> Diagnostic:
        return error(self.code, str(self), self.node.span)

    def headline(self) -> str:
        """`file:line:col: error: message [code]`, as the command line prints it."""
        return self.diagnostic().headline()


class TooLarge(KheopsError):
    """A rule base whose decision graph would take more work than its limit to build."""

    code = "rules-too-large"

    def __init__(self, message: str, node: m.Node, limit: int, part: Any = None):
        super().__init__(message, node)
        self.limit = limit
        self.part = part  # the value of the input split on whose decision went past the limit (`compile_parts`)


# Decision-tree nodes a compilation may visit (a resource controller of 21 services and 6 groups,
# one decision per service: about 300; 8 numeric inputs x 50 threshold rules: 575,000, ~30 s and
# 400 MB): past it, a diagnostic with the figures and how to split the base, never a run of many
# minutes and gigabytes (seed 000 §3.7 compiles every path of the base into the decision graph).
# The environment variable raises it for a base that is worth the wait.
WORK_LIMIT = 1_000_000
WORK_LIMIT_VARIABLE = "SPECC_RULES_WORK_LIMIT"


# ---------------------------------------------------------------- normalised rules


@dataclass(frozen=True)
class Atom:
    """`attribute op value` or `attribute [not] in values`; booleans test `== True`."""

    attribute: str
    op: str  # one of NUMERIC_OPS, "in", "notin"
    value: Any  # a constant, or a frozenset for in/notin

    def holds(self, actual: Any) -> bool:
        if self.op == "in":
            return actual in self.value
        if self.op == "notin":
            return actual not in self.value
        return compare(actual, self.op, self.value)


@dataclass(frozen=True)
class Not:
    """A condition that holds when its operand does not."""

    operand: Cond


@dataclass(frozen=True)
class All:
    """Conditions that must all hold."""

    operands: tuple[Cond, ...]


@dataclass(frozen=True)
class Any_:
    """Conditions of which one must hold."""

    operands: tuple[Cond, ...]


Cond = Union[Atom, Not, All, Any_]


@dataclass(frozen=True)
class Expr:
    """An arithmetic expression over attributes, evaluated on actual values at run time."""

    op: str  # const | attr | + - * / | neg
    args: tuple[Any, ...]

    def attributes(self) -> set[str]:
        if self.op == "attr":
            return {self.args[0]}
        if self.op == "const":
            return set()
        return set().union(*(a.attributes() for a in self.args))

    def evaluate(self, values: Mapping[str, Any]) -> Any:
        if self.op == "const":
            return self.args[0]
        if self.op == "attr":
            return values[self.args[0]]
        if self.op == "neg":
            return -self.args[0].evaluate(values)
        left, right = (a.evaluate(values) for a in self.args)
        if self.op == "+":
            return left + right
        if self.op == "-":
            return left - right
        if self.op == "*":
            return left * right
        return left / right if right else math.copysign(math.inf, left) if left else 0.0

    def python(self, name: Any) -> str:
        if self.op == "const":
            return repr(self.args[0])
        if self.op == "attr":
            return str(name(self.args[0]))
        if self.op == "neg":
            return f"(-{self.args[0].python(name)})"
        left, right = (a.python(name) for a in self.args)
        if self.op == "/":
            return f"_divide({left}, {right})"
        return f"({left} {self.op} {right})"


@dataclass(frozen=True)
class Restrict:
    """A rule's action narrowing an output to the values its atom allows."""

    atom: Atom


@dataclass(frozen=True)
class Assign:
    """A rule's `do` action giving an attribute the value of an expression."""

    target: str
    expr: Expr


@dataclass(frozen=True)
class Call:
    """A rule's `do` action calling a function of the user's with arguments."""

    function: str
    args: tuple[Expr, ...]


Action = Union[Restrict, Assign, Call]


@dataclass(frozen=True)
class Rule:
    """A rule of a normalised base: `when` (condition ==> actions), `impossible` or `else`."""

    name: str
    kind: str  # when | impossible | else
    condition: Cond | None
    actions: tuple[Action, ...]


@dataclass(frozen=True)
class Piece:
    """One interval of a numeric attribute's partition."""

    low: float
    high: float
    low_closed: bool
    high_closed: bool

    def contains(self, x: float) -> bool:
        above = x > self.low or (self.low_closed and x == self.low)
        below = x < self.high or (self.high_closed and x == self.high)
        return above and below

    def sample(self) -> float:
        if self.low == self.high:
            return self.low
        if math.isinf(self.low) and math.isinf(self.high):
            return 0.0
        if math.isinf(self.low):
            return self.high - 1.0
        if math.isinf(self.high):
            return self.low + 1.0
        return (self.low + self.high) / 2

    def __str__(self) -> str:
        if self.low == self.high:
            return f"{self.low:g}"
        left = "[" if self.low_closed else "]"
        right = "]" if self.high_closed else "["
        return f"{left}{self.low:g}, {self.high:g}{right}"


@dataclass
class Attribute:
    """An attribute of a normalised base: its role, kind and the values (or pieces) it takes."""

    name: str
    role: str  # inputs | outputs | intermediate | previous
    kind: str = "symbol"  # symbol | bool | number
    values: tuple[Any, ...] = ()  # symbols, booleans, or Pieces
    declared: bool = False
    init: Any = None  # for `@x`: the value before the first cycle
    assigned: bool = False  # given its value by a `do` assignment


@dataclass
class Base:
    """A normalised rule base: foreach expanded, constants substituted, domains computed."""

    name: str
    attributes: dict[str, Attribute]
    rules: tuple[Rule, ...]
    source: m.RuleBase | None = None

    @property
    def inputs(self) -> list[str]:
        return [a.name for a in self.attributes.values() if a.role in ("inputs", "previous")]

    @property
    def outputs(self) -> list[str]:
        return [a.name for a in self.attributes.values() if a.role == "outputs"]

    def element(self, attribute: str, actual: Any) -> Any:
        """The domain element an actual value falls in (its interval, or OTHER)."""
        attr = self.attributes[attribute]
        if attr.kind == "number":
            for piece in attr.values:
                if piece.contains(actual):
                    return piece
            raise ValueError(f"{attribute}={actual!r} falls outside its domain")
        if actual in attr.values:
            return actual
        if OTHER in attr.values:
            return OTHER
        raise ValueError(f"{attribute}={actual!r} is not one of {attr.values}")


def compare(actual: Any, op: str, value: Any) -> bool:
    if op == "==":
        return bool(actual == value)
    if op == "!=":
        return bool(actual != value)
    if not isinstance(actual, (int, float)) or isinstance(actual, bool):
        return False
    if op == "<":
        return bool(actual < value)
    if op == "<=":
        return bool(actual <= value)
    if op == ">":
        return bool(actual > value)
    return bool(actual >= value)


# ---------------------------------------------------------------- normalisation


def normalise(base: m.RuleBase) -> Base:
    constants: dict[str, Any] = {}
    for const in base.constants:
        constants[const.name] = constant_value(const.value, constants)
    rules: list[Rule] = []
    for item in base.rules:
        if isinstance(item, m.RuleForeach):
            for value in expand_items(item.items):
                for rule in item.rules:
                    rules.append(convert_rule(rule, {**constants, item.var: value}, {item.var: value}))
        else:
            rules.append(convert_rule(item, constants, {}))
    attributes = collect_attributes(base, rules, constants)
    return Base(base.name, attributes, tuple(rules), base)


def expand_items(items: Iterable[m.KItem]) -> list[Any]:
    values: list[Any] = []
    for item in items:
        if isinstance(item, m.KRange):
            low, high = item_value(item.low), item_value(item.high)
            try:
                start, stop = int(low), int(high)
            except (TypeError, ValueError) as exc:
                raise KheopsError("a range runs between integers, like [\"1\"..\"3\"]", item) from exc
            values += [type(low)(i) if isinstance(low, str) else i for i in range(start, stop + 1)]
        else:
            values.append(item_value(item))
    return values


def item_value(item: m.KItem) -> Any:
    if isinstance(item, (m.String, m.Number)):
        return item.value
    if isinstance(item, m.Ref):
        return {"true": True, "false": False}.get(item.text, item.text)
    raise TypeError(item)


def constant_value(expr: m.KExpr, constants: Mapping[str, Any]) -> Any:
    converted = convert_expr(expr, constants, {})
    if converted.op != "const":
        raise KheopsError("a constant must be a literal or other constants", expr)
    return converted.args[0]


def attribute_key(ref: m.AttrRef, loop: Mapping[str, Any]) -> str:
    name = ref.name
    if ref.index is not None:
        if ref.index not in loop:
            raise KheopsError(f"'{ref.index}' is not a foreach variable here", ref)
        name = f"{name}[{loop[ref.index]}]"
    return ("@" if ref.previous else "") + name


def convert_expr(expr: m.KExpr, constants: Mapping[str, Any], loop: Mapping[str, Any]) -> Expr:
    if isinstance(expr, (m.Number, m.String)):
        return Expr("const", (expr.value,))
    if isinstance(expr, m.AttrRef):
        if not expr.previous and expr.index is None:
            if expr.name in constants:
                return Expr("const", (constants[expr.name],))
            if expr.name in ("true", "false"):
                return Expr("const", (expr.name == "true",))
        return Expr("attr", (attribute_key(expr, loop),))
    if isinstance(expr, m.KNegate):
        inner = convert_expr(expr.operand, constants, loop)
        return Expr("const", (-inner.args[0],)) if inner.op == "const" else Expr("neg", (inner,))
    assert isinstance(expr, m.KBinary)
    left, right = convert_expr(expr.left, constants, loop), convert_expr(expr.right, constants, loop)
    if left.op == right.op == "const":
        return Expr("const", (Expr(expr.op, (left, right)).evaluate({}),))
    return Expr(expr.op, (left, right))


def convert_atom(node: Any, constants: Mapping[str, Any], loop: Mapping[str, Any], negate: bool = False) -> Atom:
    key = attribute_key(node.attr, loop)
    if isinstance(node, m.KTrue):
        return Atom(key, "==", not negate)
    if isinstance(node, m.KFalse):
        return Atom(key, "==", negate)
    if isinstance(node, m.KMember):
        values = frozenset(item_value(i) if not isinstance(i, m.Ref) or i.text not in constants
                           else constants[i.text] for i in node.items)
        op = "in" if node.op == "oneof" else "notin"
        return Atom(key, op, values)
    assert isinstance(node, m.KCompare)
    value = convert_expr(node.value, constants, loop)
    if value.op != "const":
        raise KheopsError("Kheops compares an attribute with a constant; compute the other side with "
                          "`do {x = ...}` first", node.value)
    if node.op not in ("==", "!=") and not isinstance(value.args[0], (int, float)):
        raise KheopsError(f"'{key}' {node.op} {value.args[0]!r}: an ordering compares numbers", node.value)
    return Atom(key, node.op, value.args[0])


def convert_cond(cond: m.Cond, constants: Mapping[str, Any], loop: Mapping[str, Any]) -> Cond:
    if isinstance(cond, m.KAnd):
        return All(tuple(convert_cond(c, constants, loop) for c in cond.operands))
    if isinstance(cond, m.KOr):
        return Any_(tuple(convert_cond(c, constants, loop) for c in cond.operands))
    if isinstance(cond, m.KNot):
        return Not(convert_cond(cond.operand, constants, loop))
    if isinstance(cond, m.KForeach):
        return All(tuple(convert_cond(cond.body, {**constants, cond.var: v}, {**loop, cond.var: v})
                         for v in expand_items(cond.items)))
    return convert_atom(cond, constants, loop)


def convert_rule(rule: m.Rule, constants: Mapping[str, Any], loop: Mapping[str, Any]) -> Rule:
    name = rule.name if rule.index is None else f"{rule.name}[{loop.get(rule.index, rule.index)}]"
    condition = convert_cond(rule.condition, constants, loop) if rule.condition is not None else None
    actions: list[Action] = []
    for action in rule.actions:
        if isinstance(action, m.Restrict):
            atom = convert_atom(action.restriction, constants, loop)
            if atom.attribute.startswith("@"):
                raise KheopsError("the previous cycle's value cannot be restricted", action)
            actions.append(Restrict(atom))
            continue
        for statement in action.statements:
            if isinstance(statement, m.DoAssign):
                actions.append(Assign(statement.target, convert_expr(statement.value, constants, loop)))
            else:
                actions.append(Call(statement.function,
                                    tuple(convert_expr(a, constants, loop) for a in statement.args)))
    return Rule(name, rule.kind, condition, tuple(actions))


def targets(rule: Rule) -> frozenset[str]:
    """The attributes a rule's actions restrict or assign."""
    return frozenset(action.atom.attribute if isinstance(action, Restrict) else action.target
                     for action in rule.actions if not isinstance(action, Call))


def atoms(cond: Cond | None) -> Iterator[Atom]:
    if cond is None:
        return
    if isinstance(cond, Atom):
        yield cond
    elif isinstance(cond, Not):
        yield from atoms(cond.operand)
    else:
        for operand in cond.operands:
            yield from atoms(operand)


def collect_attributes(source: m.RuleBase, rules: Iterable[Rule], constants: Mapping[str, Any]) -> dict[str, Attribute]:
    attributes: dict[str, Attribute] = {}
    for decl in source.attributes:
        attributes[decl.name] = Attribute(decl.name, decl.role)
    mentioned: dict[str, list[Atom]] = {}
    assigned: set[str] = set()
    for rule in rules:
        for atom in atoms(rule.condition):
            mentioned.setdefault(atom.attribute, []).append(atom)
        for action in rule.actions:
            if isinstance(action, Restrict):
                mentioned.setdefault(action.atom.attribute, []).append(action.atom)
            elif isinstance(action, Assign):
                assigned.add(action.target)
                mentioned.setdefault(action.target, [])
            for expr in ([action.expr] if isinstance(action, Assign) else
                         list(action.args) if isinstance(action, Call) else []):
                for name in expr.attributes():  # read at run time, so part of the observable space
                    mentioned.setdefault(name, [])
    inits = {i.name: constant_value(i.value, constants) for i in source.inits}
    for name in list(mentioned):
        if name.startswith("@"):
            mentioned.setdefault(name[1:], [])
    for name in mentioned:
        attribute = attributes.get(name)
        if attribute is None:
            if name.startswith("@"):
                attribute = Attribute(name, "previous", init=inits.get(name[1:]))
            else:
                attribute = Attribute(name, "intermediate")
            attributes[name] = attribute
        attribute.assigned = name in assigned
    declared = {d.name: d for d in source.attributes}
    for name, attribute in attributes.items():
        own = name[1:] if name.startswith("@") else name
        related = mentioned.get(own, []) + mentioned.get("@" + own, [])
        decide_domain(attribute, declared.get(own), related, own in assigned)
    return attributes


def decide_domain(attribute: Attribute, declared: m.AttrDecl | None, found: list[Atom], assigned: bool) -> None:
    constants: list[Any] = []
    for atom in found:
        constants += list(atom.value) if atom.op in ("in", "notin") else [atom.value]
    numeric = assigned or any(isinstance(c, (int, float)) and not isinstance(c, bool) for c in constants) \
        or any(a.op in ("<", "<=", ">", ">=") for a in found)
    domain = declared.domain if declared is not None else None
    if isinstance(domain, m.BoolDomain) or (domain is None and constants and all(isinstance(c, bool)
                                                                                  for c in constants)):
        attribute.kind, attribute.values, attribute.declared = "bool", (False, True), domain is not None
    elif isinstance(domain, m.SymbolDomain):
        attribute.kind, attribute.declared = "symbol", True
        attribute.values = tuple(dict.fromkeys(item_value(v) for v in domain.values))
    elif isinstance(domain, m.NumericDomain) or numeric:
        attribute.kind = "number"
        thresholds = sorted({float(c) for c in constants if isinstance(c, (int, float)) and not isinstance(c, bool)})
        low = high = None
        if isinstance(domain, m.NumericDomain) and domain.low is not None and domain.high is not None:
            low = constant_literal(domain.low)
            high = constant_literal(domain.high)
        attribute.values = partition(thresholds, found, low, high)
        attribute.declared = domain is not None
    else:
        attribute.kind = "symbol"
        attribute.values = tuple(dict.fromkeys(constants)) + (OTHER,)


def constant_literal(expr: m.KExpr) -> float:
    converted = convert_expr(expr, {}, {})
    if converted.op != "const":
        raise KheopsError("a numeric domain's bounds are numbers", expr)
    return float(converted.args[0])


def partition(thresholds: list[float], found: list[Atom], low: float | None, high: float | None) -> tuple[Piece, ...]:
    """The coarsest intervals on which every comparison the rules make is constant."""
    lo = -math.inf if low is None else low
    hi = math.inf if high is None else high
    cuts = [t for t in thresholds if lo <= t <= hi]
    elementary: list[Piece] = []
    previous, previous_closed = lo, low is not None
    for cut in cuts:
        if cut > previous or (cut == previous and not previous_closed and not elementary):
            if cut > previous:
                elementary.append(Piece(previous, cut, previous_closed, False))
        elementary.append(Piece(cut, cut, True, True))
        previous, previous_closed = cut, False
    if previous < hi or (previous == hi and high is not None and not elementary):
        elementary.append(Piece(previous, hi, previous_closed, high is not None))
    if not elementary:
        elementary = [Piece(lo, hi, low is not None, high is not None)]
    numeric_atoms = [a for a in found if a.op in NUMERIC_OPS and isinstance(a.value, (int, float))]
    merged: list[Piece] = []
    signature_of = lambda p: tuple(a.holds(p.sample()) for a in numeric_atoms)  # noqa: E731
    for piece in elementary:
        if merged and signature_of(merged[-1]) == signature_of(piece):
            last = merged.pop()
            piece = Piece(last.low, piece.high, last.low_closed, piece.high_closed)
        merged.append(piece)
    return tuple(merged)


# ---------------------------------------------------------------- three-valued evaluation


TRUE, FALSE, UNKNOWN = 1, 0, -1


_TRUTH_CACHE: dict[tuple[Atom, frozenset[Any]], int] = {}


def atom_truth(atom: Atom, possible: frozenset[Any]) -> int:
    key = (atom, possible)
    cached = _TRUTH_CACHE.get(key)
    if cached is None:
        if len(_TRUTH_CACHE) > 200_000:
            _TRUTH_CACHE.clear()
        cached = _TRUTH_CACHE[key] = _atom_truth(atom, possible)
    return cached


def _atom_truth(atom: Atom, possible: Iterable[Any]) -> int:
    results = {atom_holds(atom, value) for value in possible}
    if results == {True}:
        return TRUE
    if results == {False} or not results:
        return FALSE
    return UNKNOWN


def atom_holds(atom: Atom, element: Any) -> bool:
    if isinstance(element, Piece):
        return atom.holds(element.sample())
    if element == OTHER:
        return atom.op in ("!=", "notin")
    return atom.holds(element)


def truth(cond: Cond | None, memory: Mapping[str, frozenset[Any]]) -> int:
    if cond is None:
        return TRUE
    if isinstance(cond, Atom):
        return atom_truth(cond, memory[cond.attribute])
    if isinstance(cond, Not):
        inner = truth(cond.operand, memory)
        return UNKNOWN if inner == UNKNOWN else 1 - inner
    values = [truth(c, memory) for c in cond.operands]
    if isinstance(cond, All):
        return FALSE if FALSE in values else UNKNOWN if UNKNOWN in values else TRUE
    return TRUE if TRUE in values else UNKNOWN if UNKNOWN in values else FALSE


def restrict(memory: dict[str, frozenset[Any]], atom: Atom) -> None:
    memory[atom.attribute] = frozenset(v for v in memory[atom.attribute] if atom_holds(atom, v))


# ---------------------------------------------------------------- the reference interpreter


@dataclass
class Outcome:
    """What the reference interpreter decides for one set of inputs, and which rules fired."""

    outputs: dict[str, Any]  # determined outputs; None for an undetermined one
    fired: list[str]
    calls: list[tuple[str, tuple[Any, ...]]]
    inconsistent: list[str] = field(default_factory=list)  # attributes left with no value
    incomplete: list[str] = field(default_factory=list)  # outputs left with several values
    impossible: str | None = None  # the `impossible` rule the inputs match

    def key(self) -> tuple[Any, ...]:
        return (tuple(sorted(self.outputs.items(), key=lambda kv: kv[0])), tuple(sorted(self.calls, key=repr)),
                tuple(self.inconsistent), tuple(self.incomplete), self.impossible)


def initial_memory(base: Base) -> dict[str, frozenset[Any]]:
    return {name: frozenset(attr.values) for name, attr in base.attributes.items()}


def interpret(base: Base, inputs: Mapping[str, Any]) -> Outcome:
    """Naive forward chaining on actual input values: the oracle the compiled DAG must match."""
    memory = initial_memory(base)
    actual: dict[str, Any] = {}
    for name in base.inputs:
        value = inputs[name]
        actual[name] = value
        memory[name] = frozenset({base.element(name, value)})
    outcome = Outcome({}, [], [])
    pending = [r for r in base.rules if r.kind != "else"]
    elses = [r for r in base.rules if r.kind == "else"]
    while True:
        progress = True
        while progress:
            progress = False
            for rule in list(pending):
                if truth(rule.condition, memory) != TRUE:
                    continue
                pending.remove(rule)
                if rule.kind == "impossible":
                    outcome.impossible = rule.name
                    return outcome
                fire(base, rule, memory, actual, outcome)
                progress = True
        undetermined = [o for o in base.outputs if len(memory[o]) > 1]
        if not undetermined or not elses:
            break
        for rule in elses:
            fire(base, rule, memory, actual, outcome)
        elses = []
    finish(base, memory, outcome)
    return outcome


def fire(base: Base, rule: Rule, memory: dict[str, frozenset[Any]], actual: dict[str, Any], outcome: Outcome) -> None:
    outcome.fired.append(rule.name)
    for action in rule.actions:
        if isinstance(action, Restrict):
            restrict(memory, action.atom)
        elif isinstance(action, Assign):
            value = action.expr.evaluate(actual)
            actual[action.target] = value
            memory[action.target] = memory[action.target] & frozenset({base.element(action.target, value)})
        else:
            outcome.calls.append((action.function, tuple(a.evaluate(actual) for a in action.args)))


def finish(base: Base, memory: Mapping[str, frozenset[Any]], outcome: Outcome) -> None:
    outcome.inconsistent = sorted(name for name, values in memory.items() if not values)
    for name in base.outputs:
        values = memory[name]
        outcome.outputs[name] = next(iter(values)) if len(values) == 1 else None
        if len(values) > 1:
            outcome.incomplete.append(name)


# ---------------------------------------------------------------- the compiler


@dataclass(frozen=True)
class Leaf:
    """The end of a path of the compiled decision: each output's value, and what went wrong."""

    outputs: tuple[tuple[str, Any], ...]  # every output of the base compiled: (name, value or None)
    inconsistent: tuple[str, ...] = ()
    incomplete: tuple[str, ...] = ()
    impossible: str | None = None


@dataclass(frozen=True)
class Test:
    """A node of the compiled decision: one branch per value (or piece) of an attribute."""

    attribute: str
    branches: tuple[tuple[Any, Node], ...]  # (domain element, subgraph)


@dataclass(frozen=True)
class Do:
    """Procedural node: assignments and external calls, in rule order, then what follows."""

    actions: tuple[Assign | Call, ...]
    next: Node


Node = Union[Leaf, Test, Do]


@dataclass(frozen=True)
class Finding:
    """An inconsistency or incompleteness of a base, with the inputs that lead to it."""

    kind: str  # inconsistent | incomplete
    attributes: tuple[str, ...]
    witness: tuple[tuple[str, Any], ...]  # the tests on the path: attribute, domain element (a tuple: any of them)
    fired: tuple[str, ...]


@dataclass
class Compiled:
    """A rule base compiled into a decision graph of bounded depth (seed 000 §3.7)."""

    base: Base
    root: Node
    findings: list[Finding]
    tree_nodes: int
    dag_nodes: int
    # Compiled in parts (`compile_parts`): the input the root tests, and for each of its values the
    # outputs that value's decision leaves as they were (they keep their previous-cycle value `@name`).
    split: str | None = None
    kept: Mapping[Any, tuple[str, ...]] = field(default_factory=dict)
    findings_cut: bool = False  # FINDINGS_LIMIT stopped the listing: more inputs are unsettled than listed

    def findings_count(self) -> str:
        """'16', or 'at least 10000' when the listing was cut."""
        return f"at least {len(self.findings)}" if self.findings_cut else str(len(self.findings))

    @property
    def depth(self) -> int:
        return depth(self.root)

    def part_depths(self) -> dict[Any, int]:
        """Tests on the longest path of each part's decision, after the test on `split`."""
        if self.split is None or not isinstance(self.root, Test):
            return {}
        return {value: depth(child) for value, child in self.root.branches}


class Compiler:
    def __init__(self, base: Base, limit: int = WORK_LIMIT, spent: int = 0, shared: dict[Any, Node] | None = None):
        self.base = base
        self.limit = limit
        self.findings: list[Finding] = []
        self.tree_nodes = spent  # the work done before (the other parts of a base compiled in parts)
        self.shared: dict[Any, Node] = {} if shared is None else shared
        self.explored: dict[tuple[Any, ...], Node] = {}
        # Per explored state: the path and rules fired that first reached it, and the slice of
        # `findings` its subgraph gave; a path reaching it again gets those findings too.
        self.reached_first: dict[tuple[Any, ...], tuple[int, int, int, int]] = {}
        self.findings_cut = False  # FINDINGS_LIMIT was reached
        self.reads: dict[int, tuple[str, ...]] = {}
        self.rule_atoms: dict[int, tuple[Atom, ...]] = {}
        self.restricting: dict[int, frozenset[str]] = {}
        self.truths: dict[tuple[Any, ...], int] = {}
        self.order = list(base.attributes)
        self.observable = {n for n, a in base.attributes.items() if a.role in ("inputs", "previous")}

    def compile(self) -> Compiled:
        memory = initial_memory(self.base)
        alive = tuple(r for r in self.base.rules if r.kind != "else")
        root = self.node(memory, alive, frozenset(self.observable), (), ())
        return Compiled(self.base, root, merged_findings(self.findings), self.tree_nodes, len(self.shared),
                        findings_cut=self.findings_cut)

    def state(self, memory: Mapping[str, frozenset[Any]], alive: tuple[Rule, ...],
              testable: frozenset[str]) -> tuple[Any, ...]:
        """What the rest of the deduction depends on, so that states equal on it share one node
        (the reduction that keeps the work near the DAG's size, not the tree's): the values still
        possible of what the rules determine and of the inputs still to test; of an input tested
        already (never tested again), only how the atoms of the rules still alive judge it; of
        an input no rule still alive reads, nothing."""
        read: dict[str, list[Atom]] = {}
        for rule in alive:
            for atom in self.atoms(rule):
                read.setdefault(atom.attribute, []).append(atom)
        # An intermediate becomes testable once an assignment gives it its value (its values
        # still possible do not say so): whether it has is part of the state.
        return (*(memory[a] if a not in self.observable or (a in testable and a in read)
                  else tuple(atom_truth(atom, memory[a]) for atom in read[a]) if a in read else None
                  for a in self.order), testable - self.observable)

    def inert(self, rule: Rule, memory: Mapping[str, frozenset[Any]]) -> bool:
        """A rule whose firing would change nothing: it only restricts attributes to values they
        are already restricted to (memory only shrinks, so it stays so). Dropping it lets the
        states that differ only by it share one node."""
        if rule.kind != "when" or not all(isinstance(action, Restrict) for action in rule.actions):
            return False
        # Already restricted so: the atom holds for every value left (an attribute left with no
        # value counts too: restricting it changes nothing).
        return all(not memory[a.attribute] or atom_truth(a, memory[a.attribute]) == TRUE
                   for a in (action.atom for action in rule.actions if isinstance(action, Restrict)))

    def atoms(self, rule: Rule) -> tuple[Atom, ...]:
        found = self.rule_atoms.get(id(rule))
        if found is None:
            found = self.rule_atoms[id(rule)] = tuple(atoms(rule.condition))
        return found

    def restricts(self, rule: Rule) -> frozenset[str]:
        found = self.restricting.get(id(rule))
        if found is None:
            found = self.restricting[id(rule)] = targets(rule)
        return found

    def read(self, rule: Rule) -> tuple[str, ...]:
        """The attributes a rule's condition reads."""
        attributes = self.reads.get(id(rule))
        if attributes is None:
            attributes = self.reads[id(rule)] = tuple(sorted({a.attribute for a in self.atoms(rule)}))
        return attributes

    def truth(self, rule: Rule, memory: Mapping[str, frozenset[Any]]) -> int:
        """A rule condition's truth, cached on the values of the attributes it reads."""
        key = (id(rule), tuple(memory[a] for a in self.read(rule)))
        cached = self.truths.get(key)
        if cached is None:
            cached = self.truths[key] = truth(rule.condition, memory)
        return cached

    def intern(self, node: Node) -> Node:
        """Identical subtrees become one node of the DAG; a test whose branches all lead to
        the same place decides nothing and disappears."""
        if isinstance(node, Test) and len({id(child) for _, child in node.branches}) == 1:
            return node.branches[0][1]
        # Children are interned already: a node is known by its own fields and its children's
        # identity (hashing whole subgraphs again at every level would cost their size each time).
        key: Any = node
        if isinstance(node, Test):
            key = (node.attribute, tuple((value, id(child)) for value, child in node.branches))
        elif isinstance(node, Do):
            key = (node.actions, id(node.next))
        return self.shared.setdefault(key, node)

    def node(self, memory: dict[str, frozenset[Any]], alive: tuple[Rule, ...], testable: frozenset[str],
             path: tuple[tuple[str, Any], ...], history: tuple[str, ...], elses_fired: bool = False,
             tested: str | None = None) -> Node:
        """The subgraph for one state of the deduction: the values still possible, the rules
        that may still fire (not fired, condition not FALSE — monotony keeps a FALSE condition
        FALSE), the attributes still testable. Paths reaching the same state share it, so the
        search explores the DAG rather than the whole tree; a shared state's findings carry
        the witness of the first path that reached it. `elses_fired`: the `else` rules have fired.
        `tested`: the only attribute whose values differ from those `alive` was last filtered on
        (a test's branch): only the rules reading it may have become FALSE, and none inert."""
        self.tree_nodes += 1
        if self.tree_nodes > self.limit:
            raise self.too_large()
        if tested is None:
            alive = tuple(r for r in alive if self.truth(r, memory) != FALSE and not self.inert(r, memory))
        else:
            alive = tuple(r for r in alive if tested not in self.read(r) or self.truth(r, memory) != FALSE)
        # Rules by identity: two joined bases may each have a rule of the same name.
        key = (self.state(memory, alive, testable), tuple(id(r) for r in alive), elses_fired)
        found = self.explored.get(key)
        if found is None:
            start = len(self.findings)
            found = self.explore(memory, alive, testable, path, history, elses_fired, tested)
            self.explored[key] = found
            self.reached_first[key] = (len(path), len(history), start, len(self.findings))
        else:
            self.findings_again(key, path, history)
        return found

    def findings_again(self, key: tuple[Any, ...], path: tuple[tuple[str, Any], ...],
                       history: tuple[str, ...]) -> None:
        """Another path reaches an explored state: the inputs it stands for are unsettled wherever
        the first path's were below it. Each finding is listed again with this path's tests and
        rules fired (up to FINDINGS_LIMIT findings: past it the list is cut, and said so)."""
        tests, fired, start, end = self.reached_first[key]
        for finding in self.findings[start:end]:
            if len(self.findings) >= FINDINGS_LIMIT:
                self.findings_cut = True
                return
            self.findings.append(Finding(finding.kind, finding.attributes, path + finding.witness[tests:],
                                         history + finding.fired[fired:]))

    def explore(self, memory: dict[str, frozenset[Any]], alive: tuple[Rule, ...], testable: frozenset[str],
                path: tuple[tuple[str, Any], ...], history: tuple[str, ...], elses_fired: bool,
                tested: str | None = None) -> Node:
        memory = dict(memory)
        procedural: list[Assign | Call] = []
        fired_now: list[str] = []
        pending = list(alive)
        # With `tested`, the rules that read nothing else were UNKNOWN and not inert in the state
        # this one branches from: only those reading what changed since (the tested attribute,
        # then what firing restricts) are looked at again.
        dirty: set[str] | None = None if tested is None else {tested}
        changed: set[str] = set(dirty or ())
        progress = True
        while progress:
            progress = False
            restricted_now: set[str] = set()
            for rule in list(pending):
                if dirty is not None and dirty.isdisjoint(self.read(rule)):
                    continue
                if self.truth(rule, memory) != TRUE:
                    continue
                if rule.kind == "impossible":
                    return self.wrap(procedural, self.intern(Leaf((), impossible=rule.name)))
                pending.remove(rule)
                fired_now.append(rule.name)
                progress = True
                for action in rule.actions:
                    if isinstance(action, Restrict):
                        restrict(memory, action.atom)
                        restricted_now.add(action.atom.attribute)
                        if dirty is not None:
                            dirty.add(action.atom.attribute)  # later rules of this pass see it too
                    else:
                        procedural.append(action)
                        if isinstance(action, Assign):
                            testable = testable | {action.target}
            changed |= restricted_now
            if dirty is not None:
                dirty = restricted_now
        history = history + tuple(fired_now)
        # An attribute left with no value does not end the deduction: the other rules still fire,
        # and an `impossible` rule may still apply. What fires then can differ from the interpreter
        # (an atom on the empty attribute reads FALSE, so a negation of it turns TRUE after its rule
        # was dropped as FALSE): such a decision is only "inconsistent" (docs/reference.md).
        if tested is None:
            valid = [r for r in pending if self.truth(r, memory) == UNKNOWN and not self.inert(r, memory)]
        else:
            valid = [r for r in pending if (changed.isdisjoint(self.read(r)) or self.truth(r, memory) == UNKNOWN)
                     and (changed.isdisjoint(self.restricts(r)) or not self.inert(r, memory))]
        candidates: dict[str, int] = {}
        for rule in valid:
            for atom in self.atoms(rule):
                if atom.attribute in testable and len(memory[atom.attribute]) > 1 \
                        and atom_truth(atom, memory[atom.attribute]) == UNKNOWN:
                    candidates[atom.attribute] = candidates.get(atom.attribute, 0) + 1
        if not candidates:
            undetermined = [o for o in self.base.outputs if len(memory[o]) > 1]
            elses = [r for r in self.base.rules if r.kind == "else"]
            if not undetermined or not elses or elses_fired:
                return self.wrap(procedural, self.leaf(memory, path, history))
            # Nothing more fires and an output is undetermined: the `else` rules fire, once, and
            # the deduction goes on from what they restrict, as the interpreter's does.
            for rule in elses:
                for action in rule.actions:
                    if isinstance(action, Restrict):
                        restrict(memory, action.atom)
                    else:
                        procedural.append(action)
                        if isinstance(action, Assign):
                            testable = testable | {action.target}
            history = history + tuple(r.name for r in elses)
            return self.wrap(procedural, self.node(memory, tuple(pending), testable, path, history, elses_fired=True))
        # Heuristic: the attribute most valid rules wait for; then the fewest values; then declaration order.
        chosen = min(candidates, key=lambda a: (-candidates[a], len(memory[a]), self.order.index(a)))
        remaining = tuple(valid)
        # The values no remaining rule tells apart (every atom on the attribute holds for all of
        # them or for none) lead to one subgraph, explored once: a numeric input cut by the
        # thresholds of the whole base splits only where the rules still waiting compare it.
        tests = [atom for rule in valid for atom in self.atoms(rule) if atom.attribute == chosen]
        classes: dict[tuple[bool, ...], list[Any]] = {}
        for value in self.ordered(chosen, memory[chosen]):
            classes.setdefault(tuple(atom_holds(atom, value) for atom in tests), []).append(value)
        child_of: dict[Any, Node] = {}
        for values in classes.values():
            child_memory = {**memory, chosen: frozenset(values)}
            witness = values[0] if len(values) == 1 else tuple(values)  # a witness names the whole class
            child = self.node(child_memory, remaining, testable - {chosen}, path + ((chosen, witness),), history,
                              elses_fired, chosen)
            child_of.update(dict.fromkeys(values, child))
        branches = tuple((value, child_of[value]) for value in self.ordered(chosen, memory[chosen]))
        return self.wrap(procedural, self.intern(Test(chosen, branches)))

    def too_large(self) -> TooLarge:
        bound, largest = paths_bound_text(self.base)
        name = self.base.name
        return TooLarge(f"rule base '{name}' needs more than {self.limit:,} decision-tree nodes to compile (its "
                        f"tests split on up to {bound:,} input combinations: {largest} values): split it into "
                        "bases that each decide from fewer inputs, or use fewer thresholds per numeric input "
                        f"(each one adds a value); {WORK_LIMIT_VARIABLE}=N raises the limit",
                        self.base.source or m.RuleBase(name=name), self.limit)

    def ordered(self, attribute: str, values: frozenset[Any]) -> list[Any]:
        domain = self.base.attributes[attribute].values
        return [v for v in domain if v in values]

    def wrap(self, procedural: list[Assign | Call], node: Node) -> Node:
        return self.intern(Do(tuple(procedural), node)) if procedural else node

    def leaf(self, memory: Mapping[str, frozenset[Any]], path: tuple[tuple[str, Any], ...],
             history: tuple[str, ...]) -> Node:
        inconsistent = tuple(sorted(n for n, v in memory.items() if not v))
        incomplete = tuple(o for o in self.base.outputs if len(memory[o]) > 1)
        # Every output of the base compiled, None when undetermined: a part of a base compiled in
        # parts lists its own outputs, the others being those it keeps as they were.
        outputs = tuple((o, next(iter(memory[o])) if len(memory[o]) == 1 else None) for o in self.base.outputs)
        if inconsistent:
            self.findings.append(Finding("inconsistent", inconsistent, path, history))
        elif incomplete:
            self.findings.append(Finding("incomplete", incomplete, path, history))
        return self.intern(Leaf(outputs, inconsistent, incomplete))


def work_limit() -> int:
    given = os.environ.get(WORK_LIMIT_VARIABLE, "").replace("_", "")
    try:
        return max(1, int(float(given))) if given else WORK_LIMIT  # 2000000, 2_000_000 or 2e6
    except ValueError:
        return WORK_LIMIT  # not a number: the default, as if unset


_COMPILED: dict[tuple[Any, ...], Compiled] = {}  # the last few bases compiled, by content


def compile_base(base: Base, limit: int | None = None) -> Compiled:
    """The decision graph of `base`. `specc compile` checks a stand-alone base (what it leaves
    unsettled) before its back end writes it: the second call finds the first one's graph."""
    limit = work_limit() if limit is None else limit
    key = (base.name, base.rules, limit, tuple((a.name, a.role, a.kind, a.values, a.init, a.assigned)
                                               for a in base.attributes.values()))
    compiled = _COMPILED.get(key)
    if compiled is None:
        compiled = Compiler(base, limit).compile()
        if len(_COMPILED) >= 8:
            _COMPILED.pop(next(iter(_COMPILED)))
        _COMPILED[key] = compiled
    return compiled


def compile_parts(base: Base, split: str, parts: Mapping[Any, tuple[Base, tuple[str, ...]]],
                  limit: int | None = None) -> Compiled:
    """`base` compiled as one decision per value of its symbolic input `split`: `parts` gives, for
    each value, the sub-base deciding it (the rules that can apply with that value) and the
    outputs it leaves as they were (they keep their previous-cycle value, copied without a test).
    The root tests `split`; each decision grows with what that value's rules read, not with the
    product of every attribute of the base. The work limit is shared by the parts, and equal
    subgraphs of different parts are one node."""
    attribute = base.attributes[split]
    if attribute.kind != "symbol" or OTHER in attribute.values or set(parts) != set(attribute.values):
        raise ValueError(f"compile_parts splits on a declared symbolic input, one part per value: not {split!r}")
    limit = work_limit() if limit is None else limit
    shared: dict[Any, Node] = {}
    branches: list[tuple[Any, Node]] = []
    findings: list[Finding] = []
    spent = 0
    cut = False
    for value in attribute.values:
        part, _ = parts[value]
        compiler = Compiler(part, limit, spent, shared)
        try:
            compiled = compiler.compile()
        except TooLarge as exc:
            raise TooLarge(str(exc), exc.node, exc.limit, value) from None
        spent = compiler.tree_nodes
        cut = cut or compiled.findings_cut
        branches.append((value, compiled.root))
        findings += [Finding(f.kind, f.attributes, ((split, value), *f.witness), f.fired) for f in compiled.findings]
    return Compiled(base, Test(split, tuple(branches)), findings, spent, len(shared) + 1, split,
                    {value: kept for value, (_, kept) in parts.items()}, cut)


def paths_bound(base: Base) -> tuple[int, list[tuple[str, int]]]:
    """The most root-to-leaf paths the decision graph can have, estimated before building it:
    the product of the number of values of every attribute a test can split on (the inputs, the
    previous-cycle values and the assigned intermediates), and those counts, largest first."""
    assigned = {action.target for rule in base.rules for action in rule.actions if isinstance(action, Assign)}
    tested = {atom.attribute for rule in base.rules if rule.condition is not None for atom in atoms(rule.condition)}
    counts = sorted(((name, len(attribute.values)) for name, attribute in base.attributes.items()
                     if name in tested and (attribute.role in ("inputs", "previous") or name in assigned)),
                    key=lambda item: -item[1])
    return math.prod(count for _, count in counts), counts


def paths_bound_text(base: Base, shown: int = 6) -> tuple[int, str]:
    """`paths_bound` and its largest counts as a message says them ("x1 15 x x0 14 x ...")."""
    bound, counts = paths_bound(base)
    return bound, " x ".join(f"{name} {count}" for name, count in counts[:shown]) + (
        " x ..." if len(counts) > shown else "")


def depth(node: Node) -> int:
    """Tests on the longest root-to-leaf path: the bound on the decision's reaction time."""
    memo: dict[int, int] = {}

    def visit(n: Node) -> int:
        key = id(n)
        if key not in memo:
            if isinstance(n, Leaf):
                memo[key] = 0
            elif isinstance(n, Do):
                memo[key] = visit(n.next)
            else:
                memo[key] = 1 + max(visit(child) for _, child in n.branches)
        return memo[key]

    return visit(node)


def evaluate(compiled: Compiled, inputs: Mapping[str, Any]) -> Outcome:
    """Walk the DAG on actual inputs (what the generated function does, unrolled as code)."""
    base = compiled.base
    actual = {name: inputs[name] for name in base.inputs}
    outcome = Outcome({}, [], [])
    node = compiled.root
    while True:
        if isinstance(node, Do):
            for action in node.actions:
                if isinstance(action, Assign):
                    actual[action.target] = action.expr.evaluate(actual)
                else:
                    outcome.calls.append((action.function, tuple(a.evaluate(actual) for a in action.args)))
            node = node.next
        elif isinstance(node, Test):
            element = base.element(node.attribute, actual[node.attribute])
            node = next(child for value, child in node.branches if value == element)
        else:
            if node.impossible:
                outcome.impossible = node.impossible
                return outcome
            outcome.outputs = {o: None for o in base.outputs} | dict(node.outputs)
            if compiled.split is not None:
                for output in compiled.kept[base.element(compiled.split, actual[compiled.split])]:
                    outcome.outputs[output] = actual["@" + output]
            outcome.inconsistent = list(node.inconsistent)
            outcome.incomplete = list(node.incomplete)
            return outcome


def sample_inputs(base: Base) -> Iterator[dict[str, Any]]:
    """Every combination of one representative value per input domain element (small bases)."""
    names = base.inputs
    choices = [[sample_of(v) for v in base.attributes[n].values] for n in names]
    for combination in itertools.product(*choices):
        yield dict(zip(names, combination, strict=True))


def sample_of(element: Any) -> Any:
    if isinstance(element, Piece):
        return element.sample()
    if element == OTHER:
        return "<unmentioned>"
    return element


# ---------------------------------------------------------------- findings, as people read them

FINDINGS_LIMIT = 10_000  # unsettled cases listed for one base, before they are merged
MERGED_AT_MOST = 5_000  # cases `merged_findings` merges (more are listed path by path)


def merged_findings(findings: Sequence[Finding]) -> list[Finding]:
    """The findings with the cases that differ in one test only merged into one (`temp=[0, 30[ |
    [30, 40[`), until none can be: each finding still stands for a box of inputs, and the list
    reads as few cases as the paths allow. The rules fired are those of the first case merged.
    One position at a time, every group of cases alike but there merged at once: a few sweeps
    over the list, not a pass per pair (a base of 8 inputs x 50 rules lists 26,000 paths)."""
    merged = list(findings)
    if len(merged) > MERGED_AT_MOST:  # a listing nobody reads case by case: not worth seconds of merging
        return merged
    width = max((len(f.witness) for f in merged), default=0)
    changed = True
    while changed:
        changed = False
        for position in range(width):
            groups: dict[tuple[Any, ...], list[Finding]] = {}
            for finding in merged:
                if position >= len(finding.witness):
                    groups.setdefault((id(finding),), []).append(finding)
                    continue
                key = (finding.kind, finding.attributes, tuple(a for a, _ in finding.witness),
                       finding.witness[:position], finding.witness[position + 1:])
                groups.setdefault(key, []).append(finding)
            if all(len(group) == 1 for group in groups.values()):
                continue
            out = []
            for group in groups.values():
                first = group[0]
                if len(group) > 1:
                    attribute = first.witness[position][0]
                    values = tuple(v for f in group for v in _elements(f.witness[position][1]))
                    first = Finding(first.kind, first.attributes, (*first.witness[:position], (attribute, values),
                                                                    *first.witness[position + 1:]), first.fired)
                    changed = True
                out.append(first)
            merged = out
    return merged


def _elements(value: Any) -> tuple[Any, ...]:
    """A witness's domain elements: a tuple stands for any of them."""
    return value if isinstance(value, tuple) else (value,)


def describe(finding: Finding) -> str:
    witness = ", ".join(f"{a}={' | '.join(map(str, _coalesced(v))) if isinstance(v, tuple) else v}"
                        for a, v in finding.witness) or "any input"
    fired = ", ".join(finding.fired) or "none"
    what = "no value left for" if finding.kind == "inconsistent" else "undetermined"
    return f"{finding.kind}: {what} {', '.join(finding.attributes)} when {witness} (rules fired: {fired})"


def _coalesced(values: tuple[Any, ...]) -> list[Any]:
    """A witness's values with the intervals that touch written as one (`[0, 3[ | [3, 6[` as
    `[0, 6[`): the pieces of a numeric input's partition are disjoint, so what touches adds up."""
    out: list[Any] = []
    for value in sorted(values, key=lambda v: (v.low, v.high) if isinstance(v, Piece) else (math.inf, math.inf)):
        last = out[-1] if out else None
        if (isinstance(value, Piece) and isinstance(last, Piece) and last.high == value.low
                and last.high_closed != value.low_closed):
            out[-1] = Piece(last.low, value.high, last.low_closed, value.high_closed)
        else:
            out.append(value)
    return out


def worst_first(findings: Sequence[Finding]) -> list[Finding]:
    """Inconsistent configurations (no value left) before incomplete ones (no value deduced)."""
    return sorted(findings, key=lambda finding: finding.kind != "inconsistent")


def tally(findings: Sequence[Finding]) -> str:
    """'48 inconsistent, 188 incomplete': the count of each kind found."""
    counts = Counter(finding.kind for finding in findings)
    return ", ".join(f"{counts[kind]} {kind}" for kind in ("inconsistent", "incomplete") if counts[kind])


LARGE_DAG_NODES = 5_000  # past it the generated module runs to megabytes (about 750 bytes a node) and imports slowly


def size_warning(compiled: Compiled, what: str, node: m.Node) -> Diagnostic | None:
    """A decision graph under the work limit but large enough to weigh on the generated package:
    said with its figures, and how to make it smaller."""
    if compiled.dag_nodes <= LARGE_DAG_NODES:
        return None
    megabytes = compiled.dag_nodes * 750 / 1e6
    return Diagnostic("rules-large", f"{what} compiles into a decision graph of {compiled.dag_nodes:,} nodes "
                      f"({compiled.tree_nodes:,} explored): about {megabytes:.0f} MB of generated Python, seconds to "
                      "import; split it into bases that each decide from fewer inputs, or compare each numeric "
                      "input with fewer thresholds", node.span, "warning")


def compiled_warnings(compiled: Compiled, what: str, node: m.Node) -> list[Diagnostic]:
    """What check and compile say of a compiled base: the inputs it leaves unsettled, its size."""
    return [w for w in (unsettled_warning(compiled, what, node), size_warning(compiled, what, node)) if w is not None]


def unsettled_warning(compiled: Compiled, what: str, node: m.Node) -> Diagnostic | None:
    """A compiled base that leaves inputs unsettled deserves a word (check and compile alike)."""
    findings = compiled.findings
    if not findings:
        return None
    return Diagnostic("rules-unsettled", f"{what} leaves {compiled.findings_count()} case(s) of inputs unsettled "
                      f"({tally(findings)}), e.g. {describe(worst_first(findings)[0])}; `specc rules` lists them",
                      node.span, "warning")
