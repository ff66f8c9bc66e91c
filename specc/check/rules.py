"""Kheops rule bases (seed 000 §3.7, annex A).

Attributes that are neither inputs nor outputs are intermediate, declared or not (annex A:
`diagn` and `difP` of Fig. 3.8 are never declared). What is checked: inputs are never
restricted, outputs are all deduced by some rule, inputs are all tested by some rule (a
warning), `@x` has an `init`, values compared with a declared symbolic attribute belong to its
domain, and `foreach` variables are in scope.
"""

from __future__ import annotations

import math

from specc.check.context import Context
from specc.diagnostics import did_you_mean
from specc.model import nodes as m
from specc.model.visitor import Visitor, walk

BOOL_WORDS = ("true", "false")  # what a bool is compared with by mistake
ARITHMETIC = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
              "/": lambda a, b: a / b if b else None}


def literal(expr: m.KExpr | None, constants: dict[str, m.KExpr], depth: int = 0) -> float | str | None:
    """The value of a rule base's expression made of literals and constants only (`-30`,
    `SLOW`, `LIMIT * 2`), or None when it reads an attribute (or is circular)."""
    if isinstance(expr, (m.Number, m.String)):
        return expr.value
    if depth > len(constants):
        return None
    if isinstance(expr, m.KNegate):
        inner = literal(expr.operand, constants, depth + 1)
        return -inner if isinstance(inner, (int, float)) else None
    if isinstance(expr, m.AttrRef) and expr.index is None and not expr.previous and expr.name in constants:
        return literal(constants[expr.name], constants, depth + 1)
    if isinstance(expr, m.KBinary) and expr.op in ARITHMETIC:
        left, right = literal(expr.left, constants, depth + 1), literal(expr.right, constants, depth + 1)
        if isinstance(left, (int, float)) and isinstance(right, (int, float)):
            result: float | None = ARITHMETIC[expr.op](left, right)
            return result
    return None


