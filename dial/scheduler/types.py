"""What the runner knows of a run's place in the script, and how a script stops early.

The runner knows nothing of MuJoCo: it drives a robot's :class:`~dial.robot.protocol.Clocked`
face over a snapshot type ``S`` of the robot's choosing, and has each run's
:class:`~dial.scheduler.primitive.Primitive` (or :class:`~dial.scheduler.primitive.Sensor`,
for zero-length sensing) made through its :class:`Makers`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, TypeVar

from dial.errors import DialError
from dial.parser.script import EventDef, Run
from dial.scheduler.primitive import Allotment, Primitive, Sensor

S = TypeVar("S")
S_contra = TypeVar("S_contra", contravariant=True)

DEFAULT_TICK = 0.25  # s, when neither the script (@tick) nor the command line sets one


def periods_per_tick(tick: float, period: float) -> int:
    """Ticks are whole numbers of control periods."""
    if not math.isfinite(tick) or round(tick / period) < 1:
        raise DialError(f"tick length {tick:g} s is shorter than the control period {period:g} s")
    return round(tick / period)


@dataclass(frozen=True)
class RunInfo:
    """Where a run sits: its event, block ticks, and the tick length in periods."""

    event: EventDef
    run: Run
    script: str
    periods_per_tick: int
    period: float

    @property
    def span(self) -> int:
        """The run's executing ticks, in control periods (a one-tick run's is one tick)."""
        return (self.run.exec_end - self.run.start + 1) * self.periods_per_tick

    @property
    def fixed(self) -> bool:
        """A fixed-length run: it ends with its last executing tick."""
        return self.event.instruction.length == "fixed"

    @property
    def timeout(self) -> float | None:
        """Simulated s after which the run ends ``timeout``: only indeterminate runs time out."""
        return None if self.fixed else self.event.args.time_limit()

    @property
    def allotment(self) -> Allotment:
        """What the run's primitive is allotted: its effectors and its span."""
        return Allotment(self.event.effectors, self.span, self.periods_per_tick, self.period)


class PrimitiveFactory(Protocol[S_contra]):
    """Makes each run's primitive, or sensor, as its event's instruction declares it."""

    def primitive(self, info: RunInfo) -> Primitive[S_contra]:
        """A run of a fixed-length or indeterminate instruction."""
        ...

    def sensor(self, info: RunInfo) -> Sensor[S_contra]:
        """A zero-length run, or a condition-only event tested once (no start record)."""
        ...


class RunAborted(DialError):
    """The script stopped: a run ended ``timeout`` or ``error``, a loop hit its max, a
    reaction aborted or retried too often, or a safety monitor tripped."""

    def __init__(self, message: str, event: str | None = None, tick: int = 0) -> None:
        super().__init__(message)
        self.event = event
        self.tick = tick


class Interrupted(DialError):
    """The run was stopped by a signal (SIGINT or SIGTERM); every effector holds."""

    def __init__(self, signal_name: str) -> None:
        super().__init__(f"interrupted by {signal_name}")
        self.signal_name = signal_name
