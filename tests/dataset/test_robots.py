"""Datasets of the second robot (allegro_panda): its own joint, load and finger names, its
joint torques and tactile pads in the frames, its name as the dataset's robot type, and no
appending of another robot's runs."""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

pytest.importorskip("pyarrow", reason="the dataset tests need the 'dataset' extra (pyarrow)")

import pyarrow.parquet as pq

import dial
from dial.cli import main

from . import layout

SCRIPT = str(Path(__file__).parents[1] / "robots" / "allegro_touch.dial")
FINGERS = ("index", "middle", "ring", "thumb")
JOINTS = tuple(f"allegro_{f}_j{j}" for f in FINGERS for j in range(4))


class Torques:
    """An independent observer: the hand's joint torque sensors, by their MJCF names, and the
    index pad's taxel depths after every control period."""

    def begin(self, run: dial.Watched) -> None:
        m, self.data = run.robot.model, run.robot.data
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, n) for n in JOINTS]
        self.load = np.array([m.sensor_adr[i] for i in ids])
        pad = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "allegro_index_tactile")
        self.pad = np.arange(m.sensor_adr[pad], m.sensor_adr[pad] + 256)
        self.torques = [self.data.sensordata[self.load].copy()]
        self.pads = [self.data.sensordata[self.pad].copy()]

    def period(self, periods: int, tick: int) -> None:
        self.torques.append(self.data.sensordata[self.load].copy())
        self.pads.append(self.data.sensordata[self.pad].copy())

    def end(self, result: dial.RunResult | None) -> None:
        pass


def test_a_run_of_the_second_robot_is_named_and_read_by_its_profile(tmp_path: Path) -> None:
    seen = Torques()
    result = dial.run(SCRIPT, observers=[seen], dataset=tmp_path / "d")
    assert result.summary.outcomes["done"] == 3
    read = layout.check(tmp_path / "d")
    info = read["info"]
    assert info["robot_type"] == "allegro_panda"
    features = info["features"]
    arm = [f"panda_joint{i}" for i in range(1, 8)]
    assert features["observation.state"]["names"] == [*arm, *JOINTS]
    assert features["action"]["shape"] == [23]
    assert features["observation.joint_load"]["names"] == [f"{j}_torque" for j in JOINTS]
    assert features["observation.tactile"]["shape"] == [4, 16, 16]
    table = pq.read_table(tmp_path / "d/data/chunk-000/file-000.parquet")
    load = np.array(table.column("observation.joint_load").to_pylist())
    tactile = np.array(table.column("observation.tactile").to_pylist())
    due = [2 * k for k in range(len(load))]  # 50 fps: every other control period
    eps = np.finfo(np.float32).eps
    np.testing.assert_allclose(load, [seen.torques[p] for p in due], rtol=eps, atol=1e-9)
    index_pad = tactile[:, 0].reshape(len(load), -1)
    np.testing.assert_allclose(index_pad, [seen.pads[p] for p in due], rtol=eps, atol=1e-12)
    assert index_pad[-1].max() > 0  # the press is in the last frame
    assert np.abs(load).max() > 1e-3


def test_another_robots_run_is_not_appended(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d = str(tmp_path / "d")
    assert main(["run", SCRIPT, "--quiet", "--dataset", d]) == 1  # no plane fitted
    capsys.readouterr()
    before = (tmp_path / "d/meta/info.json").read_text()
    assert main(["run", "reactions.dial", "--quiet", "--dataset", d]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot append to the dataset" in err, err
    assert "panda_joint1 in the dataset, puma_joint1 in this run" in err, err
    assert (tmp_path / "d/meta/info.json").read_text() == before
    assert json.loads(before)["total_episodes"] == 1
