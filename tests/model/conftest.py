"""Fixtures for the robot model tests: test scenes around the robot and a MuJoCo warning trap."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import mujoco
import numpy as np
import pytest

from dial.backend.model import ARM_HOME, RobotIndex, load_model_from_string

SCENE = """<mujoco model="test_scene">
  <include file="utah_hand_puma.xml"/>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    {extra}
  </worldbody>
</mujoco>"""

# Distal phalanx, in its body frame: the pad face is at y = -PAD_Y (the palmar side), and the
# test plate's face is centred at z = PLATE_Z, beyond the DIP joint so that only the pad meets it.
PAD_Y = 0.0095
PLATE_Z = 0.016
PLATE_HALF = np.array([0.012, 0.004, 0.014])

SceneBuilder = Callable[[str], mujoco.MjModel]
PlateBuilder = Callable[..., str]


@pytest.fixture
def mj_warnings() -> Iterator[list[str]]:
    """Collect every MuJoCo warning message issued while the test runs (compile included)."""
    messages: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(messages.append)
    yield messages
    mujoco.set_mju_user_warning(previous)


@pytest.fixture(scope="session")
def scene() -> SceneBuilder:
    """Compile the robot on a floor, with extra worldbody XML."""

    def build(extra: str) -> mujoco.MjModel:
        return load_model_from_string(SCENE.format(extra=extra))

    return build


@pytest.fixture(scope="session")
def model(scene: SceneBuilder) -> mujoco.MjModel:
    return scene("")


@pytest.fixture(scope="session")
def index(model: mujoco.MjModel) -> RobotIndex:
    return RobotIndex.from_model(model)


def _at_home(model: mujoco.MjModel, index: RobotIndex) -> mujoco.MjData:
    data = mujoco.MjData(model)
    data.qpos[index.arm_qpos] = ARM_HOME
    data.ctrl[index.arm_actuators] = ARM_HOME
    mujoco.mj_forward(model, data)
    return data


@pytest.fixture(scope="session")
def at_home(index: RobotIndex) -> Callable[[mujoco.MjModel], mujoco.MjData]:
    """New data for a scene: arm at ARM_HOME with its servos holding there, hand straight."""
    return lambda model: _at_home(model, index)


def pose_errors(
    model: mujoco.MjModel, data: mujoco.MjData, site: int, expected: np.ndarray
) -> tuple[float, float]:
    """Position (m) and angle (deg) between a site's frame, after ``mj_kinematics``, and the
    4x4 ``expected`` pose."""
    mujoco.mj_kinematics(model, data)
    position = float(np.linalg.norm(data.site_xpos[site] - expected[:3, 3]))
    relative = data.site_xmat[site].reshape(3, 3).T @ expected[:3, :3]
    angle = np.arccos(np.clip((np.trace(relative) - 1.0) / 2.0, -1.0, 1.0))
    return position, float(np.degrees(angle))


def hold_drift(model: mujoco.MjModel, data: mujoco.MjData, site: int, steps: int = 1000) -> float:
    """How far (m) a site wanders while the model steps ``steps`` times from ``data``."""
    mujoco.mj_forward(model, data)
    start = data.site_xpos[site].copy()
    drift = 0.0
    for _ in range(steps):
        mujoco.mj_step(model, data)
        drift = max(drift, float(np.linalg.norm(data.site_xpos[site] - start)))
    return drift


def rotation(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    rot = np.eye(3)
    rot[i, i], rot[i, j], rot[j, i], rot[j, j] = c, -s, s, c
    return rot


@pytest.fixture(scope="session")
def pad_plate(model: mujoco.MjModel, index: RobotIndex) -> PlateBuilder:
    """XML of a fixed plate facing a finger's pad, with the arm at home and the hand straight.

    ``gap`` (m) separates plate and pad centre. ``pitch`` > 0 (rad) turns the plate's distal end
    towards the pad, ``roll`` > 0 its side on the finger's local +x.
    """
    home = _at_home(model, index)

    def build(finger: str, gap: float, pitch: float = 0.0, roll: float = 0.0) -> str:
        body = model.body(f"hand_{finger}_distal").id
        frame = home.xmat[body].reshape(3, 3)
        # Rx(-pitch) swings +z (distal) towards -y (the pad); Rz(roll) swings +x towards +y.
        plate = frame @ rotation(0, -pitch) @ rotation(2, roll)
        face = home.xpos[body] + frame @ np.array([0.0, -PAD_Y - gap, PLATE_Z])
        centre = face + plate @ np.array([0.0, -PLATE_HALF[1], 0.0])
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, plate.ravel())
        return (
            f'<geom name="plate_{finger}" type="box" size="{" ".join(map(str, PLATE_HALF))}" '
            f'pos="{" ".join(map(str, centre))}" quat="{" ".join(map(str, quat))}"/>'
        )

    return build