class RuleVisitor(Visitor):
    """Collects, for one rule base, what each attribute is used for."""

    def __init__(self, ctx: Context, base: m.RuleBase):
        self.ctx = ctx
        self.declared = {a.name: a for a in base.attributes}
        self.constants: dict[str, m.KExpr] = {c.name: c.value for c in base.constants}
        self.inits = {i.name for i in base.inits}
        self.loop_vars: list[str] = []
        self.restricted: set[str] = set()
        # Attributes a `do` sets from their own value (`level = level + 1`), and those something else sets.
        self.set_from_itself: dict[str, m.DoAssign] = {}
        self.set_otherwise: set[str] = set()
        self.tested: set[str] = set()
        self.first_read: dict[str, m.AttrRef] = {}  # where each attribute is first tested
        self.first_set: dict[str, m.AttrRef] = {}  # where each attribute is first deduced
        self.conjuncts: set[int] = set()  # the rule's condition's conjuncts (ids): what must hold for it to fire
        self.in_action = False

    def visit_RuleForeach(self, node: m.RuleForeach) -> None:
        self.loop_vars.append(node.var)
        self.generic_visit(node)
        self.loop_vars.pop()

    def visit_KForeach(self, node: m.KForeach) -> None:
        self.loop_vars.append(node.var)
        self.generic_visit(node)
        self.loop_vars.pop()

    def visit_Rule(self, node: m.Rule) -> None:
        if node.index is not None:
            self.check_index(node.index, node.span)
        if node.condition is not None:
            self.in_action = False
            self.conjuncts = {id(c) for c in conjuncts(node.condition)}
            self.visit(node.condition)
            self.check_together(conjuncts(node.condition))
            self.conjuncts = set()
        self.in_action = True
        for action in node.actions:
            self.visit(action)
        self.in_action = False

    def visit_DoAssign(self, node: m.DoAssign) -> None:
        if any(isinstance(n, m.AttrRef) and n.name == node.target and not n.previous for n in walk(node.value)):
            self.set_from_itself.setdefault(node.target, node)  # `level = level + 1`
        else:
            self.set_otherwise.add(node.target)
        self.restricted.add(node.target)
        self.check_not_input(node.target, node.span)
        declared = self.declared.get(node.target)
        if declared is not None and declared.role == "outputs":
            self.ctx.report("assigned-output", f"'{node.target}' is an output: a decision's outputs take the values "
                            f"its rules restrict them to (`restrict {node.target} == 5`, or `oneof [...]`), and `do` "
                            "computes a value for the rules' own tests (an intermediate): decide would give "
                            f"'{node.target}' unrestricted. A value computed from the inputs (`battery / 10`) is no "
                            "output of a propositional rule base: let the caller compute it", node.span)
        self.in_action = False
        self.visit(node.value)
        self.in_action = True

    def visit_DoCall(self, node: m.DoCall) -> None:
        self.in_action = False
        for arg in node.args:
            self.visit(arg)
        self.in_action = True

    def visit_KCompare(self, node: m.KCompare) -> None:
        self.use(node.attr)
        self.check_value(node.attr, node.value, numeric=node.op not in ("==", "!="))
        self.check_range(node)
        if isinstance(node.value, m.AttrRef) and node.value.name.lower() in BOOL_WORDS and self.is_bool(node.attr):
            return  # `e == false`: said by check_value, not also as an undefined attribute 'false'
        self.in_action, was = False, self.in_action
        self.visit(node.value)
        self.in_action = was

    def check_range(self, node: m.KCompare) -> None:
        """A comparison of a numeric attribute with a number it can never satisfy within its declared
        range (`x > 20` with x in [0, 10]): the rule testing it never fires, a typo the likeliest cause."""
        if self.in_action or id(node) not in self.conjuncts:
            return  # under `!` or `|` a comparison that never holds may leave the rule firing
        declared = self.declared_of(node.attr)
        domain = declared.domain if declared is not None else None
        value = literal(node.value, self.constants)
        if not (isinstance(domain, m.NumericDomain) and isinstance(value, (int, float))
                and math.isfinite(value)):  # a number too large is an error of its own
            return
        low, high = self.numeric_bounds(domain)
        if low > high:
            return  # an empty domain, said once (`empty-domain`)
        never = {"<": low >= value, "<=": low > value, ">": high <= value, ">=": high < value,
                 "==": not low <= value <= high}.get(node.op, False)
        # Only a threshold outside the domain (`battery < 180` on [0, 100], a typo): `x <= 10` on
        # [0, 10] is a rule written to cover every value, on purpose.
        always = {"<": high < value, "<=": high < value, ">": low > value, ">=": low > value,
                  "!=": not low <= value <= high}.get(node.op, False)
        if never:
            self.ctx.warn("comparison-never-holds", f"{node.attr.name} {node.op} {value:g} never holds: "
                          f"'{node.attr.name}' lies in [{low:g}, {high:g}]; the rule testing it never fires",
                          node.span)
        elif always:
            self.ctx.warn("comparison-always-holds", f"{node.attr.name} {node.op} {value:g} always holds: "
                          f"'{node.attr.name}' lies in [{low:g}, {high:g}], so it tests nothing (a threshold "
                          "outside the domain: a typo?)", node.span)

    def numeric_bounds(self, domain: m.NumericDomain) -> tuple[float, float]:
        """A numeric domain's bounds, infinite where it gives none (or none known before run time)."""
        low, high = literal(domain.low, self.constants), literal(domain.high, self.constants)
        return (low if isinstance(low, (int, float)) else -math.inf,
                high if isinstance(high, (int, float)) else math.inf)

    def check_together(self, parts: list[m.Node]) -> None:
        """Comparisons of one numeric attribute with numbers that no value satisfies together
        (`charge < 10, charge > 20`): the rule never fires. Each alone may hold (`check_range`)."""
        # (attribute, of the previous cycle) -> low, low included, high, high included
        bounds: dict[tuple[str, bool], tuple[float, bool, float, bool]] = {}
        for part in parts:
            value = literal(part.value, self.constants) if isinstance(part, m.KCompare) else None
            if not (isinstance(part, m.KCompare) and isinstance(value, (int, float)) and part.attr.index is None
                    and math.isfinite(value) and part.op in ("<", "<=", ">", ">=", "==")):
                continue  # an indexed attribute's comparisons may each be of another element
            name, op = part.attr.name, part.op
            key = (name, part.attr.previous)
            low, low_in, high, high_in = bounds.get(key, (-math.inf, False, math.inf, False))
            if op in (">", ">=", "==") and (value > low or value == low and op == ">"):
                low, low_in = value, op != ">"
            if op in ("<", "<=", "==") and (value < high or value == high and op == "<"):
                high, high_in = value, op != "<"
            bounds[key] = (low, low_in, high, high_in)
            if low > high or low == high and not (low_in and high_in):
                self.ctx.warn("comparison-never-holds", f"{name} {op} {value:g} never holds together with the "
                              f"rule's other comparisons of '{name}' (no value is both above {low:g} and below "
                              f"{high:g} as they ask): the rule never fires", part.span)
                return

    def is_bool(self, attr: m.AttrRef) -> bool:
        declared = self.declared_of(attr)
        return declared is not None and isinstance(declared.domain, m.BoolDomain)

    def visit_KMember(self, node: m.KMember) -> None:
        self.use(node.attr)
        for item in node.items:
            if isinstance(item, (m.String, m.Number)):
                self.check_value(node.attr, item, numeric=False)

    def visit_KTrue(self, node: m.KTrue) -> None:
        self.use(node.attr)

    def visit_KFalse(self, node: m.KFalse) -> None:
        self.use(node.attr)

    def visit_AttrRef(self, node: m.AttrRef) -> None:
        if node.name in self.constants or node.name in self.loop_vars:
            return
        self.use(node)

    def elements(self, attr: m.AttrRef) -> list[str]:
        """The attributes a reference may name: `level[i]` in a foreach names each declared
        `level[1]`, `level[2]`...; a plain reference, or one to no declared element, its name."""
        if attr.index is not None:
            declared = [name for name in self.declared if name.startswith(attr.name + "[")]
            if declared:
                return declared
        return [attr.name]

    def declared_of(self, attr: m.AttrRef) -> m.AttrDecl | None:
        """The declaration of the attribute a reference names (of its first element, indexed)."""
        return self.declared.get(self.elements(attr)[0])

    def use(self, attr: m.AttrRef) -> None:
        if attr.index is not None:
            self.check_index(attr.index, attr.span)
        names = self.elements(attr)
        if attr.previous:
            self.tested.update(names)
            if not any(name in self.inits for name in names):
                self.ctx.report("missing-init",
                                f"'@{attr.name}' reads the previous cycle's value: add 'init @{names[0]} = ...;'",
                                attr.span)
            return
        for name in names:
            if self.in_action:
                self.set_otherwise.add(name)
                self.restricted.add(name)
                self.first_set.setdefault(name, attr)
                self.check_not_input(name, attr.span)
            else:
                self.tested.add(name)
                self.first_read.setdefault(name, attr)

    def check_not_input(self, name: str, span: object) -> None:
        declared = self.declared.get(name)
        if declared is not None and declared.role == "inputs":
            assert isinstance(span, m.Span)
            self.ctx.report("restrict-input", f"'{name}' is an input: rules may test it, not deduce it", span)

    def check_index(self, index: str, span: m.Span) -> None:
        if index not in self.loop_vars:
            self.ctx.report("undefined-loop-variable",
                            f"'{index}' is not a foreach variable here; wrap the rule in 'foreach {index} in [...]'",
                            span)

    def check_value(self, attr: m.AttrRef, value: m.KExpr, numeric: bool) -> None:
        declared = self.declared_of(attr)
        if declared is None or declared.domain is None:
            return
        domain = declared.domain
        constant = literal(value, self.constants)
        if isinstance(domain, m.SymbolDomain):
            if numeric:
                self.ctx.report("type-mismatch",
                                f"'{attr.name}' is symbolic; compare it with == != oneof noneof, not an ordering",
                                attr.span)
            elif isinstance(value, (m.String, m.Number)):
                allowed = [v.value for v in domain.values if isinstance(v, (m.String, m.Number))]
                if value.value not in allowed:
                    self.ctx.report("value-outside-domain",
                                    f"{value.value!r} is not a value of '{attr.name}' "
                                    f"(domain: {', '.join(repr(a) for a in allowed)})", value.span)
        elif isinstance(domain, m.BoolDomain):
            if numeric or isinstance(value, (m.String, m.Number)) or (
                    isinstance(value, m.AttrRef) and value.name.lower() in BOOL_WORDS):
                shown = value.value if isinstance(value, (m.String, m.Number)) else getattr(value, "name", "")
                self.ctx.report("type-mismatch", f"'{attr.name}' is a bool: test it as '{attr.name}' (true) or "
                                f"'!{attr.name}' (false), not against {shown!r}", value.span)
        elif isinstance(domain, m.NumericDomain) and isinstance(constant, str):
            named = "" if isinstance(value, m.String) else f" ({getattr(value, 'name', 'a constant')})"
            self.ctx.report("type-mismatch", f"'{attr.name}' is numeric; it cannot be compared with the string "
                            f"{constant!r}{named}", value.span)


