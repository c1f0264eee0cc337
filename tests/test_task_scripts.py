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
    assert runs[:9] == [
        ("get_top", 1, 13),
        ("pit_top", 1, 13),
        ("grab_top", 14, 14),
        ("lift_top", 15, 24),
        ("pit_top", 25, 28),
        ("to_grasp", 29, 35),
        ("prepit", 29, 35),
        ("grabpit", 36, 36),
        ("pourpit", 37, 44),
    ]
    (release, r0, r1), (retract, t0, _) = runs[9:]
    assert (release, retract) == ("prepit", "retract_arm")
    assert 44 < r0 <= r1 < t0


@pytest.mark.parametrize("name", ["lightbulb.dial", "pour.dial"])
def test_task_scripts_are_formatted(name: str, in_root: Path) -> None:
    assert main(["fmt", "--check", f"scripts/{name}"]) == 0
