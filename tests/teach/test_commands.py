"""The teaching session's command parser: forms, units, and errors that list what is valid."""

from __future__ import annotations

import math

import pytest

from dial.scene.valii import Appro, Depart, Drive, Move
from dial.teach.commands import (
    SPECS,
    Arm,
    CommandError,
    Ex,
    FingerJoints,
    Jog,
    Limp,
    Pose,
    SaveLocation,
    SavePose,
    Word,
    help_text,
    parse_command,
)


def test_jog_three_or_six_numbers_in_mm_and_deg_world_frame_by_default() -> None:
    assert parse_command("jog 10 0 -5") == Jog("world", (0.01, 0.0, -0.005), (0.0, 0.0, 0.0))
    jog = parse_command("jog tool 0 0 1cm 0 0 90")
    assert isinstance(jog, Jog) and jog.frame == "tool"
    assert jog.delta == (0.0, 0.0, 0.01)
    assert jog.turn[2] == pytest.approx(math.pi / 2)


def test_jog_one_axis() -> None:
    assert parse_command("jog z -20") == Jog("world", (0.0, 0.0, -0.02), (0.0, 0.0, 0.0))
    jog = parse_command("jog tool rx 0.5rad")
    assert jog == Jog("tool", (0.0, 0.0, 0.0), (0.5, 0.0, 0.0))


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("jog 1 2", "usage: jog [world|tool]"),
        ("jog w 10", "usage: jog [world|tool]"),
        ("jog z 10kg", "unit 'kg' is not a length unit"),
        ("jgo z 10", "unknown command 'jgo'; commands: jog, drive, finger, limp, goto"),
        ("finger pinky mcp 10", "expected a finger: index, middle, ring or thumb"),
        ("finger index knuckle 10", "unknown joint 'knuckle'; joints: abd, mcp, pip, dip"),
        ("finger index 1 2 3", "usage: finger F JOINT DEG"),
        ("limp pinky", "unknown finger 'pinky'; fingers: index, middle, ring, thumb"),
        ("limp for=20s", "for= must be from 0 to 10 s"),
        ("limp speed=3", "unknown option 'speed='; options: fingers=, for="),
        ("pose open_hand fingers=0x10000", "bits above bit 15"),
        ("save thing x", "usage: save pose NAME"),
        ("save pose 9lives", "expected a pose name"),
        ("save location x relative-to", "usage: save location NAME"),
        ("save location x axes=world", "axes=world applies to a location relative-to"),
        ("drive 0 10", "expected an arm joint number from 1 to 9"),
        ("goto", "expected 'MOVE LOCATION'"),
        ("ex", "usage: ex PROGRAM"),
        ("where now", "usage: where"),
    ],
)
def test_bad_lines_say_what_is_valid(line: str, message: str) -> None:
    with pytest.raises(CommandError) as e:
        parse_command(line)
    assert message in str(e.value)


def test_valii_statements_and_programs() -> None:
    assert parse_command("goto home") == Arm(Move(1, "home", False), "goto home")
    assert parse_command("moves home") == Arm(Move(1, "home", True), "moves home")
    appro = parse_command("appro lid_grasp 50mm")
    assert isinstance(appro, Arm) and appro.statement == Appro(1, "lid_grasp", 0.05)
    assert parse_command("depart 0.1") == Arm(Depart(1, 0.1), "depart 0.1")
    drive = parse_command("drive 6 -90")
    assert isinstance(drive, Arm) and drive.statement == Drive(1, 6, pytest.approx(-math.pi / 2))
    assert parse_command("ex get_top") == Ex("get_top")


def test_finger_relative_one_joint_or_absolute_four() -> None:
    one = parse_command("finger thumb mcp -10")
    assert one == FingerJoints(3, (1,), (pytest.approx(math.radians(-10)),), True)
    four = parse_command("finger 1 0 20 30 20")
    assert isinstance(four, FingerJoints) and four.finger == 1 and not four.relative
    assert four.angles == pytest.approx(tuple(math.radians(a) for a in (0, 20, 30, 20)))


def test_limp_and_pose_masks() -> None:
    assert parse_command("limp") == Limp(0xFFFF, 0.5)
    assert parse_command("limp middle thumb for=1s") == Limp(0xF0F0, 1.0)
    assert parse_command("limp fingers=0x000F") == Limp(0x000F, 0.5)
    assert parse_command("pose prelight") == Pose("prelight", 0xFFFF)
    assert parse_command("pose prelight fingers=0x00F0") == Pose("prelight", 0x00F0)


def test_save_forms() -> None:
    assert parse_command("save pose grip fingers=0xF0F0") == SavePose("grip", 0xF0F0, False)
    assert parse_command("save pose grip replace") == SavePose("grip", 0xFFFF, True)
    assert parse_command("save location here") == SaveLocation("here", None, False, False)
    loc = parse_command("save location near relative-to bulb axes=world replace")
    assert loc == SaveLocation("near", "bulb", True, True)


def test_blank_and_comment_lines_are_no_command() -> None:
    assert parse_command("   ") is None
    assert parse_command("# a comment") is None
    assert parse_command("where   # trailing comment") == Word("where")


def test_help_lists_every_command_and_one_usage() -> None:
    text = help_text()
    for verb, spec in SPECS.items():
        assert spec.usage in text, verb
    assert help_text("limp").startswith("limp [FINGER...]")
    with pytest.raises(CommandError, match="unknown command 'fly'; commands: jog"):
        help_text("fly")
