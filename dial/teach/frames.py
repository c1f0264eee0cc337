"""Tool frames as world files write them: position and fixed-axis roll, pitch, yaw."""

from __future__ import annotations

from collections.abc import Iterable

from dial.geometry import matrix_rpy
from dial.robot.snapshot import FloatArray

__all__ = ["deg_text", "fixed", "half_turn", "matrix_rpy", "mm_text", "relative"]


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


def relative(
    pos: FloatArray, rot: FloatArray, frame_pos: FloatArray, frame_rot: FloatArray, world_axes: bool
) -> tuple[FloatArray, FloatArray]:
    """A pose in an object's frame (``world_axes``: offset from its origin, world axes), so that
    :func:`dial.geometry.location_pose` gives ``pos``, ``rot`` back."""
    if world_axes:
        return pos - frame_pos, rot
    return frame_rot.T @ (pos - frame_pos), frame_rot.T @ rot
