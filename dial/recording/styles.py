"""The plots' series names and colours, per robot: a joint's colour is the same in every
finger's plot, a tendon hand's extensor is drawn in its joint's colour, darker."""

from __future__ import annotations

from dataclasses import dataclass

from dial.backend.model import FINGERS
from dial.robots.profile import RobotProfile

Color = tuple[int, int, int]

JOINTS = ("abd", "mcp", "pip", "dip")
JOINT_COLORS: tuple[Color, ...] = ((255, 202, 40), (239, 83, 80), (102, 187, 106), (66, 165, 245))
EXTENSOR_SHADE = 0.55  # an extensor is drawn in its joint's colour, darker
ARM_COLORS: tuple[Color, ...] = (
    (239, 83, 80),
    (255, 167, 38),
    (255, 238, 88),
    (102, 187, 106),
    (66, 165, 245),
    (171, 71, 188),
    (141, 110, 99),
)
TASK_COLOR = (255, 255, 255)


def shade(color: Color, factor: float) -> Color:
    r, g, b = (round(c * factor) for c in color)
    return (r, g, b)


@dataclass(frozen=True)
class Series:
    """One plot's lines: their names and colours."""

    names: list[str]
    colors: list[Color]


def finger_series(profile: RobotProfile) -> list[tuple[str, Series, Series]]:
    """Per finger: its name, its joints' series, its load readings' series (a tendon hand's
    flexor and extensor per joint, another hand's one torque per joint)."""
    out = []
    for finger, spec in zip(FINGERS, profile.fingers, strict=True):
        names = [f"{finger} {j}" for j in JOINTS[: len(spec.joints)]]
        joints = Series(names, list(JOINT_COLORS[: len(names)]))
        loads = joints
        if profile.hand.load == "tendon":
            loads = Series(
                [f"{n} {k}" for n in names for k in ("flexor", "extensor")],
                [shade(c, f) for c in joints.colors for f in (1.0, EXTENSOR_SHADE)],
            )
        out.append((finger, joints, loads))
    return out


def arm_series(profile: RobotProfile) -> Series:
    names = [f"joint {i}" for i in range(1, len(profile.arm.joints) + 1)]
    return Series(names, list(ARM_COLORS[: len(names)]))
