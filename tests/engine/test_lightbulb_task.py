"""The light-bulb task under perturbation (tests/scenarios runs it at the default tick).

The grasp must make up a bulb that is not where the world model believes: with seed 4 the
offset is one that made the paper's index-middle-ring grip curl under the glass and jam.
At 10 mm, seeds 1, 6 and 7 lost the freed bulb from an off-centre pinch until the script
learnt to feel for the glass and centre over it before grasping.
"""

from __future__ import annotations

import pytest

from dial.engine import RunOptions, run
from dial.parser import load
from dial.scene import load_scene_names

from ..conftest import ROOT


def test_lightbulb_comes_out_held_when_5mm_off() -> None:
    script = load(ROOT / "scripts" / "lightbulb.dial", loader=load_scene_names)
    result = run(script, RunOptions(perturb_mm=5.0, seed=4))
    assert result.summary.ok, result.summary.error
    assert result.success == {"bulb_out": True, "bulb_held": True}, result.details
    # The thread lets go during the last twist, as in the paper: no stroke is wasted.
    (released,) = result.log.of("thread")
    last_grasp = result.log.of("start")[-4]
    assert last_grasp["event"] == "grasp_bulb" and released["t"] > last_grasp["t"]


@pytest.mark.parametrize("seed", [1, 6, 7])
def test_lightbulb_centres_on_the_glass_by_touch_when_10mm_off(seed: int) -> None:
    script = load(ROOT / "scripts" / "lightbulb.dial", loader=load_scene_names)
    result = run(script, RunOptions(perturb_mm=10.0, seed=seed))
    assert result.summary.ok, result.summary.error
    assert result.success == {"bulb_out": True, "bulb_held": True}, result.details
    # Two touches of the thumb, one per horizontal axis, each stopped by its tendon force.
    feels = [r for r in result.log.of("end") if r["event"] == "feel_glass"]
    assert [(r["outcome"], r["data"]["kind"], r["data"]["finger"]) for r in feels] == [
        ("done", "force", "thumb")
    ] * 2
    # The travel to the touch is the believed one (about 20 mm) plus the offset along it.
    assert all(0.008 < r["data"]["travel"] < 0.032 for r in feels)


def test_at_a_fast_tick_the_thumb_feels_only_once_at_rest() -> None:
    # At 0.04 s the fingers still ring from the approach: without waiting for them to rest,
    # the force guard fired after 1-3 mm, before the glass.
    script = load(ROOT / "scripts" / "lightbulb.dial", loader=load_scene_names)
    result = run(script, RunOptions(tick=0.04))
    assert result.success == {"bulb_out": True, "bulb_held": True}, result.details
    waits = [r["value"] for r in result.log.of("condition") if r["condition"] == "ringing"]
    assert waits.count(True) >= 2 and waits[-1] is False  # it waited, then went on
    feels = [r["data"]["travel"] for r in result.log.of("end") if r["event"] == "feel_glass"]
    assert feels == [pytest.approx(0.0198, abs=0.001)] * 2
