"""Helpers for the recording tests (the short script is tests/conftest.py's)."""

from __future__ import annotations

from pathlib import Path


def without_wall_time(log: Path) -> list[str]:
    """The log's lines, with the summary's wall time (its one wall-clock field) blanked."""
    lines = log.read_text().splitlines()
    assert lines[-1].startswith('{"kind":"summary"')
    head, _, tail = lines[-1].partition('"wall_time":')
    return [*lines[:-1], head + tail.partition(",")[2]]
