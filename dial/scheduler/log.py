"""The event log: JSON Lines records, written and flushed as the run goes.

Records hold simulated time and ticks only (no wall-clock time), so the same
run gives the same bytes. Floats are rounded to fixed precision so that the
text does not depend on the last bits of a sum.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import IO, Any

_DIGITS = 6


def _clean(value: Any) -> Any:
    kind = type(value)
    if kind is int or kind is str or kind is bool or value is None:  # most values: fast path
        return value
    if isinstance(value, float):
        return round(value, _DIGITS) + 0.0  # +0.0 turns -0.0 into 0.0
    if isinstance(value, Mapping):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _clean(value.tolist())
    return value


class EventLog:
    """Collects records in order; optionally writes each as a JSON line and flushes."""

    def __init__(self, sink: IO[str] | None = None) -> None:
        self.records: list[dict[str, Any]] = []
        self._sink = sink

    def write(self, kind: str, **fields: Any) -> dict[str, Any]:
        record = {"kind": kind, **_clean(fields)}
        self.records.append(record)
        if self._sink is not None:
            self._sink.write(json.dumps(record, separators=(",", ":")) + "\n")
            self._sink.flush()
        return record

    def of(self, kind: str) -> list[dict[str, Any]]:
        return [r for r in self.records if r["kind"] == kind]