def check_never_set(ctx: Context, base: m.RuleBase, visitor: RuleVisitor) -> None:
    """An attribute a rule tests that is no input, has no init and that no rule sets never has a
    value: the rule can never fire (a misspelt input or constant becomes such an attribute)."""
    inputs = {a.name for a in base.attributes if a.role == "inputs"}
    for name, ref in visitor.first_read.items():
        if name in inputs or name in visitor.restricted or name in visitor.inits:
            continue
        known = inputs | visitor.restricted | set(visitor.constants)
        ctx.report("undefined-attribute", f"'{name}' is tested, but it is no input, has no init and no rule sets "
                   f"it: the rule can never fire (a misspelt input or constant?){did_you_mean(name, known)}",
                   ref.span)
    for name, assign in visitor.set_from_itself.items():
        if name not in inputs and name not in visitor.set_otherwise:
            ctx.report("undefined-attribute", f"'{name} = ...' reads '{name}' itself, which has no value then: no "
                       "input gives it and nothing else sets it; compute it from inputs and constants, or from a "
                       "previous cycle's value (`@x`, with its `init`)", assign.span)


def check_rules_never_fire(ctx: Context, base: m.RuleBase, visitor: RuleVisitor) -> None:
    """Rules that test attributes only rules which need them first can set (`c1: mood == "a" ==>
    restrict state == "b"; c2: state == "b" ==> restrict mood == "a";`): neither ever fires.
    What can have a value grows from the inputs through the rules that may fire, to a fixpoint;
    a rule written per element (`r[i]`, `foreach`) counts as firing."""
    def named(node: m.Node | None) -> set[str]:
        return {n.name for n in (walk(node) if node is not None else ()) if isinstance(n, m.AttrRef)
                and not n.previous and n.index is None and n.name not in visitor.constants}

    def needs(node: m.Node | None) -> list[frozenset[str]]:
        """The sets of attributes a condition reads, any one of which may let it hold once they all
        have values: `a | b` holds with either side's, `a, b` needs both sides'."""
        if isinstance(node, m.KOr):
            return [alternative for operand in node.operands for alternative in needs(operand)]
        if isinstance(node, m.KAnd):
            found = [frozenset[str]()]
            for operand in node.operands:
                found = [a | b for a in found for b in needs(operand)][:ALTERNATIVES]
            return found
        return [frozenset(named(node))]

    def sets(rule: m.Rule) -> set[str]:
        return {n.target if isinstance(n, m.DoAssign) else n.name for action in rule.actions for n in walk(action)
                if isinstance(n, m.DoAssign) or (isinstance(n, m.AttrRef) and isinstance(action, m.Restrict))}

    plain = [r for r in base.rules if isinstance(r, m.Rule) and r.index is None and r.kind == "when"]
    valued = {a.name for a in base.attributes if a.role == "inputs"}
    for rule in base.rules:
        if rule not in plain:  # an else rule, a rule written per element: taken to fire
            valued |= set().union(*(sets(r) for r in (rule.rules if isinstance(rule, m.RuleForeach) else (rule,))))
    waiting = [(rule, needs(rule.condition), sets(rule)) for rule in plain]
    grew = True
    while grew:
        grew = False
        for _, alternatives, targets in waiting:
            if any(reads <= valued for reads in alternatives) and not targets <= valued:
                valued |= targets
                grew = True
    deduced = {name for _, _, targets in waiting for name in targets}
    for rule, alternatives, _ in waiting:
        if any(reads <= valued for reads in alternatives):
            continue
        fewest = min((reads - valued for reads in alternatives), key=len)
        missing = sorted(fewest)
        if missing and set(missing) <= deduced & visitor.set_otherwise:  # else `undefined-attribute` says it
            setters = sorted(r.name for r, _, targets in waiting if targets & set(missing))
            said = " and ".join(f"'{name}'" for name in missing)
            one = len(missing) == 1
            ctx.warn("rule-never-fires", f"rule '{rule.name}' can never fire: {said} {'gets' if one else 'get'} a "
                     f"value only from rules that need {'it' if one else 'them'} first ({', '.join(setters)}); "
                     "start the chain from an input", rule.span)


