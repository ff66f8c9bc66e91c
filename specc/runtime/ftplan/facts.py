"""What FTplan's facts are made of: a fact's key, the bindings of a rule's ?variables, and the
matching of a rule's terms against a report's values.

FTplan's state (`state`) and a planner's vocabulary (`view`) both speak these; they live below
both so that the state can write its changes through a view without the view importing the state.
"""

from __future__ import annotations

from collections.abc import Mapping

from specc.runtime.ftplan.config import Term, Value, Var
from specc.runtime.planner.validate import normalise, same

FactKey = tuple[str, tuple[Value, ...]]
Bindings = dict[str, Value]


def match(terms: tuple[Term, ...], values: tuple[Value, ...], bindings: Bindings | None = None) -> Bindings | None:
    """The bindings that make `terms` read `values` (extending `bindings`), or None."""
    if len(terms) != len(values):
        return None
    found: Bindings = dict(bindings or {})
    for term, value in zip(terms, values, strict=True):
        value = normalise(value)
        if isinstance(term, Var):
            bound = found.get(term.name)
            if bound is None:
                found[term.name] = value
            elif not same(bound, value):
                return None
        elif not same(normalise(term), value):
            return None
    return found


def substitute(term: Term, bindings: Mapping[str, Value]) -> Value:
    if isinstance(term, Var):
        if term.name not in bindings:
            raise KeyError(f"{term.name} is not bound by the rule's task or report")
        return bindings[term.name]
    return normalise(term)
