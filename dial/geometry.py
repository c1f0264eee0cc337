"""Rotations, time scalings and named locations: the geometry every layer shares.

Pure numpy. Rotations are (3, 3) matrices; rpy angles are fixed-axis roll, pitch, yaw in
rad, as in world files.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from dial.scene.world import World

FloatArray = NDArray[np.float64]

Pose = tuple[FloatArray, FloatArray]  # position (3,) m, rotation (3, 3)


def rpy_matrix(rpy: tuple[float, float, float]) -> FloatArray:
    """R = Rz(yaw) Ry(pitch) Rx(roll), fixed axes."""
    (cr, sr), (cp, sp), (cy, sy) = ((np.cos(a), np.sin(a)) for a in rpy)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


GIMBAL = 1e-3  # cos(pitch) below this: pitch is +-90 deg, and only roll -/+ yaw is defined


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


def smooth(u: float) -> float:
    """Minimum-jerk time scaling of a segment: zero velocity and acceleration at both ends."""
    u = min(1.0, max(0.0, u))
    return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)


def smooth_array(u: FloatArray) -> FloatArray:
    """:func:`smooth` of each element, bit for bit (the same operations in the same order)."""
    u = np.minimum(1.0, np.maximum(0.0, u))
    out: FloatArray = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    return out


def slerp(r0: FloatArray, r1: FloatArray, u: float) -> FloatArray:
    """Rotation between ``r0`` and ``r1`` (u in [0, 1]) about their relative axis."""
    return Slerp(r0, r1)(u)


_EYE = np.eye(3)
_EYE.flags.writeable = False


class Slerp:
    """Rotations between ``r0`` and ``r1`` about their relative axis, the axis found once."""

    def __init__(self, r0: FloatArray, r1: FloatArray) -> None:
        self.r0 = r0
        rel = r0.T @ r1
        self.angle = float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))
        if self.angle < 1e-9:
            return
        axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
        norm = np.linalg.norm(axis)
        # A half turn has no antisymmetric part: its axis is the top eigenvector of rel + rel^T.
        axis = np.linalg.eigh(rel + rel.T)[1][:, -1] if norm < 1e-9 else axis / norm
        self.k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        self.kk = self.k @ self.k

    def __call__(self, u: float) -> FloatArray:
        """The rotation at fraction ``u`` in [0, 1]."""
        if self.angle < 1e-9:
            return self.r0.copy()
        a = self.angle * u
        step = _EYE + np.sin(a) * self.k + (1.0 - np.cos(a)) * self.kk
        out: FloatArray = self.r0 @ step
        return out


def location_pose(world: World, believed: Mapping[str, Pose], name: str) -> Pose:
    """A named location's tool pose in the world: position (3,), rotation (3, 3).

    An object-relative location follows the object's *believed* pose.
    """
    loc = world.locations[name]
    pos, rot = np.array(loc.pos, dtype=np.float64), rpy_matrix(loc.rpy)
    if loc.body is None:
        return pos, rot
    body_pos, body_rot = believed[loc.body]
    if loc.axes == "world":
        return body_pos + pos, rot
    return body_pos + body_rot @ pos, body_rot @ rot
