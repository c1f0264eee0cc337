"""The contract between the block runner, the primitives and the robot.

The runner knows nothing of MuJoCo: it drives any :class:`Robot` and builds a
:class:`Primitive` per run through a :data:`PrimitiveFactory`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any, Protocol

from dial.errors import DialError
from dial.parser.script import EventDef, Run


class Outcome(StrEnum):
    """How a run ended (DESIGN 2.5)."""

    DONE = "done"
    MISSED = "missed"
    TIMEOUT = "timeout"
    ERROR = "error"


@dataclass(frozen=True)
class Ended:
    """A run's outcome, with a message for ``error`` and any sensed data to log."""

    outcome: Outcome
    message: str = ""
    data: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Now:
    """What a primitive knows of time in one control period.

    ``progress`` is the run's progress through its executing ticks in **tick
    time** (0 at its start, 1 at the end of its last ``#``/``=`` tick); it stands
    still while a tick is stretched. ``elapsed`` is simulated time since the
    run started, which never stands still.
    """

    sim_time: float
    tick: int
    progress: float
    elapsed: float
    stretched: bool


class Primitive(ABC):
    """One run of an instruction.

    Lifecycle: :meth:`start` once, :meth:`step` every control period until it
    returns an :class:`Ended` (or, for fixed-length runs, until the runner calls
    :meth:`finish` at the end of the last executing tick), and :meth:`stop`
    always, also when the run is cancelled. Steps read the immutable snapshot and
    write only the run's own effectors' command slots.
    """

    @abstractmethod
    def start(self, snapshot: Any) -> None: ...

    @abstractmethod
    def step(self, snapshot: Any, now: Now) -> Ended | None: ...

    def finish(self, snapshot: Any) -> Ended:
        """End a fixed-length run at the end of its last executing tick."""
        return Ended(Outcome.DONE)

    def stop(self) -> None:  # noqa: B027 - optional hook, most primitives need no cleanup
        """Clean up; the effectors keep holding their last command."""


class InstantPrimitive(Primitive):
    """A zero-length (sensing) run: it happens at the start of its tick."""

    @abstractmethod
    def sense(self, snapshot: Any) -> Ended: ...

    def start(self, snapshot: Any) -> None:
        raise AssertionError("instant primitives are sensed, not started")

    def step(self, snapshot: Any, now: Now) -> Ended | None:
        raise AssertionError("instant primitives are sensed, not stepped")


@dataclass(frozen=True)
class RunInfo:
    """Where a run sits: its event, block ticks, and the tick length in periods."""

    event: EventDef
    run: Run
    script: str
    periods_per_tick: int
    period: float
    instant: bool = False  # a condition-only event, sensed once with zero duration


PrimitiveFactory = Callable[[RunInfo], Primitive]


class Robot(Protocol):
    """What the runner needs of a robot backend."""

    @property
    def period(self) -> float:
        """The control period in seconds."""
        ...

    def snapshot(self) -> Any:
        """An immutable view of the sensors for this control period."""
        ...

    async def advance(self) -> str | None:
        """Apply the command slots and simulate one control period.

        Returns a message when an engine-owned safety monitor trips (joint or
        tension limit, non-finite state); the runner then aborts.
        """
        ...

    def hold_all(self) -> None:
        """Freeze every effector at its current pose (on abort or interrupt)."""
        ...


class RunAborted(DialError):
    """The script stopped: a run ended ``timeout`` or ``error``, or a loop hit its max."""

    def __init__(self, message: str, event: str | None = None, tick: int = 0) -> None:
        super().__init__(message)
        self.event = event
        self.tick = tick
