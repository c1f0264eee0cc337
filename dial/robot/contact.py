"""The readings that guards (in the driver) and contact waits (primitives) compare with
their thresholds: one definition, so that a guard and a wait mean the same contact."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dial.robot.snapshot import FloatArray

POSITION_LEVER = 0.1  # m: joint error (rad) to fingertip displacement, about a finger length


def contact_reading(
    kind: str,
    finger: int,
    depths: ArrayLike,
    differentials: FloatArray,
    target: FloatArray,
    q: FloatArray,
    baseline: FloatArray | None = None,
) -> float:
    """The reading of contact ``kind`` (tactile, force or position) on ``finger``.

    ``depths``: that finger's taxel depths (m, any shape); ``differentials``, ``target`` and
    ``q``: (16,) tendon differentials (N) and joint set-points and angles (rad), mask order;
    ``baseline``: differentials to measure a change from (force), or None for their value.
    Returns m (tactile: deepest taxel; position: set-point error times the lever) or N.
    """
    joints = slice(4 * finger, 4 * finger + 4)
    if kind == "tactile":
        return float(np.max(depths))
    if kind == "force":
        base = baseline[joints] if baseline is not None else 0.0
        return float(np.abs(differentials[joints] - base).max())
    return float(np.linalg.norm(target[joints] - q[joints])) * POSITION_LEVER
