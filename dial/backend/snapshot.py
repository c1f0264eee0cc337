"""The immutable sensor snapshot primitives read once per control period."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Trip:
    """A guard that fired: when (simulated s, physics step), on what, and the reading.

    ``tactile`` and ``link``: where the finger touched at that physics step (world m, see
    :mod:`dial.backend.locate`), or None when its array (or its links) touched nothing.
    """

    time: float
    step: int
    kind: str  # tactile, force or position
    finger: int
    value: float
    tactile: FloatArray | None = None
    link: FloatArray | None = None


@dataclass(frozen=True)
class Snapshot:
    """Sensors and command slots at the start of a control period. Arrays are read-only.

    Shapes: ``arm_q``/``arm_target`` (6,) rad; ``hand_q``/``hand_target`` (16,) rad, mask
    order; ``tensions`` (32,) N, tendon order; ``differentials`` (16,) N, flexor minus
    extensor; ``tactile`` (4, 16, 16) taxel depths in m; ``tool_pos`` (3,) m and ``tool_rot``
    (3, 3) of the ``hand_palm`` site; ``tips`` (4, 3) fingertip positions in m.
    """

    time: float
    step: int
    arm_q: FloatArray
    arm_target: FloatArray
    hand_q: FloatArray
    hand_target: FloatArray
    tensions: FloatArray
    differentials: FloatArray
    tactile: FloatArray
    tool_pos: FloatArray
    tool_rot: FloatArray
    tips: FloatArray
    trips: Mapping[int, Trip]


def frozen(array: NDArray[np.float64], fresh: bool = False) -> FloatArray:
    """A read-only array: a copy, or ``array`` itself when it is ``fresh`` (owned by no one)."""
    out = array if fresh else np.array(array, dtype=np.float64)
    out.flags.writeable = False
    return out