# Alternatives a condition's `|` under `,` may multiply into, kept: past them a rule counts as one
# that may fire (a warning is only given when sure).
ALTERNATIVES = 64


def conjuncts(condition: m.Node) -> list[m.Node]:
    """The parts of a condition that must each hold: `a, b, (c, d)` gives a, b, c and d; `!a` or
    `a | b` is one part."""
    if isinstance(condition, m.KAnd):
        return [part for operand in condition.operands for part in conjuncts(operand)]
    return [condition]


def check_set_never_read(ctx: Context, base: m.RuleBase, visitor: RuleVisitor) -> None:
    """An undeclared attribute rules deduce and no rule tests is an intermediate that changes
    nothing: most likely a misspelt output (`restrict oo == ...` for `o`)."""
    outputs = [a.name for a in base.attributes if a.role == "outputs"]
    for name, ref in visitor.first_set.items():
        if name not in visitor.declared and name not in visitor.tested:
            ctx.warn("intermediate-never-read", f"rules deduce '{name}', which is not declared and no rule tests: "
                     f"it changes no decision{did_you_mean(name, outputs) or ' (a misspelt output?)'}", ref.span)


def check_never_read(ctx: Context, base: m.RuleBase, visitor: RuleVisitor) -> None:
    """An input no rule tests changes no decision: a warning, since a misspelt test elsewhere (an
    undefined attribute) or a forgotten rule is the likely cause."""
    for attr in base.attributes:
        if attr.role == "inputs" and attr.name not in visitor.tested:
            ctx.warn("input-never-read", f"no rule tests input '{attr.name}': it changes no decision; test it "
                     f"in a rule or remove it", attr.span)


