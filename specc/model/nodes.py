"""The specc model: frozen dataclasses, one per language construct, each with a span.

Spans never take part in equality, so `parse(print(model)) == model` compares meaning only.
Blocks written as GenoM-style `key: value;` properties declare those keys in field metadata
(see `prop`): the builder fills them and the printer writes them back from the same schema.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import FrozenInstanceError, dataclass, field, fields
from typing import TYPE_CHECKING, Any, Literal, TypeVar, Union

from specc.model.span import NO_SPAN, Span

ValueKind = Literal["ref", "refs", "int", "string", "duration", "typed", "symbol"]


def span_field() -> Any:
    return field(default=NO_SPAN, compare=False, repr=False)


def prop(key: str, kind: ValueKind, *, choices: tuple[str, ...] = (), doc: str = "") -> Any:
    """A field filled from the property `key: ...;`.

    kind: ref (one name), refs (a list of names), int, string, duration, typed (a list of
    `name: type`), symbol (one name out of `choices`).
    """
    default: Any = () if kind in ("refs", "typed") else None
    return field(default=default, metadata={"key": key, "kind": kind, "choices": choices, "doc": doc})


def property_fields(node_type: type) -> list[Any]:
    return [f for f in fields(node_type) if "key" in f.metadata]


NodeType = TypeVar("NodeType", bound=type)

if TYPE_CHECKING:  # what the classes are: frozen keyword-only dataclasses
    from typing_extensions import dataclass_transform

    @dataclass_transform(kw_only_default=True, frozen_default=True, eq_default=False, field_specifiers=(field,))
    def node(cls: NodeType) -> NodeType: ...
else:
    # How they are made: frozen by Node's own __setattr__ (below), not by a __setattr__ and a
    # __delattr__ `dataclass(frozen=True)` would generate for each of the model's classes.
    node: Callable[[NodeType], NodeType] = dataclass(kw_only=True, eq=False, repr=False)


@node
class Node:
    """The base of every construct: where it was written (spans never take part in equality)."""

    span: Span = span_field()

    # Equality, hash, repr and frozenness are written once here, from each class's fields, where
    # `dataclass` would generate them for every class (eq=False, repr=False and not frozen on each,
    # see `node`): generating them for the model's 129 classes was 50 ms of every command's start.
    # They mean what the generated ones do: same class and same compared fields; a hash of those;
    # the repr fields by name; each field set once, by __init__, and nothing set or deleted after.
    def __setattr__(self, name: str, value: Any) -> None:
        if name in self.__dict__ or name not in self.__dataclass_fields__:
            what = "field" if name in self.__dataclass_fields__ else "attribute"
            raise FrozenInstanceError(f"cannot assign to {what} {name!r}")
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        raise FrozenInstanceError(f"cannot delete field {name!r}")

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return _compared_values(self) == _compared_values(other)

    def __hash__(self) -> int:
        return hash(_compared_values(self))

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in _field_names(type(self), "repr"))
        return f"{type(self).__name__}({shown})"


def _field_names(node_type: type, flag: str) -> tuple[str, ...]:
    """The names of the fields of `node_type` whose `flag` ("compare" or "repr") is set."""
    names = _FIELD_NAMES.get((node_type, flag))
    if names is None:
        names = _FIELD_NAMES[node_type, flag] = tuple(f.name for f in fields(node_type) if getattr(f, flag))
    return names


_FIELD_NAMES: dict[tuple[type, str], tuple[str, ...]] = {}


def _compared_values(node: Node) -> tuple[Any, ...]:
    return tuple([getattr(node, name) for name in _field_names(type(node), "compare")])


# ---------------------------------------------------------------- values


class Word(str):
    """A keyword-like value kept as plain text (`type: exec;`, `property: x;`).

    It compares and hashes as the string, so checks and back ends test `kind == "exec"`
    and models still compare by meaning; it remembers where it was written so that the
    formatter can keep a comment on its line (`type: exec;  // why`) where it was.
    """

    span: Span

    def __new__(cls, text: str, span: Span = NO_SPAN) -> Word:
        word = super().__new__(cls, text)
        word.span = span
        return word


@node
class Ref(Node):
    """A name, possibly dotted (`pilo.execPosterTraj`)."""

    parts: tuple[str, ...]

    @property
    def text(self) -> str:
        return ".".join(self.parts)


@node
class Number(Node):
    """A number as written (`3`, `0.25`)."""

    value: int | float


@node
class Duration(Node):
    """A number with its unit of time (`50 ms`, `2 min`)."""

    value: int | float
    unit: str

    SCALE = {"us": 1e-6, "ms": 1e-3, "s": 1.0, "min": 60.0}

    @property
    def seconds(self) -> float:
        return float(self.value) * self.SCALE[self.unit]


@node
class String(Node):
    """A double-quoted string (`"tug_codels"`)."""

    value: str


@node
class TypeRef(Node):
    """A GenoM type (`double`, `char[32]`, a struct or enum of the module)."""

    name: str
    size: int | None = None


@node
class TypedName(Node):
    """`name: type`, in a request's `input:` or `output:`."""

    name: str
    type: TypeRef


