"""The immutable sensor snapshot primitives read once per control period."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


class Touch(NamedTuple):
    """Where a finger touches (world m): ``tactile``, the depth-weighted centroid of the
    taxels that feel something, None when its array feels nothing (or has dropped out);
    ``link``, the deepest contact point of its links with anything outside the robot, None
    when they touch nothing there. See :mod:`dial.backend.locate`."""

    tactile: FloatArray | None
    link: FloatArray | None


NO_TOUCH = Touch(None, None)


@dataclass(frozen=True)
class Trip:
    """A guard that fired: when (simulated s, physics step), on what, the reading, and where
    the finger touched at that physics step."""

    time: float
    step: int
    kind: str  # tactile, force or position
    finger: int
    value: float
    touch: Touch = NO_TOUCH


class Sensors(Protocol):
    """Where a snapshot reads its sensors: the robot, as it is at this control period."""

    @property
    def generation(self) -> int:
        """How often the robot has advanced: a snapshot is valid at its own generation."""
        ...

    def read(self, name: str, hand_target: FloatArray) -> FloatArray:
        """A fresh, read-only array for the snapshot field ``name``."""
        ...

    def touch(self, finger: int) -> Touch:
        """Where ``finger`` touches now."""
        ...


class StaleSnapshotError(RuntimeError):
    """A sensor of a snapshot read after the robot moved on (a bug in a primitive)."""


class _Sensor:
    """A snapshot field read from the robot the first time it is asked for: the physics does
    not change before the robot advances, and most periods read few of them."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, snap: Snapshot, owner: type | None = None) -> FloatArray:
        value = snap._cache.get(self.name)
        if value is None:
            if snap._sensors.generation != snap._generation:
                raise StaleSnapshotError(f"snapshot field '{self.name}' read a period late")
            value = snap._cache[self.name] = snap._sensors.read(self.name, snap.hand_target)
        return value


class Snapshot:
    """Sensors and command slots at the start of a control period. Arrays are read-only.

    Shapes: ``arm_q``/``arm_target`` (6,) rad; ``hand_q``/``hand_target`` (16,) rad, mask
    order; ``tensions`` (32,) N, tendon order; ``differentials`` (16,) N, flexor minus
    extensor; ``tactile`` (4, 16, 16) taxel depths in m; ``tool_pos`` (3,) m and ``tool_rot``
    (3, 3) of the ``hand_palm`` site; ``tips`` (4, 3) fingertip positions in m. The command
    slots, trips and dropouts are copied when the snapshot is taken; the sensors are read
    when first asked for, in the same control period (a later read is an error).
    """

    __slots__ = (
        "_cache",
        "_generation",
        "_sensors",
        "arm_target",
        "dropped",
        "hand_target",
        "step",
        "time",
        "trips",
    )

    arm_q = _Sensor()
    hand_q = _Sensor()
    tensions = _Sensor()
    differentials = _Sensor()
    tactile = _Sensor()
    tool_pos = _Sensor()
    tool_rot = _Sensor()
    tips = _Sensor()

    def __init__(
        self,
        sensors: Sensors,
        time: float,
        step: int,
        arm_target: FloatArray,
        hand_target: FloatArray,
        trips: Mapping[int, Trip],
        dropped: frozenset[tuple[str, int]] = frozenset(),
    ) -> None:
        self._sensors, self._generation = sensors, sensors.generation
        self._cache: dict[str, FloatArray] = {}
        self.time, self.step = time, step
        self.arm_target, self.hand_target = arm_target, hand_target
        self.trips, self.dropped = trips, dropped

    def touch(self, finger: int) -> Touch:
        """Where ``finger`` touches (world m) in this control period."""
        if self._sensors.generation != self._generation:
            raise StaleSnapshotError("snapshot touch read a period late")
        return self._sensors.touch(finger)


def frozen(array: NDArray[np.float64], fresh: bool = False) -> FloatArray:
    """A read-only array: a copy, or ``array`` itself when it is ``fresh`` (owned by no one)."""
    out = array if fresh else np.array(array, dtype=np.float64)
    out.flags.writeable = False
    return out
