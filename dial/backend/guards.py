"""Contact conditions the driver tests after every physics step: guards and monitors.

A **guard** belongs to a guarded move: when it trips, the driver freezes the guarded
effector at that physics step. A **monitor** belongs to a watched span (DESIGN 2.7): it
freezes nothing; the runner preempts the block. Both read the same contact readings as a
contact wait does (:func:`~dial.backend.contact.contact_reading`), so a guard, a monitor
and a wait mean the same contact.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from dial.backend.contact import contact_reading
from dial.backend.snapshot import FloatArray, Trip


@dataclass(frozen=True)
class Guard:
    """Holds when any condition holds on any of the ``sense`` fingers (``negated``: when none
    does). ``effector`` is frozen when a guard trips; None for a monitor."""

    effector: str | None
    conditions: tuple[tuple[str, float], ...]
    sense: tuple[int, ...]
    baseline: FloatArray  # (16,) differentials when armed, for force conditions
    negated: bool = False


@dataclass(frozen=True)
class Readings:
    """What the contact conditions read at one physics step (sensor dropouts applied).

    ``tactile``: four (256,) taxel depth arrays in m, finger order; ``differentials`` (16,)
    N; ``target`` and ``q`` (16,) joint set-points and angles in rad, mask order.
    """

    tactile: Sequence[FloatArray]
    differentials: FloatArray
    target: FloatArray
    q: FloatArray


def first_trip(guard: Guard, r: Readings, time: float, step: int) -> Trip | None:
    """The condition that holds, if the guard fires at this step.

    A guard fires on the first (condition, finger) whose reading reaches its threshold, in
    declaration then finger order. A negated one fires when none does, and reports the
    first reading.
    """
    first: tuple[str, int, float] | None = None
    for kind, threshold in guard.conditions:
        for f in guard.sense:
            value = contact_reading(
                kind, f, r.tactile[f], r.differentials, r.target, r.q, guard.baseline
            )
            if value >= threshold:
                return None if guard.negated else Trip(time, step, kind, f, value)
            if first is None:
                first = (kind, f, value)
    if guard.negated and first is not None:
        return Trip(time, step, *first)
    return None


class Guards:
    """The armed guards and monitors, by key, in the order they were armed."""

    def __init__(self) -> None:
        self.armed: dict[int, Guard] = {}
        self._next = 0

    def __bool__(self) -> bool:
        return bool(self.armed)

    def arm(self, guard: Guard) -> int:
        self._next += 1
        self.armed[self._next] = guard
        return self._next

    def disarm(self, key: int) -> None:
        self.armed.pop(key, None)

    def clear(self) -> None:
        self.armed.clear()

    def check(self, readings: Readings, time: float, step: int) -> list[tuple[int, Guard, Trip]]:
        """The guards that trip at this step (each is disarmed: it fires once)."""
        tripped = []
        for key, guard in self.armed.items():
            trip = first_trip(guard, readings, time, step)
            if trip is not None:
                tripped.append((key, guard, trip))
        for key, _, _ in tripped:
            del self.armed[key]
        return tripped