PropValue = Union[Ref, Number, Duration, String, TypedName]


# ---------------------------------------------------------------- module (GenoM)


@node
class Field(Node):
    """A field of a struct or of a module's internal data (`x: double;`)."""

    name: str
    type: TypeRef


@node
class StructDecl(Node):
    """`struct NAME { field: type; ... }` in a module."""

    name: str
    fields: tuple[Field, ...] = ()


@node
class EnumDecl(Node):
    """`enum NAME { A, B, ... }` in a module."""

    name: str
    values: tuple[str, ...] = ()


@node
class Codel(Node):
    """`codel <state>: <function> [-> next, states];` — the codel run in that activity state."""

    state: str
    function: str
    yields: tuple[str, ...] = ()


@node
class Request(Node):
    """`request NAME { type: control|exec; ... }`: what a module offers (GenoM), with its codels."""

    name: str
    kind: str | None = prop("type", "symbol", choices=("control", "exec"))
    activity: Ref | None = prop("activity", "ref", doc="activity kind, e.g. filter")
    inputs: tuple[TypedName, ...] = prop("input", "typed")
    outputs: tuple[TypedName, ...] = prop("output", "typed")
    validate: Ref | None = prop("validate", "ref", doc="validation codel (control function)")
    task: Ref | None = prop("task", "ref", doc="exec task that runs the activity")
    fail: tuple[Ref, ...] = prop("fail", "refs", doc="the only errors a codel may report")
    incompatible_with: tuple[Ref, ...] = prop("incompatible_with", "refs")
    sends: tuple[Ref, ...] = prop("sends", "refs", doc="module.request its codels send (activity tree)")
    doc: String | None = prop("doc", "string")
    codels: tuple[Codel, ...] = ()


@node
class ExecTask(Node):
    """`exec_task NAME { period: ...; }`: the periodic task that runs a module's activities."""

    name: str
    period: Duration | None = prop("period", "duration")
    delay: Duration | None = prop("delay", "duration")
    priority: Number | None = prop("priority", "int")
    stack: Number | None = prop("stack", "int")
    resources: tuple[Ref, ...] = prop("resources", "refs")
    doc: String | None = prop("doc", "string")
    codels: tuple[Codel, ...] = ()


@node
class Poster(Node):
    """`poster NAME { data: ...; }`: data a module publishes for others to read."""

    name: str
    update: str | None = prop("update", "symbol", choices=("auto", "manual"))
    data: tuple[Ref, ...] = prop("data", "refs", doc="internal data fields exported")
    activity: Ref | None = prop("activity", "ref", doc="activity whose cycle updates the poster")
    doc: String | None = prop("doc", "string")


@node
class Module(Node):
    """`module NAME { ... }`: a GenoM functional module (seed 000 ch. 2)."""

    name: str
    number: Number | None = prop("number", "int")
    codel_module: String | None = prop("codels", "string", doc="Python module holding the codels")
    doc: String | None = prop("doc", "string")
    structs: tuple[StructDecl, ...] = ()
    enums: tuple[EnumDecl, ...] = ()
    internal_data: tuple[Field, ...] = ()
    requests: tuple[Request, ...] = ()
    exec_tasks: tuple[ExecTask, ...] = ()
    posters: tuple[Poster, ...] = ()


# ---------------------------------------------------------------- executive


