"""`dial check` checks what a script asks of the scene's robot: tactile on a finger without
an array, a mask bit for a joint the hand lacks, a DRIVE of a joint the arm lacks; each a
caret diagnostic that names the robot."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from dial.cli import main
from tests.conftest import ROOT

MODELS = ROOT / "models"


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    """The second robot without the ring's tactile array, and with a 3-joint thumb."""
    folder = tmp_path / "lesser"
    shutil.copytree(MODELS / "allegro_panda", folder, ignore=shutil.ignore_patterns("worlds"))
    toml = folder / "robot.toml"
    text = toml.read_text().replace('name = "allegro_panda"', 'name = "lesser"')
    text = text.replace('tactile = "allegro_ring_tactile"\n', "")
    for key in ("joints", "servos"):
        thumb = ", ".join(f'"allegro_thumb_j{j}"' for j in range(4))
        old = f"{key} = [{thumb}]"
        assert old in text
        text = text.replace(old, old.replace(', "allegro_thumb_j3"', ""))
    toml.write_text(text)
    world = tmp_path / "world.toml"
    scene = MODELS / "allegro_panda" / "scene_surface.xml"  # the checks read no more of it
    world.write_text(
        f'robot = "lesser"\n[scene]\nmodel = "{scene}"\n[objects]\nblock = "surface_block"\n'
    )
    return folder


def check(tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str) -> tuple[int, str]:
    script = tmp_path / "s.dial"
    script.write_text("@scene world.toml\n" + body)
    status = main(["check", str(script)])
    return status, capsys.readouterr().out


def test_the_lesser_robot_checks_clean(robot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["robots", "check", str(robot)])
    assert status == 0, capsys.readouterr().out


def test_tactile_on_a_finger_without_an_array(
    robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out = check(
        tmp_path,
        capsys,
        "% t tactile_contact finger=ring\n"
        "% g guarded_move 0 0 -1 until=tactile sense=ring\n"
        "% r record_contact finger=ring\n"
        "% ok record_contact finger=ring source=links\n"
        "% fine guarded_move 0 0 -1 until=tactile\n"
        "t #\ng #\nr #\nok #\nfine #\n",
    )
    assert status == 1
    message = (
        "robot 'lesser' has no tactile array on the ring (fingers with one: index, middle, thumb)"
    )
    assert f"s.dial:2:28: event 't': {message}" in out
    assert f"s.dial:3:45: event 'g': {message}" in out
    assert f"s.dial:4:27: event 'r': {message}" in out
    assert "event 'ok'" not in out and "event 'fine'" not in out
    assert " 2 | % t tactile_contact finger=ring\n   |                            ^^^^" in out


def test_a_mask_bit_for_a_joint_the_hand_lacks(
    robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out = check(
        tmp_path,
        capsys,
        '% g grasp_force "0xF060_0x2020 5N"\n% l limp fingers=0x8000\n% ok limp fingers=0x7FFF\n'
        "g #\nl #\nok #\n",
    )
    assert status == 1
    assert (
        "s.dial:2:18: event 'g': robot 'lesser' has no thumb dip joint (mask bit 15); "
        "its joints are mask 0x7FFF" in out
    )
    assert "s.dial:3:18: event 'l': robot 'lesser' has no thumb dip joint" in out
    assert "event 'ok'" not in out


def test_a_drive_of_a_joint_the_arm_lacks(
    robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out = check(
        tmp_path,
        capsys,
        '% d puma_command "drive 8 10"\n% ok puma_command "drive 7 10"\nd #\nok #\n',
    )
    assert status == 1
    assert "s.dial:2:25: event 'd': robot 'lesser': the Panda has joints 1 to 7, not 8" in out
    assert "event 'ok'" not in out


def test_a_pose_for_a_joint_the_hand_lacks(
    robot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    world = tmp_path / "world.toml"
    world.write_text(world.read_text() + "[poses.p]\nthumb = [0, 30, 10, 10]\n")
    status, out = check(tmp_path, capsys, '% p hand_pose "p"\np #\n')
    assert status == 1
    assert "poses.p.thumb: expected a list of 3 numbers" in out
    world.write_text(world.read_text().replace("[0, 30, 10, 10]", "{ dip = 10 }"))
    status, out = check(tmp_path, capsys, '% p hand_pose "p"\np #\n')
    assert "poses.p.thumb.dip: unknown key; valid keys: abd, mcp, pip" in out