def check(ctx: Context) -> None:
    # An executive's own rules add to the controller generated from its conflicts, which
    # deduces the group states: only stand-alone bases must deduce every output themselves.
    completed = {ref.text for executive in ctx.items(m.Executive) for ref in executive.rules}
    for base in ctx.items(m.RuleBase):
        ctx.duplicates(base.attributes, "attribute")
        ctx.duplicates(base.constants, "constant")
        ctx.duplicates([r for r in base.rules if isinstance(r, m.Rule)], "rule")
        if not base.rules:
            ctx.warn("empty-rule-base", f"rule base '{base.name}' has no rules: it decides nothing; add one, e.g. "
                     "`slow: load > 100 ==> restrict speed == \"slow\";`", base.span)
        visitor = RuleVisitor(ctx, base)
        visitor.visit(base)
        if base.name not in completed:  # an executive's own rules read the controller's attributes
            check_never_set(ctx, base, visitor)
            check_set_never_read(ctx, base, visitor)
            check_rules_never_fire(ctx, base, visitor)
        check_never_read(ctx, base, visitor)
        for attr in base.attributes:
            domain = attr.domain
            low, high = visitor.numeric_bounds(domain) if isinstance(domain, m.NumericDomain) else (0, 0)
            if low > high and domain is not None:
                ctx.report("empty-domain", f"[{low:g}, {high:g}] holds no value of '{attr.name}': write the low "
                           "bound first", domain.span)
            if attr.role == "outputs" and attr.name not in visitor.restricted and base.name not in completed:
                ctx.report("output-never-set", f"no rule deduces output '{attr.name}'", attr.span)
        for init in base.inits:
            declared = visitor.declared.get(init.name)
            if declared is None:
                ctx.warn("init-undeclared", f"'init @{init.name}' for an attribute that is not declared", init.span)
            else:
                check_init_value(ctx, visitor, declared, init)


def check_init_value(ctx: Context, visitor: RuleVisitor, declared: m.AttrDecl, init: m.InitDecl) -> None:
    """The value `init @x = ...` gives is one `x` may take: the first cycle reads it as `@x`."""
    domain = declared.domain
    value = literal(init.value, visitor.constants)
    if isinstance(init.value, m.AttrRef) and init.value.name.lower() in BOOL_WORDS:
        value = init.value.name.lower() == "true"
    if domain is None or value is None and not isinstance(domain, m.BoolDomain):
        return
    if isinstance(domain, m.SymbolDomain):
        allowed = [v.value for v in domain.values if isinstance(v, (m.String, m.Number))]
        if value not in allowed:
            ctx.report("value-outside-domain", f"{value!r} is not a value of '{declared.name}' (domain: "
                       f"{', '.join(repr(a) for a in allowed)}){did_you_mean(str(value), [str(a) for a in allowed])}",
                       init.value.span)
    elif isinstance(domain, m.BoolDomain):
        if not isinstance(value, bool):
            ctx.report("type-mismatch", f"'{declared.name}' is a bool: its init is true or false, not {value!r}",
                       init.value.span)
    else:
        low, high = visitor.numeric_bounds(domain)
        if not isinstance(value, (int, float)) or not low <= value <= high:
            ctx.report("value-outside-domain", f"{value!r} is not a value of '{declared.name}', which lies in "
                       f"[{low:g}, {high:g}]", init.value.span)
