"""Fixtures for the second robot's model tests (models/allegro_panda): its profile, test scenes
around it, and its parts' addresses, looked up through the profile's names."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
import pytest

from dial.robots.profile import RobotProfile, load_profile
from tests.conftest import ROOT

FOLDER = ROOT / "models" / "allegro_panda"
SCENE = """<mujoco model="test_scene">
  <asset><model name="allegro_hand" file="allegro_hand.xml"/></asset>
  <include file="panda.xml"/>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    {extra}
  </worldbody>
</mujoco>"""

SceneBuilder = Callable[[str], mujoco.MjModel]


@dataclass(frozen=True)
class Parts:
    """Addresses of the robot's parts in one compiled model, by the profile's names."""

    arm_qpos: np.ndarray  # (7,)
    arm_actuators: np.ndarray
    hand_qpos: np.ndarray  # (16,) mask order
    hand_actuators: np.ndarray
    torques: np.ndarray  # (16,) sensordata addresses of the joint torque sensors
    tactile: np.ndarray  # (4,) sensordata addresses of the tactile arrays
    tool_site: int
    hand_range: np.ndarray  # (16, 2) rad

    @classmethod
    def of(cls, model: mujoco.MjModel, profile: RobotProfile) -> Parts:
        joints = [j for f in profile.fingers for j in f.joints]
        servos = [s for f in profile.fingers for s in f.servos]
        return cls(
            arm_qpos=np.array([model.joint(j).qposadr[0] for j in profile.arm.joints]),
            arm_actuators=np.array([model.actuator(a).id for a in profile.arm.servos]),
            hand_qpos=np.array([model.joint(j).qposadr[0] for j in joints]),
            hand_actuators=np.array([model.actuator(a).id for a in servos]),
            torques=np.array([model.sensor(j).adr[0] for j in joints]),
            tactile=np.array([model.sensor(f.tactile).adr[0] for f in profile.fingers]),
            tool_site=model.site(profile.arm.tool_site).id,
            hand_range=np.array([model.joint(j).range for j in joints]),
        )


def robot_files() -> dict[str, bytes]:
    """The robot folder's MJCF files by name, so that a scene anywhere can include them."""
    return {p.name: p.read_bytes() for p in FOLDER.glob("*.xml")}


@pytest.fixture(scope="session")
def profile() -> RobotProfile:
    return load_profile(FOLDER)


@pytest.fixture(scope="session")
def scene() -> SceneBuilder:
    """Compile the robot on a floor, with extra worldbody XML."""
    files = robot_files()
    return lambda extra: mujoco.MjModel.from_xml_string(SCENE.format(extra=extra), files)


@pytest.fixture(scope="session")
def model(scene: SceneBuilder) -> mujoco.MjModel:
    return scene("")


@pytest.fixture(scope="session")
def parts(model: mujoco.MjModel, profile: RobotProfile) -> Parts:
    return Parts.of(model, profile)


def rest(parts: Parts) -> np.ndarray:
    """(16,) the straight hand, clipped into the joint ranges (the thumb's base joint's range
    starts at 15 deg)."""
    return np.clip(np.zeros(16), parts.hand_range[:, 0], parts.hand_range[:, 1])


def at_home(model: mujoco.MjModel, profile: RobotProfile) -> tuple[mujoco.MjData, Parts]:
    """New data: the arm at the profile's home with its servos holding there, the hand at rest."""
    parts = Parts.of(model, profile)
    data = mujoco.MjData(model)
    data.qpos[parts.arm_qpos] = profile.arm.home
    data.ctrl[parts.arm_actuators] = profile.arm.home
    data.qpos[parts.hand_qpos] = data.ctrl[parts.hand_actuators] = rest(parts)
    mujoco.mj_forward(model, data)
    return data, parts