@node
class Timeouts(Node):
    """`timeout { start: ...; interm: ...; final: ...; }` of a service: how long each reply may take."""

    start: Duration | None = prop("start", "duration")
    interm: Duration | None = prop("interm", "duration")
    final: Duration | None = prop("final", "duration")


@node
class Conflict(Node):
    """`SERVICE: interrupt;` or `SERVICE: wait;` in a service's `conflicts { }`: what happens when both are asked."""

    service: str
    policy: str  # "interrupt" | "wait"


@node
class Argument(Node):
    """A constant input of the service's request (`args { speed: 0.3; }`)."""

    name: str
    value: PropValue


@node
class Service(Node):
    """`service NAME { request: module.REQUEST; ... }`: a request the executive runs for the task level."""

    name: str
    request: Ref | None = prop("request", "ref", doc="module.request the service runs")
    input: Ref | None = prop("input", "ref", doc="input function or poster giving the request's input")
    output: Ref | None = prop("output", "ref", doc="output function receiving the final reply")
    takes: tuple[Ref, ...] = prop("takes", "refs", doc="the request's inputs the task level gives, in order")
    doc: String | None = prop("doc", "string")
    timeout: Timeouts | None = None
    args: tuple[Argument, ...] = ()
    conflicts: tuple[Conflict, ...] = ()


@node
class Comparison(Node):
    """`OP value` in a reflex's trigger (`> 0.5`)."""

    op: str
    value: PropValue


@node
class ReflexAction(Node):
    """`request|abort|start TARGET` in a reflex: what it does when triggered."""

    verb: str  # request | abort | start
    target: Ref


@node
class Reflex(Node):
    """`reflex [NAME] on reply|warning|interm SOURCE [OP value] => actions;`: the executive's own
    reaction."""

    name: str | None
    trigger: str  # reply | warning | interm
    source: Ref
    comparison: Comparison | None = None
    actions: tuple[ReflexAction, ...] = ()


@node
class Parameter(Node):
    """A GET-PARAM / SET-PARAM parameter of the executive (seed 000 §4.2.2)."""

    name: str
    get: Ref | None = prop("get", "ref", doc="poster or poster field read by GET-PARAM")
    set: Ref | None = prop("set", "ref", doc="control request written by SET-PARAM")
    doc: String | None = prop("doc", "string")


@node
class Executive(Node):
    """`executive NAME { service ...; reflex ...; }`: the services and their incompatibilities (seed 000 ch. 3)."""

    name: str
    rules: tuple[Ref, ...] = prop("rules", "refs", doc="rule bases added to the generated controller")
    codel_module: String | None = prop("codels", "string", doc="Python module of input/output functions")
    doc: String | None = prop("doc", "string")
    services: tuple[Service, ...] = ()
    reflexes: tuple[Reflex, ...] = ()
    parameters: tuple[Parameter, ...] = ()


# ---------------------------------------------------------------- rules (Kheops)


@node
class AttrRef(Node):
    """An attribute of a rule base as a rule reads it (`speed`; `@speed`, its previous value; `range[i]`)."""

    name: str
    previous: bool = False
    index: str | None = None


@node
class KBinary(Node):
    """`left OP right`: arithmetic in a rule base."""

    op: str
    left: KExpr
    right: KExpr


@node
class KNegate(Node):
    """`-operand` in a rule base."""

    operand: KExpr


KExpr = Union[Number, String, AttrRef, KBinary, KNegate]


@node
class KRange(Node):
    """`low..high` in a rule base's list of values."""

    low: KItem
    high: KItem


KItem = Union[String, Number, Ref, KRange]


@node
class SymbolDomain(Node):
    """`{"fast", "slow"}`: the symbols an attribute of a rule base takes."""

    values: tuple[KItem, ...]


@node
class NumericDomain(Node):
    """`[low, high]` or `number`: the numbers an attribute of a rule base takes."""

    low: KExpr | None = None
    high: KExpr | None = None


@node
class BoolDomain(Node):
    """`bool`: a true/false attribute of a rule base."""


AttrDomain = Union[SymbolDomain, NumericDomain, BoolDomain]


@node
class AttrDecl(Node):
    """`inputs|outputs|intermediate name: domain, ...;` in a rule base."""

    role: str  # inputs | outputs | intermediate
    name: str
    domain: AttrDomain | None = None


