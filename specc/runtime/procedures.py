"""A procedure library as the supervisor runs it: predicates, primitive actions and KAs (seed 000
ch. 4). The back end `supervisor` writes one library per `procedures` block as Python source
built from these records; `specc.runtime.supervisor` interprets it.

Terms are plain values: a symbol or string is a `str`, a number an `int`/`float`, a `$x` or
`@x` variable a `Var`, and an s-expression `(HEAD arg ...)` a `Compound`. Every statement keeps
the line of the spec it came from, so traces and failures point back at the KA source.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Union

# What a predicate is (§4.4.2): `standard` facts are affirmed, negated or unknown; `closed` ones
# are true or false (absence is negation); `functional` ones hold one value (the last argument)
# per key (the others); `event` facts are consumed once used; `evaluable` ones call Python.
PREDICATE_KINDS = ("standard", "closed", "functional", "event", "evaluable")


@dataclass(frozen=True)
class Var:
    name: str  # with its sigil: `$X` unifies once, `@X` may be reassigned

    @property
    def is_program(self) -> bool:
        return self.name.startswith("@")

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class Compound:
    head: str
    args: tuple[Term, ...] = ()

    def __str__(self) -> str:
        return "(" + " ".join([self.head, *(show(a) for a in self.args)]) + ")"


Term = Union[str, int, float, Var, Compound]


def show(term: Term) -> str:
    return str(term)


@dataclass(frozen=True)
class Goal:
    op: str  # ! ? ^ => ~> # %
    expr: Compound
    line: int = 0

    def __str__(self) -> str:
        return f"{self.op}{self.expr}"


@dataclass(frozen=True)
class Step:
    """An arc of the KA graph: a goal to achieve, test, wait for, conclude or retract."""

    goal: Goal

    @property
    def line(self) -> int:
        return self.goal.line


@dataclass(frozen=True)
class If:
    """A condition node (§4.4.5): the test's success leads to `then`, its failure to `orelse`."""

    condition: Goal
    then: tuple[Statement, ...]
    orelse: tuple[Statement, ...] = ()
    line: int = 0


@dataclass(frozen=True)
class While:
    condition: Goal
    body: tuple[Statement, ...]
    line: int = 0


@dataclass(frozen=True)
class Parallel:
    """A split node and its join (§4.4.5): every branch must succeed."""

    branches: tuple[tuple[Statement, ...], ...]
    line: int = 0


@dataclass(frozen=True)
class Choose:
    """Several arcs leaving one node (§4.4.7): branches are tried in turn until one's first arc
    is crossed; after that the KA is committed to that branch (no backtracking)."""

    branches: tuple[tuple[Statement, ...], ...]
    line: int = 0


@dataclass(frozen=True)
class Assign:
    var: Var
    value: Term
    line: int = 0


@dataclass(frozen=True)
class Fail:
    line: int = 0


Statement = Union[Step, If, While, Parallel, Choose, Assign, Fail]


@dataclass(frozen=True)
class Action:
    """A primitive KA's ACTION (Fig 4.2): call a primitive, bind its value to `result`."""

    call: Compound
    result: Var | None = None
    line: int = 0


@dataclass(frozen=True)
class KA:
    name: str
    invocation: Goal | Compound  # a goal `!(...)`, or a fact pattern whose conclusion invokes it
    context: Goal | Compound | None = None
    body: tuple[Statement, ...] | None = None
    action: Action | None = None
    effects: tuple[Goal, ...] = ()
    documentation: str = ""
    properties: tuple[str, ...] = ()
    line: int = 0

    @property
    def is_meta(self) -> bool:
        return "meta" in self.properties

    @property
    def goal_invoked(self) -> bool:
        return isinstance(self.invocation, Goal)

    @property
    def trigger(self) -> Compound:
        """The goal or fact that invokes the KA."""
        return self.invocation.expr if isinstance(self.invocation, Goal) else self.invocation


