"""Shared fixtures: repository paths and golden-file helpers."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
UPDATE = os.environ.get("DIAL_UPDATE_GOLDEN") == "1"


def golden(path: Path, actual: str) -> None:
    """Compare ``actual`` with the golden file; with DIAL_UPDATE_GOLDEN=1, rewrite it."""
    if UPDATE:
        path.write_text(actual, encoding="utf-8")
        return
    assert path.is_file(), f"missing golden file {path}; run with DIAL_UPDATE_GOLDEN=1"
    assert actual == path.read_text(encoding="utf-8")


@pytest.fixture
def in_root(monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(ROOT)
    return ROOT
