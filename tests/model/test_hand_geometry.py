"""The hand's layout and sign conventions are the documented ones (docs/model.md)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from dial.backend.model import FINGERS, RobotIndex


def tips_in_palm_frame(model: mujoco.MjModel, index: RobotIndex, q: np.ndarray) -> np.ndarray:
    """(4, 3) fingertip positions in the hand_palm frame for hand angles q (mask order)."""
    data = mujoco.MjData(model)
    data.qpos[index.hand_qpos] = q
    mujoco.mj_kinematics(model, data)
    palm = data.site_xmat[index.tool_site].reshape(3, 3)
    offsets = data.site_xpos[index.fingertip_sites] - data.site_xpos[index.tool_site]
    return np.asarray(offsets @ palm)


def test_straight_fingers_stand_out_of_the_palm(model: mujoco.MjModel, index: RobotIndex) -> None:
    tips = tips_in_palm_frame(model, index, np.zeros(16))
    # Knuckle 12 mm + phalanges 45 + 30 + 25 mm, along palm z; fingers in a row, thumb opposite.
    np.testing.assert_allclose(tips[:, 2], 0.112, atol=1e-9)
    np.testing.assert_allclose(
        tips[:, :2], [[0.028, 0.045], [0, 0.045], [-0.028, 0.045], [0, -0.045]]
    )


@pytest.mark.parametrize("finger", range(4), ids=FINGERS)
def test_flexion_closes_towards_the_opposite_side(
    finger: int, model: mujoco.MjModel, index: RobotIndex
) -> None:
    straight = tips_in_palm_frame(model, index, np.zeros(16))[finger]
    for joint in (1, 2, 3):
        q = np.zeros(16)
        q[4 * finger + joint] = 0.3
        moved = tips_in_palm_frame(model, index, q)[finger] - straight
        towards_middle = -np.sign(straight[1])
        assert moved[1] * towards_middle > 0.0, (joint, moved)


@pytest.mark.parametrize("finger", range(4), ids=FINGERS)
def test_abduction_swings_the_tip_towards_local_plus_x(
    finger: int, model: mujoco.MjModel, index: RobotIndex
) -> None:
    q = np.zeros(16)
    q[4 * finger] = 0.2
    moved = (
        tips_in_palm_frame(model, index, q)[finger]
        - tips_in_palm_frame(model, index, np.zeros(16))[finger]
    )
    local_x = -1.0 if FINGERS[finger] == "thumb" else 1.0  # the thumb is turned half a turn
    assert moved[0] * local_x > 0.0
