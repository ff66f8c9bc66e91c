"""IxTeT expressions as the planner's model holds them (`specc.runtime.planner.model`): names,
?variables and numbers, constant arithmetic folded (`-3` and `0 -. 3.0` alike, the dotted
operators written plainly). One lowering, used by the checks (an FTplan rule's arguments must be
constants or ?variables) and by the analyses (`specc.analysis.planning.Lowering` lowers every
expression of a planning model through it)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping

from specc.model import nodes as m
from specc.runtime.ftplan import config as fc
from specc.runtime.planner import model as pm


class UnknownFunction(ValueError):
    """A call of a function the planner does not have (`specc check` reports it as such)."""


def lowered(e: m.IxExpr, timepoints: Collection[str] = (), arguments: Mapping[str, pm.Expr] | None = None,
            renames: Mapping[str, str] | None = None) -> pm.Expr:
    """`e` with names read as `timepoints` (else symbols), macro parameters replaced by their
    `arguments`, macro variables renamed; UnknownFunction for a function the planner lacks."""
    arguments = arguments or {}
    renames = renames or {}

    def lower(e: m.IxExpr) -> pm.Expr:
        if isinstance(e, m.Number):
            return pm.Num(float(e.value))
        if isinstance(e, m.Infinity):
            return pm.Num(pm.INF)
        if isinstance(e, m.IxVar):
            return pm.Var(renames.get(e.name, e.name))
        if isinstance(e, m.IxName):
            if e.name in arguments:
                return arguments[e.name]
            return pm.Time(e.name) if e.name in timepoints else pm.Sym(e.name)
        if isinstance(e, m.IxCall):
            if e.function not in pm.FUNCTIONS:
                raise UnknownFunction(f"unknown function '{e.function}'")
            return pm.Op(e.function, tuple(lower(a) for a in e.args))
        if isinstance(e, m.IxUnary):
            inner = lower(e.operand)
            if e.op == "+":
                return inner
            return pm.Num(-inner.value) if isinstance(inner, pm.Num) else pm.Op("neg", (inner,))
        left, right = lower(e.left), lower(e.right)
        op = e.op.rstrip(".")
        if isinstance(left, pm.Num) and isinstance(right, pm.Num):
            folded = pm.fold(op, left.value, right.value)
            if folded is not None:
                return pm.Num(folded)
        return pm.Op(op, (left, right))

    return lower(e)


class NotConstant(ValueError):
    """An argument of an FTplan analyzer or state rule that is neither a ?variable nor a constant."""


def _constant(e: m.IxExpr) -> pm.Expr | None:
    try:
        return lowered(e)
    except UnknownFunction:
        return None


def term(e: m.IxExpr) -> fc.Term:
    """An FTplan rule argument: a ?variable, a symbol, or a number."""
    value = _constant(e)
    if isinstance(value, pm.Var):
        return fc.Var(value.name)
    if isinstance(value, pm.Sym):
        return value.name
    if isinstance(value, pm.Num) and math.isfinite(value.value):
        return value.value
    raise NotConstant("a rule argument is a ?variable, a symbol or a number")


def bound(e: m.IxExpr) -> float:
    """An interval's bound: a number, `-oo` or `+oo`."""
    value = _constant(e)
    if isinstance(value, pm.Num):
        return float(value.value)
    raise NotConstant("an interval's bounds are numbers")
