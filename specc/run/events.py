"""The event log of a run: one JSON object per line (JSONL), stamped with simulated time.

    with EventLog("hunt.jsonl") as log:
        log.emit(12.5, "reply", service="SEARCH-OBJ", id=312, result=1)
    read_events("hunt.jsonl")   # [{"t": 12.5, "kind": "reply", "service": "SEARCH-OBJ", ...}]

Every event has `t`, the simulated time in seconds (rounded to the microsecond), and `kind`; the
other keys depend on the kind. The log is deterministic: keys sorted, floats as Python writes
them (shortest round-trip form), no wall-clock time anywhere, so one seed gives one file. Events
stay in memory too (`EventLog.events`), exactly as `read_events` gives them back.

Kinds written by the runners (a runner may add its own; a reader ignores the kinds it does not
know):

| kind | when | fields |
| --- | --- | --- |
| `mission-start` | the run begins | what was asked (`seed`, `goals`, ...), `body`, `objects`, `world_data` (*) |
| `goal` | a goal is posted to the supervisor, and when it ends | `goal`, `status` (posted, succeeded, failed) |
| `request` | the task level asks the executive for a service (RQST EXEC, §3.9) | `service`, `id`, `request` |
| `activity` | an executive activity changes phase (Fig 3.3; WAIT→INIT is its start) | `service`, `id`, `from`, `to` |
| `reply` | the executive answers `(REPLY id result)` | `service`, `id`, `result`, `detail`, `ok` (it succeeded) |
| `warning` | the executive sends `(WARNING service id type)` | `service`, `id`, `type`, `detail` |
| `reflex` | a reflex of the executive fires (§3.5) | `reflex`, `on` (trigger, source), `code`, `actions` |
| `fact` | a fact of the supervisor's database is concluded or retracted | `fact`, `change` |
| `operator` | a procedure tells the operator something (WARN-OPERATOR) | `text` |
| `robot-motion` | the robot starts or stops moving (true motion, from the simulator) | `moving`, `x`, `y`, `theta` |
| `arm-motion` | the arm starts or stops moving | `moving`, `service` (the service whose codel moved it) |
| `pose` | every 0.5 s of simulated time | `x`, `y`, `theta`: the robot's true pose |
| `alarm` | trouble the procedures miss (robot blocked, executive ERROR, a codel that raised...) | `what`, `detail` |
| `mission-end` | the run ends | `outcome` (succeeded, failed, horizon), `why`, and the run's figures |

A robot's extension (`specc.run.mission`) may log kinds of its own; these are drawn on the map:

| kind | what | fields |
| --- | --- | --- |
| `object-detected` | a sensor sees one of mission-start's `objects` for the first time | `object`, `x`, `y` |
| `object-retrieved` | the robot goes for an object | `object`, `x`, `y` (null: none there), ... |
| `object-taken` | the object is on the robot | `object`, `x`, `y`, `taken` |
| `trajectory` | a trajectory is planned | `service`, `points` ([x, y] ...) |
| `model` | a model with certainty cells (seed 000's Fig 5.11) | `goal` ([x, y] or null), `certainty` (**) |
| `mark` | something worth a marker on the path | `label`, `at` (a time of the run) |

(*) the world whole, as `specc.runtime.sim.parse_world` reads it, so a log can be redrawn alone.
(**) `cell`, `nx`, `ny` and `values`, the certainty per cell row by row from (0, 0).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import IO, Any

from specc.run import RunError

RESERVED = ("t", "kind")  # every event's own keys: no field may take their names
TIME_DIGITS = 6  # simulated time is written to the microsecond


# One encoder for every line: json.dumps makes a new one at each call given these options.
_ENCODER = json.JSONEncoder(sort_keys=True, separators=(",", ":"), allow_nan=False, ensure_ascii=False)


def encode(event: dict[str, Any]) -> str:
    """One event as its line of the log (without the newline)."""
    return _ENCODER.encode(event)


class EventLog:
    """Events in memory, and written to `path` as they come when a path is given."""

    def __init__(self, path: str | Path | None = None) -> None:
        self.path = Path(path) if path is not None else None
        self.events: list[dict[str, Any]] = []
        self._file: IO[str] | None = None
        self._closed = False
        if self.path is not None:
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self._file = self.path.open("w", encoding="utf-8", newline="\n")
            except OSError as error:
                raise RunError(f"{self.path}: cannot write the event log ({error.strerror or error})") from None

    def emit(self, time: float, kind: str, **fields: Any) -> dict[str, Any]:
        """Record one event at simulated time `time`; returns it as the log holds it."""
        if self._closed:
            raise RunError(f"event '{kind}' at {time} s: the event log is closed")
        if not isinstance(kind, str) or not kind:
            raise RunError(f"an event's kind must be a non-empty string, not {kind!r}")
        if not isinstance(time, int | float) or isinstance(time, bool) or not math.isfinite(time):
            raise RunError(f"event '{kind}': its time must be a finite number of seconds, not {time!r}")
        clash = [name for name in RESERVED if name in fields]
        if clash:
            raise RunError(f"event '{kind}': field '{clash[0]}' is reserved (every event has t and kind)")
        try:
            line = encode({"t": round(float(time), TIME_DIGITS), "kind": kind, **fields})
        except (TypeError, ValueError) as error:
            raise RunError(f"event '{kind}' at {time} s cannot be written as JSON: {error}") from None
        # What the log holds is what a reader gets back: tuples become lists, keys strings.
        event: dict[str, Any] = json.loads(line)
        self.events.append(event)
        if self._file is not None:
            self._file.write(line + "\n")
        return event

    def of_kind(self, *kinds: str) -> list[dict[str, Any]]:
        """The events of these kinds, in order."""
        return [e for e in self.events if e["kind"] in kinds]

    def close(self) -> None:
        """Flush and close the file (the events stay in memory); closing twice is harmless."""
        self._closed = True
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> EventLog:
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.close()


def reply_succeeded(reply: Mapping[str, Any]) -> bool:
    """Whether a `reply` event says its service succeeded: its `ok`, as the executive said it.

    A service's output function may return any word, so the result alone cannot tell a success
    from a failure; a log written before replies carried `ok` leaves only the result to go by
    (OK or a number, as an output function counting something returns, is then taken for one)."""
    if "ok" in reply:
        return bool(reply["ok"])
    result = reply.get("result")
    return result == "OK" or (isinstance(result, int | float) and not isinstance(result, bool))


def read_events(path: str | Path, notes: list[str] | None = None) -> list[dict[str, Any]]:
    """The events of a log file, in order (blank lines are skipped). With `notes`, a last line
    cut off (no newline after it: a run killed while writing it) is left out and said there,
    instead of refusing the whole log."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise RunError(f"{path}: cannot read the event log ({error.strerror or error})") from None
    except UnicodeDecodeError:
        raise RunError(f"{path}: not an event log (not UTF-8 text)") from None
    events: list[dict[str, Any]] = []
    lines = text.splitlines()
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            event = json.loads(line)
        except json.JSONDecodeError as error:
            if notes is not None and number == len(lines) and not text.endswith("\n"):
                notes.append(f"{path}:{number}: the last line is cut off (the run was killed while writing it): "
                             f"the {len(events)} event(s) before it are kept")
                break
            raise RunError(f"{path}:{number}: not a JSON event ({error.msg})") from None
        if not isinstance(event, dict) or not isinstance(event.get("kind"), str) \
                or not isinstance(event.get("t"), int | float):
            raise RunError(f"{path}:{number}: an event must be a JSON object with a time 't' and a 'kind'")
        events.append(event)
    return events
