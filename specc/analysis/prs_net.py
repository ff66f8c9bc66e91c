"""PRS procedures -> coloured Petri net, along seed 000 §4.4 (the converter §4.6 lists as future work).

What maps to what:
- a KA node is a place whose tokens are the KA's variables carried there: those already bound
  (or possibly bound) that a later statement still uses, plus the invocation's variables, kept to
  the end so a goal's answer names its arguments (§4.4.3); an unbound variable has colour IDLE;
- a KA has INIT (context test) -> START ... END (effects) -> TERM, and FAIL (§4.4.8);
- each statement is a token router from its node to the next one (T) or to FAIL (F) (§4.4.1):
  tests and waits read the database places, conclusions and retractions move their tokens;
- database predicates (§4.4.2): closed ones DEF/UNDEF, functional ones DEF(key, value)/UNDEF(key),
  standard ones AFF DEF/UNDEF and NEG DEF/UNDEF, basic events one place whose tokens are consumed;
- a goal `!G` is first tested in the database when anything can make G true (a conclusion, an
  initial fact, an evaluable or built-in predicate), else posted: a token in POST_G while the
  poster waits in W for SUCC_G or FAIL_G (§4.4.4); the goal's server starts the KA it invokes, or
  tries each applicable KA in turn with the tried-branches structure of Fig 4.22/4.28; the same
  structure models `choose`, whose waits race for the first event;
- condition nodes (if/while) have a T half and an F half; `parallel` splits and joins (§4.4.5);
  the first branch to fail fails the KA, the others run on and are then forgotten; branches may
  not give a value to a variable another branch uses (each token carries its own copy);
- an error the interpreter would raise (an unbound or ill-typed value in a test) fails the KA;
- fact-invoked KAs get a token in INIT when a conclusion matches their invocation (Fig 4.25);
- the executive: the KA marked `property: executive` is the request protocol (Fig 4.3); its goal
  is modelled by the services it names: a service starts when its group place is IDLE and no
  group holds a service it conflicts with (§5.4.1), then answers (an environment choice): OK, or
  with an output function any value of the answer's domain but its failures, which `--fail` adds;
- evaluable predicates and primitive actions are environment choices over their results.

Rejected with a diagnostic (§4.4.10): `#` and `%`, meta KAs, variables without a finite domain,
tests of basic events, parallel branches sharing a variable, choices whose branch does not start
with a goal.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from specc.analysis import petri
from specc.analysis.procedures import library
from specc.check.procedures import Domains
from specc.diagnostics import Diagnostic, did_you_mean, sort_key
from specc.model import nodes as m
from specc.model.visitor import walk
from specc.runtime import procedures as rp

IDLE = "IDLE"
EXECUTIVE_PROPERTY = "executive"
COMPARISONS, ARITHMETIC = rp.COMPARISONS, rp.ARITHMETIC
Env = dict[str, Any]
CONSUMED = "\0consumed"  # an Env entry: the event occurrences a solution uses up


class Undefined(Exception):
    """A term has no value here (an unbound variable, arithmetic on a symbol)."""


@dataclass(frozen=True)
class Service:
    """What the translation needs of one executive service."""

    name: str
    group: str | None  # the group place holding it while it runs
    excluded_by: tuple[tuple[str, str], ...]  # (group place, service) that must not be running
    # What the executive answers when it worked: OK, or what its output function returns (a value
    # the net cannot compute, so any value of the answer's domain).
    output_function: str | None = None
    failure_reports: frozenset[str] = frozenset()  # the report codes its module request fails with


@dataclass
class ExecutiveModel:
    services: dict[str, Service]
    groups: dict[str, tuple[str, ...]]  # group place -> its services (its colours, with IDLE)
    failing: frozenset[str] = frozenset()  # services whose answer may be a failure ("*": all)

    def may_fail(self, service: str) -> bool:
        return "*" in self.failing or service in self.failing


@dataclass(frozen=True)
class Node:
    """A place of a KA and the variables its tokens carry (plus fixed trailing colour parts)."""

    place: str
    vars: tuple[str, ...]
    extra: tuple[Any, ...] = ()

    def colour(self, env: Mapping[str, Any]) -> tuple[Any, ...]:
        return tuple(env.get(v, IDLE) for v in self.vars) + self.extra


@dataclass
class Where:
    """Where a place sits in the procedures: shown in traces and marking descriptions."""

    ka: str
    line: int
    what: str
    vars: tuple[str, ...] = ()

    def values(self, colour: Any) -> dict[str, Any]:
        """The bound variables a token of this place carries."""
        carried = colour if isinstance(colour, tuple) else ()
        return {v: c for v, c in zip(self.vars, carried, strict=False) if c != IDLE}


@dataclass
class PendingReceive:
    goal: str
    wait: Node
    target: Node
    fail: Node
    origin: str
    args: tuple[Any, ...]  # the goal's argument terms

    def posted(self, env: Env) -> tuple[Any, ...] | None:
        try:
            return tuple(argument(a, env) for a in self.args)
        except Undefined:
            return None


@dataclass
class Translation:
    net: petri.Net
    top: list[tuple[str, tuple[Any, ...]]]  # the posted goals: (goal place prefix, colour)
    environment: set[str] = field(default_factory=set)  # transitions whose choice is the world's
    errors: dict[str, tuple[str, str]] = field(default_factory=dict)  # error place -> (finding kind, meaning)
    where: dict[str, Where] = field(default_factory=dict)  # place -> KA position
    # Statements by (KA, line, n-th on the line): the places their token waits in, the names of
    # the transitions that cross them, and their text.
    statements: dict[tuple[str, int, int], list[str]] = field(default_factory=dict)
    successes: dict[tuple[str, int, int], list[str]] = field(default_factory=dict)
    # ... those of its successes that change nothing (a retraction with an unbound argument).
    idle_successes: dict[tuple[str, int, int], list[str]] = field(default_factory=dict)
    text: dict[tuple[str, int, int], str] = field(default_factory=dict)
    kas: list[str] = field(default_factory=list)
    solver: Solver | None = None  # evaluates conditions over a marking's database
    # Transition -> the firing it stands for: a statement's firings touching other places are
    # separate transitions (`name #2`), one firing all the same.
    firings: dict[str, str] = field(default_factory=dict)

    def answered(self, tokens: Callable[[str], int]) -> bool:
        """Every posted goal has its answer (SUCC or FAIL): the expected end of §4.5."""
        return all(any(tokens(f"{goal}.{outcome}") for outcome in ("SUCC", "FAIL")) for goal, _ in self.top)


class TranslationError(Exception):
    def __init__(self, diagnostics: list[Diagnostic]):
        diagnostics = sorted(diagnostics, key=sort_key)  # in the order of the files, as check reports
        super().__init__("; ".join(d.message for d in diagnostics))
        self.diagnostics = diagnostics


# ---------------------------------------------------------------- terms


def variables(term: Any) -> set[str]:
    if isinstance(term, rp.Var):
        return {term.name}
    if isinstance(term, rp.Compound):
        return set().union(*(variables(a) for a in term.args)) if term.args else set()
    if isinstance(term, rp.Goal):
        return variables(term.expr)
    return set()


def statement_vars(statement: rp.Statement) -> set[str]:
    if isinstance(statement, rp.Step):
        return variables(statement.goal)
    if isinstance(statement, rp.If):
        return variables(statement.condition) | block_vars(statement.then) | block_vars(statement.orelse)
    if isinstance(statement, rp.While):
        return variables(statement.condition) | block_vars(statement.body)
    if isinstance(statement, (rp.Parallel, rp.Choose)):
        return set().union(*(block_vars(b) for b in statement.branches))
    if isinstance(statement, rp.Assign):
        return {statement.var.name} | variables(statement.value)
    return set()


def block_vars(block: Sequence[rp.Statement]) -> set[str]:
    return set().union(*(statement_vars(s) for s in block)) if block else set()


def outputs(goal: rp.Goal) -> set[str]:
    """Program variables a test, a wait or a posted goal gives a value to: those standing as a
    predicate's or a goal's argument. Their previous value is not used (`@x` may be reassigned
    at any time; a loop's second turn tests the database afresh)."""
    if goal.op in ("=>", "~>"):
        return set()
    if goal.op == "!" and goal.expr.head == "=":
        target = goal.expr.args[0]
        return {target.name} if isinstance(target, rp.Var) and target.is_program else set()
    return _outputs(goal.expr)


def _outputs(expr: rp.Compound) -> set[str]:
    if expr.head in ("&", "|", "~"):
        return set().union(*(_outputs(a) for a in expr.args if isinstance(a, rp.Compound))) if expr.args else set()
    if expr.head in COMPARISONS or expr.head in ARITHMETIC or expr.head == "=":
        return set()
    return {a.name for a in expr.args if isinstance(a, rp.Var) and a.is_program}


def reads(goal: rp.Goal) -> set[str]:
    """The variables whose value a goal uses (a program variable the goal itself gives a value
    to is not: `^(& (OBJ-FOUND @I) (> @I @TAKEN))` reads @TAKEN only)."""
    return _reads(goal.expr, goal.op in ("=>", "~>")) - outputs(goal)


def _reads(term: Any, everything: bool) -> set[str]:
    if isinstance(term, rp.Var):
        return {term.name}
    if not isinstance(term, rp.Compound):
        return set()
    if everything or term.head in COMPARISONS or term.head in ARITHMETIC:
        return variables(term)
    found: set[str] = set()
    for a in term.args:
        if isinstance(a, rp.Var):
            # A program variable a predicate's argument is given afresh (`outputs`); one that `=`
            # compares is read, as the interpreter reads it: `?(= @R B)` tests the value @R holds.
            if not a.is_program or term.head == "=":
                found.add(a.name)
        else:
            found |= _reads(a, term.head == "=")
    return found


def live_before(block: Sequence[rp.Statement], after: set[str]) -> set[str]:
    live = set(after)
    for statement in reversed(block):
        live = _live_statement(statement, live)
    return live


def _live_statement(statement: rp.Statement, after: set[str]) -> set[str]:
    if isinstance(statement, rp.Step):
        return (after - outputs(statement.goal)) | reads(statement.goal)
    if isinstance(statement, rp.Assign):
        return (after - {statement.var.name}) | variables(statement.value)
    if isinstance(statement, rp.If):
        # The T half has the condition's outputs afresh; the F half sees their old values.
        then = live_before(statement.then, after) - outputs(statement.condition)
        return then | live_before(statement.orelse, after) | reads(statement.condition)
    if isinstance(statement, rp.While):
        live = after | reads(statement.condition)
        while True:  # the loop head sees what the body needs on its next turn
            grown = live | (live_before(statement.body, live) - outputs(statement.condition))
            if grown == live:
                return live
            live = grown
    if isinstance(statement, (rp.Parallel, rp.Choose)):
        return after.union(*(live_before(b, after) for b in statement.branches))
    return set()  # fail: nothing after it runs


def evaluate(term: Any, env: Mapping[str, Any]) -> Any:
    if isinstance(term, rp.Var):
        value = env.get(term.name, IDLE)
        if value == IDLE:
            raise Undefined(term.name)
        return value
    if isinstance(term, rp.Compound):
        if term.head not in ARITHMETIC:
            raise Undefined(str(term))
        try:  # as the interpreter computes: its values must stay in the variables' domains
            return rp.compute(term.head, tuple(evaluate(a, env) for a in term.args))
        except ValueError:
            raise Undefined(str(term)) from None
    return term


def argument(term: Any, env: Mapping[str, Any], posted: bool = True) -> Any:
    """An argument's colour: its value, or IDLE for an unbound variable; a posted goal's
    program variable is IDLE too, as it receives the answer (see `outputs`)."""
    if isinstance(term, rp.Var):
        return IDLE if posted and term.is_program else env.get(term.name, IDLE)
    return evaluate(term, env)


def unify_into(pattern: Sequence[Any], values: Sequence[Any], env: Env) -> Env | None:
    """`env` extended so that the pattern's arguments match `values` (IDLE matches anything)."""
    out = dict(env)
    for term, value in zip(pattern, values, strict=True):
        if isinstance(term, rp.Var):
            current = out.get(term.name, IDLE)
            if current == IDLE:
                out[term.name] = value
            elif value != IDLE and current != value:
                return None
        else:
            try:
                constant = evaluate(term, out)
            except Undefined:
                return None
            if value != IDLE and constant != value:
                return None
    return out


def compatible(posted: Sequence[Any], answer: Sequence[Any]) -> bool:
    return all(p == IDLE or p == a for p, a in zip(posted, answer, strict=True))


# ---------------------------------------------------------------- the database


@dataclass(frozen=True)
class KeyState:
    """One possible state of one database key and the tokens that witness it."""

    predicate: str
    key: tuple[Any, ...]
    value: Any  # closed/standard: DEF|UNDEF / AFF|NEG|UNKNOWN; functional: the value or UNDEF
    takes: tuple[tuple[str, Any], ...]
    puts: tuple[tuple[str, Any], ...]  # what a read puts back


class Database:
    """The places of the database predicates and the states a test may find them in."""

    def __init__(self, predicates: Mapping[str, rp.Predicate], domains: Domains):
        self.predicates = predicates
        self.domains = domains
        self.used: set[str] = set()

    def kind(self, name: str) -> str:
        predicate = self.predicates.get(name)
        return predicate.kind if predicate is not None else "standard"

    def argument_values(self, name: str, index: int) -> tuple[Any, ...]:
        values = self.domains.argument(name, index)
        return values if values is not None else ()

    def keys(self, name: str, args: Sequence[Any]) -> list[tuple[Any, ...]]:
        """Ground keys of `name` matching `args` (IDLE stands for any value)."""
        kind = self.kind(name)
        arity = len(args) - 1 if kind == "functional" else len(args)
        choices = [self.argument_values(name, i) if args[i] == IDLE else (args[i],) for i in range(arity)]
        return [tuple(k) for k in itertools.product(*choices)]

    def all_keys(self, name: str) -> list[tuple[Any, ...]]:
        predicate = self.predicates[name]
        arity = predicate.arity - 1 if predicate.kind == "functional" else predicate.arity
        return [tuple(k) for k in itertools.product(*(self.argument_values(name, i) for i in range(arity)))]

    def states(self, name: str, key: tuple[Any, ...]) -> list[KeyState]:
        self.used.add(name)
        kind = self.kind(name)
        if kind == "closed":
            return [KeyState(name, key, s, ((f"{name}.{s}", key),), ((f"{name}.{s}", key),)) for s in ("DEF", "UNDEF")]
        if kind == "functional":
            undefined = KeyState(name, key, "UNDEF", ((f"{name}.UNDEF", key),), ((f"{name}.UNDEF", key),))
            values = self.argument_values(name, self.predicates[name].arity - 1)
            return [undefined] + [KeyState(name, key, v, ((f"{name}.DEF", key + (v,)),), ((f"{name}.DEF", key + (v,)),))
                                  for v in values]
        if kind == "event":
            present = KeyState(name, key, "PRESENT", ((f"{name}.EVENT", key),), ())
            return [present, KeyState(name, key, "ABSENT", (), ())]
        pairs = {"AFF": ("DEF", "UNDEF"), "NEG": ("UNDEF", "DEF"), "UNKNOWN": ("UNDEF", "UNDEF")}
        result = []
        for state, (aff, neg) in pairs.items():
            tokens = ((f"{name}.AFF.{aff}", key), (f"{name}.NEG.{neg}", key))
            result.append(KeyState(name, key, state, tokens, tokens))
        return result

    def places(self) -> Iterator[tuple[str, list[Any], dict[Any, int]]]:
        """(place, colours, initial marking) of every predicate a statement touched."""
        for name in sorted(self.used):
            kind = self.kind(name)
            keys = self.all_keys(name)
            if kind == "closed":
                yield f"{name}.DEF", keys, {}
                yield f"{name}.UNDEF", keys, {k: 1 for k in keys}
            elif kind == "functional":
                values = self.argument_values(name, self.predicates[name].arity - 1)
                yield f"{name}.DEF", [k + (v,) for k in keys for v in values], {}
                yield f"{name}.UNDEF", keys, {k: 1 for k in keys}
            elif kind == "event":
                yield f"{name}.EVENT", keys, {}
            else:
                for sign in ("AFF", "NEG"):
                    yield f"{name}.{sign}.DEF", keys, {}
                    yield f"{name}.{sign}.UNDEF", keys, {k: 1 for k in keys}


@dataclass
class Reading:
    """States chosen for the keys a condition looks at, and what the condition found."""

    states: dict[tuple[str, tuple[Any, ...]], KeyState]
    choices: dict[tuple[str, tuple[Any, ...]], bool] = field(default_factory=dict)  # evaluable outcomes


class Solver:
    """Evaluates a PRS condition over one reading of the database, as the interpreter would:
    `&` left to right, `|` either side, `~` negation (as failure for closed predicates)."""

    def __init__(self, database: Database):
        self.db = database

    def atoms(self, expr: rp.Compound, env: Env) -> list[tuple[str, tuple[Any, ...]]]:
        """The keys a condition may look at, given what is bound now (later conjuncts may bind
        more, so unbound arguments range over their domain)."""
        head = expr.head
        if head in ("&", "|", "~"):
            return [k for a in expr.args if isinstance(a, rp.Compound) for k in self.atoms(a, env)]
        if head in COMPARISONS or head in ARITHMETIC or head in ("=", "BOUNDP") or self.db.kind(head) == "evaluable":
            return []
        args = []
        for a in expr.args:
            try:
                args.append(argument(a, env))
            except Undefined:
                args.append(IDLE)
        return [(head, key) for key in self.db.keys(head, args)]

    def problems(self, expr: rp.Compound) -> list[str]:
        """What makes a condition given from outside the specs (a --reach query) unable to mean
        anything: an unknown predicate, a wrong number of arguments, a value outside a domain."""
        head, args = expr.head, expr.args
        if head in ("&", "|", "~"):
            return [p for a in args if isinstance(a, rp.Compound) for p in self.problems(a)]
        if head in COMPARISONS or head in ARITHMETIC or head in ("=", "BOUNDP"):
            return []
        predicate = self.db.predicates.get(head)
        if predicate is None:
            known = ", ".join(sorted(self.db.predicates))
            return [f"no predicate '{head}'{did_you_mean(head, self.db.predicates)} (predicates: {known})"]
        if len(args) != predicate.arity:
            return [f"'{head}' takes {predicate.arity} argument(s), {len(args)} given in '{expr}'"]
        found = []
        for i, arg in enumerate(args):
            values = self.db.domains.argument(head, i)
            if not isinstance(arg, (rp.Var, rp.Compound)) and values is not None and arg not in values:
                found.append(f"{arg} is not in the domain of argument {i + 1} of '{head}' "
                             f"({', '.join(map(str, values))})")
        return found

    def readings(self, expr: rp.Compound, env: Env) -> Iterator[Reading]:
        keys = list(dict.fromkeys(self.atoms(expr, env)))
        evaluables = [a for a in _subterms(expr) if self.db.kind(a.head) == "evaluable"]
        for combination in itertools.product(*(self.db.states(name, key) for name, key in keys)):
            states = dict(zip(keys, combination, strict=True))
            for outcomes in itertools.product((True, False), repeat=len(evaluables)):
                yield Reading(states, choices={(a.head, tuple(a.args)): o for a, o in
                                               zip(evaluables, outcomes, strict=True)})

    def solve(self, expr: rp.Compound, env: Env, reading: Reading) -> list[Env]:
        head, args = expr.head, expr.args
        if head == "&":
            envs = [env]
            for conjunct in args:
                envs = [e2 for e in envs for e2 in self.solve(_compound(conjunct), e, reading)]
            return envs
        if head == "|":  # the interpreter looks at the right side only when the left has no solution
            found: list[Env] = []
            for disjunct in args:
                try:
                    found.extend(self.solve(_compound(disjunct), env, reading))
                except Undefined:
                    if not found:
                        raise
            return found
        if head == "~":
            inner = _compound(args[0])
            builtin = inner.head in (*COMPARISONS, "=", "&", "|", "~", "BOUNDP")
            if self.db.kind(inner.head) == "standard" and not builtin:
                return self._atom(inner, env, reading, negated=True)
            return [] if self.solve(inner, env, reading) else [env]
        if head in COMPARISONS:
            left, right = (evaluate(a, env) for a in args)  # unbound: Undefined, an error
            try:
                return [env] if rp.compare(head, left, right) else []
            except ValueError:
                raise Undefined(str(expr)) from None
        if head == "=":
            return self._equal(args[0], args[1], env)
        if head == "BOUNDP":  # §4.4.6: are the arguments bound?
            return [env] if all(env.get(a.name, IDLE) != IDLE for a in args if isinstance(a, rp.Var)) else []
        if self.db.kind(head) == "evaluable":
            for a in args:
                evaluate(a, env)  # an evaluable predicate needs its arguments bound
            return [env] if reading.choices.get((head, tuple(args)), False) else []
        return self._atom(expr, env, reading, negated=False)

    def _equal(self, left: Any, right: Any, env: Env) -> list[Env]:
        for var, other in ((left, right), (right, left)):
            if isinstance(var, rp.Var) and env.get(var.name, IDLE) == IDLE:
                return [{**env, var.name: evaluate(other, env)}]  # both unbound: Undefined
        return [env] if evaluate(left, env) == evaluate(right, env) else []

    def _atom(self, expr: rp.Compound, env: Env, reading: Reading, negated: bool) -> list[Env]:
        kind = self.db.kind(expr.head)
        found = []
        for (name, key), state in reading.states.items():
            if name != expr.head:
                continue
            if kind == "functional":
                if state.value == "UNDEF":
                    continue
                values: tuple[Any, ...] = key + (state.value,)
            elif kind == "closed":
                if state.value != "DEF":
                    continue
                values = key
            elif kind == "event":
                if state.value != "PRESENT":
                    continue
                values = key
            else:
                if state.value != ("NEG" if negated else "AFF"):
                    continue
                values = key
            extended = unify_into(expr.args, values, env)
            if extended is not None:
                if kind == "event":  # this solution uses that occurrence up
                    extended[CONSUMED] = (*extended.get(CONSUMED, ()), (name, key))
                found.append(extended)
        return found


def _compound(term: Any) -> rp.Compound:
    if not isinstance(term, rp.Compound):
        raise Undefined(str(term))
    return term


def _subterms(expr: rp.Compound) -> Iterator[rp.Compound]:
    yield expr
    for a in expr.args:
        if isinstance(a, rp.Compound):
            yield from _subterms(a)


# ---------------------------------------------------------------- building the net


class Emitter:
    """Collects elementary firings and groups them into coloured transitions: firings of one
    statement that touch the same places become one transition whose bindings list them."""

    def __init__(self) -> None:
        self.firings: dict[tuple[str, tuple[str, ...], tuple[str, ...]], dict[tuple[Any, ...], None]] = {}
        self.origins: dict[str, str] = {}
        self.colours: dict[str, dict[Any, None]] = {}
        self.names: dict[tuple[str, tuple[str, ...], tuple[str, ...]], str] = {}

    def fire(self, name: str, origin: str, takes: Iterable[tuple[str, Any]], puts: Iterable[tuple[str, Any]]) -> None:
        takes, puts = sorted(takes, key=repr), sorted(puts, key=repr)
        key = (name, tuple(p for p, _ in takes), tuple(p for p, _ in puts))
        self.firings.setdefault(key, {})[tuple(c for _, c in takes) + tuple(c for _, c in puts)] = None
        self.origins[name] = origin
        for place, colour in (*takes, *puts):
            self.colours.setdefault(place, {})[colour] = None

    def build(self, net: petri.Net, initial: Mapping[str, Mapping[Any, int]],
              colours: Mapping[str, Sequence[Any]]) -> dict[str, str]:
        """Declare every place and transition; returns transition -> firing name."""
        for place in sorted(set(self.colours) | set(initial) | set(colours)):
            known = dict.fromkeys(colours.get(place, ()))
            known.update(self.colours.get(place, {}))
            known.update(dict.fromkeys(initial.get(place, {})))
            net.place(place, [_colour(c) for c in known], {_colour(c): n for c, n in initial.get(place, {}).items()})
        counts: dict[str, int] = {}
        firings: dict[str, str] = {}
        for key in sorted(self.firings, key=repr):
            name, takes, puts = key
            counts[name] = counts.get(name, 0) + 1
            unique = name if counts[name] == 1 else f"{name} #{counts[name]}"
            inputs = [petri.Arc(p, colour=_pick(i)) for i, p in enumerate(takes)]
            outputs = [petri.Arc(p, colour=_pick(len(takes) + i)) for i, p in enumerate(puts)]
            bindings = [{str(i): _colour(c) for i, c in enumerate(row)} for row in self.firings[key]]
            net.transition(unique, inputs, outputs, bindings=bindings, origin=self.origins[name])
            firings[unique] = name
        return firings



def _colour(colour: Any) -> Any:
    """Tokens of places without variables are black."""
    return petri.BLACK if colour == () else colour


def _pick(index: int) -> Callable[[Mapping[str, Any]], Any]:
    return lambda binding: binding[str(index)]


class Translator:
    def __init__(self, procedures: m.Procedures, executive: ExecutiveModel | None):
        self.node_ast = procedures
        self.library = library(procedures)
        self.kas = {k.name: k for k in self.library.kas}
        self.predicates = {p.name: p for p in self.library.predicates}
        self.domains = Domains(procedures)
        self.db = Database(self.predicates, self.domains)
        self.solver = Solver(self.db)
        self.executive = executive
        self.emit = Emitter()
        self.diagnostics: list[Diagnostic] = []
        self.pending: list[PendingReceive] = []
        self.posted: dict[str, dict[tuple[Any, ...], None]] = {}  # goal -> colours posted
        self._heard: dict[tuple[str, ...], bool] = {}  # _hears_warnings, by the protocol's KAs
        self.translated: dict[str, None] = {}
        self.var_domains: dict[str, dict[str, tuple[Any, ...]]] = {}
        self.result = Translation(petri.Net(procedures.name), [])
        self.initial_heads: set[str] = set()  # predicates the database starts with
        self.concluded: set[str] = set()  # predicates the translated KAs conclude
        # Where an error in a statement goes: the enclosing parallel branch's failure, or FAIL.
        self._aborts: list[Node] = []
        self._keys: list[tuple[str, int, int]] = []  # the statements being translated, innermost last

    # ------------------------------------------------------------ entry
    def translate(self, goals: Sequence[rp.Goal], facts: Sequence[rp.Compound]) -> Translation:
        for goal in goals:
            self._check_posted(goal)
        self.initial_heads = {f.head for f in facts}
        self._select_kas(goals, facts)
        if self.diagnostics:
            raise TranslationError(self.diagnostics)
        for name in self.translated:
            self._ka(self.kas[name])
        if self.diagnostics:  # what the statements' translation could not represent
            raise TranslationError(self.diagnostics)
        for goal in goals:
            posted = tuple(argument(a, {}) for a in goal.expr.args)
            self.posted.setdefault(goal.expr.head, {})[posted] = None
            self.result.top.append((goal.expr.head, posted))
        self._servers()
        if self.diagnostics:  # a request protocol the net cannot answer
            raise TranslationError(self.diagnostics)
        initial: dict[str, dict[Any, int]] = {}
        colours: dict[str, list[Any]] = {}
        for place, place_colours, marking in self.db.places():
            colours[place] = place_colours
            initial[place] = dict(marking)
        for fact in facts:
            self._initial_fact(fact, initial)
        for head, posted in self.result.top:
            initial.setdefault(f"{head}.POST", {})[posted] = initial.get(f"{head}.POST", {}).get(posted, 0) + 1
        if self.executive is not None:
            for group, services in self.executive.groups.items():
                if group in self.emit.colours:
                    colours[group] = [IDLE, *services]
                    initial[group] = {IDLE: 1}
        self.result.firings = self.emit.build(self.result.net, initial, colours)
        self.result.kas = list(self.translated)
        self.result.solver = self.solver
        return self.result

    def _check_posted(self, goal: rp.Goal) -> None:
        """A goal given on the command line: `!(HEAD value ...)` for a goal some KA achieves or a
        declared predicate, with the right number of arguments, each in its domain."""
        head, args = goal.expr.head, goal.expr.args
        if goal.op != "!":
            raise ValueError(f"only achievement goals '!(...)' can be posted, not '{goal}'")
        invoked = [k for k in self.library.kas if k.goal_invoked and k.trigger.head == head]
        if head not in self.predicates and not invoked:
            known = {k.trigger.head for k in self.library.kas if k.goal_invoked} | set(self.predicates)
            raise ValueError(f"no KA achieves '{head}' and no predicate is called so{did_you_mean(head, known)}: "
                             f"'{goal}' cannot be posted")
        arity = self.predicates[head].arity if head in self.predicates else len(invoked[0].trigger.args)
        if len(args) != arity:
            raise ValueError(f"'{head}' takes {arity} argument(s), {len(args)} given in '{goal}'")
        for i, arg in enumerate(args):
            values = self.domains.argument(head, i)
            if isinstance(arg, rp.Compound) or (isinstance(arg, rp.Var) and arg.is_program):
                raise ValueError(f"argument {i + 1} of '{goal}' must be a value or a $variable")
            if not isinstance(arg, rp.Var) and values is not None and arg not in values:
                raise ValueError(f"{arg} is not in the domain of argument {i + 1} of '{head}' "
                                 f"({', '.join(map(str, values))})")

    def _initial_fact(self, fact: rp.Compound, initial: dict[str, dict[Any, int]]) -> None:
        name, args = fact.head, tuple(fact.args)
        kind = self.db.kind(name)
        self.db.used.add(name)
        if name not in self.predicates or kind in ("evaluable", "event"):
            raise ValueError(f"'{fact}' cannot start in the database: declare '{name}' as a closed, functional or "
                             "standard predicate")
        if len(args) != self.predicates[name].arity:
            raise ValueError(f"'{fact}': a fact gives '{name}' {self.predicates[name].arity} value(s), "
                             f"{len(args)} given")
        if any(isinstance(a, (rp.Var, rp.Compound)) for a in args):
            raise ValueError(f"'{fact}': a fact is ground: give each argument a value, not a variable or an "
                             "expression")
        for i, arg in enumerate(args):  # a functional predicate's value too: the net has no place for another
            values = self.domains.argument(name, i)
            if values is not None and arg not in values:
                raise ValueError(f"'{fact}': {arg} is not in the domain of argument {i + 1} of '{name}' "
                                 f"({', '.join(map(str, values))})")
        for place, _, marking in self.db.places():
            initial.setdefault(place, dict(marking))
        key = args[:-1] if kind == "functional" else args
        undefined = f"{name}.UNDEF" if kind in ("closed", "functional") else f"{name}.AFF.UNDEF"
        if initial.get(undefined, {}).get(key, 0) != 1:
            given = "a value" if kind == "functional" else "its truth"
            raise ValueError(f"'{fact}' is given twice: each fact of '{name}' is given {given} once")
        initial[undefined][key] = 0
        defined = {"closed": f"{name}.DEF", "functional": f"{name}.DEF"}.get(kind, f"{name}.AFF.DEF")
        colour = key + (args[-1],) if kind == "functional" else key
        initial.setdefault(defined, {})[colour] = 1

    # ------------------------------------------------------------ which KAs
    def _select_kas(self, goals: Sequence[rp.Goal], facts: Sequence[rp.Compound]) -> None:
        """The KAs the posted goals can reach: goal-invoked KAs through the goals bodies post,
        fact-invoked KAs through the facts they conclude; each checked against what a net can
        represent."""
        work = [("goal", g.expr.head) for g in goals] + [("fact", f.head) for f in facts]
        seen: set[tuple[str, str]] = set()
        while work:
            item = work.pop()
            if item in seen:
                continue
            seen.add(item)
            kind, head = item
            for ka in self.library.kas:
                if ka.name in self.translated or ka.trigger.head != head or ka.goal_invoked != (kind == "goal"):
                    continue
                if ka.is_meta:
                    self._reject(ka, f"meta KA '{ka.name}' chooses among KAs for '{head}': a Petri net cannot "
                                 "represent meta-level reasoning (§4.4.10); verify without it or drop the property",
                                 "unsupported-meta")
                    continue
                self.translated[ka.name] = None
                if EXECUTIVE_PROPERTY in ka.properties:
                    self._check_executive_ka(ka)
                    continue
                self.var_domains[ka.name] = self._infer_domains(ka)
                posted, concluded = self._posted_heads(ka)
                self.concluded |= concluded
                work.extend(("goal", h) for h in posted)
                work.extend(("fact", h) for h in concluded)

    def _posted_heads(self, ka: rp.KA) -> tuple[list[str], set[str]]:
        posted: list[str] = []
        concluded: set[str] = set()
        for goal in _goals(ka):
            if goal.op in ("#", "%"):
                self._reject(ka, f"'{goal.op}' (preserve/maintain) has no Petri-net equivalent (§4.4.10); "
                             "use a fact-invoked KA that reacts when the condition changes", "unsupported-goal",
                             line=goal.line, op=goal.op)
            elif goal.op == "!" and goal.expr.head != "=":
                posted.append(goal.expr.head)
            elif goal.op == "=>":
                concluded.add(_positive(goal.expr).head)
        return posted, concluded

    def _check_executive_ka(self, ka: rp.KA) -> None:
        if self.executive is None:
            self._reject(ka, f"KA '{ka.name}' is the executive's request protocol but no system connects these "
                         "procedures to an executive: add 'supervisor:' and 'executive:' to a system block",
                         "no-executive")
        elif not isinstance(ka.invocation, rp.Goal) or len(ka.trigger.args) < 2:
            self._reject(ka, f"the executive KA '{ka.name}' must be invoked by a goal naming a service first and "
                         "its result last, like !(EXEC-REQUEST $REQUEST $RESULT)", "bad-executive-ka")

    def _infer_domains(self, ka: rp.KA) -> dict[str, tuple[Any, ...]]:
        """Each variable's values: those of the predicate arguments it stands for, widened by
        what it is compared with or assigned; rejected when none is finite."""
        found: dict[str, dict[Any, None]] = {}
        unbounded: set[str] = set()
        links: list[tuple[str, Any]] = []
        primitives = {p.name: p for p in self.library.primitives}
        params = {a.name: a.params for a in self.node_ast.actions}

        def note(var: str, values: tuple[Any, ...] | None) -> None:
            if values is None:
                unbounded.add(var)
            else:
                found.setdefault(var, {}).update(dict.fromkeys(values))

        for expr in _compounds(ka):
            if expr.head in COMPARISONS or expr.head == "=":
                left, right = expr.args
                if isinstance(left, rp.Var):
                    links.append((left.name, right))
                if isinstance(right, rp.Var):
                    links.append((right.name, left))
                continue
            if expr.head in ("&", "|", "~") or expr.head in ARITHMETIC:
                continue
            for i, arg in enumerate(expr.args):
                if isinstance(arg, rp.Var):
                    if expr.head in self.predicates or self.domains.params.get(expr.head) is not None:
                        note(arg.name, self.domains.argument(expr.head, i))
        if ka.action is not None:
            primitive = primitives.get(ka.action.call.head)
            for i, arg in enumerate(ka.action.call.args):
                if isinstance(arg, rp.Var) and primitive is not None and i < len(params.get(primitive.name, ())):
                    note(arg.name, self.domains.values(params[primitive.name][i].domain))
            if ka.action.result is not None:
                decl = next((a for a in self.node_ast.actions if a.name == ka.action.call.head), None)
                note(ka.action.result.name, self.domains.values(decl.result) if decl and decl.result else None)
        for statement in _statements(ka.body or ()):
            if isinstance(statement, rp.Assign):
                links.append((statement.var.name, statement.value))
        grown, bounds = True, None
        while grown:
            changed = True
            while changed:  # comparisons and assignments share domains both ways
                changed = False
                for var, other in links:
                    if isinstance(other, rp.Var):
                        for a, b in ((var, other.name), (other.name, var)):
                            before = len(found.get(a, {}))
                            if b in found:
                                found.setdefault(a, {}).update(found[b])
                            changed |= len(found.get(a, {})) != before
                    elif not isinstance(other, rp.Compound):
                        before = len(found.get(var, {}))
                        found.setdefault(var, {})[other] = None
                        changed |= len(found[var]) != before
            if bounds is None:  # the numbers given and compared with, before any arithmetic
                bounds = {var: (min(numbers), max(numbers)) for var, values in found.items()
                          if (numbers := [v for v in values if rp.is_number(v)])}
            grown = _arithmetic_closure(links, found, bounds)
        every = {v for expr in _compounds(ka) for v in variables(expr)}
        if ka.action is not None and ka.action.result is not None:
            every.add(ka.action.result.name)
        for statement in _statements(ka.body or ()):
            if isinstance(statement, rp.Assign):
                every.add(statement.var.name)
        # A request's id, waited for in its reply: the net follows requests only in the executive's
        # request protocol (a KA with `property: executive`), whose id it leaves out.
        waited = {v for statement in _statements(ka.body or ()) if isinstance(statement, rp.Step)
                  and statement.goal.op == "^" for v in variables(statement.goal.expr)}
        if ka.action is not None and ka.action.result is not None:
            waited.add(ka.action.result.name)
        for var in sorted(every):
            if var in unbounded:
                protocol = (" (a request's id: send the request and wait for its reply in a KA with `property: "
                            "executive`, the request protocol, which the net models without the id; see "
                            "docs/your-robot.md)" if var in waited and EXECUTIVE_PROPERTY not in ka.properties else "")
                self._reject(ka, f"variable {var} of KA '{ka.name}' ranges over an unbounded domain (int, string...): "
                             f"give the predicate argument it stands for a finite domain, e.g. 0..5 or {{A, B}}"
                             f"{protocol}", "unbounded-variable", var=var)
            elif var not in found:
                self._reject(ka, f"the values of variable {var} of KA '{ka.name}' cannot be told: use it as the "
                             "argument of a predicate with a finite domain", "unbounded-variable", var=var)
        return {v: tuple(values) for v, values in found.items()}

    # ------------------------------------------------------------ diagnostics
    def _reject(self, ka: rp.KA | None, message: str, code: str, line: int | None = None,
                var: str | None = None, op: str | None = None) -> None:
        span = self.node_ast.span
        if ka is not None:
            node = next(k for k in self.node_ast.kas if k.name == ka.name)
            span = node.span
            for item in walk(node):
                item_span = getattr(item, "span", None)
                if item_span is None:
                    continue
                if var is not None and isinstance(item, (m.LogicVar, m.ProgramVar)) and item.name == var:
                    span = item_span
                    break
                if line is not None and isinstance(item, m.Goal) and item_span.line == line and op in (None, item.op):
                    span = item_span
                    break
                if var is None and line is None and isinstance(item, m.Word) and item == "meta":
                    span = item_span
                    break
        self.diagnostics.append(Diagnostic(code, message, span))

    # ------------------------------------------------------------ KAs
    def _tokens(self, ka: str, node: Node) -> Iterator[Env]:
        domains = self.var_domains.get(ka, {})
        for values in itertools.product(*((IDLE, *domains.get(v, ())) for v in node.vars)):
            yield dict(zip(node.vars, values, strict=True))

    def _node(self, ka: rp.KA, suffix: str, carried: Iterable[str], line: int, what: str) -> Node:
        place = f"{ka.name}.{suffix}"
        if suffix.startswith("L"):
            # Statements are named by their line; several on one line get a place each.
            taken = 1
            while place in self.result.where:
                taken += 1
                place = f"{ka.name}.{suffix}#{taken}"
        # The invocation's variables travel to the end (§4.4.3): the answer names the goal.
        node = Node(place, tuple(sorted(set(carried) | self._invocation_vars(ka))))
        self.result.where[place] = Where(ka.name, line, what, node.vars)
        return node

    def _invocation_vars(self, ka: rp.KA) -> set[str]:
        return variables(ka.trigger)

    def init_node(self, ka: rp.KA) -> Node:
        return self._node(ka, "INIT", self._invocation_vars(ka), ka.line, "invoked")

    def term_node(self, ka: rp.KA) -> Node:
        return self._node(ka, "TERM", self._invocation_vars(ka), ka.line, "succeeded")

    def fail_node(self, ka: rp.KA) -> Node:
        return self._node(ka, "FAIL", self._invocation_vars(ka), ka.line, "failed")

    def _ka(self, ka: rp.KA) -> None:
        if EXECUTIVE_PROPERTY in ka.properties:
            return  # modelled by the executive's services (see _executive_server)
        invocation = self._invocation_vars(ka)
        init, term, fail = self.init_node(ka), self.term_node(ka), self.fail_node(ka)
        if not ka.goal_invoked:
            # Nothing waits for the end of a fact-invoked KA (Fig 4.25).
            self._silent(ka, term, None, f"{ka.name}:{ka.line} ends")
            self._silent(ka, fail, None, f"{ka.name}:{ka.line} fails")
        effects_vars = set().union(*(variables(e) for e in ka.effects)) if ka.effects else set()
        body: tuple[rp.Statement, ...] = ka.body or ()
        end_vars = invocation | effects_vars
        context_vars = variables(ka.context) if ka.context is not None else set()
        first = body[0] if body else None
        start = self._node(ka, "START", (live_before(body, end_vars) & (invocation | context_vars)),
                           first.line if first else ka.line, _show(first) if first else "started")
        if ka.context is not None:
            condition = ka.context if isinstance(ka.context, rp.Goal) else rp.Goal("?", ka.context, ka.line)
            otherwise = fail
            if not ka.goal_invoked and self.db.kind(ka.trigger.head) == "event":
                # An event invokes only the KAs whose context holds; otherwise it stays for others.
                otherwise = self._node(ka, "CONTEXT-FALSE", (), ka.line, "not invoked: the event stays")
                for env in self._tokens(ka.name, otherwise):
                    args = tuple(argument(a, env, posted=False) for a in ka.trigger.args)
                    if IDLE not in args:
                        self.emit.fire(f"{ka.name}:{ka.line} leaves the event", f"{ka.name}:{ka.line} context",
                                       [(otherwise.place, otherwise.colour(env))],
                                       [(f"{ka.trigger.head}.EVENT", args)])
            self._test(ka, condition, init, start, otherwise, f"{ka.name}:{ka.line} context {condition}")
        else:
            self._silent(ka, init, start, f"{ka.name}:{ka.line} starts")
        produced = {ka.action.result.name} if ka.action is not None and ka.action.result is not None else set()
        end = self._node(ka, "END", end_vars & (invocation | context_vars | block_vars(body) | produced),
                         ka.line, "body done")
        if ka.action is not None:
            self._action(ka, start, end)
        else:
            self._block(ka, body, start, end, fail, invocation | context_vars, end_vars)
        node = end
        for i, effect in enumerate(ka.effects):
            following = term if i == len(ka.effects) - 1 else self._node(
                ka, f"EFFECT{i + 1}", end_vars, effect.line, f"effect {effect}")
            self._step(ka, effect, node, following, fail)
            node = following
        if not ka.effects:
            self._silent(ka, end, term, f"{ka.name}:{ka.line} ends")

    def _silent(self, ka: rp.KA, source: Node, target: Node | None, origin: str) -> None:
        for env in self._tokens(ka.name, source):
            puts = [] if target is None else [(target.place, target.colour(env))]
            self.emit.fire(origin, origin, [(source.place, source.colour(env))], puts)

    def _action(self, ka: rp.KA, start: Node, end: Node) -> None:
        """A primitive KA (Fig 4.2): with its arguments bound, its action answers any value of its
        result (primitives "never fail", §4.4.6); an unbound argument fails the KA."""
        assert ka.action is not None
        origin = f"{ka.name}:{ka.action.line} action {ka.action.call}"
        result = ka.action.result
        self.result.environment.add(origin)
        fail = self.fail_node(ka)
        for env in self._tokens(ka.name, start):
            try:
                for arg in ka.action.call.args:
                    evaluate(arg, env)
            except Undefined:
                self.emit.fire(f"{origin} [unbound]", origin, [(start.place, start.colour(env))],
                               [(fail.place, fail.colour(env))])
                continue
            values = self.var_domains[ka.name].get(result.name, ()) if result is not None else (None,)
            for value in values:
                after = dict(env) if result is None else {**env, result.name: value}
                if result is not None and not result.is_program and env.get(result.name, IDLE) not in (IDLE, value):
                    continue
                self.emit.fire(origin, origin, [(start.place, start.colour(env))], [(end.place, end.colour(after))])

    # ------------------------------------------------------------ statements
    def _block(self, ka: rp.KA, block: Sequence[rp.Statement], source: Node, target: Node, fail: Node,
               bound: set[str], live_after: set[str]) -> None:
        if not block:
            self._silent(ka, source, target, f"{ka.name}:{source.place} empty")
            return
        if isinstance(block[0], rp.While):
            # A loop head carries what the loop binds for its next turn: give it a place of its own.
            carried = live_before(block, live_after) & (bound | statement_vars(block[0]))
            head = self._node(ka, f"L{block[0].line}", carried, block[0].line, _show(block[0]))
            self._silent(ka, source, head, f"{ka.name}:{block[0].line} enters the loop")
            source = head
        nodes = [source]
        mentioned = set(bound)
        for i in range(1, len(block)):
            mentioned |= statement_vars(block[i - 1])
            loop = statement_vars(block[i]) if isinstance(block[i], rp.While) else set()
            carried = live_before(block[i:], live_after) & (mentioned | loop)
            nodes.append(self._node(ka, f"L{block[i].line}", carried, block[i].line, _show(block[i])))
        nodes.append(target)
        mentioned = set(bound)
        for i, statement in enumerate(block):
            # What is live after this statement, not after the block: a parallel's join must keep
            # the values its branches give to the statements that follow it in the block.
            self._statement(ka, statement, nodes[i], nodes[i + 1], fail, mentioned,
                            live_before(block[i + 1:], live_after))
            mentioned |= statement_vars(statement)

    def _enter(self, ka: rp.KA, statement: rp.Statement, place: str) -> str:
        """Register a statement (the n-th on its line) and where its token waits; returns how
        traces name it: KA:LINE, or KA:LINE#n after the first statement of a line."""
        line = statement.line
        n = sum(1 for key in self.result.statements if key[:2] == (ka.name, line))
        key = (ka.name, line, n)
        self._keys.append(key)
        self.result.statements[key] = [place]
        self.result.text[key] = _show(statement)
        return f"{ka.name}:{line}" + (f"#{n + 1}" if n else "")

    def _statement(self, ka: rp.KA, statement: rp.Statement, source: Node, target: Node, fail: Node,
                   bound: set[str], live_after: set[str]) -> None:
        where = self._enter(ka, statement, source.place)
        try:
            self._statement_body(ka, statement, source, target, fail, bound, live_after, where)
        finally:
            self._keys.pop()

    def _statement_body(self, ka: rp.KA, statement: rp.Statement, source: Node, target: Node, fail: Node,
                        bound: set[str], live_after: set[str], where: str) -> None:
        inside = bound | statement_vars(statement)
        if isinstance(statement, rp.Step):
            self._step(ka, statement.goal, source, target, fail, where)
        elif isinstance(statement, rp.Assign):
            self._assign(ka, statement, source, target, fail, where)
        elif isinstance(statement, rp.Fail):
            self._silent(ka, source, fail, f"{where} fail")
        elif isinstance(statement, rp.If):
            after = live_before((), live_after)
            then = self._node(ka, f"L{statement.line}.T", live_before(statement.then, after) & inside, statement.line,
                              f"if {statement.condition}: true")
            orelse = self._node(ka, f"L{statement.line}.F", live_before(statement.orelse, after) & inside,
                                statement.line, f"if {statement.condition}: false")
            self._test(ka, statement.condition, source, then, orelse, f"{where} if {statement.condition}")
            self._block(ka, statement.then, then, target, fail, inside, live_after)
            self._block(ka, statement.orelse, orelse, target, fail, inside, live_after)
        elif isinstance(statement, rp.While):
            head = live_before((statement,), live_after)
            body = self._node(ka, f"L{statement.line}.T", live_before(statement.body, head) & inside, statement.line,
                              f"while {statement.condition}: true")
            self._test(ka, statement.condition, source, body, target, f"{where} while {statement.condition}")
            self._block(ka, statement.body, body, source, fail, inside, head)
        elif isinstance(statement, rp.Parallel):
            self._parallel(ka, statement, source, target, fail, bound, live_after)
        elif isinstance(statement, rp.Choose):
            self._choose(ka, statement, source, target, fail, bound, live_after)

    def _parallel(self, ka: rp.KA, statement: rp.Parallel, source: Node, target: Node, fail: Node,
                  bound: set[str], live_after: set[str]) -> None:
        where = f"{ka.name}:{statement.line}"
        # Branches share their KA's variables in the interpreter; a token carries its own copy.
        # The two agree unless a branch gives a value to a variable another branch uses.
        for i, branch in enumerate(statement.branches):
            written = _written(branch, bound)
            for j, other in enumerate(statement.branches):
                shared = sorted(written & block_vars(other)) if i != j else []
                if shared:
                    self._reject(ka, f"branch {i + 1} of this parallel gives {shared[0]} a value that branch {j + 1} "
                                 "uses: a net gives each branch its own copy of the variables; pass the value "
                                 "through a fact, or bind it before the split", "shared-variable",
                                 var=shared[0])
                    return
        starts, ends = [], []
        for i, branch in enumerate(statement.branches):
            inside = bound | block_vars(branch)
            starts.append(self._node(ka, f"L{statement.line}.B{i + 1}", live_before(branch, live_after) & bound,
                                     statement.line, f"branch {i + 1} started"))
            ends.append(self._node(ka, f"L{statement.line}.B{i + 1}.END", live_after & inside, statement.line,
                                   f"branch {i + 1} done"))
        # The first failing branch fails the KA and turns ALIVE into DEAD; DEAD then counts the
        # branches that end or fail afterwards, and goes once all have: no stale token is left
        # to answer a later instance.
        count = len(statement.branches)
        alive = self._node(ka, f"L{statement.line}.ALIVE", (), statement.line, "parallel branches running")
        dead = self._node(ka, f"L{statement.line}.DEAD", (), statement.line, "a parallel branch failed")
        failed = [self._node(ka, f"L{statement.line}.B{i + 1}.FAIL", (), statement.line, f"branch {i + 1} failed")
                  for i in range(count)]
        for env in self._tokens(ka.name, source):
            self.emit.fire(f"{where} split", f"{where} split", [(source.place, source.colour(env))],
                           [(s.place, s.colour(env)) for s in starts] + [(alive.place, alive.colour(env))])
        for i, branch in enumerate(statement.branches):
            self._aborts.append(failed[i])
            self._block(ka, branch, starts[i], ends[i], failed[i], bound, live_after)
            self._aborts.pop()
        for i in range(count):
            for env in self._tokens(ka.name, failed[i]):
                self.emit.fire(f"{where} branch {i + 1} fails", f"{where} split",
                               [(failed[i].place, failed[i].colour(env)), (alive.place, alive.colour(env))],
                               [(fail.place, fail.colour(env))] + ([(dead.place, dead.colour(env) + (1,))]
                                                                  if count > 1 else []))
            for node, what in ((failed[i], "fails"), (ends[i], "ends")):
                for env in self._tokens(ka.name, node):
                    for done in range(1, count):
                        left = [(dead.place, dead.colour(env) + (done + 1,))] if done + 1 < count else []
                        self.emit.fire(f"{where} branch {i + 1} {what} after a failure", f"{where} split",
                                       [(node.place, node.colour(env)), (dead.place, dead.colour(env) + (done,))], left)
        for envs in itertools.product(*(list(self._tokens(ka.name, e)) for e in ends)):
            if len({alive.colour(env) for env in envs}) != 1:
                continue  # the branches of one instance share its invocation's values
            merged: Env = {}
            for env in envs:
                for var, value in env.items():
                    if merged.get(var, IDLE) == IDLE:
                        merged[var] = value
            self.emit.fire(f"{where} join", f"{where} join",
                           [(e.place, e.colour(env)) for e, env in zip(ends, envs, strict=True)]
                           + [(alive.place, alive.colour(envs[0]))],
                           [(target.place, target.colour(merged))])

    def _choose(self, ka: rp.KA, statement: rp.Choose, source: Node, target: Node, fail: Node,
                bound: set[str], live_after: set[str]) -> None:
        """Fig 4.22: a branch may be tried while it is untried; its first arc's failure marks it
        tried and gives the choice back; once every branch is tried, the KA fails."""
        where = f"{ka.name}:{statement.line}"
        count = len(statement.branches)
        live = live_before((statement,), live_after)
        trying = self._node(ka, f"L{statement.line}.TRY", live & bound, statement.line, "choosing a branch")
        for env in self._tokens(ka.name, source):
            self.emit.fire(f"{where} choose", f"{where} choose", [(source.place, source.colour(env))],
                           [(trying.place, trying.colour(env) + (0,))])
        full = (1 << count) - 1
        for env in self._tokens(ka.name, trying):
            self.emit.fire(f"{where} every branch failed", f"{where} every branch failed",
                           [(trying.place, trying.colour(env) + (full,))], [(fail.place, fail.colour(env))])
        for i, branch in enumerate(statement.branches):
            first = branch[0]
            if not isinstance(first, rp.Step):
                self._reject(ka, f"branch {i + 1} of this choice must start with a goal (its arc, §4.4.7)",
                             "choose-first-arc", line=first.line)
                continue
            inside = bound | block_vars(branch)
            chosen = self._node(ka, f"L{statement.line}.B{i + 1}", live_before(branch[1:], live_after) & inside,
                                first.line, f"branch {i + 1} chosen")
            label = self._enter(ka, first, trying.place)
            for mask in range(full + 1):
                if mask & (1 << i):
                    continue
                tried = Node(trying.place, trying.vars, (mask,))
                retry = Node(trying.place, trying.vars, (mask | (1 << i),))
                self._step(ka, first.goal, tried, chosen, retry, label)
            self._keys.pop()
            self._block(ka, branch[1:], chosen, target, fail, inside, live_after)

    def _assign(self, ka: rp.KA, statement: rp.Assign, source: Node, target: Node, fail: Node, where: str) -> None:
        origin = f"{where} assign {statement.var} = {rp.show(statement.value)}"
        domain = self.var_domains[ka.name].get(statement.var.name, ())
        for env in self._tokens(ka.name, source):
            try:
                value = evaluate(statement.value, env)
            except Undefined:
                self.emit.fire(f"{origin} [undefined]", origin, [(source.place, source.colour(env))],
                               [(fail.place, fail.colour(env))])
                continue
            self._bind_or_overflow(ka, origin, source, env, {**env, statement.var.name: value}, target,
                                   value in domain, statement.line)

    def _bind_or_overflow(self, ka: rp.KA, origin: str, source: Node, env: Env, after: Env, target: Node,
                          inside: bool, line: int) -> None:
        if inside:
            self.emit.fire(origin, origin, [(source.place, source.colour(env))], [(target.place, target.colour(after))])
        else:
            error = f"{ka.name}.L{line}.OUT-OF-DOMAIN"
            self.result.errors[error] = ("out-of-domain", f"{ka.name}:{line}: a value leaves its domain: give it a "
                                         "wider domain or keep it in range (a counter that passes every bound "
                                         "is a loop that may not end: its trace shows how it gets there)")
            self.result.where[error] = Where(ka.name, line, "value out of its domain")
            self.emit.fire(f"{origin} [out of domain]", origin, [(source.place, source.colour(env))],
                           [(error, petri.BLACK)])

    def _step(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, fail: Node, where: str = "") -> None:
        origin = f"{where or f'{ka.name}:{goal.line}'} {goal}"
        crossed = [origin] if goal.op in ("=>", "~>") else [f"{origin} [true]", f"{origin} in database [true]"]
        if where:  # a statement's (not an effect's)
            self.result.successes.setdefault(self._keys[-1], []).extend(crossed)
            if goal.op == "~>":  # Fig 4.12: an unbound argument retracts nothing, and the KA goes on
                self.result.successes[self._keys[-1]].append(f"{origin} [unbound]")
                self.result.idle_successes.setdefault(self._keys[-1], []).append(f"{origin} [unbound]")
        if goal.op == "?":
            self._test(ka, goal, source, target, fail, origin)
        elif goal.op == "^":
            self._wait(ka, goal, source, target, origin)
        elif goal.op in ("=>", "~>"):
            self._update(ka, goal, source, target, fail, origin)
        elif goal.op == "!":
            if goal.expr.head == "=":
                self._assign_goal(ka, goal, source, target, fail, origin)
            else:
                self._achieve(ka, goal, source, target, fail, origin)

    def _reads(self, reading: Reading, consumed: Sequence[tuple[str, tuple[Any, ...]]]
               ) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]]:
        """The tokens a reading looks at (put back) and the events a solution uses up."""
        takes: list[tuple[str, Any]] = []
        puts: list[tuple[str, Any]] = []
        for (name, key), state in reading.states.items():
            if self.db.kind(name) == "event" and (name, key) not in consumed:
                continue  # an event nobody used is not looked at
            takes.extend(state.takes)
            puts.extend(state.puts)
        return takes, puts

    def _test(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, fail: Node, origin: str,
              wait: bool = False) -> None:
        if any(self.db.kind(a.head) == "event" for a in _subterms(goal.expr)) and not wait:
            self._reject(ka, f"'{goal}' tests a basic event: a net can only wait for one, with ^(...) in a body or "
                         "as a fact invocation (§4.4.2)",
                         "event-test", line=goal.line, op=goal.op)
            return
        if any(self.db.kind(a.head) == "evaluable" for a in _subterms(goal.expr)):
            self.result.environment.add(f"{origin} [true]")
            self.result.environment.add(f"{origin} [false]")
        released = outputs(goal)
        for env in self._tokens(ka.name, source):
            # A program variable the test gives a value to is matched afresh; if the test
            # fails it keeps its old value (the F exit carries `env`).
            fresh = {**env, **dict.fromkeys(released, IDLE)}
            for reading in self.solver.readings(goal.expr, fresh):
                takes, puts = self._reads(reading, ())
                entry = [(source.place, source.colour(env)), *takes]
                try:
                    solutions = self.solver.solve(goal.expr, fresh, reading)
                except Undefined:  # an unbound or ill-typed value: the interpreter fails the KA
                    abort = self._aborts[-1] if self._aborts else self.fail_node(ka)
                    self.emit.fire(f"{origin} [error]", origin, entry, [*puts, (abort.place, abort.colour(env))])
                    continue
                if solutions:
                    for solution in solutions:
                        used, back = self._reads(reading, solution.get(CONSUMED, ()))
                        self.emit.fire(f"{origin} [true]", origin, [(source.place, source.colour(env)), *used],
                                       [*back, (target.place, target.colour(solution))])
                elif not wait:
                    self.emit.fire(f"{origin} [false]", origin, entry, [*puts, (fail.place, fail.colour(env))])

    def _wait(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, origin: str) -> None:
        """A wait never fails (Fig 4.21): it fires once its condition holds."""
        self._test(ka, goal, source, target, target, origin, wait=True)

    def _update(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, fail: Node, origin: str) -> None:
        negative = goal.expr.head == "~"
        fact = _positive(goal.expr)
        kind = self.db.kind(fact.head)
        retract = (goal.op == "~>") != (negative and kind in ("closed", "functional"))
        self.db.used.add(fact.head)
        for env in self._tokens(ka.name, source):
            try:
                args = tuple(argument(a, env, posted=False) for a in fact.args)
            except Undefined:
                args = None
            entry = (source.place, source.colour(env))
            if args is None or (IDLE in args and not retract) or (goal.op == "~>" and negative and
                                                                 kind in ("closed", "functional")):
                # §4.4.2: concluding an expression with unbound arguments is an error; retracting a
                # negation of a closed predicate means nothing (the interpreter fails the KA).
                self.emit.fire(f"{origin} [error]", origin, [entry], [(fail.place, fail.colour(env))])
                continue
            if IDLE in args:
                # Fig 4.12: retracting with an unbound argument changes nothing.
                self.emit.fire(f"{origin} [unbound]", origin, [entry], [(target.place, target.colour(env))])
                continue
            if not all(args[i] in self.db.argument_values(fact.head, i) for i in range(len(args)) if args[i] != IDLE):
                self._bind_or_overflow(ka, origin, source, env, env, target, False, goal.line)
                continue
            after = [(target.place, target.colour(env))]
            if kind == "event":
                # An occurrence that invokes a KA is used up by it; else it waits to be used.
                invoked = self._invoke(fact, args)
                self.emit.fire(origin, origin, [entry], [*after, *(invoked or [(f"{fact.head}.EVENT", args)])])
                continue
            key = args[:-1] if kind == "functional" else args
            for state in self.db.states(fact.head, key):
                change = self._change(kind, state, args, retract, negative)
                if change is None:
                    continue
                takes, puts = change
                # Only a conclusion that changes the database invokes fact-invoked KAs.
                if kind == "closed":
                    changes = state.value == "UNDEF"
                elif kind == "functional":
                    changes = state.value != args[-1]
                else:
                    changes = state.value != "AFF"
                triggered = self._invoke(fact, args) if changes and not (retract or negative) else []
                self.emit.fire(origin, origin, [entry, *takes], [*after, *puts, *triggered])

    def _change(self, kind: str, state: KeyState, args: tuple[Any, ...], retract: bool, negative: bool
                ) -> tuple[list[tuple[str, Any]], list[tuple[str, Any]]] | None:
        """The tokens a conclusion or retraction moves from `state` (None: not this state)."""
        name, key = state.predicate, state.key
        if kind == "closed":
            wanted = "UNDEF" if retract else "DEF"
            return list(state.takes), [(f"{name}.{wanted}", key)]
        if kind == "functional":
            value = args[-1]
            if retract:
                if value != IDLE and state.value != value:
                    return list(state.takes), list(state.puts)  # another value: nothing to retract
                return list(state.takes), [(f"{name}.UNDEF", key)]
            return list(state.takes), [(f"{name}.DEF", key + (value,))]
        # standard: concluding one sign removes the other; retracting one sign forgets it
        aff, neg = {"AFF": ("DEF", "UNDEF"), "NEG": ("UNDEF", "DEF"), "UNKNOWN": ("UNDEF", "UNDEF")}[state.value]
        if retract:
            aff, neg = ("UNDEF", neg) if not negative else (aff, "UNDEF")
        else:
            aff, neg = ("UNDEF", "DEF") if negative else ("DEF", "UNDEF")
        return list(state.takes), [(f"{name}.AFF.{aff}", key), (f"{name}.NEG.{neg}", key)]

    def _invoke(self, fact: rp.Compound, args: tuple[Any, ...]) -> list[tuple[str, Any]]:
        """Tokens for the INIT place of every fact-invoked KA this conclusion matches (Fig 4.25)."""
        started = []
        for ka in self.library.kas:
            if ka.goal_invoked or ka.name not in self.translated or ka.trigger.head != fact.head:
                continue
            env = unify_into(ka.trigger.args, args, {})
            if env is not None:
                started.append((f"{ka.name}.INIT", self.init_node(ka).colour(env)))
        return started

    def _assign_goal(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, fail: Node, origin: str) -> None:
        """`!(= var term)` (Fig 4.20): always for a program variable; for a logic variable only
        while it is unbound, else it succeeds only if the values agree."""
        var, value = goal.expr.args
        for env in self._tokens(ka.name, source):
            entry = (source.place, source.colour(env))
            try:
                computed = evaluate(value, env)
            except Undefined:
                self.emit.fire(f"{origin} [undefined]", origin, [entry], [(fail.place, fail.colour(env))])
                continue
            if not isinstance(var, rp.Var):
                continue
            current = env.get(var.name, IDLE)
            if var.is_program or current == IDLE:
                self._bind_or_overflow(ka, f"{origin} [true]", source, env, {**env, var.name: computed}, target,
                                       computed in self.var_domains[ka.name].get(var.name, ()), goal.line)
            elif current == computed:
                self.emit.fire(f"{origin} [true]", origin, [entry], [(target.place, target.colour(env))])
            else:
                self.emit.fire(f"{origin} [false]", origin, [entry], [(fail.place, fail.colour(env))])

    def _achieve(self, ka: rp.KA, goal: rp.Goal, source: Node, target: Node, fail: Node, origin: str) -> None:
        """§4.4.4: test the database first when something can conclude the goal, else post it to
        the KAs that achieve it and wait for the answer."""
        head = goal.expr.head
        waiting = self._node(ka, f"L{goal.line}.W", source.vars, goal.line, f"waits for {goal}")
        waiting = Node(waiting.place, waiting.vars, source.extra)
        if self._keys:
            self.result.statements[self._keys[-1]].append(waiting.place)
        testable = self._concluded_somewhere(head)
        posting = source
        if testable:
            posting = Node(f"{source.place}.POSTING", source.vars, source.extra)
            self.result.where[posting.place] = Where(ka.name, goal.line, f"posts {goal}", source.vars)
            self._test(ka, rp.Goal("?", goal.expr, goal.line), source, target, posting, f"{origin} in database")
        for env in self._tokens(ka.name, source):
            try:
                posted = tuple(argument(a, env) for a in goal.expr.args)
            except Undefined:
                self.emit.fire(f"{origin} [undefined]", origin, [(posting.place, posting.colour(env))],
                               [(fail.place, fail.colour(env))])
                continue
            self.emit.fire(f"{origin} post", origin, [(posting.place, posting.colour(env))],
                           [(waiting.place, waiting.colour(env)), (f"{head}.POST", posted)])
            self.posted.setdefault(head, {})[posted] = None
        self.pending.append(PendingReceive(head, waiting, target, fail, origin, goal.expr.args))

    def _concluded_somewhere(self, head: str) -> bool:
        """Can the database ever make `head` true (so that `!` tests it first, §4.4.4)?"""
        return (head in COMPARISONS or head == "BOUNDP" or self.db.kind(head) == "evaluable"
                or head in self.initial_heads or head in self.concluded)

    # ------------------------------------------------------------ goal servers
    def _servers(self) -> None:
        """Every posted goal's server, then every poster's receiving of the answers they give."""
        answers = {head: self._server(head, list(colours)) for head, colours in self.posted.items()}
        for pending in self.pending:
            self._receive(pending, answers.get(pending.goal, {}))

    def _server(self, head: str, posted: list[tuple[Any, ...]]) -> dict[str, dict[tuple[Any, ...], None]]:
        """Who achieves a posted goal (§4.4.9): nobody (it fails), its only KA (Fig 4.27), or
        its KAs tried in turn until one succeeds (Fig 4.28)."""
        out: dict[str, dict[tuple[Any, ...], None]] = {"SUCC": {}, "FAIL": {}}
        kas = [k for k in self.library.kas if k.goal_invoked and not k.is_meta and k.trigger.head == head
               and k.name in self.translated]
        origin = f"goal {head}"
        servers = [k for k in kas if EXECUTIVE_PROPERTY in k.properties]
        if servers:
            # The executive serves a request only through a KA whose invocation it matches, as the
            # interpreter runs it: `!(EXEC LOOK $R)` with KAs for `(EXEC STOW $R)` and `(EXEC
            # GRASP $R)` only is a goal no KA achieves, and fails.
            served = []
            for colour in posted:
                if self._applicable(servers, colour):
                    served.append(colour)
                else:
                    self.emit.fire(f"{origin}: no KA", origin, [(f"{head}.POST", colour)], [(f"{head}.FAIL", colour)])
                    out["FAIL"][colour] = None
            self._executive_server(servers, served, out)
            return out
        for colour in posted:
            applicable = self._applicable(kas, colour)
            if not applicable:
                self.emit.fire(f"{origin}: no KA", origin, [(f"{head}.POST", colour)], [(f"{head}.FAIL", colour)])
                out["FAIL"][colour] = None
            elif len(kas) == 1:
                only = applicable[0]
                env = unify_into(only.trigger.args, colour, {}) or {}
                self.emit.fire(f"{origin}: start {only.name}", origin, [(f"{head}.POST", colour)],
                               [(f"{only.name}.INIT", self.init_node(only).colour(env))])
            else:
                self._try_kas(head, colour, applicable, out)
        if len(kas) == 1:
            only = kas[0]
            for outcome, node in (("SUCC", self.term_node(only)), ("FAIL", self.fail_node(only))):
                for env in self._tokens(only.name, node):
                    answer = self._answer(only, env)
                    if answer is not None and any(compatible(c, answer) for c in posted):
                        verb = "succeeds" if outcome == "SUCC" else "fails"
                        self.emit.fire(f"{origin}: {only.name} {verb}", origin,
                                       [(node.place, node.colour(env))], [(f"{head}.{outcome}", answer)])
                        out[outcome][answer] = None
        return out

    def _hears_warnings(self, serving: tuple[str, ...]) -> bool:
        """Does the request protocol (these KAs, and those their subgoals reach) wait for a
        `(WARNING ...)` anywhere? Worked out once per protocol, not once per service."""
        heard = self._heard.get(serving)
        if heard is None:
            kas = [k for k in self.library.kas if k.name in serving]
            heard = self._heard[serving] = any(
                isinstance(s, rp.Step) and s.goal.op == "^" and s.goal.expr.head == "WARNING"
                for k in self._reached_from(kas) for s in _statements(k.body or ()))
        return heard

    def _reached_from(self, kas: list[rp.KA]) -> list[rp.KA]:
        """The KAs, and those the goals of their bodies invoke, and so on (by the goals' heads)."""
        reached = {k.name: k for k in kas}
        waiting = list(kas)
        while waiting:
            ka = waiting.pop()
            for statement in _statements(ka.body or ()):
                if isinstance(statement, rp.Step) and statement.goal.op == "!":
                    for other in self.library.kas:
                        if other.goal_invoked and other.trigger.head == statement.goal.expr.head \
                                and other.name not in reached:
                            reached[other.name] = other
                            waiting.append(other)
        return list(reached.values())

    def _applicable(self, kas: list[rp.KA], colour: tuple[Any, ...]) -> list[rp.KA]:
        return [k for k in kas
                if len(k.trigger.args) == len(colour) and unify_into(k.trigger.args, colour, {}) is not None]

    def _answer(self, ka: rp.KA, env: Env) -> tuple[Any, ...] | None:
        try:
            return tuple(argument(a, env, posted=False) for a in ka.trigger.args)
        except Undefined:
            return None

    def _try_kas(self, head: str, colour: tuple[Any, ...], kas: list[rp.KA],
                 out: dict[str, dict[tuple[Any, ...], None]]) -> None:
        """Fig 4.28: TRY(goal, tried) holds the goal while an untried KA may be started; the KA
        runs with TRYING(goal, tried, KA) parked; its failure marks it tried, its success answers."""
        origin = f"goal {head}"
        full = (1 << len(kas)) - 1
        self.emit.fire(f"{origin}: try its KAs", origin, [(f"{head}.POST", colour)], [(f"{head}.TRY", colour + (0,))])
        self.emit.fire(f"{origin}: every KA failed", origin, [(f"{head}.TRY", colour + (full,))],
                       [(f"{head}.FAIL", colour)])
        out["FAIL"][colour] = None
        for i, ka in enumerate(kas):
            env = unify_into(ka.trigger.args, colour, {}) or {}
            bit = 1 << i
            for mask in range(full + 1):
                if mask & bit:
                    continue
                parked = (f"{head}.TRYING", colour + (mask, ka.name))
                self.emit.fire(f"{origin}: try {ka.name}", origin, [(f"{head}.TRY", colour + (mask,))],
                               [parked, (f"{ka.name}.INIT", self.init_node(ka).colour(env))])
                for outcome, node in (("SUCC", self.term_node(ka)), ("FAIL", self.fail_node(ka))):
                    for final in self._tokens(ka.name, node):
                        answer = self._answer(ka, final)
                        if answer is None or not compatible(colour, answer):
                            continue
                        if outcome == "SUCC":
                            self.emit.fire(f"{origin}: {ka.name} succeeds", origin,
                                           [(node.place, node.colour(final)), parked], [(f"{head}.SUCC", answer)])
                            out["SUCC"][answer] = None
                        else:
                            self.emit.fire(f"{origin}: {ka.name} fails, try another", origin,
                                           [(node.place, node.colour(final)), parked],
                                           [(f"{head}.TRY", colour + (mask | bit,))])

    def _executive_server(self, servers: list[rp.KA], posted: list[tuple[Any, ...]],
                          out: dict[str, dict[tuple[Any, ...], None]]) -> None:
        """The services of §5.4.1: a group place per service group (colour: the running service
        or IDLE); a service starts when its group is IDLE and no group runs a service it
        conflicts with, then answers. A net has no time: interrupting is modelled as waiting."""
        assert self.executive is not None
        ka = servers[0]  # the protocol's head and arity are theirs all
        head = ka.trigger.head
        results = self.db.argument_values(head, len(ka.trigger.args) - 1)
        if not results or not any(p.name == head for p in self.node_ast.predicates):
            # The answers would be only the words the KAs happen to write (no OK): services would
            # never answer, a deadlock the robot does not have.
            self._reject(ka, f"the answer of {head} (its last argument) has no declared domain, so the net cannot "
                         f"tell what the services answer: declare `predicate {head}(service: SERVICES, ..., result: "
                         "RESULTS);` with a type of the answers the procedures expect (OK, and the failures they "
                         "test)", "unbounded-variable")
            return
        for colour in posted:
            name = colour[0]
            service = self.executive.services.get(name)
            origin = f"service {name}"
            if service is None:
                error = f"{head}.UNKNOWN-SERVICE" if name != IDLE else f"{head}.UNBOUND-SERVICE"
                if name == IDLE:
                    self.result.errors[error] = ("unknown-service", "a KA asks the executive for a service named by "
                                                 "an unbound variable: bind it before the request")
                    self.emit.fire(f"{origin} is unbound", origin, [(f"{head}.POST", colour)], [(error, petri.BLACK)])
                    continue
                # The executive answers BAD-SERVICE and the KA goes on with that answer (§3.9). A
                # result domain without that value has no colour for it: the net stops there
                # rather than follow another answer the KA may treat otherwise.
                failure = "BAD-SERVICE" if "BAD-SERVICE" in results else None
                answered = ("it answers BAD-SERVICE" if failure is not None else "it answers BAD-SERVICE, which "
                            "the answer's domain lacks (add it to follow what the KA does next): the net stops here")
                self.result.errors[error] = ("unknown-service", f"a KA asks the executive for a service it does "
                                             f"not offer ({name}, asked through {head}): "
                                             f"{answered}; declare the service or fix the request")
                puts: list[tuple[str, Any]] = [(error, petri.BLACK)]
                if failure is not None:
                    answer = colour[:-1] + (failure,)
                    puts.append((f"{head}.SUCC", answer))
                    out["SUCC"][answer] = None
                self.emit.fire(f"{origin} is not offered", origin, [(f"{head}.POST", colour)], puts)
                continue
            takes: list[tuple[str, Any]] = [(f"{head}.POST", colour)]
            puts = [(f"{head}.RUN", colour)]
            if service.group is not None:
                takes.append((service.group, IDLE))
                puts.append((service.group, name))
            excluded: dict[str, set[str]] = {}
            for group, other in service.excluded_by:
                if group != service.group:
                    excluded.setdefault(group, set()).add(other)
            groups = sorted(excluded)
            for states in itertools.product(*([s for s in (IDLE, *self.executive.groups[g]) if s not in excluded[g]]
                                              for g in groups)):
                reads = list(zip(groups, states, strict=True))
                self.emit.fire(f"{origin} starts", origin, [*takes, *reads], [*puts, *reads])
            answers = [r for r in results if self.executive.may_fail(name) or _success(r, service)]
            if not answers:  # it would never answer: a deadlock of the model, not of the robot
                self._reject(ka, f"service {name} answers OK when it works, which the domain of {head}'s answer "
                             f"({', '.join(map(str, results))}) lacks: add OK to it", "answer-without-ok")
                continue
            self.result.environment.add(f"{origin} answers")
            # Does the protocol hear a ZOMBIE's warning (seed 000 Fig 4.3 does, and interrupts
            # the service)? Its KA may hand the wait to the KAs of its subgoals.
            serving = self._applicable(servers, colour) or servers
            handles_zombies = self._hears_warnings(tuple(k.name for k in serving))
            for result in answers:
                answer = colour[:-1] + (result,)
                release = [(service.group, name)] if service.group else []
                back = [(service.group, IDLE)] if service.group else []
                if result == "ZOMBIE" and not handles_zombies:
                    # A ZOMBIE's REPLY comes only once the procedures interrupt it (§3.4.1),
                    # after its (WARNING ...), which this protocol never waits for.
                    error = f"{head}.{name}.ZOMBIE-UNANSWERED"
                    self.result.errors[error] = (
                        "zombie-unanswered", f"service {name} may go ZOMBIE: the executive then sends (WARNING {name} "
                        f"id ZOMBIE) and no REPLY until the procedures interrupt it, and KA {serving[0].name} never "
                        "waits for the WARNING: its caller waits for ever; wait for it beside the REPLY (`choose`) "
                        "and send the interruption")
                    self.result.where[error] = Where(serving[0].name, serving[0].line,
                                                     f"{name} ZOMBIE, never interrupted")
                    self.emit.fire(f"{origin} goes ZOMBIE", origin, [(f"{head}.RUN", colour), *release],
                                   [(error, petri.BLACK), *back])
                    continue
                self.emit.fire(f"{origin} answers", origin, [(f"{head}.RUN", colour), *release],
                               [(f"{head}.SUCC", answer), *back])
                out["SUCC"][answer] = None

    def _receive(self, pending: PendingReceive, answers: dict[str, dict[tuple[Any, ...], None]]) -> None:
        ka = self.result.where[pending.wait.place].ka
        for env in self._tokens(ka, pending.wait):
            posted = pending.posted(env)
            if posted is None:
                continue
            for outcome, node in (("SUCC", pending.target), ("FAIL", pending.fail)):
                for answer in answers.get(outcome, {}):
                    if not compatible(posted, answer):
                        continue
                    fresh = {**env, **{a.name: IDLE for a in pending.args if isinstance(a, rp.Var) and a.is_program}}
                    after = unify_into(pending.args, answer, fresh) if outcome == "SUCC" else env
                    if after is None:
                        continue
                    label = "[true]" if outcome == "SUCC" else "[false]"
                    self.emit.fire(f"{pending.origin} {label}", pending.origin,
                                   [(pending.wait.place, pending.wait.colour(env)),
                                    (f"{pending.goal}.{outcome}", answer)],
                                   [(node.place, node.colour(after))])


