"""The light-bulb task: unscrewed stroke by stroke until a tug comes free, with the bulb off
its believed place and with threads of other lengths; and its reaction to an unexpected
touch on the way down (docs/scenes.md, "The light-bulb task as tuned" and its disturbance
envelope). tests/scenarios runs it at the default tick without perturbation.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import dial

from ..conftest import ROOT
from .recovery import check_recovery, ended, without_reactions

SCRIPT = ROOT / "scripts" / "lightbulb.dial"
# The documented push: the thumb's fingertip pushed 5 N towards the glass for 0.5 s while the
# hand comes down onto the bulb (lower: 1.5-2.5 s at the default tick).
PUSH = "push body=hand_thumb_distal force=0,5,0 at=1.6 for=0.5"
HELD = {"bulb_out": True, "bulb_held": True}


def _unscrewed_by_sensing(result: dial.RunResult, exact: bool = True) -> int:
    """Check the loop ended on a tug that came free after the thread let go (``exact``: in
    the twist just before it, no stroke wasted); return the number of strokes."""
    tugs = ended(result, "tug")
    assert [r["outcome"] for r in tugs[:-1]] == ["done"] * (len(tugs) - 1)
    assert tugs[-1]["outcome"] == "missed"  # the bulb came up with the hand
    assert all(r["data"]["kind"] == "force" for r in tugs[:-1])
    (released,) = result.log.of("thread")
    assert released["t"] < tugs[-1]["t"]
    if exact:
        assert tugs[-2]["t"] < released["t"]
    lift = next(r for r in result.log.of("start") if r["event"] == "retract_arm")
    assert lift["t"] >= tugs[-1]["t"]
    return len(tugs)


def test_lightbulb_comes_out_held_when_20mm_off() -> None:
    # Seed 21 puts the bulb 20 mm towards the thumb: the old preshape came down with the thumb
    # on the glass, and the script waited for it to come to rest until its loop gave up.
    result = dial.run(SCRIPT, perturb=20, seed=21)
    assert result.ok, result.error
    assert result.success == HELD, result.details
    assert not result.log.of("monitor")  # the way down touched nothing
    feels = ended(result, "feel_glass")
    assert [(r["outcome"], r["data"]["kind"], r["data"]["finger"]) for r in feels] == [
        ("done", "force", "thumb")
    ] * 2
    assert 3 <= _unscrewed_by_sensing(result) <= 5  # 1.5 turns, about 140 degrees a stroke


def test_lightbulb_centres_and_unscrews_at_its_fastest_reliable_tick_when_10mm_off() -> None:
    # Seed 34: 10 mm along the line of index and ring, across the thumb's first feel. At this
    # tick the tug just after the thread lets go may still feel the fingers ringing from the
    # fast twist: a stroke or two more, on the freed bulb (docs/tuning.md).
    result = dial.run(SCRIPT, tick=0.06, perturb=10, seed=34)
    assert result.ok and result.success == HELD, (result.error, result.details)
    assert 3 <= _unscrewed_by_sensing(result, exact=False) <= 6


def test_a_longer_thread_takes_more_strokes_and_the_hand_follows_it_up() -> None:
    result = dial.run(SCRIPT, scene="lightbulb_long", perturb=10, seed=12)
    assert result.ok and result.success == HELD, (result.error, result.details)
    assert 8 <= _unscrewed_by_sensing(result) <= 11  # 3.5 turns
    assert len(ended(result, "follow")) == len(ended(result, "tug")) - 1


def test_a_world_file_sets_the_turns_of_another_bulb(tmp_path: Path) -> None:
    bulb = tmp_path / "one_turn.toml"
    bulb.write_text('extends = "lightbulb"\n\n[thread]\nturns = 1\n')
    result = dial.run(SCRIPT, scene=str(bulb), perturb=10, seed=3)
    assert result.ok and result.success == HELD, (result.error, result.details)
    assert 2 <= _unscrewed_by_sensing(result) <= 3


def test_a_push_on_the_way_down_is_met_by_the_reaction(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    summary = check_recovery(SCRIPT, PUSH, "bump_thumb", "lower", "back_off", tmp_path, capsys)
    assert summary["success"] == HELD


def test_without_its_reaction_the_same_push_leaves_the_thumb_caught(tmp_path: Path) -> None:
    bare = without_reactions(SCRIPT, "bump_thumb   ~~~~\n", "/* FEEL FOR THE GLASS", tmp_path)
    result = dial.run(dial.load(bare), disturb=[PUSH])
    assert not result.ok
    assert result.error is not None and "@repeat while ringing" in result.error
    assert not result.log.of("monitor")


def test_sensor_dropouts_on_the_way_down_cause_no_false_reaction() -> None:
    # The monitors read tendon-force changes: a tactile or position dropout does not touch
    # them, and a force dropout reads as no change (the open fingers carry no load).
    dropouts = [
        f"sense sensor={kind}:{finger} at=1.5 for=1.0"
        for kind in ("tactile", "force", "position")
        for finger in ("thumb", "middle")
    ]
    result = dial.run(SCRIPT, disturb=dropouts)
    assert result.ok and result.success == HELD, (result.error, result.details)
    assert not result.log.of("monitor")
    assert len(result.log.of("disturb")) == 2 * len(dropouts)
