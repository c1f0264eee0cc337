"""The robot loads and steps without MuJoCo warnings, and the arm holds its pose under gravity."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import pytest

from dial.backend.model import (
    ARM_HOME,
    ROBOT_DIR,
    ROBOT_XML,
    RobotIndex,
    hand_ctrl,
    load_model,
)
from tests.model.conftest import hold_drift

# Arm holding configurations (rad): home, and stretched out horizontally, where gravity loads
# the shoulder most.
HOLDS = {"home": ARM_HOME, "stretched": (0.5, 0.0, -np.pi / 2, 0.3, 0.4, 0.0)}


def test_robot_compiles_standalone_without_warnings(mj_warnings: list[str]) -> None:
    model = load_model(ROBOT_XML)
    # The top-level file also compiles by plain MuJoCo, with no help from the loader.
    plain = mujoco.MjModel.from_xml_path(str(ROBOT_XML))
    assert (
        (model.nq, model.nu, model.nsensor) == (plain.nq, plain.nu, plain.nsensor) == (22, 38, 36)
    )
    assert model.opt.timestep == 0.002
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert mj_warnings == []


def test_scene_in_another_folder_includes_the_robot(tmp_path: Path) -> None:
    scene = tmp_path / "scene.xml"
    scene.write_text(
        '<mujoco model="elsewhere"><include file="utah_hand_puma.xml"/>'
        '<worldbody><geom type="plane" size="1 1 0.1"/></worldbody></mujoco>'
    )
    assert RobotIndex.from_model(load_model(scene)).tool_site >= 0


def test_hand_alone_compiles(mj_warnings: list[str]) -> None:
    hand = mujoco.MjModel.from_xml_path(str(ROBOT_DIR / "utah_hand.xml"))
    assert (hand.njnt, hand.nu, hand.ntendon) == (16, 32, 32)
    assert mj_warnings == []


def test_noisy_control_for_two_seconds_gives_no_warnings(
    mj_warnings: list[str],
    scene: Callable[[str], mujoco.MjModel],
    at_home: Callable[[mujoco.MjModel], mujoco.MjData],
) -> None:
    model = scene("")
    index = RobotIndex.from_model(model)
    data = at_home(model)
    low, high = model.actuator_ctrlrange[index.tendon_actuators[::2]].T
    rng = np.random.default_rng(2)
    # Control at 100 Hz, as the engine does: arm jitter around home, hand anywhere in range.
    while data.time < 2.0:
        data.ctrl[index.arm_actuators] = np.add(ARM_HOME, rng.normal(0.0, 0.05, 6))
        data.ctrl[index.tendon_actuators] = hand_ctrl(rng.uniform(low, high))
        mujoco.mj_step(model, data, nstep=5)
    assert [w.number for w in data.warning] == [0] * len(data.warning)
    assert np.isfinite(data.qpos).all() and np.isfinite(data.qvel).all()
    assert mj_warnings == []

    # Then the servos bring the arm back: the tool site settles within 1 mm of home.
    data.ctrl[index.arm_actuators] = ARM_HOME
    data.ctrl[index.tendon_actuators] = hand_ctrl(np.zeros(16))
    mujoco.mj_step(model, data, nstep=750)
    target = mujoco.MjData(model)
    target.qpos[index.arm_qpos] = ARM_HOME
    mujoco.mj_kinematics(model, target)
    error = np.linalg.norm(data.site_xpos[index.tool_site] - target.site_xpos[index.tool_site])
    assert error < 1e-3


@pytest.mark.parametrize("pose", HOLDS)
def test_arm_holds_its_pose_under_gravity(
    pose: str,
    model: mujoco.MjModel,
    index: RobotIndex,
) -> None:
    data = mujoco.MjData(model)
    data.qpos[index.arm_qpos] = HOLDS[pose]
    data.ctrl[index.arm_actuators] = HOLDS[pose]
    assert hold_drift(model, data, index.tool_site) < 1e-3
