"""``dial robots [--json]`` lists the bundled robots; ``dial robots check DIR`` reports each
problem of a robot folder at its robot.toml line and column, with what was expected."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from dial.cli import main
from tests.conftest import ROOT

MODELS = ROOT / "models"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out + out.err


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    """A copy of the second robot's folder, to break."""
    folder = tmp_path / "allegro_panda"
    shutil.copytree(MODELS / "allegro_panda", folder, ignore=shutil.ignore_patterns("worlds"))
    return folder


def edit(folder: Path, old: str, new: str, file: str = "robot.toml") -> None:
    path = folder / file
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def line_of(folder: Path, needle: str) -> int:
    lines = (folder / "robot.toml").read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if needle in line)


def test_lists_both_bundled_robots_as_json(capsys: pytest.CaptureFixture[str]) -> None:
    status, out = run(capsys, "robots", "--json")
    assert status == 0
    robots = {r["name"]: r for r in json.loads(out)}
    assert set(robots) == {"utah_hand_puma", "allegro_panda"}
    utah, allegro = robots["utah_hand_puma"], robots["allegro_panda"]
    assert [f["name"] for f in allegro["fingers"]] == ["index", "middle", "ring", "thumb"]
    assert len(allegro["arm"]["joints"]) == 7 and len(utah["arm"]["joints"]) == 6
    assert allegro["sensors"]["load"] == "joint" and utah["sensors"]["load"] == "tendon"
    assert allegro["sensors"]["tactile"] == ["index", "middle", "ring", "thumb"]
    assert allegro["sensors"]["taxels"] == [16, 16]
    assert {"pour", "lightbulb", "surface", "containment"} <= set(utah["scenes"])
    assert Path(allegro["folder"]) == (MODELS / "allegro_panda").resolve()


def test_lists_them_as_text(capsys: pytest.CaptureFixture[str]) -> None:
    status, out = run(capsys, "robots")
    assert status == 0
    assert out.index("utah_hand_puma") < out.index("allegro_panda")  # the default first
    assert "7 joints (panda_joint1 .. panda_joint7), tool site allegro_palm" in out
    assert "load: joint torques (N m); 16x16 tactile on index, middle, ring, thumb" in out


@pytest.mark.parametrize("name", ["utah_hand_puma", "allegro_panda"])
def test_bundled_robots_check_clean(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    status, out = run(capsys, "robots", "check", str(MODELS / name))
    assert (status, out.strip()) == (0, f"{MODELS / name}: OK")


def test_renamed_joint(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, '"allegro_ring_j2", "allegro_ring_j3"]', '"allegro_ring_pip", "allegro_ring_j3"]')
    status, out = run(capsys, "robots", "check", str(robot))
    line = line_of(robot, "allegro_ring_pip")
    assert status == 1
    assert (
        f"robot.toml:{line}:49: fingers[2].joints[2]: no joint 'allegro_ring_pip' in "
        "allegro_panda.xml; did you mean" in out
    )
    assert out.count("robot.toml:") == 1 and out.rstrip().endswith("1 problem")


def test_renamed_in_the_model(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, '<joint name="panda_joint4"', '<joint name="panda_elbow"', "panda.xml")
    edit(robot, 'joint="panda_joint4"', 'joint="panda_elbow"', "panda.xml")
    status, out = run(capsys, "robots", "check", str(robot))
    assert status == 1
    line = line_of(robot, 'joints = ["panda')
    assert f"robot.toml:{line}:59: arm.joints[3]: no joint 'panda_joint4' in " in out


def test_missing_site(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, '<site name="thumb_tip"', '<site name="thumb_end"', "allegro_hand.xml")
    status, out = run(capsys, "robots", "check", str(robot))
    line = line_of(robot, '"allegro_thumb_tip"')
    assert status == 1
    assert (
        f"robot.toml:{line}:12: fingers[3].tip_site: no site 'allegro_thumb_tip' in "
        "allegro_panda.xml; did you mean 'allegro_thumb_end' or" in out
    )


def test_tactile_sensor_of_the_wrong_kind(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, 'tactile = "allegro_middle_tactile"', 'tactile = "allegro_middle_j3"')
    status, out = run(capsys, "robots", "check", str(robot))
    line = line_of(robot, 'tactile = "allegro_middle_j3"')
    assert status == 1
    assert (
        f"robot.toml:{line}:11: fingers[1].tactile: sensor 'allegro_middle_j3' is a "
        "jointactuatorfrc sensor; expected a tactile sensor" in out
    )
    assert f' {line} | tactile = "allegro_middle_j3"' in out  # the line, with a caret
    assert "^^^^^^^^^^^^^^^^^^^" in out


def test_toml_syntax_error(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, "lever = 0.012", "lever = 0.012 m")
    status, out = run(capsys, "robots", "check", str(robot))
    line = line_of(robot, "lever = 0.012 m")
    assert status == 1
    assert f"robot.toml:{line}:15: invalid TOML: Expected newline or end of document" in out


def test_missing_limit(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, "load = 0.7\n", "")
    status, out = run(capsys, "robots", "check", str(robot))
    line = line_of(robot, "[limits]")
    assert status == 1
    assert f"robot.toml:{line}:1: limits: missing key 'load' (keys: joint_slack, load, " in out


def test_joint_without_a_range_in_the_model(
    robot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    edit(robot, 'range="-1.7628 1.7628" ', "", "panda.xml")
    edit(
        robot,
        'joint="panda_joint2" class="panda"',
        'joint="panda_joint2" ctrlrange="-1 1"',
        "panda.xml",
    )
    status, out = run(capsys, "robots", "check", str(robot))
    assert status == 1
    assert (
        "arm.joints[1]: joint 'panda_joint2' has no limit in allegro_panda.xml; expected a range"
        in out
    )


def test_every_problem_in_one_pass(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    edit(robot, 'tool_site = "allegro_palm"', 'tool_site = "palm"')
    edit(robot, "saturation_time = 1.0", "saturation_time = -1")
    edit(robot, 'load = "joint"', 'load = "tendons"')
    status, out = run(capsys, "robots", "check", str(robot))
    assert status == 1
    assert "arm.tool_site: no site 'palm'" in out
    assert "limits.saturation_time: expected a positive number, got -1" in out
    assert "hand.load: expected one of tendon, actuator, joint, got 'tendons'" in out
    assert out.rstrip().endswith("3 problems")


def test_not_a_robot_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    status, out = run(capsys, "robots", "check", str(tmp_path))
    assert status == 1
    assert out.strip() == f"dial: {tmp_path}: not a robot folder (no robot.toml in it)"