ARITHMETIC_VALUES = 256  # the most values an arithmetic assignment may add to a variable's domain


def _arithmetic_closure(links: Sequence[tuple[str, Any]], found: dict[str, dict[Any, None]],
                        bounds: Mapping[str, tuple[float, float]]) -> bool:
    """Widen each variable assigned an arithmetic expression (`assign @I = (+ @I 1)`, a loop's
    counter, or `(* @I 2)`) with the values the expression takes from values within `bounds`,
    the range of the numbers each variable is given or compared with: a value past them (the one
    a loop exits with) is kept, and never computed from. At most ARITHMETIC_VALUES values each
    (`(/ @I 2)` never ends; the net then finds the value it has no room for). True when a domain
    grew."""
    grown = False

    def within(name: str, value: Any) -> bool:
        low, high = bounds.get(name, (-math.inf, math.inf))
        return not rp.is_number(value) or low <= value <= high

    for var, expr in links:
        if not (isinstance(expr, rp.Compound) and expr.head in ARITHMETIC) or var not in bounds:
            continue
        names = sorted(variables(expr))
        if any(name not in found for name in names):
            continue
        values = found[var]
        pool = [tuple(v for v in found[name] if within(name, v)) for name in names]
        if math.prod(len(p) for p in pool) > ARITHMETIC_VALUES:
            continue
        for combination in itertools.product(*pool):
            try:
                value = evaluate(expr, dict(zip(names, combination, strict=True)))
            except (Undefined, TypeError, ArithmeticError):
                continue
            if rp.is_number(value) and value not in values and len(values) < ARITHMETIC_VALUES:
                values[value] = None
                grown = True
    return grown




