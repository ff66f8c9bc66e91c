"""The PRS supervisor (seed 000 ch. 4): an interpreter of the procedure libraries of
`specc.runtime.procedures`, talking to the executive (§3.9, §4.2.1).

What it keeps, as in §4.1: a **database** of facts, the **intentions** (root goals posted by the
user or the mission level, and the fact-invoked KAs, each a tree of threads), and the library.
What it does at each `step()`: advance one runnable thread to its next goal, round robin, so a
busy intention never starves another; `steps_per_turn` bounds the steps per kernel turn.

Semantics, and the choices the seed leaves open (each is marked CHOICE):

- Database (§4.4.2): `standard` facts are affirmed, negated (`=>(~ (P x))`) or unknown; `closed`
  and `functional` ones are true or false (absence is negation, so `=>(~ (P x))` is `~>(P x)`);
  concluding a functional fact replaces the value (last argument) of its key (the others);
  `event` facts (basic events) are used once: the test, wait, context or invocation that uses an
  occurrence removes it; `evaluable` predicates call their Python function. Undeclared heads are
  standard. A conclusion with an unbound argument is an error (the KA fails); a retraction with
  one changes nothing, as in Fig 4.12 (the trace says so).
- Expressions: `&` (left to right, bindings flowing), `|`, `~`, comparisons `< <= > >=`, `=`
  (binds an unbound variable, else tests equality), `BOUNDP` (§4.4.6: are all its arguments
  bound?), arithmetic `+ - * /` inside terms. A test keeps its first solution: no backtracking
  once it succeeded.
- Variables: `$X` unifies once per KA instance. `@X` may change. CHOICE: in a *matching*
  position (an argument of a database predicate in a test, wait or context, or of an achieved
  goal) a program variable is an output: it takes the value the match gives, its previous value
  forgotten (kept if the match fails). Elsewhere (comparisons, arithmetic, `=`, conclusions,
  actions, evaluable predicates) it gives its value. Why: the seed's own loop waits on
  `^(& (OBJ-FOUND @I) (> @I @TAKEN))` (§5.5), which only works if `@I` is bound afresh at each
  turn while `@TAKEN` is read, and procedures reuse one `@R` for the result of every request.
  `assign` and `!(= @X term)` always overwrite; `!(= $X term)` binds an unbound `$X`, else
  succeeds only if equal.
- `!C` (§4.4.4, §4.4.9): C is first tested in the database; else the goal-invoked KAs whose
  invocation matches C and whose context holds are tried in turn until one succeeds; the values
  of the invocation's variables then flow back into C (that is how a goal returns results).
  CHOICE: the order is random, drawn from `seed` (the PRS choice is non-deterministic, §4.4.7);
  `seed=None` keeps library order. A meta KA whose invocation matches C orders the candidates
  when there are several (its action gets `ctx.candidates` and returns the names to try, in
  order; names left out are not tried; meta KAs are never run as ordinary KAs); then the
  `meta=` hook does the same for any goal with several applicable KAs.
  A candidate's context is tested again when its turn comes (it is the KA's first arc, §4.4.8).
- `?C` test, `^C` wait (blocks until C holds, never fails), `=>C` conclude, `~>C` retract.
  `#C` and `%C` as statements hold until the enclosing KA ends: checked whenever its thread is
  about to run, `#` fails the KA once C stops holding; `%` suspends the KA and achieves `!C`
  first (its failure fails the KA). If C does not hold when the statement is reached, that
  happens at once.
- Statements: `if` (the condition's failure leads to `else`, never fails itself), `while`,
  `choose` (branches tried in turn — same order policy as KAs — until one's first statement
  succeeds; after that the KA is committed to it: no backtracking, §4.4.7; a first statement
  that is a wait is crossable once its condition holds, so a choice among waits takes whichever
  event comes first — such a choice never fails), `parallel` (one
  thread per branch sharing the KA's variables, joined when all succeeded). CHOICE: a failed
  branch fails the KA at once but its siblings are not killed: they run on detached and their
  outcome is discarded, as in the seed's nets (§5.4.1: "if the object-taking procedure fails,
  the other procedures do not stop").
- Primitive KAs call `functions[binding](ctx, *args)`; arguments must be bound; the value goes
  to the action's result variable; an exception fails the KA, recorded in the trace. EFFECTS run
  after a successful body, before the KA reports success.
- Fact-invoked KAs: a conclusion that changes the database, or an event occurrence, starts one
  new root intention per KA whose invocation pattern matches it and whose context holds.
  CHOICE: an event occurrence that invoked a KA is used up by that invocation; otherwise it
  waits in the database for a test or wait to use it.
- With an executive, each of its messages (§3.9) becomes the event `(REPLY id result)` or
  `(WARNING service id type)` (`Message.fact`); `ctx.send((service, id))` requests a service,
  `ctx.send(("INT", id))` interrupts one.

Errors in a KA (an unbound argument, a primitive that raises, a meta KA's bad answer) fail that
KA with the reason in the intention's trace; they are never raised to the caller of `step()`.
"""

from __future__ import annotations

import itertools
import logging
import math
import random
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple

from specc.runtime.procedures import (
    ARITHMETIC,
    COMPARISONS,
    KA,
    Action,
    Assign,
    Choose,
    Compound,
    Fail,
    Goal,
    If,
    Library,
    Parallel,
    Predicate,
    Statement,
    Step,
    Term,
    Var,
    While,
    compare,
    compute,
    parse_fact,
    parse_goal,
    show,
)

if TYPE_CHECKING:
    from specc.runtime.executive import Executive, Message
    from specc.runtime.kernel import Kernel


_CONNECTIVES = ("&", "|", "~")
_BUILTINS = frozenset((*COMPARISONS, "=", "BOUNDP"))
_STORED_KINDS = ("standard", "closed", "functional")


class ExecutionError(Exception):
    """A KA cannot go on (unbound argument, primitive that raised, ...): the KA fails."""

    def __init__(self, reason: str, line: int = 0):
        super().__init__(reason)
        self.reason = reason
        self.line = line


# ---------------------------------------------------------------- terms


def resolve(term: Term, env: Mapping[str, Any]) -> Any:
    """The value of `term`: bound variables replaced by their values, arithmetic computed.
    Unbound variables stay in it as `Var`s."""
    if isinstance(term, Var):
        return env.get(term.name, term)
    if not isinstance(term, Compound):
        return term
    args = tuple(resolve(a, env) for a in term.args)
    if term.head in ARITHMETIC and args:
        return _compute(term, args)
    return Compound(term.head, args)


def _compute(term: Compound, args: tuple[Any, ...]) -> Any:
    unbound = _unbound(args)
    if unbound:
        raise ExecutionError(f"{term}: {unbound[0]} is unbound")
    try:
        return compute(term.head, args)
    except ValueError as exc:
        raise ExecutionError(f"{term}: {exc}") from None


