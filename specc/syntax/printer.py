"""Model -> canonical text (`specc fmt`). `parse(print(model)) == model` for every model.

Comments are not part of the model; the formatter hands them in with the source text and
each is written back before (or at the end of the line of) the element it preceded.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from specc.model import nodes as m
from specc.model.nodes import property_fields
from specc.model.span import Span
from specc.syntax.parsed import Comment

INDENT = "  "
WRAP_AT = 100


# ---------------------------------------------------------------- expressions (pure functions)


def number(n: m.Number | int | float) -> str:
    value = n.value if isinstance(n, m.Number) else n
    return repr(value) if isinstance(value, float) else str(value)


def string(s: m.String) -> str:
    escaped = s.value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    return f'"{escaped}"'


def type_ref(t: m.TypeRef) -> str:
    return t.name if t.size is None else f"{t.name}[{t.size}]"


def prop_value(v: m.PropValue) -> str:
    if isinstance(v, m.Ref):
        return v.text
    if isinstance(v, m.Number):
        return number(v)
    if isinstance(v, m.Duration):
        return f"{number(v.value)} {v.unit}"
    if isinstance(v, m.String):
        return string(v)
    if isinstance(v, m.TypedName):
        return f"{v.name}: {type_ref(v.type)}"
    raise TypeError(v)


_K_PRECEDENCE = {"+": 1, "-": 1, "*": 2, "/": 2}


def kexpr(e: m.KExpr) -> str:
    if isinstance(e, m.Number):
        return number(e)
    if isinstance(e, m.String):
        return string(e)
    if isinstance(e, m.AttrRef):
        return attr_ref(e)
    if isinstance(e, m.KNegate):
        inner = kexpr(e.operand)
        return f"-({inner})" if isinstance(e.operand, m.KBinary) else f"-{inner}"
    if isinstance(e, m.KBinary):
        return binary(e, m.KBinary, _K_PRECEDENCE, kexpr)
    raise TypeError(e)


def binary(e: Any, kind: Any, precedence: dict[str, int], show: Callable[[Any], str]) -> str:
    """`left op right` with the fewest parentheses that still read back as the same tree
    (operators are left-associative, so an equal-precedence right operand needs them)."""
    level = precedence[e.op]
    left, right = show(e.left), show(e.right)
    if isinstance(e.left, kind) and precedence[e.left.op] < level:
        left = f"({left})"
    if isinstance(e.right, kind) and precedence[e.right.op] <= level:
        right = f"({right})"
    return f"{left} {e.op} {right}"


def attr_ref(a: m.AttrRef) -> str:
    text = ("@" if a.previous else "") + a.name
    return text + (f"[{a.index}]" if a.index is not None else "")


def kitem(i: m.KItem) -> str:
    if isinstance(i, m.KRange):
        return f"{kitem(i.low)}..{kitem(i.high)}"
    if isinstance(i, m.Ref):
        return i.text
    if isinstance(i, m.Number):
        return number(i)
    return string(i)


def klist(items: Iterable[m.KItem]) -> str:
    return "[" + ", ".join(kitem(i) for i in items) + "]"


def cond(c: m.Cond) -> str:
    if isinstance(c, m.KOr):
        return " | ".join(_cond_operand(o, m.KOr) for o in c.operands)
    if isinstance(c, m.KAnd):
        return ", ".join(_cond_operand(o, m.KAnd) for o in c.operands)
    if isinstance(c, m.KNot):
        inner = cond(c.operand)
        return f"!({inner})" if isinstance(c.operand, (m.KAnd, m.KOr, m.KNot)) else f"!{inner}"
    if isinstance(c, m.KForeach):
        return f"foreach {c.var} in {klist(c.items)} ({cond(c.body)})"
    return restriction(c)


def _cond_operand(o: m.Cond, parent: type) -> str:
    text = cond(o)
    # `a | b` inside `,` needs parentheses, and so does a nested group of the same kind,
    # or it would read back flattened.
    if isinstance(o, (m.KOr, parent)):
        return f"({text})"
    return text


def restriction(r: Any) -> str:
    if isinstance(r, m.KCompare):
        return f"{attr_ref(r.attr)} {r.op} {kexpr(r.value)}"
    if isinstance(r, m.KMember):
        return f"{attr_ref(r.attr)} {r.op} {klist(r.items)}"
    if isinstance(r, m.KTrue):
        return attr_ref(r.attr)
    if isinstance(r, m.KFalse):
        return "!" + attr_ref(r.attr)
    raise TypeError(r)


def action(a: m.Action) -> str:
    if isinstance(a, m.Restrict):
        return "restrict " + restriction(a.restriction)
    statements = []
    for s in a.statements:
        if isinstance(s, m.DoAssign):
            statements.append(f"{s.target} = {kexpr(s.value)}")
        else:
            statements.append(f"{s.function}({', '.join(kexpr(x) for x in s.args)})")
    return "do {" + "; ".join(statements) + "}"


def kdomain(d: m.AttrDomain) -> str:
    if isinstance(d, m.SymbolDomain):
        return "{" + ", ".join(kitem(v) for v in d.values) + "}"
    if isinstance(d, m.BoolDomain):
        return "bool"
    if d.low is None or d.high is None:
        return "number"
    return f"[{kexpr(d.low)}, {kexpr(d.high)}]"


def sarg(a: m.SArg) -> str:
    if isinstance(a, (m.LogicVar, m.ProgramVar)):
        return a.name
    if isinstance(a, m.Ref):
        return a.text
    if isinstance(a, m.Number):
        return number(a)
    if isinstance(a, m.String):
        return string(a)
    return sexp(a)


def sexp(s: m.SExp) -> str:
    return "(" + " ".join([s.head, *(sarg(a) for a in s.args)]) + ")"


def goal(g: m.Goal | m.SExp) -> str:
    return sexp(g) if isinstance(g, m.SExp) else f"{g.op}{sexp(g.body)}"


def pdomain(d: m.PDomain) -> str:
    if isinstance(d, m.SymbolSet):
        return "{" + ", ".join(d.values) + "}"
    if isinstance(d, m.IntRange):
        return f"{d.low}..{d.high}"
    return d.name


def pparams(params: Iterable[m.PParam]) -> str:
    return "(" + ", ".join(f"{p.name}: {pdomain(p.domain)}" for p in params) + ")"


_IX_PRECEDENCE = {"+.": 1, "-.": 1, "+": 1, "-": 1, "*.": 2, "/.": 2, "*": 2, "/": 2}


def ixexpr(e: m.IxExpr) -> str:
    if isinstance(e, m.Number):
        return number(e)
    if isinstance(e, m.Infinity):
        return "oo"
    if isinstance(e, (m.IxVar, m.IxName)):
        return e.name
    if isinstance(e, m.IxCall):
        return f"{e.function}({ix_args(e.args)})"
    if isinstance(e, m.IxUnary):
        inner = ixexpr(e.operand)
        return f"{e.op}({inner})" if isinstance(e.operand, m.IxBinary) else f"{e.op}{inner}"
    if isinstance(e, m.IxBinary):
        return binary(e, m.IxBinary, _IX_PRECEDENCE, ixexpr)
    raise TypeError(e)


def ix_args(args: Iterable[m.IxExpr]) -> str:
    return ", ".join(ixexpr(a) for a in args)


def ix_statement_expr(e: m.IxExpr) -> str:
    """A constraint's left side: `(t_end - t_start) in [2, 10]` reads better with parentheses."""
    return f"({ixexpr(e)})" if isinstance(e, m.IxBinary) else ixexpr(e)


