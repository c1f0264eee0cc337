"""The haptic exploration scripts, run headless with `dial run --json`, against their criteria."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ..conftest import ROOT

DIAL = [sys.executable, "-m", "dial.cli", "run", "--json", "--quiet"]
TOP_Z = 0.48  # m, the surface block's top face
TRUE_EXTENTS = (0.20, 0.14)  # m, its length and width


def _run(
    tmp_path: Path, script: str, *args: str
) -> tuple[int, dict[str, Any], list[dict[str, Any]]]:
    """Exit status, the --json summary (the last stdout line) and the log records."""
    log = tmp_path / "log.jsonl"
    proc = subprocess.run(
        [*DIAL, f"scripts/{script}", "--log", str(log), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    summary = json.loads(proc.stdout.strip().splitlines()[-1])
    records = [json.loads(line) for line in log.read_text().splitlines()]
    return proc.returncode, summary, records


def _check_surface(summary: dict[str, Any], records: list[dict[str, Any]]) -> None:
    assert summary["ok"], summary
    plane = summary["results"]["surface"]
    normal = np.array(plane["normal"])
    assert math.degrees(math.acos(min(1.0, abs(normal[2])))) <= 2.0
    extents = np.array(plane["extents"])
    assert np.all(np.abs(extents - TRUE_EXTENTS) <= 0.005), extents
    # Every recorded point lies on the top face, and the fit says so.
    notes = [r for r in records if r["kind"] == "end" and r["event"] == "note"]
    points = [r["data"]["point"] for r in notes if r["outcome"] == "done"]
    assert len(points) == plane["count"] >= 20
    assert np.allclose(np.array(points)[:, 2], TOP_Z, atol=0.5e-3)
    assert plane["max_residual"] < 0.5e-3
    # The traces ended on the tactile outcome: each loop stopped when the pad felt nothing.
    ends = [r for r in records if r["kind"] == "condition" and r["condition"] == "!note"]
    assert sum(r["value"] for r in ends) == 8  # a coarse and a fine loop per direction


def test_surface_exploration_fits_the_top_face(tmp_path: Path) -> None:
    status, summary, records = _run(tmp_path, "explore_surface.dial")
    assert status == 0
    _check_surface(summary, records)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_surface_exploration_finds_a_displaced_block_by_touch(tmp_path: Path, seed: int) -> None:
    status, summary, records = _run(
        tmp_path, "explore_surface.dial", "--perturb", "10", "--seed", str(seed)
    )
    assert status == 0
    shift = records[0]["perturb"]
    assert math.hypot(shift[0], shift[1]) == pytest.approx(0.010, abs=1e-6)
    _check_surface(summary, records)


def test_surface_exploration_ends_when_there_is_no_surface(tmp_path: Path) -> None:
    # The block is 25 cm away from where the world model believes it is: the first touch
    # misses, and the script takes its @if branch that ends the procedure.
    status, summary, records = _run(
        tmp_path, "explore_surface.dial", "--perturb", "250", "--seed", "0"
    )
    assert status == 1 and summary["error"] is None
    assert summary["results"] == {}
    (branch,) = [r for r in records if r["kind"] == "condition"]
    assert branch["condition"] == "!touch" and branch["value"] is True
    assert [r["event"] for r in records if r["kind"] == "end"][-1] == "give_up"
