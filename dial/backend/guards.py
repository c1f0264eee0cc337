"""Contact conditions the driver tests after every physics step: guards and monitors.

A **guard** belongs to a guarded move: when it trips, the driver freezes the guarded
effector at that physics step. A **monitor** belongs to a watched span (DESIGN 2.7): it
freezes nothing; the runner preempts the block. Both read the contact readings of
:mod:`dial.robot.contact`, as a contact wait does, so a guard, a monitor and a wait mean
the same contact.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import mujoco
import numpy as np

from dial.backend.index import RobotIndex
from dial.backend.model import hand_angles, tendon_tensions
from dial.robot.contact import force_reading, position_reading, tactile_reading
from dial.robot.snapshot import FloatArray, Trip


@dataclass(frozen=True)
class Guard:
    """Holds when any condition holds on any of the ``sense`` fingers (``negated``: when none
    does). ``effector`` is frozen when a guard trips; None for a monitor."""

    effector: str | None
    conditions: tuple[tuple[str, float], ...]
    sense: tuple[int, ...]
    baseline: FloatArray  # (16,) differentials when added, for force conditions
    negated: bool = False
    floats: tuple[float, ...] = field(init=False, repr=False)  # baseline, read every step

    def __post_init__(self) -> None:
        object.__setattr__(self, "floats", tuple(self.baseline.tolist()))


class Readings:
    """What guards and monitors read at one physics step, computed only as far as they need
    (this runs after every physics step while one is tested), each once per step: the
    readings of :mod:`dial.robot.contact`; a dropped-out sensor reads 0. One per robot:
    :meth:`at_step` starts each step afresh."""

    __slots__ = (
        "_bits", "_data", "_dropped", "_full", "_index", "_lever", "_loads", "_q", "_tactile",
        "_target", "_tendons", "_tensions", "_tips",
    )  # fmt: skip

    def __init__(self, data: mujoco.MjData, index: RobotIndex, tactile_adr: Sequence[int]) -> None:
        self._data, self._index = data, index
        # Views into sensordata stay valid for the data's life: slicing once saves a lot.
        n = index.profile.hand.taxels[0] * index.profile.hand.taxels[1]
        self._tactile = [data.sensordata[a : a + n] if a >= 0 else None for a in tactile_adr]
        self._tips: list[float | None] | None = None  # this step's deepest taxel per finger
        adr = index.load_sensors
        first = int(adr[0]) if len(adr) else -1
        # The load readings as a view where they run in order (a tendon hand: flexor,
        # extensor per joint).
        in_order = first >= 0 and np.array_equal(adr, np.arange(first, first + len(adr)))
        self._tensions = data.sensordata[first : first + len(adr)] if in_order else None
        self._bits: list[int] = index.hand_bits.tolist()  # each joint's mask bit
        self._full, self._tendons = index.full_hand, index.tendons
        self._lever = index.lever  # a joint torque (N m) over this is its load in N
        self._target: FloatArray = np.zeros(16)
        self._dropped: frozenset[tuple[str, int]] = frozenset()
        self._loads: list[float] | None = None  # this step's 16 joint loads, Python floats
        self._q: FloatArray | None = None

    def at_step(self, target: FloatArray, dropped: frozenset[tuple[str, int]]) -> Readings:
        self._target, self._dropped = target, dropped
        self._loads = self._q = self._tips = None
        return self

    def value(self, kind: str, f: int, baseline: Sequence[float]) -> float:
        """The reading of contact ``kind`` on finger ``f``: m (tactile, position) or N."""
        if self._dropped and (kind, f) in self._dropped:
            return 0.0
        if kind == "tactile":  # once per finger and step
            tips = self._tips
            if tips is None:
                tips = self._tips = [None] * len(self._tactile)
            tip = tips[f]
            if tip is None:
                row = self._tactile[f]
                tip = tips[f] = 0.0 if row is None else tactile_reading(row)
            return tip
        if kind == "force":  # the loads are read once per step, whatever the guards
            if self._loads is None:
                view = self._tensions
                raw = view if view is not None else tendon_tensions(self._data, self._index)
                self._loads = self._joint_loads(raw.tolist())
            return force_reading(self._loads, baseline, f)
        if self._q is None:
            self._q = hand_angles(self._data, self._index)
        return position_reading(self._target, self._q, f)

    def _joint_loads(self, raw: list[float]) -> list[float]:
        """The 16 joint loads (N, mask order, 0 where the hand has no joint) from the raw
        load readings, in Python floats: :func:`dial.backend.model.joint_loads`."""
        if self._tendons:
            if self._full:
                return [raw[2 * k] - raw[2 * k + 1] for k in range(16)]
            loads = [0.0] * 16
            for i, bit in enumerate(self._bits):
                loads[bit] = raw[2 * i] - raw[2 * i + 1]
            return loads
        lever = self._lever
        loads = [0.0] * 16
        for i, bit in enumerate(self._bits):
            loads[bit] = raw[i] / lever
        return loads


def first_trip(guard: Guard, r: Readings, time: float, step: int) -> Trip | None:
    """The condition that holds, if the guard fires at this step.

    A guard fires on the first (condition, finger) whose reading reaches its threshold, in
    declaration then finger order. A negated one fires when none does, and reports the
    first reading.
    """
    first: tuple[str, int, float] | None = None
    for kind, threshold in guard.conditions:
        for f in guard.sense:
            value = r.value(kind, f, guard.floats)
            if value >= threshold:
                return None if guard.negated else Trip(time, step, kind, f, value)
            if first is None:
                first = (kind, f, value)
    if guard.negated and first is not None:
        return Trip(time, step, *first)
    return None


class Guards:
    """The guards and monitors tested after every physics step, by key, in the order they
    were added."""

    def __init__(self) -> None:
        self.tested: dict[int, Guard] = {}
        self._next = 0

    def __bool__(self) -> bool:
        return bool(self.tested)

    def add(self, guard: Guard) -> int:
        self._next += 1
        self.tested[self._next] = guard
        return self._next

    def remove(self, key: int) -> None:
        self.tested.pop(key, None)

    def clear(self) -> None:
        self.tested.clear()

    def check(self, readings: Readings, time: float, step: int) -> list[tuple[int, Guard, Trip]]:
        """The guards that trip at this step (each is removed: it fires once)."""
        tripped: list[tuple[int, Guard, Trip]] = []
        for key, guard in self.tested.items():
            trip = first_trip(guard, readings, time, step)
            if trip is not None:
                tripped.append((key, guard, trip))
        for key, _, _ in tripped:
            del self.tested[key]
        return tripped
