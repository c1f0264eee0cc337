"""Joint ranges of the robot model, for the checks that need no simulator.

The values are the ``range`` attributes of ``models/utah_hand_puma/puma560.xml`` (PUMA joints
1-6) and ``utah_hand.xml`` (the hand's joint classes), in radians as there;
``tests/test_joint_limits.py`` reads the MJCF and checks that they still agree.
"""

from __future__ import annotations

import math

# PUMA joints 1-6: (lower, upper) in rad.
ARM_RANGES: tuple[tuple[float, float], ...] = (
    (-2.7925, 2.7925),
    (-0.7854, 3.9270),
    (-3.9270, 0.7854),
    (-1.9199, 2.9671),
    (-1.7453, 1.7453),
    (-4.6426, 4.6426),
)
# Hand joints by kind (joint j of every finger, thumb included): (lower, upper) in rad.
HAND_RANGES: dict[str, tuple[float, float]] = {
    "abd": (-0.3491, 0.3491),
    "mcp": (-0.3491, 1.5708),
    "pip": (-0.0873, 1.7453),
    "dip": (-0.0873, 1.5708),
}
_SLACK = 1e-6  # rad: a value written as the limit in degrees is within it


def _deg(rad: float, digits: int = 1) -> str:
    return f"{round(math.degrees(rad), digits):g}"


def _digits(excess: float) -> int:
    """Decimals that show an excess (rad) as more than 0 deg (a limit of 79.98 deg, not 80)."""
    digits = 1
    while digits < 4 and round(math.degrees(excess), digits) == 0:
        digits += 1
    return digits


def drive_problem(
    joint: int,
    angle: float,
    ranges: tuple[tuple[float, float], ...] = ARM_RANGES,
    arm: str = "PUMA",
) -> str | None:
    """Why ``DRIVE joint angle`` (relative, rad) cannot stay in joint's range, or None.

    A drive turns the joint from wherever it is, so only a turn larger than the whole range
    is known to overshoot before the run. ``ranges``: the arm's (the PUMA's by default), and
    ``arm`` what messages call it.
    """
    if not 1 <= joint <= len(ranges):
        return f"the {arm} has joints 1 to {len(ranges)}, not {joint}"
    lo, hi = ranges[joint - 1]
    excess = abs(angle) - (hi - lo)
    if excess <= _SLACK:
        return None
    return (
        f"a drive of {_deg(angle)} deg takes {arm} joint {joint} beyond its range "
        f"({_deg(lo)} to {_deg(hi)} deg, {_deg(hi - lo)} deg in all) by {_deg(excess)} deg "
        "from wherever it starts"
    )


def hand_problem(kind: str, angle: float, limits: tuple[float, float] | None = None) -> str | None:
    """Why a hand pose angle (rad) of a joint of ``kind`` is out of its range (``limits``,
    else the first robot's for that kind), or None."""
    lo, hi = HAND_RANGES[kind] if limits is None else limits
    if lo - _SLACK <= angle <= hi + _SLACK:
        return None
    limit, excess = (lo, lo - angle) if angle < lo else (hi, angle - hi)
    side = "lower" if angle < lo else "upper"
    n = _digits(excess)
    return (
        f"{_deg(angle, n)} deg is beyond the {kind} joint's {side} limit of {_deg(limit, n)} deg "
        f"by {_deg(excess, n)} deg (its range is {_deg(lo, n)} to {_deg(hi, n)} deg)"
    )