def attr_value(a: m.AttrValue) -> str:
    value = a.value
    shown = (f"({ixexpr(value.before)}, {ixexpr(value.after)})" if isinstance(value, m.Transition)
             else ixexpr(value))
    return f"{a.attribute}({ix_args(a.args)}): {shown}"


def domain_value(d: m.DomainValue) -> str:
    if isinstance(d, m.Interval):
        return f"[{ixexpr(d.low)}, {ixexpr(d.high)}]"
    return set_union(d)


def set_union(d: m.SetUnion) -> str:
    return " | ".join("{" + ", ".join(p.values) + "}" if isinstance(p, m.SetLiteral) else p.name
                      for p in d.parts)


def in_constraint(c: m.InConstraint) -> str:
    return f"{ix_statement_expr(c.expr)} in {domain_value(c.domain)}"


def rel_constraint(c: m.RelConstraint) -> str:
    return f"{ix_statement_expr(c.left)} {c.op} {ixexpr(c.right)}"


def goal_mark(g: m.GoalMark | None) -> str:
    return "" if g is None else f" goal({ixexpr(g.priority)}, {ixexpr(g.weight)})"


def tstmt(s: Any) -> str:
    if isinstance(s, m.VariableDecl):
        return "variable " + ", ".join(v.name for v in s.names) + ";"
    if isinstance(s, m.TimepointDecl):
        return "timepoint " + ", ".join(s.names) + ";"
    if isinstance(s, m.Hold):
        return f"hold({attr_value(s.attr)}, ({ixexpr(s.start)}, {ixexpr(s.end)})){goal_mark(s.goal)};"
    if isinstance(s, m.Event):
        kind = f"{s.kind} " if s.kind else ""
        return f"{kind}event({attr_value(s.attr)}, {ixexpr(s.time)}){goal_mark(s.goal)};"
    if isinstance(s, m.ResourceUse):
        when = (f"({ixexpr(s.when.start)}, {ixexpr(s.when.end)})" if isinstance(s.when, m.Window)
                else ixexpr(s.when))
        return f"{s.verb}({attr_value(s.attr)}, {when}){goal_mark(s.goal)};"
    if isinstance(s, m.InConstraint):
        return ("contingent " if s.contingent else "") + in_constraint(s) + ";"
    if isinstance(s, m.RelConstraint):
        return ("contingent " if s.contingent else "") + rel_constraint(s) + ";"
    if isinstance(s, m.Implication):
        consequence = s.consequence
        then = in_constraint(consequence) if isinstance(consequence, m.InConstraint) else rel_constraint(consequence)
        return f"{in_constraint(s.condition)} => {then};"
    if isinstance(s, m.MacroCall):
        return f"{s.name}({ix_args(s.args)});"
    if isinstance(s, m.Include):
        return f"include {s.name};"
    raise TypeError(s)


