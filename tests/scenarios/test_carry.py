"""A carried object (issue 27): the world model's pitcher follows the hand that carries it.

tests/scenarios/carry/carry.dial locates the pour scene's lid and pitcher by touch, grasps the
pitcher with its lid on, carries it 100 mm along -y, sets it down, and then feels for the lid's
knob at a location relative to the pitcher (docs/scenes.md, "A carried pitcher"). With the
objects 10 mm from where the world model believes them, it finds the knob where the hand left
the pitcher; the lid, resting on the pitcher, was carried with it in the world model too. With
grasp following switched off, the world model still believes the pitcher where it was, and
the same touch finds nothing.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import dial

SCRIPT = Path(__file__).parent / "carry" / "carry.dial"
# Two directions of the 10 mm perturbation, 135 deg apart (of eight checked: docs/tuning.md).
CARRY_SEEDS = (4172, 14454)


def _run(seed: int, follow: bool) -> tuple[dial.RunResult, dict[str, dict[str, Any]]]:
    result = dial.run(dial.load(SCRIPT), perturb=10, seed=seed, follow_grasps=follow)
    assert result.error is None, result.error
    return result, {str(r["event"]): r for r in result.log.of("end")}


@pytest.mark.parametrize("seed", CARRY_SEEDS)
def test_a_carried_pitcher_is_believed_where_the_hand_set_it_down(seed: int) -> None:
    result, ends = _run(seed, follow=True)
    assert ends["grabpit"]["outcome"] == "done" and ends["touch_lid"]["outcome"] == "done"
    assert result.success["lid_touched"] and result.success["pitcher_upright"], result.details
    assert result.ok and "contents_in_cup" not in result.success  # carry.toml drops pour's
    beliefs = result.log.of("belief")
    for name, held in (("pitcher", "grasped"), ("lid", "carried")):  # the lid rests on it
        changes = [r for r in beliefs if r["object"] == name]
        assert [r["why"] for r in changes] == ["locate", held, "released"]
        released = changes[-1]
        moved = np.array(released["after"]["pos"]) - np.array(released["before"]["pos"])
        assert np.allclose(moved, [0.0, -0.100, 0.0], atol=0.003)  # the carry, as commanded
        final = result.log.of("world")[-1]["objects"][name]
        assert float(final["off"]) < 0.015 and not final["believed"]["held"]


def test_without_following_the_lid_is_not_found() -> None:
    result, ends = _run(CARRY_SEEDS[0], follow=False)
    assert ends["grabpit"]["outcome"] == "done"
    assert ends["touch_lid"]["outcome"] == "missed"
    assert ends["touch_lid"]["message"] == "no contact within 80 mm"
    assert not result.success["lid_touched"]
    whys = {(r["object"], r["why"]) for r in result.log.of("belief")}
    assert whys == {("lid", "locate"), ("pitcher", "locate")}  # no grasp was followed
    final = result.log.of("world")[-1]["objects"]["pitcher"]
    assert float(final["off"]) > 0.09  # believed where it was found, 100 mm from the truth