@dataclass(frozen=True)
class Predicate:
    name: str
    kind: str  # one of PREDICATE_KINDS
    arity: int
    binding: str = ""  # evaluable: "python.module.function"
    # The values each argument may take where the spec gives a finite domain (`n: 0..5`,
    # `state: {GO, END}`), None where it does not (`int`, `string`); () when no argument has one.
    # What `specc verify --goal` proves assumes them: the supervisor refuses a fact outside them.
    domains: tuple[tuple[Any, ...] | None, ...] = ()

    def outside(self, args: tuple[Any, ...]) -> str | None:
        """What of `args` lies outside the declared domains, said for a message; None if nothing."""
        # A fact of another arity is the database's to refuse, not this check's.
        for index, (value, allowed) in enumerate(zip(args, self.domains, strict=False)):
            if allowed is not None and not isinstance(value, Var) and value not in allowed:
                shown = ", ".join(str(v) for v in allowed)
                return (f"{value} is outside the domain the spec declares for {self.name}'s argument {index + 1} "
                        f"({{{shown}}}), which `specc verify --goal` assumes: add {value} to it")
        return None


@dataclass(frozen=True)
class Primitive:
    name: str
    arity: int
    binding: str  # "python.module.function", called as function(ctx, *args); "" for a service
    returns: bool = False
    service: str = ""  # an executive service requested with the arguments; the value is the request's id
    # The values its result may take when the spec gives a finite domain (`-> {OK, BLOCKED}`): what
    # `specc verify --goal` assumes it returns, so the supervisor refuses any other.
    domain: tuple[Any, ...] | None = None


@dataclass(frozen=True)
class Library:
    name: str
    predicates: tuple[Predicate, ...] = ()
    primitives: tuple[Primitive, ...] = ()
    kas: tuple[KA, ...] = ()
    source: str = ""  # the spec file, for messages


# ---------------------------------------------------------------- built-in arithmetic and comparisons
# One definition for the interpreter and the Petri-net translation, so both compute alike.

COMPARISONS: dict[str, Callable[[Any, Any], bool]] = {
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b, ">=": lambda a, b: a >= b}
ARITHMETIC = ("+", "-", "*", "/")


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def compute(head: str, args: tuple[Any, ...]) -> int | float:
    """`(+ a b ...)`, `(- a)`, `(- a b ...)`, `(* ...)`, `(/ a b ...)` over numbers; ValueError
    for anything else or a division by zero."""
    if not args or not all(is_number(a) for a in args):
        raise ValueError("arithmetic on something that is not a number")
    if head == "+":
        return sum(args)
    if head == "*":
        return math.prod(args)
    if head == "-":
        return -args[0] if len(args) == 1 else args[0] - sum(args[1:])
    divisor = math.prod(args[1:])
    if divisor == 0:
        raise ValueError("division by zero")
    return args[0] / divisor


def compare(head: str, left: Any, right: Any) -> bool:
    """A comparison between two numbers; ValueError for anything else."""
    if not is_number(left) or not is_number(right):
        raise ValueError(f"{left!r} and {right!r} cannot be compared: comparisons are between numbers")
    return COMPARISONS[head](left, right)


def bindings(library: Library) -> list[str]:
    """Every "python.module.function" the library calls, sorted."""
    named = {p.binding for p in library.primitives if p.binding} | {p.binding for p in library.predicates
                                                                     if p.binding}
    return sorted(named)


def load_functions(library: Library, given: Mapping[str, Callable[..., Any]] | None = None
                   ) -> dict[str, Callable[..., Any]]:
    """The Python function behind every binding: from `given` when it has it, else imported.
    ValueError for a key of `given` no binding has (a misspelt one would leave the real function
    in its place, imported, without a word)."""
    from specc.runtime.functional import import_user_module
    from specc.runtime.hints import did_you_mean

    known = bindings(library)
    unused = sorted(set(given or ()) - set(known))
    if unused:
        raise ValueError(f"procedures '{library.name}': functions= gives '{unused[0]}', which no action or evaluable "
                         f"predicate is bound to{did_you_mean(unused[0], known)} (bound: {', '.join(known) or 'none'})")
    functions: dict[str, Callable[..., Any]] = {}
    for binding in known:
        if given is not None and binding in given:
            functions[binding] = given[binding]
            continue
        module_name, _, name = binding.rpartition(".")
        module = import_user_module(module_name, f"procedures '{library.name}'", f"the module of '{binding}'",
                                    "pass `functions=`")
        function = getattr(module, name, None)
        if not callable(function):
            raise ImportError(f"procedures '{library.name}': '{module_name}' has no function '{name}'")
        functions[binding] = function
    return functions


