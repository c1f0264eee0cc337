"""The second robot and every one of its scenes load and step 2 s under noisy control with
zero MuJoCo warnings; its files open with plain MuJoCo by a relative path, from anywhere."""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import numpy as np
import pytest

from dial.robots.profile import RobotProfile
from tests.conftest import ROOT
from tests.model.allegro.conftest import FOLDER, Parts, at_home

SCENES = sorted(p.name for p in FOLDER.glob("scene_*.xml"))


def test_robot_and_hand_compile_without_warnings(mj_warnings: list[str]) -> None:
    robot = mujoco.MjModel.from_xml_path(str(FOLDER / "allegro_panda.xml"))
    assert (robot.nq, robot.nu, robot.nsensor) == (23, 23, 20)
    assert robot.opt.timestep == 0.002
    assert robot.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    hand = mujoco.MjModel.from_xml_path(str(FOLDER / "allegro_hand.xml"))
    assert (hand.njnt, hand.nu, hand.ntendon) == (16, 16, 0)
    assert mj_warnings == []


def test_scenes_are_the_four_tasks() -> None:
    assert [f"scene_{t}.xml" for t in ("containment", "lightbulb", "pour", "surface")] == SCENES


@pytest.mark.parametrize("name", SCENES)
def test_noisy_control_for_two_seconds_gives_no_warnings(
    name: str, mj_warnings: list[str], profile: RobotProfile
) -> None:
    model = mujoco.MjModel.from_xml_path(str(FOLDER / name))
    data, parts = at_home(model, profile)
    home = np.asarray(profile.arm.home)
    low, high = model.actuator_ctrlrange[parts.hand_actuators].T
    rng = np.random.default_rng(2)
    # Control at 100 Hz, as the engine does: arm jitter around home, hand anywhere in range.
    while data.time < 2.0:
        data.ctrl[parts.arm_actuators] = home + rng.normal(0.0, 0.05, 7)
        data.ctrl[parts.hand_actuators] = rng.uniform(low, high)
        mujoco.mj_step(model, data, nstep=5)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    assert mj_warnings == []
    # Then the servos bring the arm back: the tool site settles within 1 mm of home.
    data.ctrl[parts.arm_actuators] = home
    mujoco.mj_step(model, data, nstep=750)
    target = mujoco.MjData(model)
    target.qpos[parts.arm_qpos] = home
    mujoco.mj_kinematics(model, target)
    error = data.site_xpos[parts.tool_site] - target.site_xpos[parts.tool_site]
    assert np.linalg.norm(error) < 1e-3


@pytest.mark.parametrize("name", [*SCENES, "allegro_panda.xml"])
def test_loads_by_a_relative_path_from_elsewhere(
    name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    relative = os.path.relpath(FOLDER / name, tmp_path)
    assert "/" in relative
    model = mujoco.MjModel.from_xml_path(relative)
    assert model.nu == 23
    monkeypatch.chdir(ROOT)
    assert mujoco.MjModel.from_xml_path(str(FOLDER.relative_to(ROOT) / name)).nu == 23


def test_a_finger_servo_settles_and_its_torque_reads_the_load(
    model: mujoco.MjModel, profile: RobotProfile
) -> None:
    data, parts = at_home(model, profile)
    k = 5  # middle MCP
    data.ctrl[parts.hand_actuators[k]] = 0.5
    mujoco.mj_step(model, data, nstep=400)  # 0.8 s: the servo is heavily damped
    assert data.qpos[parts.hand_qpos[k]] == pytest.approx(0.5, abs=2e-3)
    # Free (gravity compensated), the joint's torque sensor reads about nothing.
    assert abs(data.sensordata[parts.torques[k]]) < 5e-3
    # An external torque on the joint: at rest the servo's torque balances it.
    data.qfrc_applied[model.jnt_dofadr[model.actuator_trnid[parts.hand_actuators[k], 0]]] = -0.2
    mujoco.mj_step(model, data, nstep=250)
    assert data.sensordata[parts.torques[k]] == pytest.approx(0.2, abs=5e-3)


def test_parts_follow_the_profile(model: mujoco.MjModel, profile: RobotProfile) -> None:
    parts = Parts.of(model, profile)
    assert len(parts.hand_qpos) == 16 and len(set(parts.hand_qpos.tolist())) == 16
    assert model.site(parts.tool_site).name == "allegro_palm"
