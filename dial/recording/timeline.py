"""A run's timeline as text, from its log records: for ``dial replay`` and the recording's log.

Pure functions of the records (JSON objects of ``--log``); no MuJoCo, no rerun.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from dial.errors import DialError
from dial.recording.lanes import LogRecord, lane_key

BAD_OUTCOMES = {"missed": "warn", "timeout": "error", "error": "error"}


_NUM = (int, float)
# The fields every reader of a record relies on, with their types (docs/recording.md); a
# record of a kind not listed here is kept as it is (a newer dial's, say).
FIELDS: dict[str, dict[str, type | tuple[type, ...]]] = {
    "scene": {"scene": str},
    "start": {"event": str, "line": int, "tick": int, "t": _NUM},
    "end": {"event": str, "line": int, "tick": int, "t": _NUM, "outcome": str},
    "tick": {"tick": int, "t0": _NUM, "t1": _NUM, "stretch": int},
    "condition": {"condition": str, "value": bool, "tick": int, "t": _NUM},
    "call": {"script": str, "tick": int, "t": _NUM},
    "block": {"number": int, "line": int, "tick": int, "t": _NUM},
    "monitor": {"event": str, "condition": str, "line": int, "tick": int, "t": _NUM},
    "contact": {"effector": str, "sensor": str, "finger": str, "value": _NUM, "t": _NUM},
    "thread": {"name": str, "t": _NUM},
    "disturb": {"what": str, "phase": str, "t": _NUM},
    "warning": {"message": str, "t": _NUM},
    "error": {"message": str, "tick": int, "t": _NUM},
    "interrupted": {"tick": int, "t": _NUM},
    "state": {"tick": int, "t": _NUM, "qpos": list, "tension": list},
    "belief": {"object": str, "why": str, "before": dict, "after": dict, "t": _NUM},
    "world": {"objects": dict, "t": _NUM},
    "summary": {"sim_time": _NUM, "success": dict, "criteria": dict},
}


def _checked(record: object, path: Path, n: int) -> dict[str, Any]:
    if not isinstance(record, dict) or not isinstance(record.get("kind"), str):
        raise DialError(f"{path}:{n}: not a dial log record (no 'kind')")
    if n == 1 and record["kind"] != "scene":
        raise DialError(f"{path}: not a dial run log (it must start with a 'scene' record)")
    for key, kind in FIELDS.get(record["kind"], {}).items():
        value = record.get(key)
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
            raise DialError(
                f"{path}:{n}: this '{record['kind']}' record needs '{key}' as "
                f"{_names(kind)}, got {json.dumps(value)[:40]}"
            )
    return record


def _names(kind: type | tuple[type, ...]) -> str:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return " or ".join(
        {
            "int": "an integer",
            "float": "a number",
            "str": "a string",
            "bool": "true or false",
            "list": "a list",
            "dict": "an object",
        }[k.__name__]
        for k in kinds
    )


def read_log(path: Path) -> list[dict[str, Any]]:
    """The records of a ``--log`` file; a torn last line (a crash mid-write) is dropped."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as e:
        raise DialError(f"cannot read the log '{path}': {e.strerror}") from e
    except UnicodeDecodeError:
        raise DialError(f"{path}: not a dial run log (not UTF-8 text)") from None
    records = []
    for n, line in enumerate(lines, 1):
        try:
            record = json.loads(line)
        except json.JSONDecodeError as e:
            if n == len(lines):
                break
            raise DialError(f"{path}:{n}: not a JSON log record ({e.msg})") from e
        records.append(_checked(record, path, n))
    if not records or records[0]["kind"] != "scene":
        raise DialError(f"{path}: not a dial run log (it must start with a 'scene' record)")
    return records