# ---------------------------------------------------------------- layout with comments


@dataclass
class _Comments:
    """Which comment goes where: before the first element after it, or at the end of a line."""

    leading: dict[tuple[int, int], list[Comment]]
    trailing: dict[tuple[int, int], list[str]]
    rest: list[Comment]
    line_starts: set[tuple[int, int]]  # the first anchor of each source line


def _place_comments(comments: list[Comment], anchors: list[tuple[int, int]], text: str) -> _Comments:
    """Anchors are where printed lines start in the source, including each block's closing
    brace, so a comment written last in a block stays inside it."""
    ordered = sorted(set(anchors))
    source_lines = text.split("\n")
    starts = {key for i, key in enumerate(ordered) if i == 0 or ordered[i - 1][0] != key[0]}
    placed = _Comments({}, {}, [], starts)
    for comment in comments:
        position = (comment.line, comment.column)
        before = source_lines[position[0] - 1][: position[1] - 1] if position[0] <= len(source_lines) else ""
        if before.strip() and "\n" not in comment.text:
            # At the end of a line: it stays there if an element starts on that line.
            i = bisect.bisect_right(ordered, position) - 1
            if i >= 0 and ordered[i][0] == position[0]:
                placed.trailing.setdefault(ordered[i], []).append(comment.text)
                continue
        i = bisect.bisect_left(ordered, position)
        if i < len(ordered):
            placed.leading.setdefault(ordered[i], []).append(comment)
        else:
            placed.rest.append(comment)
    return placed


