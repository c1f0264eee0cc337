"""The joint-range table of the static checks agrees with the MJCF, and the checks use it."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from dial.errors import ScriptError
from dial.instructions.limits import ARM_RANGES, HAND_RANGES, drive_problem, hand_problem
from dial.parser import check_text
from dial.scene import WorldFileError, load_scene_names, models_dir
from dial.scene.world import JOINTS

MODEL = models_dir() / "utah_hand_puma"


def _range(element: ET.Element) -> tuple[float, float]:
    lo, hi = element.get("range", "").split()
    return float(lo), float(hi)


def test_arm_ranges_are_the_mjcf_ones() -> None:
    joints = {j.get("name"): j for j in ET.parse(MODEL / "puma560.xml").getroot().iter("joint")}
    assert tuple(_range(joints[f"puma_joint{i}"]) for i in range(1, 7)) == ARM_RANGES


def test_hand_ranges_are_the_mjcf_classes_of_joints_0_to_3() -> None:
    root = ET.parse(MODEL / "utah_hand.xml").getroot()
    classes = {d.get("class"): d for d in root.iter("default")}
    kinds = {"abd": "abduction", "mcp": "mcp", "pip": "pip", "dip": "dip"}
    for kind, name in kinds.items():
        joint = classes[name].find("joint")
        assert joint is not None and HAND_RANGES[kind] == _range(joint)
    for joint in root.iter("joint"):  # joint j of every finger has the class of JOINTS[j]
        if joint.get("name", "").split("_")[-1] in ("j0", "j1", "j2", "j3"):
            j = int(joint.get("name", "")[-1])
            assert joint.get("class") == kinds[JOINTS[j]]


@pytest.mark.parametrize(
    ("joint", "deg", "problem"),
    [
        (
            3,
            350,
            "a drive of 350 deg takes PUMA joint 3 beyond its range (-225 to 45 deg, "
            "270 deg in all) by 80 deg from wherever it starts",
        ),
        (3, 270, None),
        (3, -270, None),
        (6, 500, None),
        (
            1,
            -330,
            "a drive of -330 deg takes PUMA joint 1 beyond its range (-160 to 160 deg, "
            "320 deg in all) by 10 deg from wherever it starts",
        ),
    ],
)
def test_drive_problem(joint: int, deg: float, problem: str | None) -> None:
    assert drive_problem(joint, math.radians(deg)) == problem


def test_hand_problem() -> None:
    assert hand_problem("mcp", math.radians(90)) is None
    assert hand_problem("mcp", math.radians(-20)) is None
    assert hand_problem("pip", math.radians(-8)) == (
        "-8 deg is beyond the pip joint's lower limit of -5 deg by 3 deg "
        "(its range is -5 to 100 deg)"
    )


@pytest.mark.parametrize(
    ("table", "message"),
    [
        (
            "[poses.fist]\nindex = [0, 120, 0, 0]",
            "poses.fist.index.mcp: 120 deg is beyond the mcp joint's upper limit of 90 deg by "
            "30 deg (its range is -20 to 90 deg)",
        ),
        (
            '[programs]\nspin = "DRIVE 5 250"',
            "programs.spin line 1: a drive of 250 deg takes PUMA joint 5 beyond its range "
            "(-100 to 100 deg, 200 deg in all) by 50 deg from wherever it starts",
        ),
    ],
    ids=["pose", "stored-drive"],
)
def test_a_world_beyond_a_joint_range_is_an_error_at_scene(
    tmp_path: Path, table: str, message: str
) -> None:
    (tmp_path / "w.toml").write_text(f'extends = "surface"\n{table}\n')
    with pytest.raises(WorldFileError) as e:
        load_scene_names("w.toml", tmp_path)
    assert str(e.value).endswith(message)
    with pytest.raises(ScriptError) as info:
        check_text("@scene w.toml\n", str(tmp_path / "s.dial"), loader=load_scene_names)
    (d,) = info.value.diagnostics
    assert (d.span.line, d.span.col) == (1, 8) and d.message.endswith(message)
