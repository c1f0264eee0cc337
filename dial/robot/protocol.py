"""The robot protocol: what dial needs of any robot it runs scripts on.

The simulated robot (:class:`dial.backend.driver.MujocoRobot`) implements :class:`Robot`;
a remote robot or another robot profile implements it too. It has three faces:

- :class:`Clocked`, what the runner calls: the control period, a snapshot of the sensors,
  advancing (or coasting through) control periods, holding effectors, watching monitors.
  The scheduler is written against this face alone (its tests drive a fake robot).
- :class:`Commanded`, what a run's command slots (:class:`~dial.robot.slots.Slots`) write:
  the set-points, limp joints and guards.
- ``view``: the read-only :class:`~dial.robot.view.RobotView` (joint ranges, fingers, sites).

Primitives see only the :class:`Commanded` face (through their slots), the view, their
snapshot (:class:`~dial.robot.snapshot.Snapshot`) and the kinematics
(:class:`ArmKinematics`, :class:`FingerKinematics`): never the physics or the driver.
Every call is synchronous.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import NamedTuple, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray

from dial.instructions.types import Contact
from dial.robot.snapshot import FloatArray
from dial.robot.view import RobotView

S_co = TypeVar("S_co", covariant=True)
IntArray = NDArray[np.intp]

Course = Callable[[int], None]  # writes the k-th coasted period's set-points (Primitive.course)


class StopFlag(Protocol):
    """What a coasting robot polls after every period (the scheduler's
    :class:`~dial.scheduler.signals.StopRequest`)."""

    @property
    def signal(self) -> str | None:
        """The first stop signal's name, or None while the run may go on."""
        ...


class Happening(NamedTuple):
    """Something the robot observed during a period, for the runner to log.

    ``kind`` is the record kind (``contact``, ``thread``, ``disturb``, ``warning``);
    ``fields`` its fields, with the simulated time ``t`` of the physics step where it
    happened.
    """

    kind: str
    fields: Mapping[str, object]  # JSON-able values (numbers, strings, lists, arrays)


class Fired(NamedTuple):
    """A monitor whose condition held at a physics step of the period."""

    key: int
    time: float
    step: int


class Report(NamedTuple):
    """What happened during one control period, when anything did (else ``advance`` -> None).

    ``fault``: an engine-owned safety monitor tripped (joint or tension limit, non-finite
    state); the runner aborts. ``fired``: monitors, in the order they were watched.
    """

    fault: str | None = None
    happenings: tuple[Happening, ...] = ()
    fired: tuple[Fired, ...] = ()


class Monitor(NamedTuple):
    """A contact condition the robot tests at every physics step while it is watched.

    ``event`` names the watched sensing event; the robot fires when ``contact`` holds
    (``negated``: when it does not).
    """

    event: str
    contact: Contact
    negated: bool


class Clocked(Protocol[S_co]):
    """What the runner calls: the robot as the tick loop drives it."""

    @property
    def period(self) -> float:
        """The control period in seconds."""
        ...

    def snapshot(self) -> S_co:
        """An immutable view of the sensors for this control period."""
        ...

    def advance(self) -> Report | None:
        """Apply the command slots and simulate one control period."""
        ...

    def coast(
        self, writes: Sequence[Course], periods: int, stop: StopFlag
    ) -> tuple[int, Report | None]:
        """``advance`` up to ``periods`` times, each after ``write(k)`` of every course for
        the k-th period; return after a period that reports anything, or once ``stop`` has a
        signal: (periods taken, that report or None)."""
        ...

    def hold_all(self) -> None:
        """Freeze every effector where it is measured now (abort, interrupt)."""
        ...

    def hold(self, effectors: frozenset[str]) -> None:
        """Freeze these effectors where they are measured now (preemption)."""
        ...

    def watch(self, monitor: Monitor) -> int:
        """Start testing a monitor every physics step; returns its key."""
        ...

    def unwatch(self, key: int) -> None:
        """Stop testing a monitor."""
        ...


class Commanded(Protocol):
    """What a run's command slots write: the set-points, limp joints and guards."""

    arm_target: FloatArray  # (arm joints,) rad
    hand_target: FloatArray  # (16,) rad, mask order

    def set_limp(self, joints: IntArray, on: bool) -> None:
        """Make these hand joints (mask order) back-drivable, or stiff."""
        ...

    def measured_hand(self) -> FloatArray:
        """(16,) hand joint angles now (rad, mask order): where limp joints went."""
        ...

    def guard(
        self, effector: str, conditions: Iterable[tuple[str, float]], sense: Iterable[int]
    ) -> int:
        """Freeze ``effector`` at the physics step where a contact condition (kind,
        threshold) holds on a ``sense`` finger; returns the guard's key (its trip shows in
        later snapshots)."""
        ...

    def unguard(self, key: int) -> None:
        """Stop testing a guard."""
        ...


class Robot(Clocked[S_co], Commanded, Protocol[S_co]):
    """A whole robot: the runner's face, the slots' face and the read-only model view."""

    @property
    def view(self) -> RobotView:
        """What the robot is: joint ranges, fingers, sites (read-only)."""
        ...


class ArmKinematics(Protocol):
    """Forward and inverse kinematics of the arm's tool frame (m, rad)."""

    #: The memo's name for this solver's results (:mod:`dial.robot.memo`).
    MEMO: str

    def fk(self, arm_q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Tool position (3,) and rotation (3, 3) at ``arm_q``."""
        ...

    def solve(self, pos: FloatArray, rot: FloatArray, arm_q: FloatArray, what: str) -> FloatArray:
        """Converge on the pose from ``arm_q``; raise a DialError naming ``what`` if it is
        out of reach."""
        ...

    def track(
        self,
        pos: FloatArray,
        rot: FloatArray,
        arm_q: FloatArray,
        iterations: int = 2,
        guide: FloatArray | None = None,
    ) -> FloatArray:
        """A few warm-started steps from ``arm_q`` toward the pose (a redundant arm's spare
        freedom drawn towards ``guide``, if given)."""
        ...


class FingerKinematics(Protocol):
    """Fingertip positions and fingertip IK (world m, rad)."""

    def tip(self, arm_q: FloatArray, hand_q: FloatArray, finger: int) -> FloatArray:
        """The finger's tip position (3,) at these joint angles."""
        ...

    def track(
        self,
        finger: int,
        tip: FloatArray,
        arm_q: FloatArray,
        hand_q: FloatArray,
        iterations: int = 2,
    ) -> FloatArray:
        """Steps from ``hand_q`` moving the fingertip toward ``tip``; returns (16,) rad."""
        ...


def advance_through(
    robot: Clocked[object], writes: Sequence[Course], periods: int, stop: StopFlag
) -> tuple[int, Report | None]:
    """:meth:`Clocked.coast` done with :meth:`Clocked.advance`, one period after another:
    what a robot with no faster way of its own does."""
    for k in range(periods):
        for write in writes:
            write(k)
        report = robot.advance()
        if report is not None or stop.signal is not None:
            return k + 1, report
    return periods, None
