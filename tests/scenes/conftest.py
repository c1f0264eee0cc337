"""Object worlds: a scene's objects file on a floor, without the robot, for physics tests."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import pytest

from dial.scene import models_dir

MODEL_DIR = models_dir() / "utah_hand_puma"
# The physics options of utah_hand_puma.xml, so objects behave as they do in the scenes
# (test_scene_models checks that they still match).
OPTION = '<option timestep="0.002" integrator="implicitfast" cone="elliptic" impratio="10"/>'

ObjectWorld = Callable[..., tuple[mujoco.MjModel, mujoco.MjData]]


def object_world_xml(objects: str, body: str = "", equality: str = "") -> str:
    path = (MODEL_DIR / f"objects_{objects}.xml").resolve()
    return f"""<mujoco>
  {OPTION}
  <include file="{path}"/>
  <worldbody><geom name="floor" type="plane" size="2 2 0.1"/>{body}</worldbody>
  <equality>{equality}</equality>
</mujoco>"""


@pytest.fixture
def object_world() -> ObjectWorld:
    """``object_world("pour", body=..., equality=...)`` -> (model, data) after mj_forward."""

    def build(objects: str, body: str = "", equality: str = "") -> tuple[Any, Any]:
        model = mujoco.MjModel.from_xml_string(object_world_xml(objects, body, equality))
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        return model, data

    return build


def step(model: mujoco.MjModel, data: mujoco.MjData, seconds: float) -> None:
    mujoco.mj_step(model, data, round(seconds / model.opt.timestep))


def warnings(data: mujoco.MjData) -> int:
    return sum(int(w.number) for w in data.warning)


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path