# ---------------------------------------------------------------- reading goals and facts

GOAL_OPERATORS = ("=>", "~>", "!", "?", "^", "#", "%")  # longest first, for the parser


def parse_term(text: str) -> Term:
    """A term written as in a spec: `(HEAD arg ...)`, `$X`, `@X`, numbers, "strings", symbols."""
    tokens = _tokens(text)
    term = _read(tokens, text)
    if tokens:
        raise ValueError(f"{text!r}: unexpected {tokens[0]!r} after the term")
    return term


def parse_goal(text: str) -> Goal:
    """A goal such as `!(COLLECT-OBJECTS 3)` or `^(REPLY $ID $RESULT)`."""
    stripped = text.strip()
    for op in GOAL_OPERATORS:
        if stripped.startswith(op):
            expr = parse_term(stripped[len(op):])
            if isinstance(expr, Compound):
                return Goal(op, expr)
    raise ValueError(f"{text!r} is not a goal: an operator ({' '.join(GOAL_OPERATORS)}) then (HEAD arg ...)")


def parse_fact(text: str) -> Compound:
    fact = parse_term(text)
    if not isinstance(fact, Compound):
        raise ValueError(f"{text!r} is not a fact (HEAD arg ...)")
    return fact


_TOKEN = re.compile(r'\s*(?:(\()|(\))|("(?:[^"\\]|\\.)*")|([^\s()"]+))')


def _tokens(text: str) -> list[str]:
    tokens: list[str] = []
    position = 0
    while position < len(text.rstrip()):
        found = _TOKEN.match(text, position)
        if found is None:
            raise ValueError(f"{text!r}: cannot read from {text[position:]!r}")
        tokens.append(found.group(found.lastindex or 0))
        position = found.end()
    return tokens


def _read(tokens: list[str], text: str) -> Term:
    if not tokens:
        raise ValueError(f"{text!r}: a term is missing")
    token = tokens.pop(0)
    if token == ")":
        raise ValueError(f"{text!r}: unbalanced ')'")
    if token != "(":
        return _atom(token)
    if not tokens or tokens[0] in "()":
        raise ValueError(f"{text!r}: '(' must be followed by a head symbol")
    head = tokens.pop(0)
    args: list[Term] = []
    while tokens and tokens[0] != ")":
        args.append(_read(tokens, text))
    if not tokens:
        raise ValueError(f"{text!r}: missing ')'")
    tokens.pop(0)
    return Compound(head, tuple(args))


_INTEGER = re.compile(r"-?\d+")
_REAL = re.compile(r"-?(\d+\.\d*|\.\d+|\d+(?=[eE]))([eE][-+]?\d+)?")  # 2.5, .5, 1e9 (as specs write them)


def _atom(token: str) -> Term:
    if token.startswith('"'):
        return re.sub(r"\\(.)", r"\1", token[1:-1])
    if token[0] in "$@" and len(token) > 1:
        return Var(token)
    return literal(token)


def literal(token: str) -> str | int | float:
    """The value a constant written `token` stands for: a whole number, a real number (2.5, 1e9),
    or else a symbol. One reading for goals, facts and the values of a type (`{1.5, 10}`), so that
    a goal's 1.5 is the type's 1.5."""
    if _INTEGER.fullmatch(token):
        return int(token)
    if _REAL.fullmatch(token):
        number = float(token)
        if not math.isfinite(number):  # 1e999: no symbol either; what a spec's number gets
            raise ValueError(f"number {token} is too large")
        return number
    return token
