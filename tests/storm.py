"""A seeded storm of task-level events on Hilare's executive driving its real modules: random
requests (at most six outstanding), interruptions and simulated time, the ZOMBIEs acknowledged.
Shared by the executive's test (no ERROR, one final reply per request) and `make bench` (its
cycle times)."""

from __future__ import annotations

import random
import sys
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from specc.runtime import executive as rx
from specc.runtime import functional as rt
from tests.conftest import EXAMPLES, ROOT

OUTSTANDING = 6


@dataclass
class Storm:
    registry: rt.Registry
    executive: rx.Executive
    controller: Any  # the generated resource controller module
    finals: Counter[int] = field(default_factory=Counter)  # request id -> final replies heard
    requests: int = 0


def hilare_executive() -> Storm:
    for path in (str(ROOT / "generated"), str(EXAMPLES / "hilare")):
        if path not in sys.path:
            sys.path.insert(0, path)
    from hilare import modules  # type: ignore[import-not-found]
    from hilare.executive import hilare, hilare_resource_controller  # type: ignore[import-not-found]

    registry = rt.Registry()
    modules.create_all(registry)
    executive = hilare.create(registry, world=str(EXAMPLES / "hilare" / "worlds" / "room.toml"), measure=True)
    storm = Storm(registry, executive, hilare_resource_controller)

    def count(message: rx.Message) -> None:
        if message.kind == "REPLY":
            storm.finals[message.id] += 1

    executive.listeners.append(count)
    return storm


def blow(storm: Storm, cycles: int, seed: int = 11) -> None:
    """Drive the executive until it has run `cycles` cycles."""
    executive, kernel = storm.executive, storm.registry.kernel
    services = list(executive.spec.services)
    rng = random.Random(seed)
    while len(executive.cycle_durations) < cycles:
        roll = rng.random()
        if roll < 0.45 and len(executive.activities) < OUTSTANDING:
            storm.requests += 1
            executive.request(rng.choice(services), storm.requests)
        elif roll < 0.6 and executive.activities:
            executive.interrupt(rng.choice(list(executive.activities)))
        else:
            kernel.run_for(rng.choice([0.001, 0.01, 0.1, 1.0]))
        for activity in list(executive.activities.values()):  # the task level acknowledges ZOMBIEs
            if activity.state is rx.Phase.ZOMBIE:
                executive.interrupt(activity.id)