def _unbound(values: Iterable[Any]) -> list[Var]:
    """The unbound variables left in resolved values."""
    found: list[Var] = []
    for value in values:
        if isinstance(value, Var):
            found.append(value)
        elif isinstance(value, Compound):
            found.extend(_unbound(value.args))
    return found


def _variables(term: Term) -> Iterator[Var]:
    if isinstance(term, Var):
        yield term
    elif isinstance(term, Compound):
        for arg in term.args:
            yield from _variables(arg)


def match(pattern: Term, value: Any, env: dict[str, Any]) -> bool:
    """Unify `pattern` (whose variables live in `env`) with `value`, binding into `env`.

    `value` comes from another scope (a fact, the caller's goal): its unbound variables are
    not ours, so they match anything and bind nothing."""
    if isinstance(pattern, Var):
        if pattern.name not in env:
            if not isinstance(value, Var):
                env[pattern.name] = value
            return True
        return _same(env[pattern.name], value)
    if isinstance(pattern, Compound):
        if pattern.head in ARITHMETIC:
            return _same(resolve(pattern, env), value)
        return (isinstance(value, Compound) and value.head == pattern.head and len(value.args) == len(pattern.args)
                and all(match(p, v, env) for p, v in zip(pattern.args, value.args, strict=True)))
    return _same(pattern, value)


def _same(left: Any, right: Any) -> bool:
    if isinstance(left, Var) or isinstance(right, Var):
        return True
    if isinstance(left, Compound) and isinstance(right, Compound):
        return (left.head == right.head and len(left.args) == len(right.args)
                and all(_same(a, b) for a, b in zip(left.args, right.args, strict=True)))
    return bool(left == right)


# ---------------------------------------------------------------- the database


class _Occurrence:
    """One occurrence of a basic event: two equal events are two occurrences."""

    __slots__ = ("fact",)

    def __init__(self, fact: Compound):
        self.fact = fact


class Database:
    """The facts (§4.1), by predicate kind (§4.4.2). Change it through the supervisor
    (`conclude`, `retract`, `signal`), which also wakes waits and invokes fact KAs."""

    def __init__(self, predicates: Iterable[Predicate] = ()):
        self.predicates = {p.name: p for p in predicates}
        self._affirmed: dict[str, list[tuple[Any, ...]]] = {}
        self._negated: dict[str, list[tuple[Any, ...]]] = {}
        self._events: dict[str, list[_Occurrence]] = {}
        self.changes = 0  # how many times the stored facts changed: an observer compares it

    def kind(self, head: str) -> str:
        predicate = self.predicates.get(head)
        return predicate.kind if predicate is not None else "standard"

    def truth(self, fact: Compound | str) -> bool | None:
        """True if affirmed (or an occurrence of the event is pending), False if negated (or
        absent, for a closed world), None if unknown (standard predicates only)."""
        fact = parse_fact(fact) if isinstance(fact, str) else fact
        kind = self.kind(fact.head)
        if kind == "evaluable":
            raise ValueError(f"{fact.head} is evaluable: its truth is computed, not stored")
        if fact.args in self._affirmed.get(fact.head, ()) or any(
                o.fact == fact for o in self._events.get(fact.head, ())):
            return True
        if kind == "standard":
            return False if fact.args in self._negated.get(fact.head, ()) else None
        return False

    def facts(self, head: str) -> list[Compound]:
        """The affirmed facts of `head`, oldest first."""
        return [Compound(head, args) for args in self._affirmed.get(head, ())]

    def negated(self, head: str) -> list[Compound]:
        """The facts of standard predicate `head` concluded false."""
        return [Compound(head, args) for args in self._negated.get(head, ())]

    def events(self, head: str) -> list[Compound]:
        """The occurrences of `head` not used yet, oldest first."""
        return [o.fact for o in self._events.get(head, ())]

    # The supervisor's side: each returns whether the database changed.
    def _store(self, fact: Compound, negative: bool) -> bool:
        changed = self._stored(fact, negative)
        self.changes += changed
        return changed

    def _stored(self, fact: Compound, negative: bool) -> bool:
        kind = self.kind(fact.head)
        affirmed = self._affirmed.setdefault(fact.head, [])
        if kind == "standard":
            source, target = (affirmed, self._negated.setdefault(fact.head, []))
            if not negative:
                source, target = target, source
            changed = _discard(source, fact.args)
            if fact.args not in target:
                target.append(fact.args)
                changed = True
            return changed
        if negative:  # closed world: concluding the negation is retracting
            return _discard(affirmed, fact.args)
        if fact.args in affirmed:
            return False
        if kind == "functional":  # one value (the last argument) per key (the others)
            affirmed[:] = [args for args in affirmed if args[:-1] != fact.args[:-1]]
        affirmed.append(fact.args)
        return True

    def _remove(self, fact: Compound, negative: bool) -> bool:
        if negative:
            changed = _discard(self._negated.get(fact.head, []), fact.args)
        else:
            occurrences = self._events.get(fact.head, [])
            used = [o for o in occurrences if o.fact == fact]
            for occurrence in used:
                occurrences.remove(occurrence)
            changed = _discard(self._affirmed.get(fact.head, []), fact.args) or bool(used)
        self.changes += changed
        return changed

    def _add_event(self, fact: Compound) -> None:
        self._events.setdefault(fact.head, []).append(_Occurrence(fact))

    def _use(self, occurrence: _Occurrence) -> None:
        occurrences = self._events.get(occurrence.fact.head, [])
        if occurrence in occurrences:
            occurrences.remove(occurrence)

    def _facts_of(self, head: str, negative: bool = False) -> list[tuple[Any, ...]]:
        return list((self._negated if negative else self._affirmed).get(head, ()))

    def _occurrences_of(self, head: str) -> list[_Occurrence]:
        return list(self._events.get(head, ()))


def _discard(facts: list[tuple[Any, ...]], args: tuple[Any, ...]) -> bool:
    if args in facts:
        facts.remove(args)
        return True
    return False


# ---------------------------------------------------------------- intentions


TRACE_LENGTH = 10_000  # trace entries kept per intention
# Steps one intention may run at one kernel instant: a KA's goal takes one step, and a task
# reacting to an event takes tens; a loop that never waits takes them without end.
STEPS_PER_INSTANT = 100_000
# KAs one thread may run nested in one another (a KA's subgoal's KA, and so on): a recursion of
# procedures ends long before (a count to ten, a list walked); a KA posting its own goal before
# anything stops it, or two posting each other's, nests without end.
MOST_NESTED_KAS = 100


class TraceEntry(NamedTuple):
    time: float  # the kernel's clock, or the number of steps run when there is no kernel
    ka: str  # the KA, or "top" for the posted goal itself
    line: int  # in the spec
    text: str

    def __str__(self) -> str:
        return f"{self.ka}:{self.line}: {self.text}"