@node
class ConstDecl(Node):
    """`const NAME = value;` in a rule base."""

    name: str
    value: KExpr


@node
class InitDecl(Node):
    """`init @NAME = value;` in a rule base: an attribute's previous value at the first decision."""

    name: str
    value: KExpr


@node
class KCompare(Node):
    """`attr OP value` in a rule's condition."""

    attr: AttrRef
    op: str
    value: KExpr


@node
class KMember(Node):
    """`attr oneof|noneof [items]` in a rule's condition."""

    attr: AttrRef
    op: str  # oneof | noneof
    items: tuple[KItem, ...]


@node
class KTrue(Node):
    """`attr` alone in a rule's condition or restriction: a bool attribute that holds."""

    attr: AttrRef


@node
class KFalse(Node):
    """`!attr` in a restriction: a bool attribute that does not hold."""

    attr: AttrRef


@node
class KNot(Node):
    """`!condition` in a rule's condition."""

    operand: Cond


@node
class KAnd(Node):
    """Conditions that must all hold (`a, b`)."""

    operands: tuple[Cond, ...]


@node
class KOr(Node):
    """Conditions of which one must hold (`a | b`)."""

    operands: tuple[Cond, ...]


@node
class KForeach(Node):
    """`foreach VAR in [items] (condition)`: the condition for each item."""

    var: str
    items: tuple[KItem, ...]
    body: Cond


Cond = Union[KCompare, KMember, KTrue, KNot, KAnd, KOr, KForeach]
Restriction = Union[KCompare, KMember, KTrue, KFalse]


@node
class Restrict(Node):
    """`restrict RESTRICTION` in a rule's actions: it narrows an output's values."""

    restriction: Restriction


@node
class DoAssign(Node):
    """`target = value` in a rule's `do { }`."""

    target: str
    value: KExpr


@node
class DoCall(Node):
    """`function(args)` in a rule's `do { }`."""

    function: str
    args: tuple[KExpr, ...] = ()


@node
class DoAction(Node):
    """`do { target = value; function(args) }` in a rule's actions."""

    statements: tuple[DoAssign | DoCall, ...]


Action = Union[Restrict, DoAction]


@node
class Rule(Node):
    """`NAME: condition ==> actions;` in a rule base (or an `impossible` / `else` rule)."""

    name: str
    index: str | None = None
    kind: str = "when"  # when | impossible | else
    condition: Cond | None = None
    actions: tuple[Action, ...] = ()


@node
class RuleForeach(Node):
    """`foreach VAR in [items] { rules }`: rules written once for each item."""

    var: str
    items: tuple[KItem, ...]
    rules: tuple[Rule, ...]


@node
class RuleBase(Node):
    """`rules NAME { ... }`: a Kheops rule base (seed 000 §3.7), compiled to a decision of bounded depth."""

    name: str
    constants: tuple[ConstDecl, ...] = ()
    attributes: tuple[AttrDecl, ...] = ()
    inits: tuple[InitDecl, ...] = ()
    rules: tuple[Rule | RuleForeach, ...] = ()


# ---------------------------------------------------------------- procedures (PRS)


@node
class SymbolSet(Node):
    """`{A, B, C}`: the values of a PRS type or parameter."""

    values: tuple[str, ...]


@node
class DomainRef(Node):
    """A named PRS type used as a domain."""

    name: str


@node
class IntRange(Node):
    """`low..high`: the bounded integers a Petri-net translation can enumerate (§4.4.10)."""

    low: int
    high: int


PDomain = Union[SymbolSet, IntRange, DomainRef]


@node
class TypeDecl(Node):
    """`type NAME = domain;` in procedures."""

    name: str
    domain: PDomain


@node
class PParam(Node):
    """`name: domain`, a parameter of a PRS predicate or action."""

    name: str
    domain: PDomain


@node
class PredicateDecl(Node):
    """`predicate [kinds] NAME(params) [-> result];` in procedures: a fact of the database."""

    name: str
    kinds: tuple[str, ...] = ()  # closed | functional | event | evaluable
    params: tuple[PParam, ...] = ()
    result: PDomain | None = None
    binding: String | None = None  # the Python function an evaluable predicate calls


@node
class ServiceBinding(Node):
    """`action GOTO(x: float, y: float) -> int = service GOTO;`: the action requests the executive's
    service with its arguments (the service's `takes:` inputs) and its value is the request's id."""

    service: str


