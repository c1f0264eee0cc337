"""The event log: JSON Lines records, written and flushed as the run goes.

Records hold simulated time and ticks only (no wall-clock time, but in the summary), so the
same run gives the same bytes. Floats are rounded to fixed precision so that the text does
not depend on the last bits of a sum, and a non-finite float is written as null: the log
is strict JSON.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import IO

from dial.errors import DialError

DIGITS = 6

Record = dict[str, object]


class LogError(DialError):
    """The log file could not be written (disk full, file system gone read-only...)."""


def _float(value: float) -> float | None:
    if not math.isfinite(value):
        return None
    return round(value, DIGITS) + 0.0  # +0.0 turns -0.0 into 0.0


def clean(value: object) -> object:
    """``value`` as JSON-able data: rounded finite floats, lists for tuples and arrays."""
    kind = type(value)
    if kind is int or kind is str or kind is bool or value is None:
        return value
    if isinstance(value, float):
        return _float(value)
    if isinstance(value, Mapping):
        return {str(k): clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [clean(v) for v in value]
    tolist = getattr(value, "tolist", None)  # numpy arrays and scalars
    if tolist is not None:
        return clean(tolist())
    return str(value)


class EventLog:
    """Collects records in order; optionally writes each as a JSON line and flushes it."""

    def __init__(self, sink: IO[str] | None = None, name: str = "the log") -> None:
        self.records: list[Record] = []
        self._sink = sink
        self._name = name

    def write(self, kind: str, /, **fields: object) -> Record:
        """Append a record of ``kind``; its fields are cleaned (:func:`clean`)."""
        record: Record = {"kind": kind}
        for key, value in fields.items():
            kind_of = type(value)
            if kind_of is float:
                record[key] = _float(value)  # type: ignore[arg-type]
            elif kind_of is int or kind_of is str or kind_of is bool or value is None:
                record[key] = value
            else:
                record[key] = clean(value)
        return self.append(record)

    def append(self, record: Record) -> Record:
        """Append a record whose values are clean already (the runner's hot records)."""
        self.records.append(record)
        if self._sink is not None:
            try:
                self._sink.write(json.dumps(record, separators=(",", ":")) + "\n")
                self._sink.flush()
            except OSError as e:
                self._sink = None  # nothing more can be written; the run stops cleanly
                raise LogError(f"cannot write {self._name}: {e.strerror or e}") from None
        return record

    def of(self, kind: str) -> list[Record]:
        return [r for r in self.records if r["kind"] == kind]
