"""16 hand joints, 32 pull-only tendons, and a co-contraction servo whose flexor-minus-extensor
tension difference reflects the load on each joint."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest

from dial.backend.model import (
    FINGERS,
    RobotIndex,
    default_profile,
    hand_ctrl,
    tendon_differentials,
    tendon_tensions,
)

HAND_JOINTS = tuple(j for finger in default_profile().fingers for j in finger.joints)

# At rest with nothing touching, the differential only holds numerical residue (the limit
# is 50 N): this bounds it.
FREE_TOLERANCE = 0.05  # N


def test_sixteen_hinges_and_thirty_two_tendon_actuators(
    model: mujoco.MjModel, index: RobotIndex
) -> None:
    hand_joints = [j for j in range(model.njnt) if model.joint(j).name.startswith("hand_")]
    assert len(hand_joints) == 16
    assert all(model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE for j in hand_joints)
    assert [model.joint(j).name for j in hand_joints] == list(HAND_JOINTS)
    assert model.ntendon == 32
    assert len(index.tendon_actuators) == 32
    assert model.nu == 6 + 32
    for k, joint in enumerate(HAND_JOINTS):
        for slot, kind, sign in ((2 * k, "flexor", -1.0), (2 * k + 1, "extensor", 1.0)):
            actuator = index.tendon_actuators[slot]
            assert model.actuator(actuator).name == f"{joint}_{kind}"
            tendon = model.actuator_trnid[actuator, 0]
            adr = model.tendon_adr[tendon]
            assert model.tendon_num[tendon] == 1
            assert model.joint(model.wrap_objid[adr]).name == joint
            assert model.wrap_prm[adr] == sign * index.lever
    np.testing.assert_array_equal(model.actuator_forcerange[index.tendon_actuators], [[0, 50]] * 32)
    assert index.load_limit == 50.0
    assert index.lever == 0.008


def test_hand_ctrl_checks_its_shape() -> None:
    np.testing.assert_array_equal(hand_ctrl(np.arange(16.0))[:4], [0.0, 0.0, 1.0, 1.0])
    with pytest.raises(ValueError, match="16 hand joint angles"):
        hand_ctrl(np.zeros(15))


def test_tensions_never_negative_under_noisy_control(
    model: mujoco.MjModel, index: RobotIndex, at_home: Callable[[mujoco.MjModel], mujoco.MjData]
) -> None:
    data = at_home(model)
    low, high = model.actuator_ctrlrange[index.tendon_actuators[::2]].T
    rng = np.random.default_rng(32)
    slack = taut = 0
    for step in range(1000):
        if step % 5 == 0:
            data.ctrl[index.tendon_actuators] = hand_ctrl(rng.uniform(low, high))
        mujoco.mj_step(model, data)
        tensions = tendon_tensions(data, index)
        assert tensions.min() >= 0.0
        assert tensions.max() <= index.load_limit
        slack += int((tensions == 0.0).sum())
        taut += int((tensions > 0.0).sum())
    # The noise is strong enough to exercise both limits of the servo.
    assert slack > 0 and taut > 0


def press(
    model: mujoco.MjModel,
    at_home: Callable[[mujoco.MjModel], mujoco.MjData],
    finger: int,
    mcp_targets: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Step MCP flexion targets, settling 0.6 s each: (differentials, angles) of the finger."""
    index = RobotIndex.from_model(model)
    data = at_home(model)
    differentials, angles = [], []
    for target in mcp_targets:
        q = np.zeros(16)
        q[4 * finger + 1] = target
        data.ctrl[index.tendon_actuators] = hand_ctrl(q)
        for _ in range(300):
            mujoco.mj_step(model, data)
        joints = slice(4 * finger, 4 * finger + 4)
        differentials.append(tendon_differentials(data, index)[joints])
        angles.append(data.qpos[index.hand_qpos][joints])
    return np.array(differentials), np.array(angles)


@pytest.mark.parametrize("finger", range(4), ids=FINGERS)
def test_differential_tracks_the_load_of_a_pressing_finger(
    finger: int,
    model: mujoco.MjModel,
    scene: Callable[[str], mujoco.MjModel],
    at_home: Callable[[mujoco.MjModel], mujoco.MjData],
    pad_plate: Callable[..., str],
) -> None:
    targets = np.linspace(0.0, 0.5, 6)
    blocked = scene(pad_plate(FINGERS[finger], gap=0.002))
    loaded, loaded_q = press(blocked, at_home, finger, targets)
    free, free_q = press(model, at_home, finger, targets)

    # Free: the finger reaches each target and the differential stays at zero.
    np.testing.assert_allclose(free_q[:, 1], targets, atol=1e-3)
    assert np.abs(free).max() < FREE_TOLERANCE
    # Pressed on the plate: the finger stops short and the flexion joints, all loaded by the
    # pad contact, pull harder with every step of commanded flexion.
    assert loaded_q[-1, 1] < 0.2
    for joint in (1, 2, 3):
        assert np.all(np.diff(loaded[:, joint]) > 0.0), (joint, loaded[:, joint])
        assert loaded[-1, joint] > 1.0
    assert loaded[-1, 1] > 20.0
    assert abs(loaded[-1, 0]) < 0.5  # abduction sees almost none of it


def test_catalogue_tension_limit_matches_the_model() -> None:
    # grasp_force thresholds are range-checked at check time against the model's limit.
    from dial.backend.model import RobotIndex, load_model
    from dial.instructions.grasp_force import TENDON_TENSION_LIMIT

    assert RobotIndex.from_model(load_model()).load_limit == TENDON_TENSION_LIMIT