@node
class ActionDecl(Node):
    """`action NAME(params) [-> result] = ...;` in procedures: what a primitive KA may do."""

    name: str
    params: tuple[PParam, ...] = ()
    result: PDomain | None = None
    binding: String | ServiceBinding


@node
class LogicVar(Node):
    """`$X`: a PRS logical variable."""

    name: str  # with its leading $


@node
class ProgramVar(Node):
    """`@X`: a PRS program variable."""

    name: str  # with its leading @


@node
class SExp(Node):
    """`(HEAD args...)`: a PRS expression, fact or call."""

    head: str
    args: tuple[SArg, ...] = ()


SArg = Union[LogicVar, ProgramVar, Ref, Number, String, SExp]


@node
class Goal(Node):
    """`!(...)`, `?(...)`, `^(...)`, `=>(...)`, `~>(...)`, `#(...)` or `%(...)`: a PRS goal (achieve,
    test, wait, conclude, retract, preserve, maintain)."""

    op: str  # ! ? ^ => ~> # %
    body: SExp


@node
class Block(Node):
    """`{ statements }` in a KA's body."""

    statements: tuple[Stmt, ...] = ()


@node
class GoalStmt(Node):
    """A goal as a statement of a KA's body (`!(GO 2 5);`)."""

    goal: Goal


@node
class IfStmt(Node):
    """`if (goal) { ... } else { ... }` in a KA's body."""

    condition: Goal
    then: Block
    orelse: Block | IfStmt | None = None


@node
class WhileStmt(Node):
    """`while (goal) { ... }` in a KA's body."""

    condition: Goal
    body: Block


@node
class ParallelStmt(Node):
    """`parallel { ... } { ... }` in a KA's body: branches run together."""

    branches: tuple[Block, ...]


@node
class ChooseStmt(Node):
    """`choose { ... } { ... }` in a KA's body: the first branch that succeeds."""

    branches: tuple[Block, ...]


@node
class AssignStmt(Node):
    """`assign @X = value;` in a KA's body."""

    var: str
    value: SArg


@node
class FailStmt(Node):
    """`fail;` in a KA's body: the KA fails here."""


Stmt = Union[GoalStmt, IfStmt, WhileStmt, ParallelStmt, ChooseStmt, AssignStmt, FailStmt]


@node
class KAAction(Node):
    """`action: (CALL args) [-> $RESULT];`: a primitive KA's action."""

    call: SExp
    result: LogicVar | ProgramVar | None = None


@node
class KA(Node):
    """`ka NAME { invocation: ...; body { } }`: a PRS knowledge area (seed 000 ch. 4)."""

    name: str
    invocation: Goal | SExp | None = None
    context: Goal | SExp | None = None
    body: Block | None = None
    action: KAAction | None = None
    effects: tuple[Goal, ...] = ()
    documentation: String | None = None
    properties: tuple[str, ...] = ()


@node
class Procedures(Node):
    """`procedures NAME { ... }`: a PRS database's types, predicates and actions, and its KAs."""

    name: str
    types: tuple[TypeDecl, ...] = ()
    predicates: tuple[PredicateDecl, ...] = ()
    actions: tuple[ActionDecl, ...] = ()
    kas: tuple[KA, ...] = ()


# ---------------------------------------------------------------- domain / problem (IxTeT)


@node
class Infinity(Node):
    """`oo`: an unbounded end of an IxTeT interval."""


@node
class IxVar(Node):
    """`?x`: an IxTeT variable."""

    name: str  # with its leading ?


@node
class IxName(Node):
    """A constant symbol or a timepoint in IxTeT (`DOCK`, `t_start`)."""

    name: str


@node
class IxCall(Node):
    """`FUNCTION(args)` in an IxTeT expression."""

    function: str
    args: tuple[IxExpr, ...] = ()


@node
class IxBinary(Node):
    """`left OP right` in an IxTeT expression."""

    op: str
    left: IxExpr
    right: IxExpr


@node
class IxUnary(Node):
    """`-operand` (or another prefix operator) in an IxTeT expression."""

    op: str
    operand: IxExpr


IxExpr = Union[Number, Infinity, IxVar, IxName, IxCall, IxBinary, IxUnary]