def when(record: LogRecord, tick: int) -> tuple[float, int]:
    """A record's simulated time (s) and tick; ``tick`` (the latest seen) if it has none.

    (A ``summary`` holds the run's end time and the tick *length*, not a tick.)
    """
    if record["kind"] == "summary":
        return float(record.get("sim_time", 0.0)), tick
    t = record.get("t", record.get("t1", 0.0))
    return float(t), int(record.get("tick", tick))


def qualified_event(record: LogRecord) -> str:
    """The event of a ``start`` or ``end`` record; a called script's events carry that
    script's name (``explore_surface.reach``), since event names repeat across scripts."""
    return ".".join(lane_key(record))


def describe(record: LogRecord) -> tuple[str, str] | None:
    """A record as one line of text and a level (info, warn, error); None for bookkeeping."""
    kind = record["kind"]
    if kind == "scene":
        mm = 1000.0 * math.hypot(*record.get("perturb", [0.0]))
        return (
            f"scene {record['scene']} ({record.get('world', '?')}), seed {record.get('seed')}, "
            f"objects perturbed {mm:.1f} mm",
            "info",
        )
    if kind == "start":
        return f"start {qualified_event(record)} (line {record['line']})", "info"
    if kind == "end":
        outcome = record["outcome"]
        note = f": {record['message']}" if record.get("message") else ""
        return f"end   {qualified_event(record)} {outcome}{note}", BAD_OUTCOMES.get(outcome, "info")
    if kind == "tick":
        if not record.get("stretch"):
            return None
        return f"tick {record['tick']} stretched by {record['stretch']} control periods", "info"
    if kind == "condition":
        where = f" (in {Path(record['script']).name})" if record.get("script") else ""
        return f"condition {record['condition']} is {str(record['value']).lower()}{where}", "info"
    if kind == "call":
        return f"call {record['script']}", "info"
    if kind == "block":
        where = f" of {Path(record['script']).name}" if record.get("script") else ""
        return f"block {record['number']} (line {record['line']}{where})", "info"
    if kind == "contact":
        return (
            f"contact: {record['sensor']} on the {record['finger']} stopped the "
            f"{record['effector']} ({record['value']:g})",
            "info",
        )
    if kind == "thread":
        return f"thread {record['name']} released", "info"
    if kind == "belief":
        return _belief(record), "info"
    if kind == "monitor":
        return f"monitor '@on {record['condition']}' (line {record['line']}) fired", "warn"
    if kind == "disturb":
        return f"disturbance {record['phase']}s: {record['what']}", "warn"
    if kind in ("warning", "error"):
        return str(record["message"]), "warn" if kind == "warning" else "error"
    if kind == "interrupted":
        why = f" by {record['signal']}" if record.get("signal") else ""
        return f"interrupted{why}; every effector holds its pose", "error"
    if kind == "resume":
        return f"resumed from {record['file']} at block {record['block']}", "info"
    if kind == "summary":
        criteria = record.get("criteria", {})
        marks = "; ".join(
            f"[{'x' if ok else ' '}] {name}: {criteria.get(name, '')}"
            for name, ok in record.get("success", {}).items()
        )
        verdict = "OK" if record.get("ok") else "FAILED"
        return f"{verdict} {marks}".rstrip(), "info" if record.get("ok") else "error"
    return None


def _belief(record: LogRecord) -> str:
    """A ``belief`` record: which object the world model changed, why, and how far it moved."""
    before, after = record["before"].get("pos"), record["after"].get("pos")
    moved = ""
    if isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        moved = f", moved {1000.0 * math.dist(before, after):.1f} mm"
    return f"world model: {record['object']} {record['why']}{moved}"


def timeline(records: Iterable[LogRecord]) -> str:
    """The run's timeline: one line per event start, end, contact, condition and message."""
    lines = [f"{'tick':>5}  {'t (s)':>8}  what"]
    tick = 0
    for record in records:
        t, tick = when(record, tick)
        described = describe(record)
        if described is not None:
            lines.append(f"{tick:5d}  {t:8.3f}  {described[0]}")
    return "\n".join(lines) + "\n"