# What the executive answers on its own when a service did not work (specc/runtime/executive.py):
# refused, interrupted, out of time, a ZOMBIE, an input or output function that raised, a module's
# error status.
EXECUTIVE_FAILURES = frozenset({"TIMEOUT", "INT", "REFUSED", "ZOMBIE", "ERROR", "BAD-SERVICE", "BAD-INPUT",
                                "FINAL_ERROR", "SERVER_ERROR", "CS_ERROR"})


def _success(result: Any, service: Service) -> bool:
    """May `service` answer `result` when it worked? Without an output function the executive
    answers OK; a number of the domain is kept too, as before (more than the executive sends, so
    nothing it does is left out). With one it answers what the function returns, which only running
    it tells: any value of the domain the procedure receives it in (HEAVY, LIGHT...), except the
    words the executive answers this service's failures with (its own categories, its module
    request's reports), which `--fail` brings in: the procedures cannot tell such a word from a
    failure, so the net does not either."""
    if service.output_function is None:
        return result == "OK" or isinstance(result, int)
    return result not in EXECUTIVE_FAILURES and result not in service.failure_reports


def _written(block: Sequence[rp.Statement], bound: set[str]) -> set[str]:
    """The variables a block may give a value to: program variables it assigns or matches, and
    logic variables unbound before it."""
    written: set[str] = set()
    for statement in _statements(block):
        if isinstance(statement, rp.Assign):
            written.add(statement.var.name)
        elif isinstance(statement, rp.Step):
            written |= outputs(statement.goal)
        elif isinstance(statement, (rp.If, rp.While)):
            written |= outputs(statement.condition)
    return written | {v for v in block_vars(block) if not v.startswith("@") and v not in bound}


