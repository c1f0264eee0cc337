"""The bundled haptic scripts on the second robot (allegro_panda), with only the scene changed:
the surface trace and grasping by containment on each solid, on one perturbation each, run
headless end to end through the command line; every declared success criterion holds. (The
Utah hand's runs of the same scripts: tests/haptics/.)"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from ..conftest import ROOT


@pytest.mark.parametrize(
    ("script", "scene", "seed", "criteria"),
    [
        ("explore_surface", "allegro_panda/surface", 1, {"top_plane"}),
        ("containment", "allegro_panda/containment", 1, {"shape_fit"}),
        ("containment", "allegro_panda/containment_cylinder", 2, {"shape_fit"}),
        ("containment", "allegro_panda/containment_rounded", 3, {"shape_fit"}),
    ],
)
def test_a_bundled_script_succeeds_on_the_second_robot(
    script: str, scene: str, seed: int, criteria: set[str]
) -> None:
    command = [sys.executable, "-m", "dial.cli", "run", script, "--scene", scene]
    options = ["--json", "--quiet", "--perturb", "10", "--seed", str(seed)]
    done = subprocess.run(
        [*command, *options], cwd=ROOT, capture_output=True, text=True, timeout=600
    )
    summary = json.loads(done.stdout.splitlines()[-1])
    assert summary["error"] is None, summary["error"]
    success = summary["success"]
    assert isinstance(success, dict) and set(success) == criteria
    assert all(success.values()), summary["criteria"]
    assert summary["ok"] is True and done.returncode == 0