@dataclass(eq=False)
class Intention:
    """A root of the intention graph: a posted goal, or a KA invoked by a fact."""

    goal: Goal | None  # the posted goal; None for a fact-invoked KA
    trigger: Compound  # the goal's expression, or the fact that invoked `ka`
    ka: KA | None = None  # the fact-invoked KA
    status: str = "running"  # running | succeeded | failed
    bindings: dict[str, Any] = field(default_factory=dict)  # the goal's variables, once it ended
    # The latest entries only: a task that cycles for hours must not fill the memory.
    trace: deque[TraceEntry] = field(default_factory=lambda: deque(maxlen=TRACE_LENGTH))
    traced: int = 0  # entries ever recorded
    requests: list[int] = field(default_factory=list)  # the ids of the services it asked the executive for

    def lines(self) -> list[str]:
        return [str(entry) for entry in self.trace]


@dataclass(eq=False)
class _Frame:
    """One KA instance (or the posted goal, `ka` None): its variables and guards."""

    ka: KA | None
    env: dict[str, Any]
    intention: Intention
    guards: list[Goal] = field(default_factory=list)  # #C and %C, until the KA ends
    said: str = ""  # the last thing the trace recorded of it since it started: why it failed, when it did

    @property
    def name(self) -> str:
        return self.ka.name if self.ka is not None else "top"


class _Blocked(NamedTuple):
    """What a thread yields when it cannot go on: the database version it saw."""

    version: int


_Body = Generator[_Blocked | None, None, bool]
_Pursuit = Generator[_Blocked | None, None, str | None]  # returns why the goal failed, None on success


def _nesting(thread: _Thread) -> int:
    """The KAs running nested where `thread` runs: its own, and those of the threads whose
    parallel branches it is (each waits at its join with its KAs still running)."""
    depth = 0
    current: _Thread | None = thread
    while current is not None:
        depth += len(current.frames)
        current = current.parent
    return depth


class _NestedTooDeep(Exception):
    """MOST_NESTED_KAS reached: not a KA's failure, which another KA might mend, but an endless
    recursion; it ends the intention (`_advance`)."""


class _GuardBroken(Exception):
    def __init__(self, frame: _Frame, guard: Goal, reason: str):
        super().__init__(reason)
        self.frame = frame
        self.guard = guard
        self.reason = reason


@dataclass(eq=False)
class _Thread:
    intention: Intention
    parent: _Thread | None = None  # the thread waiting at the join of this parallel branch
    body: _Body = field(init=False)
    frames: list[_Frame] = field(default_factory=list)  # KA instances on this thread, outermost first
    repair: tuple[_Frame, Goal, _Pursuit] | None = None  # a % goal being re-achieved first
    pending: _GuardBroken | None = None  # to raise in the body when it next runs
    outcome: bool | None = None
    detached: bool = False  # a sibling branch failed: nobody waits for this one any more
    failure: str = ""  # why the KA that last ended on this thread failed (`line N: what`)
    at: tuple[str, Goal] | None = None  # the KA and the goal it pursues now


class PrimitiveContext:
    """What primitive actions and evaluable predicates receive first."""

    def __init__(self, supervisor: Supervisor, frame: _Frame | None = None, line: int = 0,
                 candidates: Sequence[str] = ()):
        self.supervisor = supervisor
        self.database = supervisor.database
        self.candidates = list(candidates)  # for a meta KA: the applicable KAs' names
        self._frame = frame
        self._line = line

    def send(self, message: tuple[Any, ...]) -> None:
        """(service, id, *inputs) requests a service of the executive, with the inputs it takes;
        ("INT", id) interrupts one."""
        executive = self.supervisor.executive
        if executive is None:
            raise RuntimeError(f"no executive to send {message} to")
        service, ident, *inputs = message
        if service == "INT":
            executive.interrupt(ident)
        else:
            if self._frame is not None:
                self._frame.intention.requests.append(ident)
            executive.request(service, ident, tuple(inputs))

    def new_id(self) -> int:
        """A request id of the task level: the executive's next fresh one when there is an
        executive (other clients may use it too), else the supervisor's own count."""
        executive = self.supervisor.executive
        return executive.fresh_id() if executive is not None else next(self.supervisor._ids)

    def log(self, text: str) -> None:
        """A message for the operator: logged, and kept in the intention's trace."""
        if self._frame is not None:
            self.supervisor._record(self._frame, self._line, f"operator: {text}")
        self.supervisor._log(text)

    def read_param(self, name: str) -> Any:
        """GET-PARAM (§4.2.2)."""
        executive = self.supervisor.executive
        if executive is None:
            raise RuntimeError(f"no executive to read parameter {name} from")
        return executive.get_param(name)

    def set_param(self, name: str, value: Any) -> str:
        """SET-PARAM (§4.2.2): OK or the error code."""
        executive = self.supervisor.executive
        if executive is None:
            raise RuntimeError(f"no executive to write parameter {name} to")
        return executive.set_param(name, value)


# ---------------------------------------------------------------- the interpreter


