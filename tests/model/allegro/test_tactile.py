"""Each fingertip's 16x16 array reads a press where it happens, in the documented orientation:
row 0 proximal, row 15 distal; column 0 on the finger's local +y side, 15 on its -y side."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest

from dial.robots.profile import RobotProfile
from tests.model.allegro.conftest import at_home
from tests.model.conftest import rotation
from tests.model.test_tactile import components

FINGERS = ("index", "middle", "ring", "thumb")
PRESSES = {
    "flat": (0.0, 0.0),
    "distal": (0.3, 0.0),
    "proximal": (-0.3, 0.0),
    "plus_y": (0.0, 0.3),
    "minus_y": (0.0, -0.3),
}
PAD_X = 0.0123  # the pad face, along the distal body's +x
PAD_Z = {"index": 0.0152, "middle": 0.0152, "ring": 0.0152, "thumb": 0.0308}
PLATE_HALF = np.array([0.004, 0.018, 0.016])
# The joint that swings each pad into a plate in front of it: the first flexion beyond the
# palm (the thumb's j1, its first flexion joint).
PRESSING = {"index": 1, "middle": 5, "ring": 9, "thumb": 13}


def plate(
    model: mujoco.MjModel, profile: RobotProfile, finger: str, pitch: float, roll: float
) -> str:
    """A fixed plate 1 mm off the pad. ``pitch`` > 0 turns its distal end towards the pad,
    ``roll`` > 0 its +y side."""
    data, _ = at_home(model, profile)
    body = model.body(f"allegro_{finger}_distal").id
    frame = data.xmat[body].reshape(3, 3)
    # The pad faces +x: Ry(-pitch) swings +z (distal) towards -x, the pad; Rz(roll) swings
    # +y towards -x.
    turn = frame @ rotation(1, -pitch) @ rotation(2, roll)
    face = data.xpos[body] + frame @ np.array([PAD_X + 0.001, 0.0, PAD_Z[finger]])
    centre = face + turn @ np.array([PLATE_HALF[0], 0.0, 0.0])
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, turn.ravel())
    return (
        f'<geom type="box" size="{" ".join(map(str, PLATE_HALF))}" '
        f'pos="{" ".join(map(str, centre))}" quat="{" ".join(map(str, quat))}"/>'
    )


def images(model: mujoco.MjModel, data: mujoco.MjData, tactile: np.ndarray) -> np.ndarray:
    rows = tactile[:, None] + np.arange(256)
    return np.asarray(data.sensordata[rows]).reshape(4, 16, 16)


@pytest.mark.parametrize("press", PRESSES)
@pytest.mark.parametrize("finger", FINGERS)
def test_press_lights_one_blob_in_the_right_place(
    finger: str,
    press: str,
    model: mujoco.MjModel,
    profile: RobotProfile,
    scene: Callable[[str], mujoco.MjModel],
) -> None:
    pressed = scene(plate(model, profile, finger, *PRESSES[press]))
    data, parts = at_home(pressed, profile)
    k = PRESSING[finger]
    data.ctrl[parts.hand_actuators[k]] += 0.3
    mujoco.mj_step(pressed, data, nstep=300)
    image = images(pressed, data, parts.tactile)
    f = FINGERS.index(finger)
    assert np.all(image >= 0.0)
    assert not image[[g for g in range(4) if g != f]].any(), "a free finger reads contact"
    lit = image[f] > 0.0
    assert lit.sum() >= 8
    assert components(lit) == 1
    rows, cols = np.nonzero(lit)
    match press:
        case "flat":
            assert lit.mean() > 0.5
        case "distal":
            assert rows.min() >= 8 and rows.max() == 15
        case "proximal":
            assert rows.max() < 8
        case "plus_y":
            assert cols.max() < 8 and cols.min() == 0
        case "minus_y":
            assert cols.min() >= 8 and cols.max() == 15


def test_free_hand_reads_zero(model: mujoco.MjModel, profile: RobotProfile) -> None:
    data, parts = at_home(model, profile)
    data.ctrl[parts.hand_actuators] = np.clip(0.2, *parts.hand_range.T)
    mujoco.mj_step(model, data, nstep=250)
    assert not images(model, data, parts.tactile).any()
