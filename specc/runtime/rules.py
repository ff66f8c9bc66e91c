"""What generated decision functions (compiled Kheops rule bases) share at run time."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from typing import Any, NamedTuple

from specc.runtime.hints import did_you_mean


class Decision(NamedTuple):
    """The outcome of one deduction cycle: the outputs (None when undetermined) and what went wrong."""

    outputs: Mapping[str, Any]
    inconsistent: tuple[str, ...] = ()  # attributes the rules left without a possible value
    incomplete: tuple[str, ...] = ()  # outputs the rules left undetermined
    impossible: str | None = None  # the `impossible` rule matching these inputs

    @property
    def ok(self) -> bool:
        return not (self.inconsistent or self.incomplete or self.impossible)

    def keeping(self, kept: tuple[str, ...], inputs: Mapping[str, Any],
                initial: Mapping[str, Any] | None = None) -> Decision:
        """This decision with the outputs it left as they were at their previous-cycle value
        (`@name`; its `init`, in `initial`, when the inputs leave it out)."""
        outputs = dict(self.outputs)  # a fresh mapping for each call: the leaf's own stays shared and read-only
        for name in kept:
            previous = "@" + name
            outputs[name] = inputs[previous] if initial is None or previous in inputs else initial[previous]
        return Decision(outputs, self.inconsistent, self.incomplete, self.impossible)


Calls = Callable[[str, tuple[Any, ...]], object]


def no_calls(function: str, args: tuple[Any, ...]) -> None:
    """The default for `do {f(...)}` actions: nothing to call."""


class MissingInput(KeyError):
    """A decision asked for an input its caller did not give (a KeyError, said in words)."""

    def __str__(self) -> str:
        return str(self.args[0])


def check_inputs(names: Iterable[str], inputs: Mapping[str, Any], error: KeyError) -> None:
    """After a decision raised `error`: MissingInput naming the input it needed and the caller
    left out (with the closest key given, a misspelt one), if that is the cause; else nothing."""
    needed = error.args[0] if error.args else None
    known = list(names)
    if needed in known and needed not in inputs:
        unknown = [str(k) for k in inputs if k not in known]
        raise MissingInput(f"the decision needs input '{needed}'{did_you_mean(str(needed), unknown)}; its inputs: "
                           f"{', '.join(known)}") from None


def check_numbers(numeric: Iterable[str], inputs: Mapping[str, Any], error: TypeError) -> None:
    """After a decision raised `error`: a TypeError naming the numeric input given something other
    than a number (`soc='50'`), if one was; else nothing (the caller raises `error` itself)."""
    for name in numeric:
        if name not in inputs:
            continue  # the decision did not read it (else KeyError): not the cause
        value = inputs[name]
        if not isinstance(value, (int, float)):  # a bool is a number to Python: True compares as 1
            raise TypeError(f"input {name}={value!r}: give a number ({error})") from None


def divide(left: float, right: float) -> float:
    if right:
        return left / right
    return math.copysign(math.inf, left) if left else 0.0
