"""Bench only: a normalised Kheops rule base run by CLIPS (clipspy), with the same semantics.

Each attribute's possible values are `val` facts; a condition is TRUE when some value remains
and none contradicts it, FALSE when none satisfies it; a rule fires once (a `fired` fact);
`restrict` retracts the values it excludes. Inputs are asserted and outputs read back inside
CLIPS (`cycle`), so no fact object crosses into Python in the timing loop.
"""

from __future__ import annotations

import itertools
from typing import Any

from specc.analysis import kheops as k

_names = itertools.count()


def literal(value: Any) -> str:
    if isinstance(value, bool):
        return "TRUE" if value else "FALSE"
    if isinstance(value, k.Piece):
        return repr(float(value.sample()))
    if isinstance(value, (int, float)):
        return repr(float(value))
    return '"' + str(value).replace("\\", "\\\\").replace('"', '\\"') + '"'


def predicate(atom: k.Atom, var: str) -> str:
    if atom.op in ("in", "notin"):
        test = f"(member$ {var} (create$ {' '.join(literal(v) for v in atom.value)}))"
        return test if atom.op == "in" else f"(not {test})"
    value = atom.value
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        op = {"==": "=", "!=": "<>"}.get(atom.op, atom.op)
        test = f"(and (numberp {var}) ({op} {var} {literal(value)}))"
        return f"(not (and (numberp {var}) (= {var} {literal(value)})))" if atom.op == "!=" else test
    return f"(eq {var} {literal(value)})" if atom.op == "==" else f"(neq {var} {literal(value)})"


def holds(cond: k.Cond) -> str:
    """A CLIPS conditional element true when `cond` is TRUE under the current values."""
    if isinstance(cond, k.Atom):
        var = f"?v{next(_names)}"
        return (f'(and (val (a "{cond.attribute}")) '
                f'(not (val (a "{cond.attribute}") (v {var}&:(not {predicate(cond, var)})))))')
    if isinstance(cond, k.Not):
        return fails(cond.operand)
    parts = " ".join(holds(c) for c in cond.operands)
    return f"(and {parts})" if isinstance(cond, k.All) else f"(or {parts})"


def fails(cond: k.Cond) -> str:
    """A conditional element true when `cond` is FALSE."""
    if isinstance(cond, k.Atom):
        var = f"?v{next(_names)}"
        return f'(not (val (a "{cond.attribute}") (v {var}&:{predicate(cond, var)})))'
    if isinstance(cond, k.Not):
        return holds(cond.operand)
    parts = " ".join(fails(c) for c in cond.operands)
    return f"(or {parts})" if isinstance(cond, k.All) else f"(and {parts})"


def expression(expr: k.Expr) -> str:
    if expr.op == "const":
        return literal(expr.args[0])
    if expr.op == "attr":
        return f'(value-of "{expr.args[0]}")'
    if expr.op == "neg":
        return f"(- 0 {expression(expr.args[0])})"
    left, right = (expression(a) for a in expr.args)
    return f"({expr.op} {left} {right})"


def action(act: k.Action) -> str:
    if isinstance(act, k.Restrict):
        atom = act.atom
        return (f'(do-for-all-facts ((?f val)) (and (eq ?f:a "{atom.attribute}") '
                f'(not {predicate(atom, "?f:v")})) (retract ?f))')
    if isinstance(act, k.Assign):
        return (f'(bind ?new {expression(act.expr)}) (do-for-all-facts ((?f val)) (eq ?f:a "{act.target}") '
                f'(retract ?f)) (assert (val (a "{act.target}") (v ?new)))')
    return ""  # external calls do nothing in the benchmark


def program(base: k.Base) -> list[str]:
    constructs = ["(deftemplate val (slot a) (slot v))",
                  '(deffunction value-of (?a) (bind ?r nil) (do-for-fact ((?f val)) (eq ?f:a ?a) (bind ?r ?f:v)) ?r)']
    for i, rule in enumerate(base.rules):
        name = f"rule{i}"
        if rule.kind == "else":
            continue
        body = " ".join(action(a) for a in rule.actions)
        if rule.kind == "impossible":
            body = "(assert (impossible)) (halt)"
        constructs.append(f"(defrule {name} {holds(rule.condition) if rule.condition else ''} "
                          f"(not (fired {name})) => (assert (fired {name})) {body})")
    outputs = base.outputs
    for i, rule in enumerate(r for r in base.rules if r.kind == "else"):
        undetermined = " ".join(f'(and (val (a "{o}") (v ?x{j})) (val (a "{o}") (v ~?x{j})))'
                                for j, o in enumerate(outputs))
        constructs.append(f"(defrule else{i} (declare (salience -10)) (or {undetermined}) (not (fired else{i})) => "
                          f"(assert (fired else{i})) {' '.join(action(a) for a in rule.actions)})")
    params = " ".join(f"?i{j}" for j in range(len(base.inputs)))
    asserts = " ".join(f'(assert (val (a "{name}") (v ?i{j})))' for j, name in enumerate(base.inputs))
    unknowns = " ".join(f'(assert (val (a "{name}") (v {literal(v)})))'
                        for name, attr in base.attributes.items() if name not in base.inputs for v in attr.values)
    collect = " ".join(
        f'(bind ?n 0) (bind ?x "?") (do-for-all-facts ((?f val)) (eq ?f:a "{o}") (bind ?n (+ ?n 1)) (bind ?x ?f:v)) '
        f'(if (<> ?n 1) then (bind ?x "?")) (bind ?out (str-cat ?out "|" ?x))' for o in outputs)
    constructs.append(f'(deffunction cycle ({params}) (reset) {asserts} {unknowns} (run) '
                      f'(bind ?out "") {collect} ?out)')
    return constructs


def call(base: k.Base, inputs: dict[str, Any]) -> str:
    """The CLIPS expression running one cycle on these inputs."""
    args = " ".join(literal(base.element(n, inputs[n]) if base.attributes[n].kind != "number" else inputs[n])
                    for n in base.inputs)
    return f"(cycle {args})"


def expected(base: k.Base, inputs: dict[str, Any]) -> str:
    """What `cycle` returns for these inputs, computed by the reference interpreter."""
    outcome = k.interpret(base, inputs)
    shown = []
    for o in base.outputs:
        value = outcome.outputs.get(o)
        if value is None:
            shown.append("?")
        elif isinstance(value, k.Piece):
            shown.append(repr(float(value.sample())))
        elif isinstance(value, bool):
            shown.append("TRUE" if value else "FALSE")
        else:
            shown.append(str(value))
    return "|" + "|".join(shown)
