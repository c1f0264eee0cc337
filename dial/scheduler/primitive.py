"""The contract between the runner and a run's primitive: what a run is to the runner.

A :class:`Primitive` is stepped every control period; a :class:`Sensor` is sensed once.
Each is made per run, by its instruction (``Args.primitive`` and ``Args.sensor`` of
:mod:`dial.instructions.base`), with the run's :class:`Allotment`. Nothing here knows of
scripts or of MuJoCo.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Generic, NamedTuple, Protocol, TypeVar

from dial.robot.protocol import Course

S = TypeVar("S")
S_contra = TypeVar("S_contra", contravariant=True)

# What a run reports for the log: JSON-able values (numbers, strings, lists, arrays).
Data = Mapping[str, object]


class Outcome(StrEnum):
    """How a run ended (DESIGN 2.5, 2.7)."""

    DONE = "done"
    MISSED = "missed"
    TIMEOUT = "timeout"
    ERROR = "error"
    PREEMPTED = "preempted"


@dataclass(frozen=True, slots=True)
class Ended:
    """A run's outcome, with a message for ``error``, any sensed data to log, and warnings
    (each becomes a ``warning`` record: a run that did not quite do what was asked never
    ends silently ``done``)."""

    outcome: Outcome
    message: str = ""
    data: Data = field(default_factory=dict)
    warnings: tuple[str, ...] = ()


DONE = Ended(Outcome.DONE)


def progress_after(k: int, span: int, n: int) -> float:
    """A run's progress in tick time after ``k`` of its tick-time periods: ``k / span``, at
    most 1, for a run of ``span`` executing periods; 1 from the first period of a one-tick
    run (``span == n``, the periods of a tick), a GOTO MOVE whose set-point jumps at once.

    The one definition of progress: the runner's steps, its courses (open-loop runs taking
    the coming periods at once) and the preview's walk all compute it here.
    """
    return 1.0 if span == n else min(1.0, k / span)


class Now(NamedTuple):
    """What a primitive knows of time in one control period.

    ``progress`` is the run's progress through its executing ticks in **tick time** (0 at
    its start, 1 at the end of its last ``#``/``=`` tick); it stands still while a tick is
    stretched. ``elapsed`` is simulated time since the run started (s), which never does.
    ``sim_time`` is the simulated time at the end of this period (s).
    """

    sim_time: float
    tick: int
    progress: float
    elapsed: float
    stretched: bool


class Primitive(ABC, Generic[S_contra]):
    """One run of an instruction, stepped synchronously by the runner.

    Lifecycle: :meth:`start` once; :meth:`step` every control period until it returns an
    :class:`Ended` (or, for fixed-length runs, until the runner calls :meth:`finish` at the
    end of the last executing tick); :meth:`stop` always, exactly once, after the run ends
    for whatever reason (done, timeout, error, preempted, abort, interrupt). A step reads
    the immutable snapshot and writes only its own effectors' command slots.
    """

    def start(self, snapshot: S_contra) -> None:
        """Plan the run from the snapshot at its first period."""

    @abstractmethod
    def step(self, snapshot: S_contra, now: Now) -> Ended | None:
        """Write this period's commands; return an outcome to end the run."""

    def finish(self, snapshot: S_contra) -> Ended:
        """End a fixed-length run at the end of its last executing tick."""
        return DONE

    #: An open-loop run's steps read nothing of the snapshot and never end it: its set-points
    #: are a function of its progress alone, so the runner may take them in one go (coast).
    open_loop: bool = False

    def course(self, first: int, count: int) -> Course:
        """An open-loop run's writer of the set-points that :meth:`step` would write in its
        tick-time periods ``first`` to ``first + count - 1`` (at :func:`progress_after` each):
        calling it with ``j`` writes period ``first + j``'s and leaves the run as if stepped
        through it. The set-points are worked out at once, as arrays: that is what makes
        coasting cheaper than stepping (see docs/architecture.md)."""
        raise NotImplementedError(f"{type(self).__name__} is not open-loop")

    def stop(self) -> None:
        """Clean up; the effectors keep holding their last command."""


class Sensor(Protocol[S_contra]):
    """A zero-length run or a condition test: sensed at once, at the start of its tick."""

    def sense(self, snapshot: S_contra) -> Ended: ...


class Allotment(NamedTuple):
    """What a run is allotted: the effectors it owns and its executing ticks.

    ``span``: its executing ticks in control periods (a one-tick run's is one tick);
    ``periods_per_tick``: the tick length in control periods; ``period``: the control
    period (s).
    """

    effectors: frozenset[str]
    span: int
    periods_per_tick: int
    period: float