@node
class Interval(Node):
    """`[low, high]` in IxTeT."""

    low: IxExpr
    high: IxExpr


@node
class SetLiteral(Node):
    """`{A, B}` in IxTeT."""

    values: tuple[str, ...]


@node
class SetRef(Node):
    """A named constant set in IxTeT (`PLACES`)."""

    name: str


@node
class SetUnion(Node):
    """Sets joined with `|`, or one set, in IxTeT."""

    parts: tuple[SetLiteral | SetRef, ...]


DomainValue = Union[Interval, SetUnion]


@node
class Transition(Node):
    """`(before, after)`: the value an event changes an attribute from and to."""

    before: IxExpr
    after: IxExpr


@node
class AttrValue(Node):
    """`ATTRIBUTE(args): value` in IxTeT, the value a transition or a single value."""

    attribute: str
    args: tuple[IxExpr, ...] = ()
    value: IxExpr | Transition


@node
class GoalMark(Node):
    """`goal(priority, weight)` after an assertion of a problem: it is a goal to meet."""

    priority: IxExpr
    weight: IxExpr


@node
class Hold(Node):
    """`hold(ATTR(args): value, (start, end))`: the attribute keeps its value over the interval."""

    attr: AttrValue
    start: IxExpr
    end: IxExpr
    goal: GoalMark | None = None


@node
class Event(Node):
    """`event(ATTR(args): (before, after), time)`: the attribute changes at that time."""

    kind: str | None  # explained | contingent | None
    attr: AttrValue
    time: IxExpr
    goal: GoalMark | None = None


@node
class Window(Node):
    """`(start, end)`: the interval a resource is used over."""

    start: IxExpr
    end: IxExpr


@node
class ResourceUse(Node):
    """`use|consume|produce(RESOURCE(args): amount, when)`."""

    verb: str  # use | consume | produce
    attr: AttrValue
    when: IxExpr | Window
    goal: GoalMark | None = None


@node
class VariableDecl(Node):
    """`variable ?a, ?b;` in an IxTeT task."""

    names: tuple[IxVar, ...]


@node
class TimepointDecl(Node):
    """`timepoint t1, t2;` in an IxTeT task or problem."""

    names: tuple[str, ...]


@node
class InConstraint(Node):
    """`expr in domain;` (possibly `contingent`): an IxTeT constraint."""

    expr: IxExpr
    domain: DomainValue
    contingent: bool = False


@node
class RelConstraint(Node):
    """`left OP right;` (possibly `contingent`): an IxTeT constraint."""

    left: IxExpr
    op: str
    right: IxExpr
    contingent: bool = False


@node
class Implication(Node):
    """`condition => consequence;`: a constraint that holds only when the condition does."""

    condition: InConstraint
    consequence: InConstraint | RelConstraint


@node
class MacroCall(Node):
    """`NAME(args);`: a macro's statements written in place."""

    name: str
    args: tuple[IxExpr, ...] = ()


@node
class Include(Node):
    """`include NAME;`: a fragment's statements written in place."""

    name: str


TStmt = Union[
    VariableDecl, TimepointDecl, Hold, Event, ResourceUse, InConstraint, RelConstraint,
    Implication, MacroCall,
]


@node
class Constant(Node):
    """`constant NAME = set;` in a planning domain."""

    name: str
    value: SetUnion


@node
class Attribute(Node):
    """`attribute NAME(?params) { ... }`: a state variable of a planning domain."""

    name: str
    params: tuple[IxVar, ...] = ()
    body: tuple[TStmt, ...] = ()


@node
class Resource(Node):
    """`resource NAME(?params) { ... }`: a shared resource of a planning domain."""

    name: str
    params: tuple[IxVar, ...] = ()
    body: tuple[TStmt, ...] = ()


@node
class Macro(Node):
    """`macro NAME(params) { ... }`: statements written once and used in tasks."""

    name: str
    params: tuple[str, ...] = ()
    body: tuple[TStmt, ...] = ()


@node
class Task(Node):
    """`task NAME(?params) (t_start, t_end) { ... }`: an action a plan may hold (IxTeT's chronicle)."""

    name: str
    params: tuple[IxVar, ...] = ()
    start: str = "t_start"
    end: str = "t_end"
    body: tuple[TStmt, ...] = ()
    preemption: str | None = None


