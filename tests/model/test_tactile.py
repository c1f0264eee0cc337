"""Each fingertip's 16x16 array sees a press where it happens, in the documented orientation:
row 0 proximal, row 15 distal; column 0 on the finger's local -x side, 15 on its +x side."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest

from dial.backend.model import FINGERS, TAXEL_SHAPE, RobotIndex, hand_ctrl, tactile_images

# (pitch, roll) of the plate, and which half of the image the press must fall in.
PRESSES = {
    "flat": (0.0, 0.0),
    "distal": (0.15, 0.0),
    "proximal": (-0.15, 0.0),
    "plus_x": (0.0, 0.3),
    "minus_x": (0.0, -0.3),
}


def components(mask: np.ndarray) -> int:
    """Number of 4-connected components of lit taxels."""
    seen = np.zeros_like(mask)
    count = 0
    for start in zip(*np.nonzero(mask), strict=True):
        if seen[start]:
            continue
        count += 1
        stack = [start]
        while stack:
            r, c = stack.pop()
            if not (0 <= r < mask.shape[0] and 0 <= c < mask.shape[1]):
                continue
            if seen[r, c] or not mask[r, c]:
                continue
            seen[r, c] = True
            stack += [(r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)]
    return count


@pytest.mark.parametrize("press", PRESSES)
@pytest.mark.parametrize("finger", range(4), ids=FINGERS)
def test_press_lights_one_blob_in_the_right_place(
    finger: int,
    press: str,
    scene: Callable[[str], mujoco.MjModel],
    at_home: Callable[[mujoco.MjModel], mujoco.MjData],
    pad_plate: Callable[..., str],
) -> None:
    pitch, roll = PRESSES[press]
    model = scene(pad_plate(FINGERS[finger], gap=0.001, pitch=pitch, roll=roll))
    index = RobotIndex.from_model(model)
    data = at_home(model)
    q = np.zeros(16)
    q[4 * finger + 1] = 0.3  # flex the MCP into the plate
    data.ctrl[index.tendon_actuators] = hand_ctrl(q)
    for _ in range(300):
        mujoco.mj_step(model, data)

    images = tactile_images(data, index)
    assert images.shape == (4, *TAXEL_SHAPE)
    assert np.all(images >= 0.0)
    others = [f for f in range(4) if f != finger]
    assert not images[others].any(), "a free finger reads contact"

    lit = images[finger] > 0.0
    assert lit.sum() >= 8
    assert components(lit) == 1
    rows, cols = np.nonzero(lit)
    half = TAXEL_SHAPE[0] // 2
    match press:
        case "flat":
            assert lit.mean() > 0.5
        case "distal":
            assert rows.min() >= half and rows.max() == TAXEL_SHAPE[0] - 1
        case "proximal":
            assert rows.max() < half
        case "plus_x":
            assert cols.min() >= half and cols.max() == TAXEL_SHAPE[1] - 1
        case "minus_x":
            assert cols.max() < half and cols.min() == 0


def test_free_hand_reads_zero(
    model: mujoco.MjModel, index: RobotIndex, at_home: Callable[[mujoco.MjModel], mujoco.MjData]
) -> None:
    data = at_home(model)
    data.ctrl[index.tendon_actuators] = hand_ctrl(np.full(16, 0.2))
    for _ in range(250):
        mujoco.mj_step(model, data)
    assert not tactile_images(data, index).any()
