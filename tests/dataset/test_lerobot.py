"""LeRobot's own reader loads dial's exports offline, with the right counts and values.

lerobot needs Python >= 3.12 and pins torch, so it runs in an environment of its own
(docs/datasets.md, "Loading it with LeRobot"): this test runs ``lerobot_check.py`` with the
Python named by ``DIAL_LEROBOT_PYTHON`` (or this one, if it can import lerobot), and
skips, saying so, when there is none; with ``DIAL_LEROBOT_TEST=require`` (CI) it fails.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyarrow", reason="the dataset tests need the 'dataset' extra (pyarrow)")

import dial
from dial.dataset.writer import DatasetWriter
from dial.tune import SerialExecutor

from .helpers import SWEEP, Exact, sweep

CHECK = Path(__file__).with_name("lerobot_check.py")


def _lerobot_python() -> str | None:
    named = os.environ.get("DIAL_LEROBOT_PYTHON")
    if named:
        return named
    return sys.executable if importlib.util.find_spec("lerobot") is not None else None


PYTHON = _lerobot_python()
if PYTHON is None and os.environ.get("DIAL_LEROBOT_TEST") != "require":
    pytest.skip(
        "no Python with lerobot: set DIAL_LEROBOT_PYTHON (docs/datasets.md)",
        allow_module_level=True,
    )


def _custom_sweep(root: Path) -> dict[str, object]:
    """Two perturbed runs through one writer, with the exact states and actions beside."""
    states, actions = [], []
    with DatasetWriter(root) as writer:
        for seed in (1, 2):
            exact = Exact()
            dial.run(SWEEP[0], perturb=5, seed=seed, observers=[exact], dataset=writer)
            state, action = exact.frames(50, writer.last_frames)
            states.append(state)
            actions.append(action)
    reference = root.parent / f"{root.name}.npz"
    np.savez(reference, state=np.concatenate(states), action=np.concatenate(actions))
    return {"episodes": 2, "frames": sum(len(s) for s in states), "reference": str(reference)}


def test_lerobot_loads_dials_exports(tmp_path: Path) -> None:
    assert PYTHON is not None, "DIAL_LEROBOT_TEST=require: set DIAL_LEROBOT_PYTHON"
    task = f"{SWEEP[0]} in scene reactions"
    specs = [{**_custom_sweep(tmp_path / "runs"), "root": str(tmp_path / "runs"), "fps": 50}]
    sweep(tmp_path / "sweep", SerialExecutor())
    info = json.loads((tmp_path / "sweep/meta/info.json").read_text())
    specs.append({"root": str(tmp_path / "sweep"), "episodes": 3, "fps": 50})
    specs[-1]["frames"] = info["total_frames"]
    video = tmp_path / "video"  # rendered offscreen, in a process of its own
    command = ["run", SWEEP[0], "--dataset", str(video), "--fps", "10", "--cameras", "task"]
    env = {**os.environ, "MUJOCO_GL": "egl"}
    subprocess.run([sys.executable, "-m", "dial.cli", *command], check=True, env=env)
    info = json.loads((video / "meta/info.json").read_text())
    specs.append({"root": str(video), "episodes": 1, "fps": 10, "video_size": [240, 320]})
    specs[-1]["frames"] = info["total_frames"]
    for spec in specs:
        spec["task"] = task
    (tmp_path / "specs.json").write_text(json.dumps(specs))
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "HF_DATASETS_OFFLINE": "1"}
    env["HF_HOME"] = str(tmp_path / "hf")  # LeRobot's caches, not the user's
    env.pop("PYTHONPATH", None)  # its own environment, not dial's
    done = subprocess.run(
        [PYTHON, str(CHECK), str(tmp_path / "specs.json")],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert [s["frames"] for s in seen] == [s["frames"] for s in specs]
    assert seen[2]["videos"] == specs[2]["frames"]