DomainMember = Union[Include, Constant, Attribute, Resource, Macro, Task]


@node
class Domain(Node):
    """`domain NAME { ... }`: an IxTeT planning domain (seed 004 annex A)."""

    name: str
    members: tuple[DomainMember, ...] = ()


@node
class Problem(Node):
    """`problem NAME for DOMAIN { ... }`: the initial state, goals and deadlines of a planning problem."""

    name: str
    domain: Ref
    body: tuple[TStmt | Include, ...] = ()
    preemption: str | None = None


@node
class Fragment(Node):
    """`fragment NAME { ... }`: statements shared by domains and problems (`include NAME;`)."""

    name: str
    members: tuple[DomainMember | TStmt, ...] = ()


# ---------------------------------------------------------------- ftplan


@node
class ViewFact(Node):
    """`ATTRIBUTE(args): value` in a correspondence; on FTplan's side the value may be an interval."""

    attribute: str
    args: tuple[IxExpr, ...] = ()
    value: IxExpr | Interval


@node
class Correspondence(Node):
    """`planner facts <=> FTplan's facts`: how a planner's vocabulary reads FTplan's state."""

    planner_facts: tuple[ViewFact, ...]
    state_facts: tuple[ViewFact, ...]


@node
class Planner(Node):
    """`planner NAME { domain: ...; }` in an ftplan block: one of FTplan's diverse planners."""

    name: str
    domain: Ref | None = prop("domain", "ref", doc="planning domain the planner uses")
    heuristic: Ref | None = prop("heuristic", "ref", doc="resolver ordering heuristic")
    flaws: Ref | None = prop("flaws", "ref", doc="flaw ordering: which task's open conditions come first")
    controllability: str | None = prop("controllability", "symbol", choices=("strong", "pseudo"),
                                       doc="what plans must hold against nature (specc.runtime.planner.search)")
    repair: str | None = prop("repair", "symbol", choices=("on", "off"),
                              doc="repair its plan after an action failure before FTplan recovers (IxTeT's)")
    improve: Number | None = prop("improve", "int", doc="partial plans spent improving each first plan (anytime)")
    doc: String | None = prop("doc", "string")
    view: tuple[Correspondence, ...] = ()


@node
class MissionProblem(Node):
    """`planner: problem;` in a mission: the planner's statement of the mission."""

    planner: Ref
    problem: Ref


@node
class MissionView(Node):
    """`view planner { ... }` in a mission: correspondences that hold for this mission only."""

    planner: Ref
    correspondences: tuple[Correspondence, ...] = ()


@node
class Mission(Node):
    """`mission NAME { planner: problem; ... }` in an ftplan block: the problem each planner plans."""

    name: str
    problems: tuple[MissionProblem, ...] = ()
    views: tuple[MissionView, ...] = ()


@node
class AnalyzerCondition(Node):
    """`during|at_start|at_end TASK(args) requires ATTR: value;`: a condition FTplan's plan analyser checks."""

    kind: str  # during | at_start | at_end
    task: str
    args: tuple[IxExpr, ...]
    requirement: AttrValue


@node
class AnalyzerNoOverlap(Node):
    """`no_overlap TASK, TASK;`: tasks FTplan's plan analyser forbids to overlap."""

    tasks: tuple[str, ...]


@node
class AnalyzerMaxDuration(Node):
    """`max_duration TASK duration;`: a duration FTplan's plan analyser bounds."""

    task: str
    limit: Duration


AnalyzerRule = Union[AnalyzerCondition, AnalyzerNoOverlap, AnalyzerMaxDuration]


@node
class FactUpdate(Node):
    """`ATTR(args) := value` in a state update."""

    attribute: str
    args: tuple[IxExpr, ...]
    value: IxExpr


@node
class StateUpdate(Node):
    """`on ended|failed|report TASK(args) => updates;`: how an action's outcome changes FTplan's state."""

    report: str  # ended | failed | report
    task: str
    args: tuple[IxExpr, ...]
    updates: tuple[FactUpdate, ...]


