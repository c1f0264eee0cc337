"""The pour task with the objects off their believed place: the hand feels for the lid's knob,
centres over it and locates lid and pitcher; and its reaction to an unexpected touch on the
way down beside the pitcher (docs/scenes.md, "The pour task as tuned" and its disturbance
envelope). tests/scenarios runs it at the default tick without perturbation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dial

from ..conftest import ROOT
from .recovery import check_recovery, ended, without_reactions

SCRIPT = ROOT / "scripts" / "pour.dial"
# The documented push: the thumb's fingertip pushed 5 N towards the pitcher for 0.5 s while the
# hand comes down beside it (lower_pit: 14.32-15.07 s at the default tick, watched to 14.82 s).
PUSH = "push body=hand_thumb_distal force=0,5,0 at=14.35 for=0.5"
POURED = {"contents_in_cup": True, "pitcher_upright": True}


@pytest.mark.parametrize("seed", [1, 12, 22])
def test_pour_finds_the_lid_by_touch_when_20mm_off(seed: int) -> None:
    # 1: 20 mm towards the robot (the side grasp then needs the scene's 40 mm more room);
    # 12: 20 mm along the first feel, towards the finger row; 22: both at once.
    result = dial.run(SCRIPT, perturb=20, seed=seed)
    assert result.ok, result.error
    assert result.success == POURED, result.details
    feels = ended(result, "feel_knob")
    assert [(r["outcome"], r["data"]["kind"]) for r in feels] == [("done", "tactile")] * 2
    (found,) = ended(result, "found")
    assert found["data"]["objects"] == ["lid", "pitcher"]
    (scene,) = result.log.of("scene")
    # The believed lid and pitcher moved to within 1 mm of where they truly are (0.2-0.6 mm
    # measured; in seed 1 the first feel touches the knob with the index, a side finger).
    shift = np.array(found["data"]["shift"][:2])
    assert np.linalg.norm(shift - np.array(scene["perturb"][:2])) < 0.001
    assert not result.log.of("monitor")  # the way down beside the pitcher touched nothing


def test_pour_at_its_fastest_reliable_tick_when_10mm_off() -> None:
    result = dial.run(SCRIPT, tick=0.16, perturb=10, seed=5)
    assert result.ok and result.success == POURED, (result.error, result.details)


def test_a_push_on_the_way_down_is_met_by_the_reaction(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    summary = check_recovery(SCRIPT, PUSH, "bump_thumb", "lower_pit", "back_up", tmp_path, capsys)
    assert summary["success"] == POURED


def test_without_its_reaction_the_same_push_spills_the_pour(tmp_path: Path) -> None:
    bare = without_reactions(SCRIPT, "bump_thumb  ~~\n", "/* GRASP, POUR", tmp_path)
    result = dial.run(dial.load(bare), disturb=[PUSH])
    assert not result.log.of("monitor")
    assert result.ok is False and result.success["contents_in_cup"] is False, result.details


def test_sensor_dropouts_on_the_way_down_cause_no_false_reaction() -> None:
    # The monitors read tendon-force changes: a tactile or position dropout does not touch
    # them, and a force dropout reads as no change (the open fingers carry no load).
    dropouts = [
        f"sense sensor={kind}:{finger} at=14.0 for=1.0"
        for kind in ("tactile", "force", "position")
        for finger in ("thumb", "middle")
    ]
    result = dial.run(SCRIPT, disturb=dropouts)
    assert result.ok and result.success == POURED, (result.error, result.details)
    assert not result.log.of("monitor")
    assert len(result.log.of("disturb")) == 2 * len(dropouts)
