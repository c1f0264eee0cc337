"""Scenario tests of scripts/containment.dial: grasping by containment on the three solids.

Each test runs the bundled script in one containment scene through the command line and reads
the --json summary: the run must succeed, and the superquadric fitted to the thumb and index
contacts must have the presented solid's size (within the criterion's 10 %) and shape class.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from dial.resources import data_dir

SCRIPT = data_dir("scripts") / "containment.dial"


@pytest.mark.parametrize(
    ("scene", "shape"),
    [
        ("containment", "box"),
        ("containment_cylinder", "cylinder"),
        ("containment_rounded", "rounded"),
    ],
)
def test_containment_fits_the_presented_solid(scene: str, shape: str) -> None:
    command = [sys.executable, "-m", "dial.cli", "run", str(SCRIPT), "--scene", scene]
    run = subprocess.run(
        [*command, "--json", "--quiet"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    summary = json.loads(run.stdout.strip().splitlines()[-1])
    assert run.returncode == 0, summary
    assert summary["ok"] and summary["success"] == {"shape_fit": True}, summary["criteria"]
    assert f"shape {shape} (true {shape})" in summary["criteria"]["shape_fit"]
    fit = summary["results"]["contain"]
    assert fit["count"] >= 40
