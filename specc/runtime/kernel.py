"""The event kernel: one clock for every delay, period and timeout in a specc robot.

Simulated time (the default) jumps from event to event, so a run is deterministic and far
faster than real time; `WallClock` paces the same events on the real clock for demonstrations.
Events at the same instant run by (priority, order of scheduling): lower priority numbers first.
"""

from __future__ import annotations

import heapq
import itertools
import time
from collections.abc import Callable
from typing import Any


class Clock:
    """Simulated time: waiting costs nothing."""

    def wait_until(self, instant: float, now: float) -> None:
        del instant, now


class WallClock(Clock):
    """Real time: the kernel sleeps until each event is due (scaled by `speed`)."""

    def __init__(self, speed: float = 1.0):
        self.speed = speed
        self._origin: tuple[float, float] | None = None

    def wait_until(self, instant: float, now: float) -> None:
        if self._origin is None:
            self._origin = (time.monotonic(), now)
        real_start, sim_start = self._origin
        delay = real_start + (instant - sim_start) / self.speed - time.monotonic()
        if delay > 0:
            time.sleep(delay)


class Timer:
    """A scheduled event that can be cancelled before it fires (the queue holds it itself)."""

    __slots__ = ("when", "action", "cancelled")

    def __init__(self, when: float, action: Callable[[], Any]) -> None:
        self.when = when
        self.action = action
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class Kernel:
    def __init__(self, clock: Clock | None = None, start: float = 0.0):
        self.clock = clock or Clock()
        self.now = start
        # (when, priority, order, timer): tuples compare in C, several times faster than a
        # dataclass's generated ordering, which weighed on a simulated robot's every step.
        self._queue: list[tuple[float, int, int, Timer]] = []
        self._order = itertools.count()

    def call_at(self, when: float, action: Callable[[], Any], priority: int = 0) -> Timer:
        if when < self.now:
            when = self.now
        timer = Timer(when, action)
        heapq.heappush(self._queue, (when, priority, next(self._order), timer))
        return timer

    def call_later(self, delay: float, action: Callable[[], Any], priority: int = 0) -> Timer:
        return self.call_at(self.now + max(delay, 0.0), action, priority)

    def call_every(self, period: float, action: Callable[[], Any], priority: int = 0) -> None:
        """Call `action` at now + k * period (k = 1, 2, ...) for as long as the kernel runs. The
        instants are computed from the origin, rounded to the nanosecond as the exec tasks' ticks
        are, so no rounding drift accumulates or reorders grids of the same period; the next call
        is scheduled after `action` has run, as a task rescheduling itself would."""
        origin = self.now
        calls = 0

        def tick() -> None:
            nonlocal calls
            calls += 1
            action()
            self.call_at(round(origin + (calls + 1) * period, 9), tick, priority)

        self.call_at(round(origin + period, 9), tick, priority)

    def step(self) -> bool:
        """Run the next event; False when nothing is scheduled."""
        if self.next_time() is None:
            return False
        self._fire(heapq.heappop(self._queue)[3])
        return True

    def _fire(self, timer: Timer) -> None:
        self.clock.wait_until(timer.when, self.now)
        self.now = timer.when
        timer.action()

    def next_time(self) -> float | None:
        """When the next event is due (cancelled ones are dropped); None when nothing is scheduled."""
        queue = self._queue
        while queue and queue[0][3].cancelled:
            heapq.heappop(queue)
        return queue[0][0] if queue else None

    def run_until(self, instant: float) -> None:
        """Run every event due at or before `instant`, then set the clock to `instant`."""
        while True:
            upcoming = self.next_time()
            if upcoming is None or upcoming > instant:
                break
            self._fire(heapq.heappop(self._queue)[3])  # the one next_time found
        if instant > self.now:
            self.clock.wait_until(instant, self.now)
            self.now = instant

    def run_for(self, duration: float) -> None:
        self.run_until(self.now + duration)

    def run_while(self, condition: Callable[[], bool], deadline: float) -> bool:
        """Run events while `condition()` holds and time stays within `deadline`.

        Returns True when the condition became false (what was awaited happened)."""
        queue = self._queue
        while condition():
            upcoming = self.next_time()
            if upcoming is None or upcoming > deadline:
                if deadline != float("inf") and deadline > self.now:
                    self.run_until(deadline)
                return not condition()
            self._fire(heapq.heappop(queue)[3])  # the one next_time found
        return True
