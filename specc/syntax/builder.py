"""Parse tree -> model. One method per grammar rule, named after it.

Property blocks (`key: value;`) are checked against the schema their model class declares
(`specc.model.nodes.prop`): unknown keys, repeated keys and values of the wrong kind become
diagnostics here, because only the builder still sees which key each value came with.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from lark import Token, Transformer, Tree, v_args
from lark.tree import Meta

from specc.diagnostics import Diagnostic, did_you_mean, error
from specc.model import nodes as m
from specc.model.nodes import property_fields
from specc.model.span import Span


@dataclass(frozen=True)
class Prop:
    """A `key: value;` property as written, before the block it belongs to reads it."""

    key: str
    key_span: Span
    values: tuple[m.PropValue, ...]
    span: Span


@dataclass(frozen=True)
class Section:
    """A `name { key: value; ... }` section of properties."""

    name: str
    props: tuple[Prop, ...]
    span: Span


SERVICE_SECTIONS = ("args", "conflicts", "timeout")
SYSTEM_SECTIONS = ("body", "worlds", "devices")


def _present(children: list[Any]) -> list[Any]:
    """Children without the `None` placeholders of absent `[...]` groups."""
    return [c for c in children if c is not None]


@v_args(meta=True)
class Builder(Transformer[Token, Any]):
    def __init__(self, path: str):
        super().__init__()
        self.path = path
        self.diagnostics: list[Diagnostic] = []

    # ------------------------------------------------------------ spans
    def span(self, meta: Meta) -> Span:
        if getattr(meta, "empty", True):
            return Span.unknown(self.path)
        return Span(self.path, meta.line, meta.column, meta.end_line, meta.end_column)

    def tspan(self, token: Token) -> Span:
        line = token.line or 1
        column = token.column or 1
        return Span(self.path, line, column, token.end_line or line, token.end_column or column)

    # ------------------------------------------------------------ shared values
    def start(self, meta: Meta, children: list[Any]) -> m.SourceFile:
        return m.SourceFile(path=self.path, items=tuple(children), span=self.span(meta))

    def prop(self, meta: Meta, children: list[Any]) -> Prop:
        key, values = children
        return Prop(str(key), self.tspan(key), tuple(values), self.span(meta))

    def values(self, meta: Meta, children: list[Any]) -> list[Any]:
        return children

    def typed_value(self, meta: Meta, children: list[Any]) -> m.TypedName:
        name, type_ref = children
        return m.TypedName(name=str(name), type=type_ref, span=self.span(meta))

    def ref(self, meta: Meta, children: list[Token]) -> m.Ref:
        return m.Ref(parts=tuple(str(c) for c in children), span=self.span(meta))

    def number(self, meta: Meta, children: list[Token]) -> m.Number:
        return m.Number(value=self.number_value(children[0]), span=self.span(meta))

    def signed_number(self, meta: Meta, children: list[Token]) -> m.Number:
        sign, number = children
        value = self.number_value(number)
        if str(sign) not in ("-", "+"):  # IxTeT's dotted operators are no sign
            self.diagnostics.append(error("unexpected-token", f"unexpected '{sign}': a number's sign is - or +",
                                          self.tspan(sign)))
        return m.Number(value=-value if str(sign) == "-" else value, span=self.span(meta))

    def duration(self, meta: Meta, children: list[Any]) -> m.Duration:
        number, unit = children
        duration = m.Duration(value=self.number_value(number), unit=unit, span=self.span(meta))
        if math.isfinite(duration.value) and not math.isfinite(duration.seconds):
            # A number, but not in seconds (`1e308 min`): no generated literal may hold an infinity,
            # and no clock wait one.
            self.diagnostics.append(error("bad-duration", f"{duration.value:g} {unit} is too long to be a number "
                                          "of seconds", duration.span))
        return duration

    def number_value(self, token: Token) -> int | float:
        value = parse_number(str(token))
        if math.isinf(value):
            # Stored as infinity so the checks can go on, but an error: `specc fmt` would
            # otherwise print it as `inf`, which reads back as a name.
            shown = str(token) if len(token) <= 24 else str(token)[:20] + "..."
            self.diagnostics.append(error(
                "number-too-large", f"'{shown}' is too large a number (the largest is about 1.8e308)",
                self.tspan(token)))
        return value

    def time_unit(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def string(self, meta: Meta, children: list[Token]) -> m.String:
        return m.String(value=unquote(str(children[0])), span=self.span(meta))

    def type_ref(self, meta: Meta, children: list[Any]) -> m.TypeRef:
        size = children[1] if len(children) > 1 else None
        return m.TypeRef(name=str(children[0]), size=size, span=self.span(meta))

    def array_size(self, meta: Meta, children: list[Token]) -> int:
        size = self.number_value(children[0])
        return size if isinstance(size, int) else 0

    # ------------------------------------------------------------ property schema
    def apply_props(self, cls: type, span: Span, props: list[Prop], **others: Any) -> Any:
        schema = {f.metadata["key"]: f for f in property_fields(cls)}
        seen: dict[str, Prop] = {}
        kwargs: dict[str, Any] = {}
        for p in props:
            if p.key not in schema:
                self.diagnostics.append(error(
                    "unknown-property",
                    f"'{cls.__name__.lower()}' has no property '{p.key}'{did_you_mean(p.key, schema)};"
                    f" known: {', '.join(sorted(schema))}",
                    p.key_span))
                continue
            if p.key in seen:
                self.diagnostics.append(error(
                    "duplicate-property", f"property '{p.key}' is given twice; keep one", p.key_span,
                    (seen[p.key].key_span, "first given here")))
                continue
            seen[p.key] = p
            f = schema[p.key]
            value = self.property_value(p, f.metadata["kind"], f.metadata["choices"])
            if value is not None:
                kwargs[f.name] = value
        return cls(span=span, **kwargs, **others)

    def property_value(self, p: Prop, kind: str, choices: tuple[str, ...]) -> Any:
        expected = {
            "ref": "one name", "refs": "a list of names", "int": "an integer",
            "string": "a quoted string", "duration": "a duration with a unit (e.g. 25 ms, 2 s)",
            "typed": "'name: type' entries", "symbol": "one of " + ", ".join(choices),
        }[kind]

        def bad(hint: str = "") -> None:
            self.diagnostics.append(error(
                "bad-property-value", f"property '{p.key}' expects {expected}{hint}", p.values[0].span))

        many = kind in ("refs", "typed")
        if not many and len(p.values) != 1:
            bad(f", got {len(p.values)} values")
            return None
        value = p.values[0]
        if kind == "ref":
            return value if isinstance(value, m.Ref) else bad()
        if kind == "refs":
            if all(isinstance(v, m.Ref) for v in p.values):
                return p.values
            return bad()
        if kind == "typed":
            if all(isinstance(v, m.TypedName) for v in p.values):
                return p.values
            return bad()
        if kind == "int":
            if isinstance(value, m.Number) and isinstance(value.value, int):
                return value
            if isinstance(value, m.Number) and math.isinf(value.value):
                return None  # reported as number-too-large
            if isinstance(value, m.Number):
                return bad(f", got {value.value}")
            return bad()
        if kind == "string":
            return value if isinstance(value, m.String) else bad()
        if kind == "duration":
            if isinstance(value, m.Duration):
                return value
            if isinstance(value, m.Number):
                return bad(f"; write '{value.value} ms' or '{value.value} s'")
            return bad()
        if kind == "symbol":
            if isinstance(value, m.Ref) and value.text in choices:
                return m.Word(value.text, value.span)
            if isinstance(value, m.Ref):
                return bad(f"{did_you_mean(value.text, choices)}, got '{value.text}'")
            return bad()
        raise AssertionError(kind)

    def split(self, children: list[Any]) -> tuple[list[Prop], list[Any]]:
        props = [c for c in children if isinstance(c, Prop)]
        return props, [c for c in children if not isinstance(c, Prop)]

    # ------------------------------------------------------------ module
    def module(self, meta: Meta, children: list[Any]) -> m.Module:
        name, *members = children
        props, rest = self.split(members)
        internal: list[m.Field] = []
        for data in (r for r in rest if isinstance(r, InternalData)):
            internal.extend(data.fields)
        return self.apply_props(
            m.Module, self.span(meta), props, name=str(name),
            structs=self.of(rest, m.StructDecl), enums=self.of(rest, m.EnumDecl),
            internal_data=tuple(internal), requests=self.of(rest, m.Request),
            exec_tasks=self.of(rest, m.ExecTask), posters=self.of(rest, m.Poster))

    @staticmethod
    def of(children: list[Any], cls: type) -> tuple[Any, ...]:
        return tuple(c for c in children if isinstance(c, cls))

    def struct_decl(self, meta: Meta, children: list[Any]) -> m.StructDecl:
        name, *fields = children
        return m.StructDecl(name=str(name), fields=tuple(fields), span=self.span(meta))

    def field(self, meta: Meta, children: list[Any]) -> m.Field:
        name, type_ref = children
        return m.Field(name=str(name), type=type_ref, span=self.span(meta))

    def enum_decl(self, meta: Meta, children: list[Token]) -> m.EnumDecl:
        name, *values = children
        return m.EnumDecl(name=str(name), values=tuple(str(v) for v in values), span=self.span(meta))

    def internal_data(self, meta: Meta, children: list[m.Field]) -> InternalData:
        return InternalData(tuple(children))

    def request(self, meta: Meta, children: list[Any]) -> m.Request:
        name, *members = children
        props, rest = self.split(members)
        return self.apply_props(m.Request, self.span(meta), props, name=str(name),
                                codels=self.of(rest, m.Codel))

    def codel(self, meta: Meta, children: list[Any]) -> m.Codel:
        state, function, *rest = children
        yields = rest[0] if rest else ()
        return m.Codel(state=str(state), function=str(function), yields=yields, span=self.span(meta))

    def codel_yields(self, meta: Meta, children: list[Token]) -> tuple[str, ...]:
        return tuple(str(c) for c in children)

    def exec_task(self, meta: Meta, children: list[Any]) -> m.ExecTask:
        name, *members = children
        props, rest = self.split(members)
        return self.apply_props(m.ExecTask, self.span(meta), props, name=str(name),
                                codels=self.of(rest, m.Codel))

    def poster(self, meta: Meta, children: list[Any]) -> m.Poster:
        name, *props = children
        return self.apply_props(m.Poster, self.span(meta), props, name=str(name))

    # ------------------------------------------------------------ executive
    def executive(self, meta: Meta, children: list[Any]) -> m.Executive:
        name, *members = children
        props, rest = self.split(members)
        return self.apply_props(
            m.Executive, self.span(meta), props, name=str(name),
            services=self.of(rest, m.Service), reflexes=self.of(rest, m.Reflex),
            parameters=self.of(rest, m.Parameter))

    def service(self, meta: Meta, children: list[Any]) -> m.Service:
        name, *members = children
        props, rest = self.split(members)
        timeout: m.Timeouts | None = None
        conflicts: list[m.Conflict] = []
        args: list[m.Argument] = []
        seen_sections: set[str] = set()
        for section in rest:
            if section.name in seen_sections:
                self.diagnostics.append(error(
                    "duplicate-property", f"section '{section.name}' is given twice; merge them",
                    section.span))
                continue
            seen_sections.add(section.name)
            if section.name == "timeout":
                timeout = self.apply_props(m.Timeouts, section.span, list(section.props))
            elif section.name == "conflicts":
                conflicts.extend(self.conflict_entries(section))
            elif section.name == "args":
                args.extend(self.arguments(section))
            else:
                self.diagnostics.append(error(
                    "unknown-property",
                    f"a service has no section '{section.name}'"
                    f"{did_you_mean(section.name, SERVICE_SECTIONS)}; known: {', '.join(SERVICE_SECTIONS)}",
                    section.span))
        return self.apply_props(m.Service, self.span(meta), props, name=str(name),
                                timeout=timeout, args=tuple(args), conflicts=tuple(conflicts))

    def arguments(self, section: Section) -> list[m.Argument]:
        return [m.Argument(name=p.key, value=p.values[0], span=p.span)
                for p in self.single_valued(section, "argument ")]

    def conflict_entries(self, section: Section) -> list[m.Conflict]:
        entries = []
        for p in section.props:
            policy = p.values[0]
            if len(p.values) != 1 or not isinstance(policy, m.Ref) or policy.text not in ("interrupt", "wait"):
                self.diagnostics.append(error(
                    "bad-conflict-policy",
                    f"conflict with '{p.key}' must be 'interrupt' or 'wait'", p.values[0].span))
                continue
            entries.append(m.Conflict(service=p.key, policy=policy.text, span=p.span))
        return entries

    def section(self, meta: Meta, children: list[Any]) -> Section:
        name, *props = children
        return Section(str(name), tuple(props), self.span(meta))

    def reflex(self, meta: Meta, children: list[Any]) -> m.Reflex:
        name = None
        if isinstance(children[0], Token):
            name = str(children.pop(0))
        trigger, *actions = children
        kind, source, comparison = trigger
        return m.Reflex(name=name, trigger=kind, source=source, comparison=comparison,
                        actions=tuple(actions), span=self.span(meta))

    def trigger(self, meta: Meta, children: list[Any]) -> tuple[str, m.Ref, m.Comparison | None]:
        kind, source, *rest = children
        return kind, source, (rest[0] if rest else None)

    def trigger_kind(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def comparison(self, meta: Meta, children: list[Any]) -> m.Comparison:
        op, value = children
        return m.Comparison(op=self.plain_operator(op), value=value, span=self.span(meta))

    def reflex_action(self, meta: Meta, children: list[Any]) -> m.ReflexAction:
        verb, target = children
        return m.ReflexAction(verb=verb, target=target, span=self.span(meta))

    def reflex_verb(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def parameter(self, meta: Meta, children: list[Any]) -> m.Parameter:
        name, *props = children
        return self.apply_props(m.Parameter, self.span(meta), props, name=str(name))

    # ------------------------------------------------------------ rules (Kheops)
    def rules(self, meta: Meta, children: list[Any]) -> m.RuleBase:
        name, *members = children
        attributes: list[m.AttrDecl] = []
        for decl in members:
            if isinstance(decl, list):
                attributes.extend(decl)
        return m.RuleBase(
            name=str(name), constants=self.of(members, m.ConstDecl), attributes=tuple(attributes),
            inits=self.of(members, m.InitDecl),
            rules=tuple(c for c in members if isinstance(c, (m.Rule, m.RuleForeach))),
            span=self.span(meta))

    def const_decl(self, meta: Meta, children: list[Any]) -> m.ConstDecl:
        name, value = children
        return m.ConstDecl(name=str(name), value=value, span=self.span(meta))

    def attr_decl(self, meta: Meta, children: list[Any]) -> list[m.AttrDecl]:
        role, *specs = children
        return [m.AttrDecl(role=role, name=name, domain=domain, span=span) for name, domain, span in specs]

    def attr_role(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def attr_spec(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        name, *rest = children
        text = str(name)
        if rest and isinstance(rest[0], AttrIndex):
            text += f"[{rest.pop(0).text}]"
        return text, (rest[0] if rest else None), self.span(meta)

    def attr_index(self, meta: Meta, children: list[Any]) -> AttrIndex:
        item = children[0]
        value = item.text if isinstance(item, m.Ref) else item.value
        return AttrIndex(str(int(value)) if isinstance(value, float) and value.is_integer() else str(value))

    def numeric_domain(self, meta: Meta, children: list[Any]) -> m.NumericDomain:
        low, high = (children + [None, None])[:2]
        return m.NumericDomain(low=low, high=high, span=self.span(meta))

    def boolean_domain(self, meta: Meta, children: list[Any]) -> m.BoolDomain:
        return m.BoolDomain(span=self.span(meta))

    def symbol_set(self, meta: Meta, children: list[Any]) -> m.SymbolDomain:
        return m.SymbolDomain(values=tuple(children), span=self.span(meta))

    def init_decl(self, meta: Meta, children: list[Any]) -> m.InitDecl:
        _prev, name, value = children
        return m.InitDecl(name=str(name), value=value, span=self.span(meta))

    def rule(self, meta: Meta, children: list[Any]) -> m.Rule:
        name, *rest = children
        index = rest.pop(0) if len(rest) > 1 else None
        kind, condition, actions = rest[0]
        return m.Rule(name=str(name), index=index, kind=kind, condition=condition,
                      actions=actions, span=self.span(meta))

    def rule_when(self, meta: Meta, children: list[Any]) -> tuple[str, Any, tuple[Any, ...]]:
        return "when", children[0], children[1]

    def rule_impossible(self, meta: Meta, children: list[Any]) -> tuple[str, Any, tuple[Any, ...]]:
        return "impossible", children[0], ()

    def rule_else(self, meta: Meta, children: list[Any]) -> tuple[str, Any, tuple[Any, ...]]:
        return "else", None, children[0]

    def rule_foreach(self, meta: Meta, children: list[Any]) -> m.RuleForeach:
        var, items, *rules = children
        return m.RuleForeach(var=str(var), items=items, rules=tuple(rules), span=self.span(meta))

    # An aliased `?rule` is not inlined by lark, so one operand arrives wrapped: unwrap it.
    def k_or(self, meta: Meta, children: list[Any]) -> Any:
        return children[0] if len(children) == 1 else m.KOr(operands=tuple(children), span=self.span(meta))

    def k_and(self, meta: Meta, children: list[Any]) -> Any:
        return children[0] if len(children) == 1 else m.KAnd(operands=tuple(children), span=self.span(meta))

    def k_not(self, meta: Meta, children: list[Any]) -> m.KNot:
        return m.KNot(operand=children[0], span=self.span(meta))

    def plain_operator(self, op: Token) -> str:
        """Kheops and the executive write `+ - * / ==`; IxTeT's dotted forms belong to domains."""
        text = str(op)
        if text.endswith("."):
            plain = {"=.": "=="}.get(text, text[:-1])
            self.diagnostics.append(error(
                "bad-operator", f"'{text}' is IxTeT notation; here write '{plain}'", self.tspan(op)))
            return plain
        return text

    def k_compare(self, meta: Meta, children: list[Any]) -> m.KCompare:
        attr, op, value = children
        return m.KCompare(attr=attr, op=self.plain_operator(op), value=value, span=self.span(meta))

    def k_member(self, meta: Meta, children: list[Any]) -> m.KMember:
        attr, op, items = children
        return m.KMember(attr=attr, op=op, items=items, span=self.span(meta))

    def k_true(self, meta: Meta, children: list[Any]) -> m.KTrue:
        return m.KTrue(attr=children[0], span=self.span(meta))

    def k_false(self, meta: Meta, children: list[Any]) -> m.KFalse:
        return m.KFalse(attr=children[0], span=self.span(meta))

    def k_foreach(self, meta: Meta, children: list[Any]) -> m.KForeach:
        var, items, body = children
        return m.KForeach(var=str(var), items=items, body=body, span=self.span(meta))

    def attr_ref(self, meta: Meta, children: list[Any]) -> m.AttrRef:
        previous = isinstance(children[0], Token) and children[0].type == "PREV"
        if previous:
            children = children[1:]
        index = children[1] if len(children) > 1 else None
        return m.AttrRef(name=str(children[0]), previous=previous, index=index, span=self.span(meta))

    def index(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def set_op(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def klist(self, meta: Meta, children: list[Any]) -> tuple[Any, ...]:
        return tuple(children)

    def krange(self, meta: Meta, children: list[Any]) -> m.KRange:
        low, high = children
        return m.KRange(low=low, high=high, span=self.span(meta))

    def actions(self, meta: Meta, children: list[Any]) -> tuple[Any, ...]:
        return tuple(m.Restrict(restriction=c, span=c.span) if not isinstance(c, m.DoAction) else c
                     for c in children)

    def do_action(self, meta: Meta, children: list[Any]) -> m.DoAction:
        return m.DoAction(statements=tuple(children), span=self.span(meta))

    def do_assign(self, meta: Meta, children: list[Any]) -> m.DoAssign:
        target, value = children
        return m.DoAssign(target=str(target), value=value, span=self.span(meta))

    def do_call(self, meta: Meta, children: list[Any]) -> m.DoCall:
        function, *args = _present(children)
        return m.DoCall(function=str(function), args=tuple(args), span=self.span(meta))

    def k_binary(self, meta: Meta, children: list[Any]) -> m.KBinary:
        left, op, right = children
        return m.KBinary(op=self.plain_operator(op), left=left, right=right, span=self.span(meta))

    def k_negate(self, meta: Meta, children: list[Any]) -> Any:
        sign, operand = children
        if str(sign) == "+":
            return operand  # unary plus changes nothing
        return m.KNegate(operand=operand, span=self.span(meta))

    # ------------------------------------------------------------ procedures (PRS)
    def procedures(self, meta: Meta, children: list[Any]) -> m.Procedures:
        name, *members = children
        return m.Procedures(
            name=str(name), types=self.of(members, m.TypeDecl),
            predicates=self.of(members, m.PredicateDecl), actions=self.of(members, m.ActionDecl),
            kas=self.of(members, m.KA), span=self.span(meta))

    def type_decl(self, meta: Meta, children: list[Any]) -> m.TypeDecl:
        name, domain = children
        return m.TypeDecl(name=str(name), domain=domain, span=self.span(meta))

    def predicate_decl(self, meta: Meta, children: list[Any]) -> m.PredicateDecl:
        children = _present(children)
        kinds = []
        while isinstance(children[0], tuple):
            kinds.append(children.pop(0)[0])
        name, *rest = children
        binding = rest.pop() if rest and isinstance(rest[-1], m.String) else None
        params = tuple(r for r in rest if isinstance(r, m.PParam))
        result = next((r for r in rest if not isinstance(r, m.PParam)), None)
        return m.PredicateDecl(name=str(name), kinds=tuple(kinds), params=params, result=result,
                               binding=binding, span=self.span(meta))

    def pred_kind(self, meta: Meta, children: list[Token]) -> tuple[str]:
        return (str(children[0]),)

    def pparam(self, meta: Meta, children: list[Any]) -> m.PParam:
        name, domain = children
        return m.PParam(name=str(name), domain=domain, span=self.span(meta))

    def psymset(self, meta: Meta, children: list[Any]) -> m.SymbolSet:
        return m.SymbolSet(values=tuple(str(c) for c in children), span=self.span(meta))

    def psigned(self, meta: Meta, children: list[Token]) -> str:
        """A negative (or explicitly positive) number among a PRS set's values: `{-30, 0}`."""
        self.signed_number(meta, children)  # a sign that is no sign (IxTeT's `-.`) is said there
        sign, number = children
        return f"-{number}" if str(sign) == "-" else str(number)

    def prange(self, meta: Meta, children: list[Token]) -> m.IntRange:
        bounds: list[int] = []
        sign = 1
        for token in children:  # [SIGN] INT [SIGN] INT
            if token.type == "SIGN":
                sign = -1 if token == "-" else 1
            else:
                bounds.append(sign * int(token))
                sign = 1
        low, high = bounds
        return m.IntRange(low=low, high=high, span=self.span(meta))

    def pdomain_ref(self, meta: Meta, children: list[Token]) -> m.DomainRef:
        return m.DomainRef(name=str(children[0]), span=self.span(meta))

    def action_decl(self, meta: Meta, children: list[Any]) -> m.ActionDecl:
        name, *rest = _present(children)
        binding = rest.pop()
        params = tuple(r for r in rest if isinstance(r, m.PParam))
        result = next((r for r in rest if not isinstance(r, m.PParam)), None)
        return m.ActionDecl(name=str(name), params=params, result=result, binding=binding,
                            span=self.span(meta))

    def service_binding(self, meta: Meta, children: list[Any]) -> m.ServiceBinding:
        return m.ServiceBinding(service=str(children[0]), span=self.span(meta))

    def ka(self, meta: Meta, children: list[Any]) -> m.KA:
        name, *members = children
        fields: dict[str, Any] = {}
        effects: list[m.Goal] = []
        properties: list[str] = []
        for key, value, span in members:
            if key == "effects":
                effects.extend(value)
            elif key == "property":
                properties.append(value)
            elif key in fields:
                self.diagnostics.append(error(
                    "duplicate-property", f"KA '{name}' has two '{key}' fields; keep one", span))
            else:
                fields[key] = value
        return m.KA(name=str(name), effects=tuple(effects), properties=tuple(properties),
                    span=self.span(meta), **fields)

    def ka_invocation(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        return "invocation", children[0], self.span(meta)

    def ka_context(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        return "context", children[0], self.span(meta)

    def ka_body(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        return "body", children[0], self.span(meta)

    def ka_action(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        call, *result = children
        action = m.KAAction(call=call, result=result[0] if result else None, span=self.span(meta))
        return "action", action, self.span(meta)

    def ka_effects(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        return "effects", tuple(children), self.span(meta)

    def ka_documentation(self, meta: Meta, children: list[Any]) -> tuple[str, Any, Span]:
        return "documentation", children[0], self.span(meta)

    def ka_property(self, meta: Meta, children: list[Token]) -> tuple[str, Any, Span]:
        return "property", m.Word(str(children[0]), self.span(meta)), self.span(meta)

    def goal(self, meta: Meta, children: list[Any]) -> m.Goal:
        op, body = children
        return m.Goal(op=str(op), body=body, span=self.span(meta))

    def sexp(self, meta: Meta, children: list[Any]) -> m.SExp:
        head, *args = children
        return m.SExp(head=str(head), args=tuple(self.sarg(a) for a in args), span=self.span(meta))

    def sarg(self, value: Any) -> Any:
        if isinstance(value, Token):
            return m.Ref(parts=(str(value),), span=self.tspan(value))
        return value

    def logic_var(self, meta: Meta, children: list[Token]) -> m.LogicVar:
        return m.LogicVar(name=str(children[0]), span=self.span(meta))

    def program_var(self, meta: Meta, children: list[Token]) -> m.ProgramVar:
        return m.ProgramVar(name=str(children[0]), span=self.span(meta))

    def block(self, meta: Meta, children: list[Any]) -> m.Block:
        return m.Block(statements=tuple(children), span=self.span(meta))

    def goal_stmt(self, meta: Meta, children: list[Any]) -> m.GoalStmt:
        return m.GoalStmt(goal=children[0], span=self.span(meta))

    def if_stmt(self, meta: Meta, children: list[Any]) -> m.IfStmt:
        condition, then, *orelse = children
        return m.IfStmt(condition=condition, then=then, orelse=orelse[0] if orelse else None,
                        span=self.span(meta))

    def while_stmt(self, meta: Meta, children: list[Any]) -> m.WhileStmt:
        condition, body = children
        return m.WhileStmt(condition=condition, body=body, span=self.span(meta))

    def parallel_stmt(self, meta: Meta, children: list[Any]) -> m.ParallelStmt:
        return m.ParallelStmt(branches=tuple(children), span=self.span(meta))

    def choose_stmt(self, meta: Meta, children: list[Any]) -> m.ChooseStmt:
        return m.ChooseStmt(branches=tuple(children), span=self.span(meta))

    def branch(self, meta: Meta, children: list[Any]) -> m.Block:
        return children[0]  # type: ignore[no-any-return]

    def assign_stmt(self, meta: Meta, children: list[Any]) -> m.AssignStmt:
        var, value = children
        return m.AssignStmt(var=str(var), value=self.sarg(value), span=self.span(meta))

    def fail_stmt(self, meta: Meta, children: list[Any]) -> m.FailStmt:
        return m.FailStmt(span=self.span(meta))

    # ------------------------------------------------------------ domain / problem (IxTeT)
    def domain(self, meta: Meta, children: list[Any]) -> m.Domain:
        name, *members = children
        return m.Domain(name=str(name), members=tuple(members), span=self.span(meta))

    def include(self, meta: Meta, children: list[Token]) -> m.Include:
        return m.Include(name=str(children[0]), span=self.span(meta))

    def constant(self, meta: Meta, children: list[Any]) -> m.Constant:
        name, value = children
        return m.Constant(name=str(name), value=value, span=self.span(meta))

    def _params_and_body(self, children: list[Any]) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
        params = tuple(c for c in children if isinstance(c, m.IxVar))
        body = tuple(c for c in children if not isinstance(c, m.IxVar))
        return params, body

    def attribute(self, meta: Meta, children: list[Any]) -> m.Attribute:
        name, *rest = _present(children)
        params, body = self._params_and_body(rest)
        return m.Attribute(name=str(name), params=params, body=body, span=self.span(meta))

    def resource(self, meta: Meta, children: list[Any]) -> m.Resource:
        name, *rest = _present(children)
        params, body = self._params_and_body(rest)
        return m.Resource(name=str(name), params=params, body=body, span=self.span(meta))

    def macro(self, meta: Meta, children: list[Any]) -> m.Macro:
        name, *rest = _present(children)
        params = tuple(str(c) for c in rest if isinstance(c, Token))
        body = tuple(c for c in rest if not isinstance(c, Token))
        return m.Macro(name=str(name), params=params, body=body, span=self.span(meta))

    def task(self, meta: Meta, children: list[Any]) -> m.Task:
        name, *rest = _present(children)
        preemption = rest.pop() if rest and isinstance(rest[-1], str) and not isinstance(rest[-1], Token) else None
        params = tuple(c for c in rest if isinstance(c, m.IxVar))
        tokens = [c for c in rest if isinstance(c, Token)]
        body = tuple(c for c in rest if not isinstance(c, (m.IxVar, Token)))
        start, end = (str(t) for t in tokens[:2])
        return m.Task(name=str(name), params=params, start=start, end=end, body=body,
                      preemption=preemption, span=self.span(meta))

    def preemption(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def problem(self, meta: Meta, children: list[Any]) -> m.Problem:
        name, domain, *rest = children
        preemption = rest.pop() if rest and isinstance(rest[-1], str) else None
        return m.Problem(name=str(name), domain=m.Ref(parts=(str(domain),), span=self.tspan(domain)),
                         body=tuple(rest), preemption=preemption, span=self.span(meta))

    def fragment(self, meta: Meta, children: list[Any]) -> m.Fragment:
        name, *members = children
        return m.Fragment(name=str(name), members=tuple(members), span=self.span(meta))

    def variable_decl(self, meta: Meta, children: list[Any]) -> m.VariableDecl:
        return m.VariableDecl(names=tuple(children), span=self.span(meta))

    def timepoint_decl(self, meta: Meta, children: list[Token]) -> m.TimepointDecl:
        return m.TimepointDecl(names=tuple(str(c) for c in children), span=self.span(meta))

    def goal_assertion(self, meta: Meta, children: list[Any]) -> Any:
        assertion, mark = children
        return type(assertion)(**{**assertion.__dict__, "goal": mark, "span": self.span(meta)})

    def hold(self, meta: Meta, children: list[Any]) -> m.Hold:
        attr, start, end = children
        return m.Hold(attr=attr, start=start, end=end, span=self.span(meta))

    def event(self, meta: Meta, children: list[Any]) -> m.Event:
        kind = children.pop(0) if isinstance(children[0], str) and not isinstance(children[0], Token) else None
        attr, time = children
        return m.Event(kind=kind, attr=attr, time=time, span=self.span(meta))

    def event_kind(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def resource_use(self, meta: Meta, children: list[Any]) -> m.ResourceUse:
        verb, attr, when = children
        return m.ResourceUse(verb=verb, attr=attr, when=when, span=self.span(meta))

    def res_verb(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def window(self, meta: Meta, children: list[Any]) -> m.Window:
        start, end = children
        return m.Window(start=start, end=end, span=self.span(meta))

    def goal_mark(self, meta: Meta, children: list[Any]) -> m.GoalMark:
        priority, weight = children
        return m.GoalMark(priority=priority, weight=weight, span=self.span(meta))

    def attr_value(self, meta: Meta, children: list[Any]) -> m.AttrValue:
        name, *rest = _present(children)
        value = rest.pop()
        return m.AttrValue(attribute=str(name), args=tuple(rest), value=value, span=self.span(meta))

    def transition(self, meta: Meta, children: list[Any]) -> m.Transition:
        before, after = children
        return m.Transition(before=before, after=after, span=self.span(meta))

    def in_constraint(self, meta: Meta, children: list[Any]) -> m.InConstraint:
        expr, domain = children
        return m.InConstraint(expr=expr, domain=domain, span=self.span(meta))

    in_constraint_c = in_constraint
    condition = in_constraint

    def contingent_in(self, meta: Meta, children: list[Any]) -> m.InConstraint:
        expr, domain = children
        return m.InConstraint(expr=expr, domain=domain, contingent=True, span=self.span(meta))

    def rel_constraint(self, meta: Meta, children: list[Any]) -> m.RelConstraint:
        left, op, right = children
        return m.RelConstraint(left=left, op=str(op), right=right, span=self.span(meta))

    rel_constraint_c = rel_constraint

    def contingent_rel(self, meta: Meta, children: list[Any]) -> m.RelConstraint:
        left, op, right = children
        return m.RelConstraint(left=left, op=str(op), right=right, contingent=True, span=self.span(meta))

    def implication(self, meta: Meta, children: list[Any]) -> m.Implication:
        condition, consequence = children
        return m.Implication(condition=condition, consequence=consequence, span=self.span(meta))

    def macro_call(self, meta: Meta, children: list[Any]) -> m.MacroCall:
        name, *args = _present(children)
        return m.MacroCall(name=str(name), args=tuple(args), span=self.span(meta))

    def interval(self, meta: Meta, children: list[Any]) -> m.Interval:
        low, high = children
        return m.Interval(low=low, high=high, span=self.span(meta))

    def set_union(self, meta: Meta, children: list[Any]) -> m.SetUnion:
        return m.SetUnion(parts=tuple(children), span=self.span(meta))

    def set_literal(self, meta: Meta, children: list[Token]) -> m.SetLiteral:
        return m.SetLiteral(values=tuple(str(c) for c in children), span=self.span(meta))

    def set_ref(self, meta: Meta, children: list[Token]) -> m.SetRef:
        return m.SetRef(name=str(children[0]), span=self.span(meta))

    def ix_binary(self, meta: Meta, children: list[Any]) -> m.IxBinary:
        left, op, right = children
        return m.IxBinary(op=str(op), left=left, right=right, span=self.span(meta))

    def ix_unary(self, meta: Meta, children: list[Any]) -> m.IxUnary:
        op, operand = children
        return m.IxUnary(op=str(op), operand=operand, span=self.span(meta))

    def infinity(self, meta: Meta, children: list[Any]) -> m.Infinity:
        return m.Infinity(span=self.span(meta))

    def ix_var(self, meta: Meta, children: list[Token]) -> m.IxVar:
        return m.IxVar(name=str(children[0]), span=self.span(meta))

    def ix_name(self, meta: Meta, children: list[Token]) -> m.IxName:
        return m.IxName(name=str(children[0]), span=self.span(meta))

    def ix_call(self, meta: Meta, children: list[Any]) -> m.IxCall:
        name, *args = _present(children)
        return m.IxCall(function=str(name), args=tuple(args), span=self.span(meta))

    # ------------------------------------------------------------ ftplan
    def ftplan(self, meta: Meta, children: list[Any]) -> m.FtPlan:
        name, *members = children
        props, rest = self.split(members)
        analyzer: list[Any] = []
        updates: list[Any] = []
        for member in rest:
            if isinstance(member, AnalyzerBlock):
                analyzer.extend(member.rules)
            elif isinstance(member, StateBlock):
                updates.extend(member.updates)
        return self.apply_props(m.FtPlan, self.span(meta), props, name=str(name),
                                planners=self.of(rest, m.Planner), analyzer=tuple(analyzer),
                                state_updates=tuple(updates), missions=self.of(rest, m.Mission))

    def planner(self, meta: Meta, children: list[Any]) -> m.Planner:
        name, *members = children
        props, rest = self.split(members)
        view = tuple(c for block in rest for c in block.correspondences)
        return self.apply_props(m.Planner, self.span(meta), props, name=str(name), view=view)

    def view(self, meta: Meta, children: list[Any]) -> ViewBlock:
        return ViewBlock(tuple(children))

    def correspondence(self, meta: Meta, children: list[Any]) -> m.Correspondence:
        planner_facts, state_facts = children
        return m.Correspondence(planner_facts=planner_facts, state_facts=state_facts, span=self.span(meta))

    def view_side(self, meta: Meta, children: list[Any]) -> tuple[m.ViewFact, ...]:
        return tuple(children)

    def view_fact(self, meta: Meta, children: list[Any]) -> m.ViewFact:
        name, *rest = _present(children)
        value = rest.pop()
        return m.ViewFact(attribute=str(name), args=tuple(rest), value=value, span=self.span(meta))

    def mission(self, meta: Meta, children: list[Any]) -> m.Mission:
        name, *members = children
        return m.Mission(name=str(name), problems=self.of(members, m.MissionProblem),
                         views=self.of(members, m.MissionView), span=self.span(meta))

    def mission_problem(self, meta: Meta, children: list[Any]) -> m.MissionProblem:
        planner, problem = children
        return m.MissionProblem(planner=m.Ref(parts=(str(planner),), span=self.tspan(planner)),
                                problem=problem, span=self.span(meta))

    def mission_view(self, meta: Meta, children: list[Any]) -> m.MissionView:
        planner, *correspondences = children
        return m.MissionView(planner=planner, correspondences=tuple(correspondences), span=self.span(meta))

    def analyzer(self, meta: Meta, children: list[Any]) -> AnalyzerBlock:
        return AnalyzerBlock(tuple(children))

    def analyzer_condition(self, meta: Meta, children: list[Any]) -> m.AnalyzerCondition:
        kind, task, *rest = _present(children)
        requirement = rest.pop()
        return m.AnalyzerCondition(kind=kind, task=str(task), args=tuple(rest), requirement=requirement,
                                   span=self.span(meta))

    def analyzer_kind(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def analyzer_no_overlap(self, meta: Meta, children: list[Token]) -> m.AnalyzerNoOverlap:
        return m.AnalyzerNoOverlap(tasks=tuple(str(c) for c in children), span=self.span(meta))

    def analyzer_max_duration(self, meta: Meta, children: list[Any]) -> m.AnalyzerMaxDuration:
        task, limit = children
        return m.AnalyzerMaxDuration(task=str(task), limit=limit, span=self.span(meta))

    def state_updates(self, meta: Meta, children: list[Any]) -> StateBlock:
        return StateBlock(tuple(children))

    def state_update(self, meta: Meta, children: list[Any]) -> m.StateUpdate:
        report, task, *rest = _present(children)
        updates = tuple(r for r in rest if isinstance(r, m.FactUpdate))
        args = tuple(r for r in rest if not isinstance(r, m.FactUpdate))
        return m.StateUpdate(report=report, task=str(task), args=args, updates=updates, span=self.span(meta))

    def report_kind(self, meta: Meta, children: list[Token]) -> str:
        return str(children[0])

    def fact_update(self, meta: Meta, children: list[Any]) -> m.FactUpdate:
        name, *rest = _present(children)
        value = rest.pop()
        return m.FactUpdate(attribute=str(name), args=tuple(rest), value=value, span=self.span(meta))

    # ------------------------------------------------------------ system
    def system(self, meta: Meta, children: list[Any]) -> m.System:
        name, *members = children
        props, rest = self.split(members)
        sections: dict[str, Any] = {}
        for section in (r for r in rest if isinstance(r, Section)):
            if section.name not in SYSTEM_SECTIONS:
                self.diagnostics.append(error(
                    "unknown-property",
                    f"a system has no section '{section.name}'{did_you_mean(section.name, SYSTEM_SECTIONS)}; "
                    f"known: {', '.join(SYSTEM_SECTIONS)}", section.span))
            elif section.name in sections:
                self.diagnostics.append(error(
                    "duplicate-property", f"section '{section.name}' is given twice; merge them", section.span))
            elif section.name == "devices":
                sections[section.name] = m.DeviceGrants(entries=tuple(
                    m.DeviceGrant(module=p.key, devices=tuple(v for v in p.values if isinstance(v, m.Ref)),
                                  span=p.span) for p in section.props), span=section.span)
            else:
                sections[section.name] = self.settings(section)
        missions = self.of(rest, m.SystemMission)
        bindings = self.of(rest, m.Bindings)
        for repeated in bindings[1:]:
            self.diagnostics.append(error("duplicate-property", "section 'bindings' is given twice; merge them",
                                          repeated.span))
        return self.apply_props(m.System, self.span(meta), props, name=str(name), body=sections.get("body"),
                                worlds=sections.get("worlds"), devices=sections.get("devices"), missions=missions,
                                bindings=bindings[0] if bindings else None)

    def bindings(self, meta: Meta, children: list[Any]) -> m.Bindings:
        return m.Bindings(entries=tuple(children), span=self.span(meta))

    def binding(self, meta: Meta, children: list[Any]) -> m.Binding:
        task, *rest = _present(children)
        report = rest.pop() if rest and isinstance(rest[-1], m.BindingReport) else None
        where = rest.pop() if rest and isinstance(rest[-1], m.BindingWhere) else None
        split = next(k for k, c in enumerate(rest) if isinstance(c, Token) and c.type == "BINDING_KIND")
        target, *target_args = rest[split + 1:]
        return m.Binding(task=str(task), args=tuple(rest[:split]), kind=str(rest[split]), target=target,
                         target_args=tuple(target_args), where=where, report=report, span=self.span(meta))

    def binding_where(self, meta: Meta, children: list[Any]) -> m.BindingWhere:
        attribute, *args, value = _present(children)
        return m.BindingWhere(attribute=str(attribute), args=tuple(args), value=value, span=self.span(meta))

    def binding_report(self, meta: Meta, children: list[Any]) -> m.BindingReport:
        name, *values = _present(children)
        return m.BindingReport(name=str(name), values=tuple(values), span=self.span(meta))

    def settings(self, section: Section) -> m.Settings:
        """`name: value;` entries, one value each."""
        return m.Settings(entries=tuple(m.Setting(name=p.key, value=p.values[0], span=p.span)
                                        for p in self.single_valued(section, "")), span=section.span)

    def single_valued(self, section: Section, what: str) -> list[Prop]:
        """The section's `name: value;` entries; one with several values is reported and left out."""
        kept = []
        for p in section.props:
            if len(p.values) != 1:
                self.diagnostics.append(error("bad-property-value", f"{what}'{p.key}' takes one value",
                                              p.values[0].span))
            else:
                kept.append(p)
        return kept

    def system_mission(self, meta: Meta, children: list[Any]) -> m.SystemMission:
        name, *members = children
        props, goals = self.split(members)
        return self.apply_props(m.SystemMission, self.span(meta), props, name=str(name), goals=tuple(goals))

    def mission_goal(self, meta: Meta, children: list[Any]) -> m.Goal:
        return children[0]  # type: ignore[no-any-return]

    def __default__(self, data: str, children: list[Any], meta: Meta) -> Any:
        raise AssertionError(f"grammar rule '{data}' has no builder method")


@dataclass(frozen=True)
class AttrIndex:
    """The `[i]` of an indexed attribute of a rule base."""

    text: str


@dataclass(frozen=True)
class InternalData:
    """A module's `internal_data { }` fields, before the module gathers them."""

    fields: tuple[m.Field, ...]


@dataclass(frozen=True)
class AnalyzerBlock:
    """An ftplan block's `analyzer { }` rules, before the block gathers them."""

    rules: tuple[Any, ...]


@dataclass(frozen=True)
class StateBlock:
    """An ftplan block's `state { }` updates, before the block gathers them."""

    updates: tuple[Any, ...]


@dataclass(frozen=True)
class ViewBlock:
    """A planner's `view { }` correspondences, before the planner gathers them."""

    correspondences: tuple[Any, ...]


def parse_number(text: str) -> int | float:
    """The literal's value; infinity when a float cannot hold it (`1e999`, 400 digits)."""
    if any(c in text for c in ".eE"):
        return float(text)
    if len(text.lstrip("0")) > 308:  # past float's range (and int() refuses 4300+ digits)
        return math.inf
    return int(text)


_ESCAPES = {"n": "\n", "t": "\t"}


def unquote(text: str) -> str:
    """The value of a string literal: `\\n` and `\\t` are newline and tab, `\\x` is x."""
    return re.sub(r"\\(.)", lambda match: _ESCAPES.get(match.group(1), match.group(1)), text[1:-1])


def build(tree: Tree[Token], path: str) -> tuple[m.SourceFile, list[Diagnostic]]:
    builder = Builder(path)
    source = builder.transform(tree)
    return source, builder.diagnostics
