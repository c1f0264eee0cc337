"""The PUMA 560 flange matches an independent standard-DH forward kinematics."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from dial.backend.model import ARM_HOME, RobotIndex
from tests.model.conftest import pose_errors

# Standard (distal) DH table of the PUMA 560: (d, a, alpha) per joint, theta_i = q_i.
DH = [
    (0.6718, 0.0, np.pi / 2),
    (0.0, 0.4318, 0.0),
    (0.15005, 0.0203, -np.pi / 2),
    (0.4318, 0.0, np.pi / 2),
    (0.0, 0.0, -np.pi / 2),
    (0.0, 0.0, 0.0),
]
# Joint limits (deg) documented in models/utah_hand_puma/README.md.
LIMITS_DEG = [(-160, 160), (-45, 225), (-225, 45), (-110, 170), (-100, 100), (-266, 266)]


def dh_forward(q: np.ndarray) -> np.ndarray:
    """4x4 pose of DH frame 6 in the base frame: product of Rz(q) Tz(d) Tx(a) Rx(alpha)."""
    pose = np.eye(4)
    for theta, (d, a, alpha) in zip(q, DH, strict=True):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        link = np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0.0, sa, ca, d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        pose = pose @ link
    return pose


def test_joint_limits_are_the_documented_ones(model: mujoco.MjModel, index: RobotIndex) -> None:
    joints = model.dof_jntid[index.arm_dof]
    np.testing.assert_allclose(np.degrees(model.jnt_range[joints]), LIMITS_DEG, atol=0.01)
    np.testing.assert_allclose(
        model.actuator_ctrlrange[index.arm_actuators], model.jnt_range[joints]
    )


def test_flange_matches_dh_at_random_configurations(
    model: mujoco.MjModel, index: RobotIndex
) -> None:
    data = mujoco.MjData(model)
    flange = model.site("puma_flange").id
    limits = np.radians(LIMITS_DEG)
    rng = np.random.default_rng(560)
    for _ in range(200):
        q = rng.uniform(limits[:, 0], limits[:, 1])
        data.qpos[index.arm_qpos] = q
        position_error, angle_error = pose_errors(model, data, flange, dh_forward(q))
        assert position_error < 1e-3, (q, position_error)
        assert angle_error < 0.1, (q, angle_error)


def test_base_stands_on_the_floor_at_the_origin(model: mujoco.MjModel) -> None:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    base = model.body("puma_base").id
    np.testing.assert_allclose(data.xpos[base], 0.0)
    # Shoulder height d1 above the floor, and nothing of the arm below it.
    np.testing.assert_allclose(data.xpos[model.body("puma_link2").id], [0.0, 0.0, 0.6718])
    pedestal = model.geom("puma_pedestal").id
    assert data.geom_xpos[pedestal][2] - model.geom_size[pedestal][1] == pytest.approx(0.0)


def test_home_pose_points_the_palm_down(model: mujoco.MjModel, index: RobotIndex) -> None:
    data = mujoco.MjData(model)
    data.qpos[index.arm_qpos] = ARM_HOME
    mujoco.mj_kinematics(model, data)
    palm_z = data.site_xmat[index.tool_site].reshape(3, 3)[:, 2]
    np.testing.assert_allclose(palm_z, [0.0, 0.0, -1.0], atol=0.01)
    np.testing.assert_allclose(data.site_xpos[index.tool_site], [0.55, -0.15, 0.45], atol=0.01)
