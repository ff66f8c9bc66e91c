"""The hint a message gives for a misspelt name, shared by the compiler's diagnostics and the
runtime's errors (a codel's misspelt device or SDI field, a body key)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """' (did you mean 'X'?)' when a close candidate exists, else ''."""
    pool = sorted(set(candidates))
    match = difflib.get_close_matches(name, pool, n=1, cutoff=0.6)
    if not match:
        lowered = {c.lower(): c for c in pool}
        if name.lower() in lowered:
            match = [lowered[name.lower()]]
    return f" (did you mean '{match[0]}'?)" if match else ""
