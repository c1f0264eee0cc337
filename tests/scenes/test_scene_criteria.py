"""Success criteria evaluated on object worlds and on fit results."""

from __future__ import annotations

import math

import mujoco
import pytest

from dial.scene import Above, FingerContacts, FractionInRegion, PlaneFit, SuperquadricFit, Upright
from dial.scene.evaluate import evaluate, measure, shape_class

from .conftest import ObjectWorld

FINGERS = ("hand_index", "hand_middle", "hand_ring", "hand_thumb")


def test_fraction_in_region_and_upright(object_world: ObjectWorld) -> None:
    model, data = object_world("pour")
    criteria = [
        FractionInRegion("in_pitcher", "pour_ball_*", "pour_pitcher_inside", 1.0),
        FractionInRegion("in_cup", "pour_ball_*", "pour_cup_inside", 0.5),
        Upright("upright", "pour_pitcher", math.radians(10)),
    ]
    assert evaluate(criteria, model, data, {}) == {
        "in_pitcher": True,
        "in_cup": False,
        "upright": True,
    }
    assert measure(criteria[1], model, data, {}) == (False, "0/20 in pour_cup_inside (min 50%)")
    # Tip the pitcher 30 degrees about x.
    adr = model.joint("pour_pitcher").qposadr[0]
    data.qpos[adr + 3 : adr + 7] = (math.cos(math.radians(15)), math.sin(math.radians(15)), 0, 0)
    mujoco.mj_forward(model, data)
    ok, text = measure(criteria[2], model, data, {})
    assert not ok and text == "tilt 30.0 deg"


def test_above_and_finger_contacts(object_world: ObjectWorld) -> None:
    # Two stand-in finger pads touching the glass from either side.
    pad = '<body name="{}" pos="0.55 {} 0.496"><geom type="box" size="0.005 0.005 0.005"/></body>'
    pads = pad.format("hand_index_pad", 0.0345) + pad.format("hand_thumb_pad", -0.0345)
    model, data = object_world("lightbulb", body=pads)
    out = Above("out", "lightbulb_bulb", "lightbulb_socket_top", 0.07)
    held = FingerContacts("held", "lightbulb_bulb", FINGERS, 2)
    firm = FingerContacts("firm", "lightbulb_bulb", FINGERS, 3)
    assert evaluate([out, held, firm], model, data, {}) == {
        "out": False,
        "held": True,
        "firm": False,
    }
    assert measure(held, model, data, {})[1] == "2 fingers touch (hand_index, hand_thumb)"
    model.eq_active0[:] = 0
    mujoco.mj_resetData(model, data)
    data.qpos[model.joint("lightbulb_bulb").qposadr[0] + 2] += 0.04
    mujoco.mj_forward(model, data)
    assert measure(out, model, data, {}) == (True, "81.0 mm above lightbulb_socket_top")


def test_plane_fit_against_the_block_top(object_world: ObjectWorld) -> None:
    model, data = object_world("surface")
    plane = PlaneFit("top", "surface", "surface_block", "+z", math.radians(2), 0.005)
    tilt = math.radians(1.5)
    good = {"normal": [0, math.sin(tilt), -math.cos(tilt)], "extents": [0.137, 0.197]}
    assert measure(plane, model, data, {"surface": good}) == (
        True,
        "normal off by 1.50 deg, extents off by 3.0 mm",
    )
    steep = dict(good, normal=[0, math.sin(3 * tilt), math.cos(3 * tilt)])
    short = dict(good, extents=[0.14, 0.19])
    assert evaluate([plane], model, data, {"surface": steep}) == {"top": False}
    assert evaluate([plane], model, data, {"surface": short}) == {"top": False}
    assert measure(plane, model, data, {}) == (False, "no plane fit of set 'surface'")
    with pytest.raises(ValueError, match="fit result 'normal' must be 3 finite numbers"):
        evaluate([plane], model, data, {"surface": {"normal": [0, 1], "extents": [1, 1]}})


@pytest.mark.parametrize(
    ("body", "size", "shape", "ok"),
    [
        ("containment_box", [0.036, 0.025, 0.03], [0.1, 0.2], True),
        ("containment_box", [0.036, 0.025, 0.03], [0.1, 1.0], False),  # a cylinder's exponents
        ("containment_box", [0.04, 0.025, 0.03], [0.1, 0.1], False),  # 14% too long
        ("containment_cylinder", [0.03, 0.031, 0.039], [0.2, 0.9], True),
        ("containment_rounded", [0.03, 0.04, 0.034], [0.9, 1.1], True),
        ("containment_rounded", [0.03, 0.04, 0.034], [0.1, 1.1], False),
    ],
)
def test_superquadric_fit(
    object_world: ObjectWorld, body: str, size: list[float], shape: list[float], ok: bool
) -> None:
    model, data = object_world("containment")
    fit = SuperquadricFit("shape", "contain", body, 0.1)
    assert evaluate([fit], model, data, {"contain": {"size": size, "shape": shape}}) == {
        "shape": ok
    }


def test_shape_classes() -> None:
    assert [shape_class(*e) for e in ((0.1, 0.1), (0.1, 1), (1, 1), (1, 0.1))] == [
        "box",
        "cylinder",
        "rounded",
        "other",
    ]
