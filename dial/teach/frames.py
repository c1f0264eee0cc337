"""Tool frames as world files write them: position and fixed-axis roll, pitch, yaw."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from dial.backend.snapshot import FloatArray

GIMBAL = 1e-3  # cos(pitch) below this: pitch is +-90 deg, and only roll -/+ yaw is defined


def fixed(value: float, digits: int = 1) -> str:
    """``value`` with ``digits`` decimals, never ``-0.0``."""
    return f"{round(float(value), digits) + 0.0:.{digits}f}"


def mm_text(pos: Iterable[float]) -> str:
    """``[x, y, z]`` in mm from metres."""
    return "[" + ", ".join(fixed(v * 1000) for v in pos) + "]"


def half_turn(deg: float) -> float:
    """An angle in degrees with -180 written as 180 (they are the same turn)."""
    return 180.0 if deg <= -179.95 else deg


def deg_text(angles: Iterable[float]) -> str:
    """``[r, p, y]`` of angles already in degrees."""
    return "[" + ", ".join(fixed(half_turn(v)) for v in angles) + "]"


def matrix_rpy(rot: FloatArray) -> tuple[float, float, float]:
    """Roll, pitch, yaw (deg) with ``rot = Rz(yaw) Ry(pitch) Rx(roll)``, the inverse of
    :func:`dial.geometry.rpy_matrix`.

    Of the two solutions, the one with the smaller roll and yaw is taken (a hand pointing
    down is ``[0, 180, 0]``, not ``[180, 0, 180]``); at pitch +-90 deg yaw is taken as 0.
    """
    r = np.asarray(rot, dtype=np.float64)
    pitch = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    if math.cos(pitch) < GIMBAL:
        pitch = math.copysign(math.pi / 2, pitch)
        sign = 1.0 if pitch > 0 else -1.0
        roll, yaw = math.atan2(sign * r[0, 1], r[1, 1]), 0.0
    else:
        roll, yaw = math.atan2(r[2, 1], r[2, 2]), math.atan2(r[1, 0], r[0, 0])
        flipped = (_wrap(roll + math.pi), math.pi - pitch, _wrap(yaw + math.pi))
        if max(abs(flipped[0]), abs(flipped[2])) < max(abs(roll), abs(yaw)) - 1e-9:
            roll, pitch, yaw = flipped
    return (
        math.degrees(roll) + 0.0,
        math.degrees(_wrap(pitch)) + 0.0,
        math.degrees(yaw) + 0.0,
    )


def _wrap(angle: float) -> float:
    """The angle in (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2 * math.pi)


def relative(
    pos: FloatArray, rot: FloatArray, frame_pos: FloatArray, frame_rot: FloatArray, world_axes: bool
) -> tuple[FloatArray, FloatArray]:
    """A pose in an object's frame (``world_axes``: offset from its origin, world axes), so that
    :func:`dial.geometry.location_pose` gives ``pos``, ``rot`` back."""
    if world_axes:
        return pos - frame_pos, rot
    return frame_rot.T @ (pos - frame_pos), frame_rot.T @ rot