class Printer:
    def __init__(self, comments: _Comments | None = None, text: str = ""):
        self.out: list[str] = []
        self.depth = 0
        self.comments = comments
        self.source_lines = text.split("\n")
        self.anchors: list[tuple[int, int]] = []

    # -- output primitives
    def line(self, text: str, anchor: Span | None = None) -> None:
        key = self._anchor(anchor)
        pad = INDENT * self.depth
        if key is not None and self.comments is not None:
            self.leading_comments(self.comments.leading.pop(key, []), pad)
            if key in self.comments.line_starts and self._source_blank(key[0] - 1):
                # A blank line kept from the source (only above an element that began its line:
                # `{ a; b; }` after a blank line is not three paragraphs).
                self.blank()
        self.out.append(pad + text + self._trailing(key))

    def closing(self, text: str, closer: Span | None) -> None:
        """A block's last line (`}`): comments just before the brace stay inside the block."""
        key = None if closer is None else self._anchor(
            Span(closer.file, closer.end_line, max(closer.end_column - 1, 1), closer.end_line, closer.end_column))
        if key is not None and self.comments is not None:
            self.leading_comments(self.comments.leading.pop(key, []), INDENT * (self.depth + 1))
        self.out.append(INDENT * self.depth + text + self._trailing(key))

    def leading_comments(self, comments: list[Comment], pad: str) -> None:
        for comment in comments:
            if self._source_blank(comment.line - 1):
                self.blank()
            self.out.extend(comment.lines(pad))

    def _trailing(self, key: tuple[int, int] | None) -> str:
        if key is None or self.comments is None:
            return ""
        return "".join("  " + comment for comment in self.comments.trailing.pop(key, []))

    def _anchor(self, span: Span | None) -> tuple[int, int] | None:
        if span is None or span.file == "<unknown>":
            return None
        key = (span.line, span.column)
        self.anchors.append(key)
        return key

    def _source_blank(self, line: int) -> bool:
        return 1 <= line <= len(self.source_lines) and not self.source_lines[line - 1].strip()

    def blank(self) -> None:
        if self.out and self.out[-1].strip() and not self.out[-1].endswith("{"):
            self.out.append("")

    @contextmanager
    def block(self, header: str, anchor: Span | None, footer: str = "}") -> Iterator[None]:
        """A `header {` ... `footer` block, its comments kept where the source has them."""
        self.line(header + " {", anchor)
        self.depth += 1
        yield
        self.depth -= 1
        self.closing(footer, anchor)

    @contextmanager
    def section(self, keyword: str, first: Span | None) -> Iterator[None]:
        """A `keyword {` ... `}` section with no node of its own (`internal_data`, `conflicts`):
        the keyword, found in the source just before the section's first element, anchors the
        comments written above it; the comments after its last element go with whatever
        follows the section."""
        self.line(keyword + " {", self._keyword_before(keyword, first))
        self.depth += 1
        yield
        self.depth -= 1
        self.out.append(INDENT * self.depth + "}")

    def _keyword_before(self, keyword: str, first: Span | None) -> Span | None:
        """Where `keyword {` is written last before `first`, as a span of the keyword."""
        if first is None or first.file == "<unknown>" or not 1 <= first.line <= len(self.source_lines):
            return None
        before = "\n".join(self.source_lines[:first.line - 1] + [self.source_lines[first.line - 1][:first.column - 1]])
        matches = list(re.finditer(rf"(?<![\w-]){re.escape(keyword)}\s*\{{", before))
        if not matches:
            return None
        found = matches[-1]
        line = before.count("\n", 0, found.start()) + 1
        column = found.start() - (before.rfind("\n", 0, found.start()) + 1) + 1
        return Span(first.file, line, column, line, column + len(keyword))

    def props(self, node: Any) -> None:
        for f in property_fields(type(node)):
            value = getattr(node, f.name)
            if value is None or value == ():
                continue
            values = value if isinstance(value, tuple) else (value,)
            anchor = values[0].span if hasattr(values[0], "span") else None
            shown = ", ".join(v if isinstance(v, str) else prop_value(v) for v in values)
            self.line(f"{f.metadata['key']}: {shown};", anchor)

    # -- files and items
    def source_file(self, source: m.SourceFile) -> None:
        for i, item in enumerate(source.items):
            if i:
                self.out.append("")
            self.item(item)
        if self.comments is not None:
            self.leading_comments(self.comments.rest, "")

    def item(self, item: m.Item) -> None:
        method: Callable[[Any], None] = getattr(self, "p_" + type(item).__name__)
        method(item)

    # -- module
    def p_Module(self, node: m.Module) -> None:
        with self.block(f"module {node.name}", node.span):
            self.props(node)
            for s in node.structs:
                with self.block(f"struct {s.name}", s.span):
                    self.fields(s.fields)
            for e in node.enums:
                self.line(f"enum {e.name} {{ {', '.join(e.values)} }}", e.span)
            if node.internal_data:
                with self.section("internal_data", node.internal_data[0].span):
                    self.fields(node.internal_data)
            for r in node.requests:
                with self.block(f"request {r.name}", r.span):
                    self.props_and_codels(r)
            for t in node.exec_tasks:
                with self.block(f"exec_task {t.name}", t.span):
                    self.props_and_codels(t)
            for p in node.posters:
                with self.block(f"poster {p.name}", p.span):
                    self.props(p)

    def fields(self, fields: Iterable[m.Field]) -> None:
        for f in fields:
            self.line(f"{f.name}: {type_ref(f.type)};", f.span)

    def props_and_codels(self, node: m.Request | m.ExecTask) -> None:
        self.props(node)
        for c in node.codels:
            yields = f" -> {', '.join(c.yields)}" if c.yields else ""
            self.line(f"codel {c.state}: {c.function}{yields};", c.span)

    # -- executive
    def p_Executive(self, node: m.Executive) -> None:
        with self.block(f"executive {node.name}", node.span):
            self.props(node)
            for s in node.services:
                with self.block(f"service {s.name}", s.span):
                    self.service(s)
            for p in node.parameters:
                with self.block(f"parameter {p.name}", p.span):
                    self.props(p)
            for r in node.reflexes:
                self.line(self.reflex(r), r.span)

    def service(self, s: m.Service) -> None:
        self.props(s)
        if s.args:
            with self.section("args", s.args[0].span):
                for a in s.args:
                    self.line(f"{a.name}: {prop_value(a.value)};", a.span)
        if s.timeout is not None:
            with self.block("timeout", s.timeout.span):
                self.props(s.timeout)
        if s.conflicts:
            with self.section("conflicts", s.conflicts[0].span):
                for c in s.conflicts:
                    self.line(f"{c.service}: {c.policy};", c.span)

    @staticmethod
    def reflex(r: m.Reflex) -> str:
        name = f" {r.name}" if r.name else ""
        comparison = f" {r.comparison.op} {prop_value(r.comparison.value)}" if r.comparison else ""
        actions = ", ".join(f"{a.verb} {a.target.text}" for a in r.actions)
        return f"reflex{name} on {r.trigger} {r.source.text}{comparison} => {actions};"

    # -- rules
    def p_RuleBase(self, node: m.RuleBase) -> None:
        with self.block(f"rules {node.name}", node.span):
            for c in node.constants:
                self.line(f"const {c.name} = {kexpr(c.value)};", c.span)
            for role, group in _runs(node.attributes, lambda a: a.role):
                specs = ", ".join(a.name + (f": {kdomain(a.domain)}" if a.domain else "") for a in group)
                self.line(f"{role} {specs};", group[0].span)
            for i in node.inits:
                self.line(f"init @{i.name} = {kexpr(i.value)};", i.span)
            for r in node.rules:
                if isinstance(r, m.RuleForeach):
                    with self.block(f"foreach {r.var} in {klist(r.items)}", r.span):
                        for x in r.rules:
                            self.rule(x)
                else:
                    self.rule(r)

    def rule(self, r: m.Rule) -> None:
        name = r.name + (f"[{r.index}]" if r.index is not None else "")
        actions = ", ".join(action(a) for a in r.actions)
        if r.kind == "impossible":
            assert r.condition is not None
            self.line(f"{name}: impossible {cond(r.condition)};", r.span)
        elif r.kind == "else":
            self.line(f"{name}: else {actions};", r.span)
        else:
            assert r.condition is not None
            text = f"{name}: {cond(r.condition)} ==> {actions};"
            if len(text) + len(INDENT) * self.depth <= WRAP_AT:
                self.line(text, r.span)
            else:
                self.line(f"{name}: {cond(r.condition)}", r.span)
                self.out.append(INDENT * (self.depth + 2) + f"==> {actions};")

    # -- procedures
    def p_Procedures(self, node: m.Procedures) -> None:
        with self.block(f"procedures {node.name}", node.span):
            for t in node.types:
                self.line(f"type {t.name} = {pdomain(t.domain)};", t.span)
            for p in node.predicates:
                kinds = "".join(k + " " for k in p.kinds)
                result = f" -> {pdomain(p.result)}" if p.result else ""
                binding = f" = {string(p.binding)}" if p.binding else ""
                self.line(f"predicate {kinds}{p.name}{pparams(p.params)}{result}{binding};", p.span)
            for a in node.actions:
                result = f" -> {pdomain(a.result)}" if a.result else ""
                bound = f"service {a.binding.service}" if isinstance(a.binding, m.ServiceBinding) else string(a.binding)
                self.line(f"action {a.name}{pparams(a.params)}{result} = {bound};", a.span)
            for ka in node.kas:
                with self.block(f"ka {ka.name}", ka.span):
                    self.ka(ka)

    def ka(self, ka: m.KA) -> None:
        if ka.invocation is not None:
            self.line(f"invocation: {goal(ka.invocation)};", ka.invocation.span)
        if ka.context is not None:
            self.line(f"context: {goal(ka.context)};", ka.context.span)
        for p in ka.properties:
            self.line(f"property: {p};", getattr(p, "span", None))
        if ka.action is not None:
            result = f" -> {ka.action.result.name}" if ka.action.result else ""
            self.line(f"action: {sexp(ka.action.call)}{result};", ka.action.span)
        if ka.body is not None:
            with self.block("body", ka.body.span):
                self.statements(ka.body)
        if ka.effects:
            with self.section("effects", ka.effects[0].span):
                for g in ka.effects:
                    self.line(goal(g) + ";", g.span)
        if ka.documentation is not None:
            self.line(f"documentation: {string(ka.documentation)};", ka.documentation.span)

    def statements(self, block: m.Block) -> None:
        for s in block.statements:
            self.statement(s)

    def statement(self, s: m.Stmt) -> None:
        if isinstance(s, m.GoalStmt):
            self.line(goal(s.goal) + ";", s.span)
        elif isinstance(s, m.IfStmt):
            self.if_statement(s, "if")
        elif isinstance(s, m.WhileStmt):
            with self.block(f"while {goal(s.condition)}", s.span):
                self.statements(s.body)
        elif isinstance(s, (m.ParallelStmt, m.ChooseStmt)):
            keyword = "parallel" if isinstance(s, m.ParallelStmt) else "choose"
            with self.block(keyword, s.span):
                for branch in s.branches:
                    with self.block("branch", branch.span):
                        self.statements(branch)
        elif isinstance(s, m.AssignStmt):
            self.line(f"assign {s.var} = {sarg(s.value)};", s.span)
        elif isinstance(s, m.FailStmt):
            self.line("fail;", s.span)
        else:
            raise TypeError(s)

    def if_statement(self, s: m.IfStmt, keyword: str) -> None:
        self.line(f"{keyword} {goal(s.condition)} {{", s.span)
        self.depth += 1
        self.statements(s.then)
        self.depth -= 1
        self._else_tail(s)

    def _else_tail(self, s: m.IfStmt) -> None:
        orelse = s.orelse
        if orelse is None:
            self.closing("}", s.then.span)
        elif isinstance(orelse, m.IfStmt):
            self.closing(f"}} else if {goal(orelse.condition)} {{", s.then.span)
            self.depth += 1
            self.statements(orelse.then)
            self.depth -= 1
            self._else_tail(orelse)
        else:
            self.closing("} else {", s.then.span)
            self.depth += 1
            self.statements(orelse)
            self.depth -= 1
            self.closing("}", orelse.span)

    # -- IxTeT
    def p_Domain(self, node: m.Domain) -> None:
        with self.block(f"domain {node.name}", node.span):
            self.members(node.members)

    def p_Fragment(self, node: m.Fragment) -> None:
        with self.block(f"fragment {node.name}", node.span):
            self.members(node.members)

    def p_Problem(self, node: m.Problem) -> None:
        footer = "}" + (f" {node.preemption}" if node.preemption else "")
        with self.block(f"problem {node.name} for {node.domain.text}", node.span, footer):
            self.members(node.body)

    def members(self, members: Iterable[Any]) -> None:
        for member in members:
            if isinstance(member, m.Constant):
                self.line(f"constant {member.name} = {set_union(member.value)};", member.span)
            elif isinstance(member, (m.Attribute, m.Resource)):
                keyword = "attribute" if isinstance(member, m.Attribute) else "resource"
                params = ", ".join(p.name for p in member.params)
                with self.block(f"{keyword} {member.name}({params})", member.span):
                    self.members(member.body)
            elif isinstance(member, m.Macro):
                with self.block(f"macro {member.name}({', '.join(member.params)})", member.span):
                    self.members(member.body)
            elif isinstance(member, m.Task):
                params = ", ".join(p.name for p in member.params)
                footer = "}" + (f" {member.preemption}" if member.preemption else "")
                with self.block(f"task {member.name}({params}) ({member.start}, {member.end})", member.span, footer):
                    self.members(member.body)
            else:
                self.line(tstmt(member), member.span)

    # -- ftplan and system
    def p_FtPlan(self, node: m.FtPlan) -> None:
        with self.block(f"ftplan {node.name}", node.span):
            self.props(node)
            for p in node.planners:
                with self.block(f"planner {p.name}", p.span):
                    self.props(p)
                    if p.view:
                        with self.section("view", p.view[0].span):
                            self.correspondences(p.view)
            if node.analyzer:
                with self.section("analyzer", node.analyzer[0].span):
                    for rule in node.analyzer:
                        self.analyzer_rule(rule)
            if node.state_updates:
                with self.section("state", node.state_updates[0].span):
                    for update in node.state_updates:
                        self.state_update(update)
            for mission in node.missions:
                with self.block(f"mission {mission.name}", mission.span):
                    for problem in mission.problems:
                        self.line(f"{problem.planner.text}: {problem.problem.text};", problem.span)
                    for view in mission.views:
                        with self.block(f"view {view.planner.text}", view.span):
                            self.correspondences(view.correspondences)

    def correspondences(self, correspondences: Iterable[m.Correspondence]) -> None:
        def side(facts: tuple[m.ViewFact, ...]) -> str:
            return ", ".join(f"{f.attribute}({ix_args(f.args)}): "
                             + (domain_value(f.value) if isinstance(f.value, m.Interval) else ixexpr(f.value))
                             for f in facts)

        for c in correspondences:
            self.line(f"{side(c.planner_facts)} <=> {side(c.state_facts)};", c.span)

    def analyzer_rule(self, r: m.AnalyzerRule) -> None:
        if isinstance(r, m.AnalyzerCondition):
            self.line(f"{r.kind} {r.task}({ix_args(r.args)}) requires {attr_value(r.requirement)};", r.span)
        elif isinstance(r, m.AnalyzerNoOverlap):
            self.line(f"no_overlap {', '.join(r.tasks)};", r.span)
        else:
            self.line(f"max_duration {r.task} {prop_value(r.limit)};", r.span)

    def state_update(self, u: m.StateUpdate) -> None:
        updates = ", ".join(f"{f.attribute}({ix_args(f.args)}) := {ixexpr(f.value)}" for f in u.updates)
        self.line(f"on {u.report} {u.task}({ix_args(u.args)}) => {updates};", u.span)

    def p_System(self, node: m.System) -> None:
        with self.block(f"system {node.name}", node.span):
            self.props(node)
            for section, settings in (("body", node.body), ("worlds", node.worlds)):
                if settings is not None:
                    with self.block(section, settings.span):
                        for entry in settings.entries:
                            self.line(f"{entry.name}: {prop_value(entry.value)};", entry.span)
            if node.devices is not None:
                with self.block("devices", node.devices.span):
                    for grant in node.devices.entries:
                        self.line(f"{grant.module}: {', '.join(d.text for d in grant.devices)};", grant.span)
            for mission in node.missions:
                with self.block(f"mission {mission.name}", mission.span):
                    self.props(mission)
                    for g in mission.goals:
                        self.line(f"goal: {goal(g)};", g.span)
            if node.bindings is not None:
                with self.block("bindings", node.bindings.span):
                    for b in node.bindings.entries:
                        report = f" report {b.report.name}({', '.join(v.text for v in b.report.values)})" \
                            if b.report is not None else ""
                        where = f" where {b.where.attribute}({ix_args(b.where.args)}) := {ixexpr(b.where.value)}" \
                            if b.where is not None else ""
                        self.line(f"{b.task}({ix_args(b.args)}) => {b.kind} {b.target.text}({ix_args(b.target_args)})"
                                  f"{where}{report};", b.span)


def _runs(items: Iterable[Any], key: Callable[[Any], str]) -> list[tuple[str, list[Any]]]:
    """Consecutive items with the same key, grouped (so `inputs a, b;` stays one line)."""
    runs: list[tuple[str, list[Any]]] = []
    for item in items:
        k = key(item)
        if runs and runs[-1][0] == k:
            runs[-1][1].append(item)
        else:
            runs.append((k, [item]))
    return runs


def print_source(source: m.SourceFile) -> str:
    """Canonical text of one file, without comments."""
    printer = Printer()
    printer.source_file(source)
    return "\n".join(printer.out) + "\n"


def format_source(source: m.SourceFile, text: str, comments: list[Comment]) -> str:
    """Canonical text of one file, keeping its comments (what `specc fmt` writes)."""
    dry = Printer(None, text)
    dry.source_file(source)
    placed = _place_comments(comments, dry.anchors, text)
    printer = Printer(placed, text)
    printer.source_file(source)
    return "\n".join(printer.out).rstrip("\n") + "\n"