@node
class FtPlan(Node):
    """`ftplan NAME { ... }`: the fault-tolerant planning component (seed 004 ch. 3) and its planners."""

    name: str
    order: tuple[Ref, ...] = prop("planners", "refs", doc="planners in the order successive planning tries them")
    policy: str | None = prop("policy", "symbol", choices=("successive", "concurrent"))
    watchdog: Duration | None = prop("watchdog", "duration")
    doc: String | None = prop("doc", "string")
    planners: tuple[Planner, ...] = ()
    analyzer: tuple[AnalyzerRule, ...] = ()
    state_updates: tuple[StateUpdate, ...] = ()
    missions: tuple[Mission, ...] = ()


# ---------------------------------------------------------------- system


@node
class Setting(Node):
    """One `name: value;` entry of a system's `body { }` or `worlds { }`."""

    name: str
    value: PropValue


@node
class Settings(Node):
    """A system's `body { }` or `worlds { }` section."""

    entries: tuple[Setting, ...] = ()


@node
class DeviceGrant(Node):
    """`module: device, ...;` in a system's `devices { }`: what the module's codels may drive."""

    module: str
    devices: tuple[Ref, ...] = ()


@node
class DeviceGrants(Node):
    """A system's `devices { }` section."""

    entries: tuple[DeviceGrant, ...] = ()


@node
class Binding(Node):
    """`TASK(?a, ?b) => goal G(?a);`: how a planning task is carried out (kind: goal, service or
    request), with the target's arguments made from the task's."""

    task: str
    args: tuple[IxExpr, ...] = ()
    kind: str  # goal | service | request
    target: Ref
    target_args: tuple[IxExpr, ...] = ()  # ?variables, constants, or ATTR(...): FTplan's state after the action
    where: BindingWhere | None = None
    report: BindingReport | None = None


@node
class BindingWhere(Node):
    """`where ATTR(?o, ...) := VALUE`: ?variables bound by the first of FTplan's state changes at
    the action's end that reads so."""

    attribute: str
    args: tuple[IxExpr, ...] = ()
    value: IxExpr


@node
class BindingReport(Node):
    """`report NAME(module.Poster.field, ...)`: posters read when the action is over, reported to FTplan."""

    name: str
    values: tuple[Ref, ...] = ()


@node
class Bindings(Node):
    """A system's `bindings { }` section."""

    entries: tuple[Binding, ...] = ()


@node
class SystemMission(Node):
    """A mission of the robot: the goals its supervisor is given, in one of its worlds."""

    name: str
    world: Ref | None = prop("world", "ref", doc="one of the system's worlds (default: its only one)")
    horizon: Duration | None = prop("horizon", "duration", doc="simulated time after which the run stops")
    plan: Ref | None = prop("plan", "ref", doc="the mission of the system's ftplan block that FTplan plans")
    doc: String | None = prop("doc", "string")
    goals: tuple[Goal, ...] = ()  # `goal: !(...);`, posted together at the start


@node
class System(Node):
    """`system NAME { ... }`: how a robot runs: its modules, executive, supervisor, body, worlds, missions."""

    name: str
    modules: tuple[Ref, ...] = prop("modules", "refs")
    executive: Ref | None = prop("executive", "ref")
    supervisor: Ref | None = prop("supervisor", "ref")
    planning: Ref | None = prop("planning", "ref", doc="the ftplan block")
    extension: String | None = prop("extension", "string", doc="Python module beside the codels with the "
                                    "robot's own run hooks (world draws, observers, measures)")
    doc: String | None = prop("doc", "string")
    body: Settings | None = None  # `body { radius: 0.3; ... }` (specc.runtime.body)
    worlds: Settings | None = None  # `worlds { room: "worlds/room.toml"; }`, relative to the spec
    missions: tuple[SystemMission, ...] = ()
    bindings: Bindings | None = None  # how the planners' tasks are carried out
    devices: DeviceGrants | None = None  # which module's codels drive which device (default: all, all)


Item = Union[Module, Executive, RuleBase, Procedures, Domain, Problem, Fragment, FtPlan, System]


@node
class SourceFile(Node):
    """One spec file and the blocks it holds."""

    path: str
    items: tuple[Item, ...] = ()


@node
class Program(Node):
    """Every file of one robot, in the order they were given."""

    files: tuple[SourceFile, ...] = ()

    @property
    def items(self) -> tuple[Item, ...]:
        return tuple(item for f in self.files for item in f.items)
