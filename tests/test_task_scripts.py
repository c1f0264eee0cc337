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
    assert runs[:2] == [("to_bulb", 1, 10), ("preshape", 6, 10)]
    # Added to the paper's script: feel for the glass along two axes and centre over it,
    # each time once the thumb is at rest (a while loop: shown once, run zero or more times).
    assert runs[2:10] == [
        ("settle", 11, 11),
        ("feel_glass", 12, 12),
        ("centre_y", 13, 15),
        ("turn_probe", 16, 21),
        ("settle", 22, 22),
        ("feel_glass", 23, 23),
        ("centre_x", 24, 26),
        ("turn_back", 27, 32),
    ]
    first_iteration = [
        ("grasp_bulb", 33, 33),
        ("twist_hand", 34, 42),
        ("twist_armCCW", 34, 42),
        ("ungrasp", 43, 45),
        ("preshape", 46, 52),
        ("twist_armCW", 46, 52),
    ]
    # Every repeated iteration is the same 20 ticks, shifted.
    iterations = (len(runs) - 10 - 4) // 6
    assert iterations >= 2
    for i in range(iterations):
        shifted = [(e, s + 20 * i, h + 20 * i) for e, s, h in first_iteration]
        assert runs[10 + 6 * i : 16 + 6 * i] == shifted
    last = 32 + 20 * iterations
    assert runs[-4:] == [
        ("grasp_bulb", last + 1, last + 1),
        ("twist_hand", last + 2, last + 10),
        ("twist_armCCW", last + 2, last + 10),
        ("retract_arm", last + 11, last + 20),
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
