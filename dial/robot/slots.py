"""The command slots of one run: it may command, limp and guard only its own effectors."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from dial.errors import DialError
from dial.instructions.types import FINGERS
from dial.robot.protocol import Commanded, Course, IntArray
from dial.robot.snapshot import FloatArray


class EffectorError(DialError):
    """A primitive wrote to an effector its run does not own (a bug, not a script error)."""


def _bits(mask: int) -> list[int]:
    return [k for k in range(16) if mask >> k & 1]


class ArmCourse:
    """A course that writes the arm's set-points and nothing else (the driver, knowing it,
    leaves the hand's controls as they are while it coasts)."""

    __slots__ = ("robot", "rows")

    def __init__(self, robot: Commanded, rows: FloatArray) -> None:
        self.robot, self.rows = robot, rows

    def __call__(self, k: int) -> None:
        self.robot.arm_target = self.rows[k]  # never written in place: a row of rows will do


def still(k: int) -> None:
    """The course of a run that writes no set-point (a limp run, an arm with nowhere to go)."""


class Slots:
    """The command slots a run owns: writing another effector's raises :class:`EffectorError`."""

    def __init__(self, robot: Commanded, effectors: frozenset[str]) -> None:
        self.robot, self.effectors = robot, effectors
        self._owned: dict[int, IntArray] = {}  # masks checked, and their joints

    def _own(self, effector: str) -> None:
        if effector not in self.effectors:
            raise EffectorError(f"run does not own the {effector}")

    def _own_bits(self, mask: int) -> IntArray:
        """The joints of ``mask`` as an index array, their fingers' ownership checked (once
        per mask: a grasp writes the same one every period)."""
        bits = self._owned.get(mask)
        if bits is None:
            listed = _bits(mask)
            for f in {k // 4 for k in listed}:
                self._own(FINGERS[f])
            bits = self._owned[mask] = np.array(listed, dtype=np.intp)
        return bits

    def arm(self, q: FloatArray) -> None:
        """Set the six arm joint set-points (rad)."""
        self._own("arm")
        self.robot.arm_target = np.array(q, dtype=np.float64)

    def joints(self, mask: int, q16: FloatArray) -> None:
        """Set the hand joints selected by ``mask`` (bit 4*f + j) from ``q16`` (16,) rad."""
        bits = self._own_bits(mask)
        self.robot.hand_target[bits] = np.asarray(q16)[bits]

    def arm_course(self, rows: FloatArray) -> ArmCourse:
        """A writer of the arm set-points ``rows[k]`` ((K, 6) rad) of coasted periods; the
        ownership is checked once, here (see :meth:`dial.scheduler.types.Primitive.course`)."""
        self._own("arm")
        return ArmCourse(self.robot, rows)

    def joints_course(self, mask: int, rows: FloatArray) -> Course:
        """A writer of the masked hand joints' set-points from ``rows[k]`` ((K, 16) rad)."""
        bits = self._own_bits(mask)
        masked, robot = rows[:, bits], self.robot

        def write(k: int) -> None:
            robot.hand_target[bits] = masked[k]

        return write

    def limp(self, mask: int, on: bool) -> None:
        """Make the masked joints back-drivable, or stiff again where they went."""
        bits = self._own_bits(mask)
        self.robot.set_limp(bits, on)
        if not on:  # the joints hold where they went
            self.robot.hand_target[bits] = self.robot.measured_hand()[bits]

    def guard(
        self, effector: str, conditions: Iterable[tuple[str, float]], sense: Iterable[int]
    ) -> int:
        """Freeze ``effector`` at the physics step where a contact condition holds on a
        ``sense`` finger; returns the guard's key (its trip shows in later snapshots)."""
        self._own(effector)
        return self.robot.guard(effector, conditions, sense)

    def unguard(self, key: int) -> None:
        self.robot.unguard(key)
