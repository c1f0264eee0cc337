"""Joint ranges read from the MJCF without MuJoCo agree with MuJoCo's compiled ones: on the
bundled robots and scenes, and on a model that uses every rule the reader follows."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from dial.robots.ranges import joint_ranges
from tests.conftest import ROOT

MODELS = ROOT / "models"

ARM = """<mujoco model="arm">
  <!-- compiler angle left at MuJoCo's default: degrees -- also after this comment's "--" -->
  <default>
    <joint range="-90 90"/>
    <default class="big"><joint range="-170 170"/>
      <default class="bigger"/>
    </default>
  </default>
  <asset><model name="hand" file="hand.xml"/></asset>
  <worldbody>
    <body name="base" childclass="big">
      <joint name="a1" type="hinge"/>
      <geom type="box" size=".1 .1 .1"/>
      <body name="l2" pos="0 0 .2">
        <joint name="a2" class="bigger" range="-10 20"/>
        <joint name="a3" class="main"/>
        <geom type="box" size=".1 .1 .1"/>
        <include file="wrist.xml"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""
WRIST = """<mujoco>
  <body name="wrist" pos="0 0 .2">
    <joint name="a4" limited="false" range="-1 1"/>
    <joint name="s5" type="slide" range="0 0.04"/>
    <geom type="box" size=".05 .05 .05"/>
    <frame pos="0 0 .1"><attach model="hand" body="palm" prefix="h_"/></frame>
  </body>
</mujoco>"""
HAND = """<mujoco model="hand">
  <compiler angle="radian" autolimits="true"/>
  <default>
    <default class="hand"><joint axis="0 1 0" range="-0.5 1.5"/>
      <default class="tip"><joint range="0 1.2"/></default>
    </default>
  </default>
  <worldbody>
    <body name="palm" childclass="hand">
      <geom type="box" size=".04 .04 .01"/>
      <body name="f1" pos="0 0 .05"><joint name="j1"/><geom type="box" size=".01 .01 .02"/>
        <body name="f2" pos="0 0 .05"><joint name="j2" class="tip"/>
          <geom type="box" size=".01 .01 .02"/></body>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def compiled(path: Path) -> dict[str, tuple[float, float]]:
    model = mujoco.MjModel.from_xml_path(str(path))
    return {
        model.joint(j).name: (float(model.jnt_range[j, 0]), float(model.jnt_range[j, 1]))
        for j in range(model.njnt)
        if model.jnt_limited[j]
    }


@pytest.mark.parametrize(
    "path",
    [
        *sorted((MODELS / "utah_hand_puma").glob("*.xml")),
        *sorted((MODELS / "allegro_panda").glob("*.xml")),
    ],
    ids=lambda p: f"{p.parent.name}/{p.name}",
)
def test_bundled_models(path: Path) -> None:
    if path.name.startswith("objects_") or path.name in ("puma560.xml", "panda.xml"):
        pytest.skip("not a model on its own")
    expected = compiled(path)
    found = joint_ranges(path, path.parent)
    assert found.keys() == expected.keys()
    for name, (lo, hi) in expected.items():
        assert found[name] == pytest.approx((lo, hi), abs=1e-12), name


def test_every_rule(tmp_path: Path) -> None:
    for name, text in (("arm.xml", ARM), ("wrist.xml", WRIST), ("hand.xml", HAND)):
        (tmp_path / name).write_text(text)
    expected = compiled(tmp_path / "arm.xml")
    assert set(expected) == {"a1", "a2", "a3", "s5", "h_j1", "h_j2"}
    found = joint_ranges(tmp_path / "arm.xml")
    assert found.keys() == expected.keys()
    for name, (lo, hi) in expected.items():
        np.testing.assert_allclose(found[name], (lo, hi), atol=1e-12, err_msg=name)