class Supervisor:
    """A PRS agent running `library` (see the module docstring): post goals, update its
    database, and step it, or let it run on the kernel (the executive's by default)."""

    def __init__(self, library: Library, functions: Mapping[str, Callable[..., Any]] | None = None, *,
                 kernel: Kernel | None = None, executive: Executive | None = None, seed: int | None = 0,
                 steps_per_turn: int = 100, meta: Callable[[Goal, list[KA]], list[KA]] | None = None,
                 log: Callable[[str], None] | None = None):
        for ka in library.kas:
            if ka.is_meta and ka.action is None:
                raise ValueError(f"meta KA {ka.name} has no action to order the applicable KAs with")
        self.library = library
        self.functions = dict(functions or {})
        self.executive = executive
        # Replies come from the executive's kernel: running on another clock would stall them.
        if kernel is not None and executive is not None and kernel is not executive.kernel:
            raise ValueError("the supervisor runs on its executive's kernel: give `kernel=` the executive's "
                             "(`executive.kernel`), or leave it out")
        self.kernel = kernel if kernel is not None else executive.kernel if executive is not None else None
        self.steps_per_turn = steps_per_turn
        self.database = Database(library.predicates)
        self.intentions: list[Intention] = []
        self._primitives = {p.name: p for p in library.primitives}
        self._goal_kas = [k for k in library.kas if k.goal_invoked and not k.is_meta]
        self._fact_kas = [k for k in library.kas if not k.goal_invoked and not k.is_meta]
        self._meta_kas = [k for k in library.kas if k.is_meta]
        self._meta = meta
        self._log = log or logging.getLogger(__name__).info
        self._random = random.Random(seed) if seed is not None else None
        self._ids = itertools.count(1)
        self._runnable: deque[_Thread] = deque()
        self._blocked: dict[_Thread, None] = {}  # insertion-ordered, so waking keeps turns fair
        self._version = 0  # counts database changes and thread ends
        self._steps = 0
        self._instant = -math.inf  # the kernel time `_spent` counts at
        self._spent: dict[int, int] = {}  # steps each intention (by id) ran at that instant
        self._turn_pending = False
        if executive is not None:
            executive.listeners.append(self._on_message)

    # ------------------------------------------------------------ the user's interface
    def post(self, goal: Goal | str) -> Intention:
        """A top-level goal, e.g. `post("!(COLLECT-OBJECTS 3)")`; its intention is returned."""
        goal = parse_goal(goal) if isinstance(goal, str) else goal
        outside = self._outside(_polarity(goal.expr)[1]) if goal.expr.head in self.database.predicates else None
        if outside is not None:
            raise ValueError(f"{goal}: {outside}")
        intention = Intention(goal=goal, trigger=goal.expr)
        frame = _Frame(None, {}, intention)
        thread = _Thread(intention)
        thread.body = self._run_top(thread, frame, goal)
        self.intentions.append(intention)
        self._start(thread)
        return intention

    def abandon(self, intention: Intention, why: str) -> None:
        """Drop an intention still running, as the layer above that posted it gave up on it (an
        action of a plan past its deadline, a safe state): its threads stop where they stand, the
        services it asked the executive for and that still run are interrupted (INT, §3.9), and
        the intention fails."""
        if intention.status != "running":
            return
        if self.executive is not None:
            for ident in intention.requests:
                if ident in self.executive.activities:
                    self.executive.interrupt(ident)
        self._runnable = deque(t for t in self._runnable if t.intention is not intention)
        for thread in [t for t in self._blocked if t.intention is intention]:
            del self._blocked[thread]
        when = self.kernel.now if self.kernel is not None else float(self._steps)
        intention.trace.append(TraceEntry(when, "top", 0, f"abandoned: {why}"))
        intention.traced += 1
        intention.status = "failed"
        self._version += 1

    def conclude(self, fact: Compound | str) -> None:
        """`=>fact` from the environment or the user; `(~ (P ...))` concludes a negation."""
        self._from_outside(self._conclude, fact)

    def retract(self, fact: Compound | str) -> None:
        """`~>fact` from the environment or the user; `(~ (P ...))` retracts a negation."""
        self._from_outside(self._retract, fact)

    def signal(self, event: Compound | str) -> None:
        """An occurrence of a basic event (an executive message, a sensor's news)."""
        self._from_outside(self._signal, event)

    def step(self) -> bool:
        """Advance one runnable thread to its next goal; False when no thread can run."""
        if not self._runnable:
            return False
        self._steps += 1
        thread = self._runnable.popleft()
        if self.kernel is None or not self._spinning(thread):
            self._advance(thread)
        return True

    def _spinning(self, thread: _Thread) -> bool:
        """Has the thread's intention run STEPS_PER_INSTANT steps at this instant? Then it is a
        loop that never waits (`while ?(>= @N 0) { assign ...; }`), which would hold the kernel
        at this instant for ever (the robot's time stops): the intention is abandoned, saying
        where it stood, and the robot goes on."""
        assert self.kernel is not None
        now = self.kernel.now
        if now != self._instant:
            self._instant, self._spent = now, {}
        intention = thread.intention
        spent = self._spent[id(intention)] = self._spent.get(id(intention), 0) + 1
        if spent <= STEPS_PER_INSTANT:
            return False
        where = f" (at {thread.at[0]}:{thread.at[1].line}: {thread.at[1]})" if thread.at is not None else ""
        self.abandon(intention, f"it ran {STEPS_PER_INSTANT:,} steps at {now:g} s with no time passing{where}: a "
                                "loop that never waits; let it wait for something (`^(...)`, a service's reply)")
        return True

    def run(self, max_steps: int = 100_000) -> None:
        """Step until every thread has ended or is blocked (or `max_steps` were run)."""
        for _ in range(max_steps):
            if not self.step():
                return

    def _from_outside(self, update: Callable[[Compound], None], fact: Compound | str) -> None:
        """A database update from the user: what would fail a KA is their mistake (ValueError)."""
        fact = parse_fact(fact) if isinstance(fact, str) else fact
        unbound = _unbound([fact])
        if unbound:
            raise ValueError(f"{fact}: {unbound[0]} has no value")
        try:
            update(fact)
        except ExecutionError as error:
            raise ValueError(error.reason) from None

    # ------------------------------------------------------------ scheduling
    def _start(self, thread: _Thread) -> None:
        self._runnable.append(thread)
        self._schedule_turn()

    def _wake(self, thread: _Thread) -> None:
        if thread in self._blocked:
            del self._blocked[thread]
            self._start(thread)

    def _changed(self) -> None:
        """The database changed: every blocked thread looks again (waits, guards)."""
        self._version += 1
        woken = list(self._blocked)
        self._blocked.clear()
        self._runnable.extend(woken)
        if woken:
            self._schedule_turn()

    def _schedule_turn(self) -> None:
        if self.kernel is not None and not self._turn_pending:
            self._turn_pending = True
            self.kernel.call_later(0, self._turn)

    def _turn(self) -> None:
        for _ in range(self.steps_per_turn):
            if not self.step():
                break
        self._turn_pending = False
        if self._runnable:
            self._schedule_turn()

    def _advance(self, thread: _Thread) -> None:
        if thread.pending is None and thread.repair is None:
            self._check_guards(thread)
        try:
            if thread.repair is not None:
                signal = next(thread.repair[2])
            elif thread.pending is not None:
                broken, thread.pending = thread.pending, None
                signal = thread.body.throw(broken)
            else:
                signal = next(thread.body)
        except _NestedTooDeep as deep:
            self.abandon(thread.intention, str(deep))
            return
        except RecursionError:  # fewer KAs, each nesting statements deeply: the same endless recursion
            self.abandon(thread.intention, "KAs nested too deep for Python's stack: a KA posting its own goal, "
                                           "or KAs posting each other's, with nothing to end it")
            return
        except StopIteration as stop:
            if thread.repair is not None:
                self._repaired(thread, stop.value)
            else:
                self._finish(thread, bool(stop.value))
            return
        if isinstance(signal, _Blocked) and signal.version == self._version:
            self._blocked[thread] = None
        else:
            self._runnable.append(thread)

    def _check_guards(self, thread: _Thread) -> None:
        """#C fails its KA once C stops holding; %C has C achieved again first."""
        for frame in thread.frames:
            for guard in frame.guards:
                try:
                    holds = self._holds(frame, guard.expr)
                except ExecutionError as error:
                    thread.pending = _GuardBroken(frame, guard, f"{guard} cannot be tested: {error.reason}")
                    return
                if holds:
                    continue
                if guard.op == "#":
                    thread.pending = _GuardBroken(frame, guard, f"{guard} no longer holds")
                else:
                    self._record(frame, guard.line, f"{guard} no longer holds: achieving it again")
                    thread.repair = (frame, guard, self._achieve(thread, frame, Goal("!", guard.expr, guard.line)))
                return

    def _repaired(self, thread: _Thread, failure: str | None) -> None:
        assert thread.repair is not None
        frame, guard, _ = thread.repair
        thread.repair = None
        if failure is not None:
            thread.pending = _GuardBroken(frame, guard, f"{guard} could not be achieved again: {failure}")
        self._runnable.append(thread)

    def _finish(self, thread: _Thread, succeeded: bool) -> None:
        thread.outcome = succeeded
        self._version += 1
        if thread.parent is None:
            thread.intention.status = "succeeded" if succeeded else "failed"
        elif not thread.detached:
            self._wake(thread.parent)

    def _record(self, frame: _Frame, line: int, text: str) -> None:
        when = self.kernel.now if self.kernel is not None else float(self._steps)
        frame.intention.trace.append(TraceEntry(when, frame.name, line, text))
        frame.intention.traced += 1
        frame.said = f"line {line}: {text}"

    # ------------------------------------------------------------ running KAs
    def _run_top(self, thread: _Thread, frame: _Frame, goal: Goal) -> _Body:
        try:
            failure = yield from self._pursue(thread, frame, goal)
        except ExecutionError as error:
            failure = error.reason
        if failure is not None:
            self._record(frame, goal.line, f"{goal} failed: {failure}")
        frame.intention.bindings = dict(frame.env)
        return failure is None

    def _run_ka(self, thread: _Thread, ka: KA, env: dict[str, Any], why: str) -> _Body:
        if _nesting(thread) >= MOST_NESTED_KAS:
            last = [f.name for f in thread.frames[-4:]]
            raise _NestedTooDeep(f"KAs nested {MOST_NESTED_KAS} deep (... {' -> '.join(last)} -> {ka.name} for {why}), "
                                 "the most the supervisor runs (MOST_NESTED_KAS): most often a KA posting its own "
                                 "goal, or KAs posting each other's, with nothing to end it; test first what ends "
                                 "the recursion (an `if`, a context), or post another goal")
        frame = _Frame(ka, env, thread.intention)
        thread.frames.append(frame)
        self._record(frame, ka.line, f"started for {why}")
        frame.said = ""
        try:
            if ka.action is not None:
                succeeded = self._act(frame, ka.action)
            else:
                succeeded = yield from self._run_block(thread, frame, ka.body or ())
            if succeeded:
                for effect in ka.effects:  # Fig 4.23: between END and TERM
                    self._update(frame, effect)
        except ExecutionError as error:
            self._record(frame, error.line or ka.line, error.reason)
            succeeded = False
        except _GuardBroken as broken:
            if broken.frame is not frame:
                self._record(frame, ka.line, f"abandoned: {broken.frame.name}'s {broken.reason}")
                raise
            self._record(frame, broken.guard.line, broken.reason)
            succeeded = False
        finally:
            thread.frames.remove(frame)
        thread.failure = "" if succeeded else frame.said or f"line {ka.line}: failed"
        self._record(frame, ka.line, "succeeded" if succeeded else "failed")
        return succeeded

    def _run_invoked(self, thread: _Thread, ka: KA, env: dict[str, Any], fact: Compound) -> _Body:
        succeeded = yield from self._run_ka(thread, ka, env, str(fact))
        thread.intention.bindings = dict(env)
        return succeeded

    def _run_branch(self, thread: _Thread, frame: _Frame, statements: Sequence[Statement], line: int) -> _Body:
        """One branch of a parallel statement, on its own thread. The KA's guards stay with the
        KA's thread, which checks them while it waits at the join."""
        try:
            succeeded = yield from self._run_block(thread, frame, statements)
        except ExecutionError as error:
            self._record(frame, error.line, error.reason)
            succeeded = False
        if thread.detached:
            self._record(frame, line, f"detached parallel branch {'succeeded' if succeeded else 'failed'} "
                                      "(its outcome is discarded)")
        return succeeded

    def _run_block(self, thread: _Thread, frame: _Frame, statements: Sequence[Statement]) -> _Body:
        for statement in statements:
            if not (yield from self._run_statement(thread, frame, statement)):
                return False
        return True

    def _run_statement(self, thread: _Thread, frame: _Frame, statement: Statement) -> _Body:
        if isinstance(statement, Step):
            failure = yield from self._pursue(thread, frame, statement.goal)
            if failure is not None:
                self._record(frame, statement.line, f"{statement.goal} failed: {failure}")
            return failure is None
        if isinstance(statement, If):
            holds = (yield from self._pursue(thread, frame, statement.condition)) is None
            return (yield from self._run_block(thread, frame, statement.then if holds else statement.orelse))
        if isinstance(statement, While):
            while (yield from self._pursue(thread, frame, statement.condition)) is None:
                if not (yield from self._run_block(thread, frame, statement.body)):
                    return False
            return True
        if isinstance(statement, Parallel):
            return (yield from self._run_parallel(thread, frame, statement))
        if isinstance(statement, Choose):
            return (yield from self._run_choose(thread, frame, statement))
        if isinstance(statement, Assign):
            return self._assign(frame, statement.var, statement.value, statement.line)
        assert isinstance(statement, Fail)
        self._record(frame, statement.line, "fail")
        return False

    def _run_parallel(self, thread: _Thread, frame: _Frame, statement: Parallel) -> _Body:
        """Split, then join when every branch succeeded (§4.4.5)."""
        branches: list[_Thread] = []
        for statements in statement.branches:
            branch = _Thread(thread.intention, parent=thread)
            branch.body = self._run_branch(branch, frame, statements, statement.line)
            branches.append(branch)
            self._start(branch)
        try:
            while True:
                failed = [number for number, b in enumerate(branches, 1) if b.outcome is False]
                if failed:
                    running = sum(1 for b in branches if b.outcome is None)
                    self._record(frame, statement.line, f"parallel branch {failed[0]} failed: the KA fails; "
                                                        f"{running} other branch(es) keep running, detached")
                    return False
                if all(b.outcome for b in branches):
                    return True
                yield _Blocked(self._version)
        finally:  # failed, or the KA was abandoned (a broken #): nobody joins the others any more
            for branch in branches:
                branch.detached = branch.outcome is None

    def _run_choose(self, thread: _Thread, frame: _Frame, statement: Choose) -> _Body:
        """§4.4.7: try the branches' first arcs in turn; once one is crossed, no going back.

        A wait arc never fails, it is just not crossable yet: when no arc could be crossed and
        some are waits, the choice waits for whichever becomes crossable first (as the competing
        transitions of Fig 4.22 do), e.g. a REPLY or a ZOMBIE warning (Fig 4.3)."""
        untried = self._order(list(enumerate(statement.branches, 1)))
        while True:
            version = self._version
            waits: list[tuple[int, tuple[Statement, ...]]] = []
            for number, branch in untried:
                first = branch[0] if branch else None
                if isinstance(first, Step) and first.goal.op == "^":
                    crossed = self._test(frame, first.goal.expr)
                    if not crossed:
                        waits.append((number, branch))
                else:
                    crossed = first is None or (yield from self._run_statement(thread, frame, first))
                if crossed:
                    self._record(frame, statement.line, f"choose: committed to branch {number}")
                    return (yield from self._run_block(thread, frame, branch[1:]))
            if not waits:
                self._record(frame, statement.line, "choose: no branch's first step succeeded")
                return False
            untried = waits  # the branches whose first arc failed are not tried again
            yield _Blocked(version)

    # ------------------------------------------------------------ goals
    def _pursue(self, thread: _Thread, frame: _Frame, goal: Goal) -> _Pursuit:
        """Achieve, test, wait for, conclude or retract: why it failed, or None."""
        thread.at = (frame.name, goal)
        yield None  # one goal per step: what bounds the work of a step
        try:
            op, expr = goal.op, goal.expr
            if op == "!":
                return (yield from self._achieve(thread, frame, goal))
            if op == "?":
                if self._test(frame, expr):
                    return None
                # What the variables held: a reply's result the test looked at (`$RESULT = ERROR`).
                bound = {v.name: frame.env[v.name] for v in _variables(expr) if v.name in frame.env}
                held = ", ".join(f"{name} = {show(value)}" for name, value in bound.items())
                return "no solution" + (f" ({held})" if held else "")
            if op == "^":  # never fails (§4.4.6): look again after every change
                while True:
                    version = self._version
                    if self._test(frame, expr):
                        return None
                    yield _Blocked(version)
            if op in ("=>", "~>"):
                self._update(frame, goal)
                return None
            if op in ("#", "%"):
                return (yield from self._guard(thread, frame, goal))
            raise ExecutionError(f"unknown goal operator {op!r}")
        except ExecutionError as error:
            if error.line:
                raise
            raise ExecutionError(f"{goal} failed: {error.reason}", goal.line) from None

    def _guard(self, thread: _Thread, frame: _Frame, goal: Goal) -> _Pursuit:
        if not self._holds(frame, goal.expr):
            if goal.op == "#":
                return "does not hold"
            failure = yield from self._achieve(thread, frame, Goal("!", goal.expr, goal.line))
            if failure is not None:
                return failure
        frame.guards.append(goal)
        return None

    def _achieve(self, thread: _Thread, frame: _Frame, goal: Goal) -> _Pursuit:
        expr = goal.expr
        if expr.head == "=" and len(expr.args) == 2 and isinstance(expr.args[0], Var):  # the assignment primitive
            ok = self._assign(frame, expr.args[0], expr.args[1], goal.line)
            return None if ok else f"{expr.args[0]} already has another value"
        if self._test(frame, expr):  # §4.4.4: already true in the database
            return None
        instance = resolve(expr, self._released(frame.env, expr))
        candidates = self._applicable(frame, goal, instance)
        if not candidates:
            return f"no applicable KA for {instance}"
        tried: list[str] = []
        for ka, invoked in candidates:
            env = self._context(frame, goal, ka, invoked)
            if env is None:
                self._record(frame, goal.line, f"{ka.name}: context no longer holds")
                tried.append(f"{ka.name}: its context no longer holds")
                continue
            if (yield from self._run_ka(thread, ka, env, str(instance))):
                return self._give_back(frame, expr, ka, env)
            tried.append(f"{ka.name}: {thread.failure}")  # why each failed: the cause, however deep
        return f"every applicable KA failed ({'; '.join(tried)})"

    def _applicable(self, frame: _Frame, goal: Goal, instance: Compound) -> list[tuple[KA, dict[str, Any]]]:
        """The KAs whose invocation matches and whose context holds, in the order to try them.
        Each comes with its variables as bound by the invocation (the context is tested again
        when its turn comes)."""
        candidates: list[tuple[KA, dict[str, Any]]] = []
        for ka in self._goal_kas:
            env: dict[str, Any] = {}
            if match(ka.trigger, instance, env) and self._context(frame, goal, ka, env, consume=False) is not None:
                candidates.append((ka, env))
        candidates = self._order(candidates)
        if len(candidates) > 1:
            candidates = self._arbitrate(frame, goal, instance, candidates)
        return candidates

    def _context(self, frame: _Frame, goal: Goal, ka: KA, env: dict[str, Any],
                 consume: bool = True) -> dict[str, Any] | None:
        """The KA's variables once its context holds (None if it does not, or cannot be tested)."""
        if ka.context is None:
            return env
        try:
            return self._first(_expression(ka.context), env, frame, ka.line, consume)
        except ExecutionError as error:
            self._record(frame, goal.line, f"{ka.name}: context cannot be tested: {error.reason}")
            return None

    def _arbitrate(self, frame: _Frame, goal: Goal, instance: Compound,
                   candidates: list[tuple[KA, dict[str, Any]]]) -> list[tuple[KA, dict[str, Any]]]:
        """Meta KAs, then the `meta` hook, choose which KAs to try and in what order."""
        by_name = {ka.name: (ka, env) for ka, env in candidates}
        for meta in self._meta_kas:
            env: dict[str, Any] = {}
            if not match(meta.trigger, instance, env):
                continue
            if meta.context is not None and self._first(_expression(meta.context), env, frame, meta.line) is None:
                continue
            assert meta.action is not None
            chosen = self._call(frame, meta.action, env, [ka.name for ka, _ in candidates])
            if not isinstance(chosen, (list, tuple)) or any(name not in by_name for name in chosen):
                raise ExecutionError(f"meta KA {meta.name} returned {chosen!r}, not a list of names among "
                                     f"{', '.join(by_name)}")
            candidates = [by_name[name] for name in chosen]
            self._record(frame, goal.line, f"meta KA {meta.name} chose {', '.join(chosen) or 'none'}")
            break
        if self._meta is not None:
            kas = self._meta(Goal(goal.op, instance, goal.line), [ka for ka, _ in candidates])
            envs = {id(ka): env for ka, env in candidates}
            candidates = [(ka, envs[id(ka)]) for ka in kas if id(ka) in envs]
        return candidates

    def _give_back(self, frame: _Frame, expr: Compound, ka: KA, env: dict[str, Any]) -> str | None:
        """The values the KA gave its invocation's variables flow back into the goal."""
        returned = self._released(frame.env, expr)
        for goal_arg, ka_arg in zip(expr.args, ka.trigger.args, strict=True):
            if not match(goal_arg, resolve(ka_arg, env), returned):
                return f"{ka.name} succeeded with {ka_arg} = {resolve(ka_arg, env)}, which does not match {goal_arg}"
        frame.env.update(returned)
        return None

    def _order(self, items: list[Any]) -> list[Any]:
        if self._random is not None:
            self._random.shuffle(items)
        return items

    # ------------------------------------------------------------ tests and updates
    def _test(self, frame: _Frame, expr: Compound) -> bool:
        """?expr: its first solution binds the frame's variables and uses its events."""
        solution = self._first(expr, self._released(frame.env, expr), frame, 0)
        if solution is None:
            return False
        frame.env.update(solution)
        return True

    def _holds(self, frame: _Frame, expr: Compound) -> bool:
        """Does expr hold? Binds nothing, uses no event."""
        return self._first(expr, self._released(frame.env, expr), frame, 0, consume=False) is not None

    def _first(self, expr: Compound, env: dict[str, Any], frame: _Frame | None, line: int,
               consume: bool = True) -> dict[str, Any] | None:
        ctx = PrimitiveContext(self, frame, line)
        for solution, used in self._solve(expr, env, ctx):
            if consume and used:
                for occurrence in used:
                    self.database._use(occurrence)
                self._changed()
            return solution
        return None

    def _released(self, env: dict[str, Any], expr: Compound) -> dict[str, Any]:
        """A copy of env without the program variables that expr binds afresh (see the module
        docstring): those in the arguments of database predicates and achieved goals."""
        released = dict(env)
        for name in self._outputs(expr):
            released.pop(name, None)
        return released

    def _outputs(self, expr: Compound) -> set[str]:
        if expr.head in _CONNECTIVES:
            return set().union(*(self._outputs(a) for a in expr.args if isinstance(a, Compound)))
        if expr.head in _BUILTINS or self.database.kind(expr.head) == "evaluable":
            return set()
        # An argument itself, not one inside an expression (`!(NOTED (+ @I 1))` reads @I), as the
        # Petri-net translation reads them (`specc.analysis.prs_net.outputs`).
        return {a.name for a in expr.args if isinstance(a, Var) and a.is_program}

    def _solve(self, expr: Term, env: dict[str, Any], ctx: PrimitiveContext
               ) -> Iterator[tuple[dict[str, Any], tuple[_Occurrence, ...]]]:
        """Every solution of expr: the variables it binds, and the event occurrences it used."""
        if not isinstance(expr, Compound):
            raise ExecutionError(f"{expr} is not a condition (HEAD arg ...)")
        head, args = expr.head, expr.args
        if head == "&":
            yield from self._solve_all(args, env, ctx, ())
        elif head == "|":
            for alternative in args:
                yield from self._solve(alternative, env, ctx)
        elif head == "~":
            yield from self._solve_not(expr, env, ctx)
        elif head in COMPARISONS:
            values = [resolve(a, env) for a in args]
            if len(values) != 2:
                raise ExecutionError(f"{expr}: a comparison takes two values")
            if _unbound(values):
                raise ExecutionError(f"{expr}: {_unbound(values)[0]} is unbound")
            try:
                if compare(head, values[0], values[1]):
                    yield env, ()
            except ValueError as exc:
                raise ExecutionError(f"{expr}: {exc}") from None
        elif head == "=":
            solution = self._unify(expr, env)
            if solution is not None:
                yield solution, ()
        elif head == "BOUNDP":
            if not _unbound([resolve(a, env) for a in args]):
                yield env, ()
        elif self.database.kind(head) == "evaluable":
            if self._evaluate(expr, env, ctx):
                yield env, ()
        else:
            for args_of in self.database._facts_of(head):
                solution = dict(env)
                if match(expr, Compound(head, args_of), solution):
                    yield solution, ()
            for occurrence in self.database._occurrences_of(head):
                solution = dict(env)
                if match(expr, occurrence.fact, solution):
                    yield solution, (occurrence,)

    def _solve_all(self, conjuncts: Sequence[Term], env: dict[str, Any], ctx: PrimitiveContext,
                   used: tuple[_Occurrence, ...]) -> Iterator[tuple[dict[str, Any], tuple[_Occurrence, ...]]]:
        if not conjuncts:
            yield env, used
            return
        for solution, more in self._solve(conjuncts[0], env, ctx):
            if not any(occurrence in used for occurrence in more):  # an occurrence serves once
                yield from self._solve_all(conjuncts[1:], solution, ctx, used + more)

    def _solve_not(self, expr: Compound, env: dict[str, Any], ctx: PrimitiveContext
                   ) -> Iterator[tuple[dict[str, Any], tuple[_Occurrence, ...]]]:
        if len(expr.args) != 1 or not isinstance(expr.args[0], Compound):
            raise ExecutionError(f"{expr}: ~ takes one condition")
        inner = expr.args[0]
        stored = inner.head not in _CONNECTIVES and inner.head not in _BUILTINS
        if stored and self.database.kind(inner.head) == "standard":  # three-valued: look for the negation
            for args_of in self.database._facts_of(inner.head, negative=True):
                solution = dict(env)
                if match(inner, Compound(inner.head, args_of), solution):
                    yield solution, ()
        elif next(self._solve(inner, env, ctx), None) is None:  # closed world: negation as failure
            yield env, ()

    def _unify(self, expr: Compound, env: dict[str, Any]) -> dict[str, Any] | None:
        if len(expr.args) != 2:
            raise ExecutionError(f"{expr}: = takes two terms")
        left, right = (resolve(a, env) for a in expr.args)
        solution = dict(env)
        if isinstance(left, Var) and not _unbound([right]):
            solution[left.name] = right
        elif isinstance(right, Var) and not _unbound([left]):
            solution[right.name] = left
        elif _unbound([left, right]):
            raise ExecutionError(f"{expr}: {_unbound([left, right])[0]} is unbound")
        elif not _same(left, right):
            return None
        return solution

    def _evaluate(self, expr: Compound, env: dict[str, Any], ctx: PrimitiveContext) -> bool:
        args = [resolve(a, env) for a in expr.args]
        if _unbound(args):
            raise ExecutionError(f"evaluable predicate {expr}: {_unbound(args)[0]} is unbound")
        binding = self.database.predicates[expr.head].binding
        function = self._function(binding, expr.head)
        try:
            return bool(function(ctx, *args))
        except Exception as exc:
            raise ExecutionError(f"evaluable predicate {expr.head} raised {type(exc).__name__}: {exc}") from None

    def _update(self, frame: _Frame, goal: Goal) -> None:
        """=>C or ~>C from a KA."""
        if goal.op not in ("=>", "~>"):
            raise ExecutionError(f"{goal}: effects only conclude (=>) or retract (~>)", goal.line)
        fact = resolve(goal.expr, frame.env)
        unbound = _unbound([fact])
        if goal.op == "=>":
            if unbound:  # Fig 4.11: an error
                raise ExecutionError(f"{goal} failed: {unbound[0]} is unbound", goal.line)
            self._conclude(fact)
        elif unbound:  # Fig 4.12: nothing changes
            self._record(frame, goal.line, f"{goal}: nothing retracted, {unbound[0]} is unbound")
        else:
            self._retract(fact)

    def _outside(self, fact: Compound) -> str | None:
        """What of `fact` lies outside its predicate's declared domains (None if nothing)."""
        predicate = self.database.predicates.get(fact.head)
        return predicate.outside(fact.args) if predicate is not None and predicate.domains else None

    def _conclude(self, fact: Compound, checked: bool = True) -> None:
        negative, positive = _polarity(fact)
        outside = self._outside(positive) if checked else None
        if outside is not None:
            raise ExecutionError(f"=>{fact}: {outside}")
        kind = self.database.kind(positive.head)
        if kind == "evaluable":
            raise ExecutionError(f"=>{fact}: {positive.head} is evaluable, it cannot be concluded")
        if kind == "event":
            if negative:
                raise ExecutionError(f"=>{fact}: an event cannot be concluded false")
            self._signal(positive, checked=False)  # its domain is checked above
            return
        if self.database._store(positive, negative):
            self._changed()
            self._invoke(fact)

    def _retract(self, fact: Compound) -> None:
        negative, positive = _polarity(fact)
        kind = self.database.kind(positive.head)
        if negative and kind != "standard":
            raise ExecutionError(f"~>{fact}: {positive.head} is {kind}, its negation is its absence")
        if self.database._remove(positive, negative):
            self._changed()

    def _signal(self, event: Compound, checked: bool = True) -> None:
        if event.head in self.database.predicates and self.database.kind(event.head) in _STORED_KINDS:
            self._conclude(event, checked)  # the library keeps these facts: the message concludes one
            return
        outside = self._outside(event) if checked else None
        if outside is not None:
            raise ExecutionError(f"{event}: {outside}")
        if not self._invoke(event):
            self.database._add_event(event)
        self._changed()

    def _invoke(self, fact: Compound) -> int:
        """Start the fact-invoked KAs that `fact` triggers; how many started."""
        started = 0
        for ka in self._fact_kas:
            env: dict[str, Any] = {}
            if not match(ka.trigger, fact, env):
                continue
            try:
                if ka.context is not None and self._first(_expression(ka.context), env, None, ka.line) is None:
                    continue
            except ExecutionError as error:
                self._log(f"{ka.name} not invoked by {fact}: its context cannot be tested: {error.reason}")
                continue
            intention = Intention(goal=None, trigger=fact, ka=ka)
            thread = _Thread(intention)
            thread.body = self._run_invoked(thread, ka, env, fact)
            self.intentions.append(intention)
            self._start(thread)
            started += 1
        return started

    def _assign(self, frame: _Frame, var: Var, term: Term, line: int) -> bool:
        try:
            value = resolve(term, frame.env)
        except ExecutionError as error:
            raise ExecutionError(f"{var} = {term}: {error.reason}", line) from None
        if _unbound([value]):
            raise ExecutionError(f"{var} = {term}: {_unbound([value])[0]} is unbound", line)
        if var.is_program or var.name not in frame.env:
            frame.env[var.name] = value
            return True
        if _same(frame.env[var.name], value):
            return True
        self._record(frame, line, f"{var} is {frame.env[var.name]!r}: it cannot become {value!r}")
        return False

    # ------------------------------------------------------------ primitives
    def _act(self, frame: _Frame, action: Action) -> bool:
        """A primitive KA's ACTION (Fig 4.2)."""
        value = self._call(frame, action, frame.env)
        if action.result is None:
            return True
        if action.result.is_program:
            frame.env[action.result.name] = value
            return True
        if match(action.result, value, frame.env):
            return True
        self._record(frame, action.line, f"{action.result} is {frame.env[action.result.name]!r}, "
                                         f"the action returned {value!r}")
        return False

    def _call(self, frame: _Frame, action: Action, env: dict[str, Any], candidates: Sequence[str] = ()) -> Any:
        call = action.call
        primitive = self._primitives.get(call.head)
        if primitive is None:
            raise ExecutionError(f"{call}: the library declares no primitive action {call.head}", action.line)
        args = [resolve(a, env) for a in call.args]
        if _unbound(args):
            raise ExecutionError(f"{call}: {_unbound(args)[0]} is unbound", action.line)
        if len(args) != primitive.arity:
            raise ExecutionError(f"{call}: {call.head} takes {primitive.arity} argument(s)", action.line)
        function = self._request_service(primitive.service) if primitive.service else \
            self._function(primitive.binding, call.head)
        try:
            value = function(PrimitiveContext(self, frame, action.line, candidates), *args)
        except Exception as exc:
            raise ExecutionError(f"{resolve(call, env)} raised {type(exc).__name__}: {exc}", action.line) from None
        if primitive.domain is not None and not any(_same(value, allowed) for allowed in primitive.domain):
            raise ExecutionError(f"{resolve(call, env)} returned {value!r}, which is not in the domain of its result "
                                 f"({', '.join(map(show, primitive.domain))})", action.line)
        self._record(frame, action.line, f"{resolve(call, env)}" + (f" -> {value!r}" if primitive.returns else ""))
        return value

    @staticmethod
    def _request_service(service: str) -> Callable[..., Any]:
        """An action bound to an executive service: SEND-REQUEST (Fig 4.2) with the action's
        arguments as the service's inputs; its value is the request's id."""

        def request(ctx: PrimitiveContext, *args: Any) -> int:
            ident = ctx.new_id()
            ctx.send((service, ident, *args))
            return ident

        return request

    def _function(self, binding: str, name: str) -> Callable[..., Any]:
        function = self.functions.get(binding)
        if function is None:
            raise ExecutionError(f"{name}: no Python function for '{binding}' (pass it in `functions=`)")
        return function

    # ------------------------------------------------------------ the executive
    def _on_message(self, message: Message) -> None:
        """An executive message, as a basic event. One outside its predicate's declared domain
        (a result the procedures do not list) is what the procedures' proofs did not cover: the
        executive notes an incident, and the event is still received, as the robot would."""
        head, *args = message.fact
        event = Compound(head, tuple(args))
        outside = self._outside(event)
        if outside is not None and self.executive is not None:
            self.executive.incidents.append(f"the supervisor received {event}: {outside}")
        self._signal(event, checked=False)


def _expression(condition: Goal | Compound) -> Compound:
    return condition.expr if isinstance(condition, Goal) else condition


def _polarity(fact: Compound) -> tuple[bool, Compound]:
    """(negative?, the fact without its ~)."""
    if fact.head == "~":
        inner = fact.args[0] if len(fact.args) == 1 else None
        if not isinstance(inner, Compound):
            raise ExecutionError(f"{fact}: ~ takes one fact")
        return True, inner
    return False, fact