def _positive(expr: rp.Compound) -> rp.Compound:
    return _compound(expr.args[0]) if expr.head == "~" else expr


def _statements(block: Sequence[rp.Statement]) -> Iterator[rp.Statement]:
    for statement in block:
        yield statement
        if isinstance(statement, rp.If):
            yield from _statements(statement.then)
            yield from _statements(statement.orelse)
        elif isinstance(statement, rp.While):
            yield from _statements(statement.body)
        elif isinstance(statement, (rp.Parallel, rp.Choose)):
            for branch in statement.branches:
                yield from _statements(branch)


def _goals(ka: rp.KA) -> Iterator[rp.Goal]:
    if isinstance(ka.invocation, rp.Goal):
        yield ka.invocation
    if isinstance(ka.context, rp.Goal):
        yield ka.context
    for statement in _statements(ka.body or ()):
        if isinstance(statement, rp.Step):
            yield statement.goal
        elif isinstance(statement, (rp.If, rp.While)):
            yield statement.condition
    yield from ka.effects


def _compounds(ka: rp.KA) -> Iterator[rp.Compound]:
    roots: list[rp.Compound] = [g.expr for g in _goals(ka)]
    if isinstance(ka.invocation, rp.Compound):
        roots.append(ka.invocation)
    if isinstance(ka.context, rp.Compound):
        roots.append(ka.context)
    if ka.action is not None:
        roots.append(ka.action.call)
    for statement in _statements(ka.body or ()):
        if isinstance(statement, rp.Assign) and isinstance(statement.value, rp.Compound):
            roots.append(statement.value)
    for root in roots:
        yield from _subterms(root)


def _show(statement: rp.Statement) -> str:
    if isinstance(statement, rp.Step):
        return str(statement.goal)
    if isinstance(statement, rp.If):
        return f"if {statement.condition}"
    if isinstance(statement, rp.While):
        return f"while {statement.condition}"
    if isinstance(statement, rp.Parallel):
        return "parallel"
    if isinstance(statement, rp.Choose):
        return "choose"
    if isinstance(statement, rp.Assign):
        return f"assign {statement.var} = {rp.show(statement.value)}"
    return "fail"
