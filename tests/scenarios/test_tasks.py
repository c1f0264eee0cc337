"""The paper's two tasks, run headless end to end: every declared success criterion holds.

The criteria are read from `dial run --json`, the way a user or a script would read them.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from ..conftest import ROOT


def _run(script: str, *extra: str) -> tuple[int, dict[str, object]]:
    done = subprocess.run(
        [sys.executable, "-m", "dial.cli", "run", script, "--json", "--quiet", *extra],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
    )
    summary = json.loads(done.stdout.splitlines()[-1])
    return done.returncode, summary


@pytest.mark.parametrize(
    ("script", "criteria"),
    [
        ("scripts/lightbulb.dial", {"bulb_out", "bulb_held"}),
        ("scripts/pour.dial", {"contents_in_cup", "pitcher_upright"}),
    ],
)
def test_task_succeeds_at_the_default_tick(script: str, criteria: set[str]) -> None:
    status, summary = _run(script)
    assert summary["error"] is None, summary["error"]
    success = summary["success"]
    assert isinstance(success, dict) and set(success) == criteria
    assert all(success.values()), summary["criteria"]
    assert summary["ok"] is True and status == 0
    outcomes = summary["outcomes"]
    assert isinstance(outcomes, dict) and outcomes.get("timeout", 0) == 0
