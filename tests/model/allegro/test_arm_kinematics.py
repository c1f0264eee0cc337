"""The Panda-like arm's flange matches an independent modified-DH forward kinematics, and its
joint limits are the documented ones (models/allegro_panda/README.md)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from dial.robots.profile import RobotProfile
from tests.model.allegro.conftest import Parts
from tests.model.conftest import hold_drift, pose_errors

# Franka Emika Panda, modified (Craig) DH: (a_{i-1}, d_i, alpha_{i-1}) per joint, theta_i = q_i;
# then the flange, d = 0.107 along z_7. The base stands on a 0.40 m pedestal.
DH = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -np.pi / 2),
    (0.0, 0.316, np.pi / 2),
    (0.0825, 0.0, np.pi / 2),
    (-0.0825, 0.384, -np.pi / 2),
    (0.0, 0.0, np.pi / 2),
    (0.088, 0.0, np.pi / 2),
]
FLANGE = 0.107
BASE_HEIGHT = 0.40
LIMITS = [
    (-2.8973, 2.8973),
    (-1.7628, 1.7628),
    (-2.8973, 2.8973),
    (-3.0718, -0.0698),
    (-2.8973, 2.8973),
    (-0.0175, 3.7525),
    (-2.8973, 2.8973),
]
TORQUES = [87, 87, 87, 87, 12, 12, 12]  # N m


def modified_dh(q: np.ndarray) -> np.ndarray:
    """4x4 pose of the flange in the world: product of Rx(alpha) Tx(a) Rz(q) Tz(d)."""
    pose = np.eye(4)
    pose[2, 3] = BASE_HEIGHT
    for theta, (a, d, alpha) in zip(q, DH, strict=True):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        link = np.array(
            [
                [ct, -st, 0.0, a],
                [st * ca, ct * ca, -sa, -sa * d],
                [st * sa, ct * sa, ca, ca * d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
        pose = pose @ link
    flange = np.eye(4)
    flange[2, 3] = FLANGE
    return pose @ flange


def test_joint_limits_and_torques_are_the_documented_ones(
    model: mujoco.MjModel, parts: Parts
) -> None:
    joints = [model.actuator(a).trnid[0] for a in parts.arm_actuators]
    np.testing.assert_allclose(model.jnt_range[joints], LIMITS, atol=1e-9)
    np.testing.assert_allclose(model.actuator_ctrlrange[parts.arm_actuators], LIMITS)
    np.testing.assert_allclose(model.actuator_forcerange[parts.arm_actuators, 1], TORQUES)


def test_flange_matches_dh_at_random_configurations(model: mujoco.MjModel, parts: Parts) -> None:
    data = mujoco.MjData(model)
    flange = model.site("panda_flange").id
    limits = np.array(LIMITS)
    rng = np.random.default_rng(7)
    for _ in range(200):
        q = rng.uniform(limits[:, 0], limits[:, 1])
        data.qpos[parts.arm_qpos] = q
        position_error, angle_error = pose_errors(model, data, flange, modified_dh(q))
        assert position_error < 1e-3, (q, position_error)
        assert angle_error < 0.1, (q, angle_error)


def test_home_is_the_ready_pose_pointing_the_flange_down(
    model: mujoco.MjModel, profile: RobotProfile, parts: Parts
) -> None:
    data = mujoco.MjData(model)
    data.qpos[parts.arm_qpos] = profile.arm.home
    mujoco.mj_kinematics(model, data)
    flange = model.site("panda_flange").id
    # Franka's published ready pose: the flange 0.307 m out and 0.590 m up from the base.
    np.testing.assert_allclose(data.site_xpos[flange], [0.307, 0.0, 0.590 + BASE_HEIGHT], atol=1e-3)
    np.testing.assert_allclose(data.site_xmat[flange].reshape(3, 3)[:, 2], [0, 0, -1], atol=1e-9)


@pytest.mark.parametrize("pose", ["home", "stretched"])
def test_arm_holds_its_pose_under_gravity(
    pose: str, model: mujoco.MjModel, profile: RobotProfile, parts: Parts
) -> None:
    q = profile.arm.home if pose == "home" else (0.5, 0.6, -0.3, -0.8, 0.4, 1.6, 0.2)
    data = mujoco.MjData(model)
    data.qpos[parts.arm_qpos] = data.ctrl[parts.arm_actuators] = q
    assert hold_drift(model, data, parts.tool_site) < 1e-3
