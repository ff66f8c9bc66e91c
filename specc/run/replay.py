"""`specc replay RUN`: a run's event log played back as readable lines, and its pictures drawn
again from the log alone (`specc.run.render`).

    folder, events = load_run(Path("runs/tug-shuttle-hall-Robot1-2-s0"))
    for event in select(events, kinds=("action", "ftplan")):
        print(describe(event))
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

from specc.run import RunError
from specc.run.events import read_events
from specc.run.session import LOG

QUIET_KINDS = ("pose",)  # sampled at 2 Hz: shown only when asked for by name


def load_run(run: Path, notes: list[str] | None = None) -> tuple[Path, list[dict[str, Any]]]:
    """The run folder and its events, from the folder or from its events.jsonl (`notes`: see
    `read_events`)."""
    if run.is_dir():
        folder, log = run, run / LOG
        if not log.is_file():
            raise RunError(f"'{run}' holds no {LOG}: give a run folder `specc run` wrote, or an event log")
    elif run.is_file():
        folder, log = run.parent, run
    else:
        raise RunError(f"no run folder or event log '{run}': give a folder `specc run` wrote (runs/...)")
    events = read_events(log, notes)
    if not events:
        raise RunError(f"{log}: the log is empty (the run stopped before its first event)")
    return folder, events


def check_kinds(events: Iterable[Mapping[str, Any]], kinds: Sequence[str]) -> str | None:
    """The kinds asked for that the log lacks: RunError naming the kinds it has when it has none
    of them (a typo, or the wrong run); a note to print when it has some (a run without actions
    asked for its actions and its FTplan events shows the latter)."""
    present = sorted({str(e["kind"]) for e in events})
    missing = [k for k in dict.fromkeys(kinds) if k not in present]
    if not missing:
        return None
    said = f"no event of kind {', '.join(repr(k) for k in missing)} in this log (it has: {', '.join(present)})"
    if set(missing) == set(kinds):
        raise RunError(said)
    return said


def select(events: Iterable[Mapping[str, Any]], kinds: Sequence[str] = (), start: float | None = None,
           end: float | None = None) -> Iterator[Mapping[str, Any]]:
    """The events of `kinds` (default: every kind but the pose samples) between `start` and `end`."""
    for event in events:
        if kinds and event["kind"] not in kinds:
            continue
        if not kinds and event["kind"] in QUIET_KINDS:
            continue
        if start is not None and event["t"] < start:
            continue
        if end is not None and event["t"] > end:
            continue
        yield event


def describe(event: Mapping[str, Any]) -> str:
    """One line for a person: the time, the kind, then what matters for that kind."""
    kind = event["kind"]
    fields = {k: v for k, v in event.items() if k not in ("t", "kind")}
    text = _DESCRIBERS.get(kind, _generic)(fields)
    return f"{event['t']:10.3f}  {kind:<16} {text}"


def _generic(fields: Mapping[str, Any]) -> str:
    return " ".join(f"{k}={_short(v)}" for k, v in sorted(fields.items()))


def _short(value: Any, limit: int = 60) -> str:
    text = str(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _mission_start(f: Mapping[str, Any]) -> str:
    shown = {k: v for k, v in f.items() if k not in ("world_data", "objects", "targets", "windows")}
    return _generic(shown)


def _action(f: Mapping[str, Any]) -> str:
    args = ", ".join(str(a) for a in f.get("args", ()))
    why = f" ({f['why']})" if f.get("why") else ""
    return f"{f.get('status')} {f.get('task')}({args}) [plan {f.get('plan')}, {f.get('id')}]{why}"


def _ftplan(f: Mapping[str, Any]) -> str:
    planner = f"{f['planner']}: " if f.get("planner") else ""
    return f"{f.get('event')}: {planner}{f.get('text')}"


def _reply(f: Mapping[str, Any]) -> str:
    detail = f" ({f['detail']})" if f.get("detail") else ""
    return f"{f.get('service')} #{f.get('id')} -> {f.get('result')}{detail}"


def _mission_end(f: Mapping[str, Any]) -> str:
    return f"{f.get('outcome')}: {f.get('why')}"


_DESCRIBERS = {"mission-start": _mission_start, "action": _action, "ftplan": _ftplan, "reply": _reply,
               "mission-end": _mission_end,
               "request": lambda f: f"{f.get('service')} #{f.get('id')}",
               "activity": lambda f: f"{f.get('service')} #{f.get('id')} {f.get('from')} -> {f.get('to')}",
               "fact": lambda f: f"{f.get('change')} {f.get('fact')}",
               "reflex": lambda f: f"{f.get('reflex')} on {f.get('on')} {f.get('code')}: "
                                   + ", ".join(f.get("actions") or ()),
               "operator": lambda f: str(f.get("text")),
               "alarm": lambda f: f"{f.get('what')}: {f.get('detail')}",
               "trajectory": lambda f: f"{f.get('service')}: {len(f.get('points') or ())} points",
               "model": lambda f: f"goal {f.get('goal')}"}
