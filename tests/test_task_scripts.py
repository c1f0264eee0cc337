"""The paper's two task scripts: `dial show` pins their charts and tick ranges."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.cli import main
from dial.parser import expand, load
from dial.scene import load_scene_names

from .conftest import DATA, ROOT, golden


def _ranges(name: str) -> list[tuple[str, int, int]]:
    layout = expand(load(ROOT / "scripts" / name, loader=load_scene_names))
    return [(p.run.event, p.start, p.hold_end) for p in layout.runs]


@pytest.mark.parametrize("name", ["lightbulb", "pour"])
def test_show_chart_is_pinned(name: str, in_root: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", f"scripts/{name}.dial"]) == 0
    golden(DATA / "golden" / f"{name}.show", capsys.readouterr().out)


def test_lightbulb_tick_ranges_follow_the_paper() -> None:
    runs = _ranges("lightbulb.dial")
    # Fig. 10's approach in two parts: to 10 cm above the bulb while preshaping, then down
    # onto it, watched; each reaction (thumb, middle) backs off and waits for the thumb.
    assert runs[:8] == [
        ("to_bulb", 1, 6),
        ("preshape", 3, 6),
        ("settle", 7, 7),
        ("lower", 8, 11),
        *[("back_off", 12, 13), ("settle", 14, 14)] * 2,
    ]
    # Added to the paper's script: feel for the glass along two axes and centre over it,
    # each time once the thumb is at rest (a while loop: shown once, run zero or more times).
    assert runs[8:16] == [
        ("settle", 15, 15),
        ("feel_glass", 16, 16),
        ("centre_y", 17, 19),
        ("turn_probe", 20, 25),
        ("settle", 26, 26),
        ("feel_glass", 27, 27),
        ("centre_x", 28, 30),
        ("turn_back", 31, 36),
    ]
    # One stroke of the loop that ends when the tug comes free (shown once): the paper's
    # grasp and twist, a hold and the tug; if the bulb held, release, follow it up, turn back.
    assert runs[16:] == [
        ("grasp_bulb", 37, 37),
        ("twist_hand", 38, 46),
        ("twist_armCCW", 38, 48),
        ("tug", 49, 49),
        ("ungrasp", 50, 52),
        ("follow", 52, 52),
        ("preshape", 53, 59),
        ("twist_armCW", 53, 59),
        ("retract_arm", 60, 69),
    ]


def test_pour_tick_ranges_follow_the_paper() -> None:
    runs = _ranges("pour.dial")
    assert runs[:2] == [("get_top", 1, 13), ("pit_top", 1, 13)]
    # Added to the paper's script: feel for the knob along two axes and centre over it, each
    # time once the thumb is at rest (a while loop: shown once, run zero or more times), then
    # locate lid and pitcher from where the hand is.
    assert runs[2:11] == [
        ("settle", 14, 14),
        ("feel_knob", 15, 15),
        ("centre", 16, 17),
        ("turn", 18, 23),
        ("settle", 24, 24),
        ("feel_knob", 25, 25),
        ("centre", 26, 27),
        ("turn_back", 28, 33),
        ("found", 34, 34),
    ]
    # The paper's lid and approach; the last 13 cm down beside the pitcher is watched, and
    # each reaction (thumb, middle) backs up and waits for thumb and middle to rest.
    assert runs[11:24] == [
        ("grab_top", 34, 34),
        ("lift_top", 35, 44),
        ("pit_top", 45, 48),
        ("to_grasp", 49, 54),
        ("prepit", 49, 54),
        ("settle", 55, 55),
        ("lower_pit", 56, 58),
        *[("back_up", 59, 60), ("settle", 61, 61), ("settle", 62, 62)] * 2,
    ]
    assert runs[24:26] == [("grabpit", 63, 63), ("pourpit", 64, 71)]
    (release, r0, r1), (retract, t0, _) = runs[26:]
    assert (release, retract) == ("prepit", "retract_arm")
    assert 71 < r0 <= r1 < t0


@pytest.mark.parametrize("name", ["lightbulb.dial", "pour.dial"])
def test_task_scripts_are_formatted(name: str, in_root: Path) -> None:
    assert main(["fmt", "--check", f"scripts/{name}"]) == 0
