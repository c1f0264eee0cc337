"""What the checks that run before any simulator need to know of a robot, without MuJoCo.

A world file's hand poses and arm programs, and a script's masks, fingers and drives, are
checked against the robot the scene binds them to: which mask bits are joints, their
ranges, which fingers have a tactile array, how many arm joints there are and their ranges.
Read from the robot's ``robot.toml`` and its MJCF (:mod:`dial.robots.ranges`), once per
process and folder.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

from dial.errors import DialError
from dial.resources import data_dir
from dial.robots.profile import DEFAULT_ROBOT, FINGER_NAMES, RobotProfile, load_profile
from dial.robots.ranges import Range, joint_ranges

JOINT_KINDS = ("abd", "mcp", "pip", "dip")  # joint j of a finger, as world files name it


@dataclass(frozen=True)
class RobotFacts:
    """A robot as the checker sees it. ``hand_ranges``: each mask bit that is a joint, with its
    range (rad); ``tactile``: the fingers (0-3) that have an array."""

    name: str
    arm_name: str
    arm_ranges: tuple[Range, ...]
    hand_ranges: Mapping[int, Range]
    tactile: frozenset[int]

    @property
    def mask(self) -> int:
        """The 16-bit mask of every joint the hand has."""
        return sum(1 << bit for bit in self.hand_ranges)

    def joint_name(self, bit: int) -> str:
        """``"thumb dip"``: a mask bit as world files and messages name it."""
        return f"{FINGER_NAMES[bit // 4]} {JOINT_KINDS[bit % 4]}"

    def lacks(self, mask: int) -> list[int]:
        """The bits of ``mask`` that are no joint of this hand."""
        return [bit for bit in range(16) if mask >> bit & 1 and bit not in self.hand_ranges]


def facts_of(profile: RobotProfile) -> RobotFacts:
    """The facts of a loaded profile (its MJCF read for the joint ranges)."""
    ranges = joint_ranges(profile.model, profile.folder)

    def range_of(joint: str) -> Range:
        if joint not in ranges:
            raise DialError(
                f"{profile.path}: joint '{joint}' has no range in {profile.model.name} "
                "(dial robots check says more)"
            )
        return ranges[joint]

    hand = {
        4 * f + j: range_of(joint)
        for f, finger in enumerate(profile.fingers)
        for j, joint in enumerate(finger.joints)
    }
    return RobotFacts(
        name=profile.name,
        arm_name=profile.arm.name,
        arm_ranges=tuple(range_of(j) for j in profile.arm.joints),
        hand_ranges=MappingProxyType(hand),
        tactile=frozenset(f for f, g in enumerate(profile.fingers) if g.tactile is not None),
    )


@functools.cache
def robot_facts(folder: Path) -> RobotFacts:
    """The facts of the robot in ``folder`` (read once per process)."""
    return facts_of(load_profile(folder))


def default_facts() -> RobotFacts:
    """The facts of the default robot (the robot of a script checked without a scene)."""
    return robot_facts((data_dir("models") / DEFAULT_ROBOT).resolve())
