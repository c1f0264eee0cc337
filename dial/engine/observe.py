"""Watching a run without changing it: the observer protocol, and the state log.

Recording, video and the live viewers (``dial.recording``) are observers. They sample on
simulated time (whole control periods), never on the wall clock, and never write to the
physics; so a run watched gives the same log and final state as one not watched.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from dial.backend.driver import MujocoRobot
from dial.backend.model import tendon_tensions
from dial.parser.lanes import LanePlan
from dial.scene.world import World
from dial.scheduler.log import EventLog
from dial.scheduler.types import RunAborted

if TYPE_CHECKING:
    from dial.engine.result import RunResult

STATE_HZ = 25.0  # state records per second of simulated time (--log-states)
STATE_DIGITS = 4  # 0.1 mm and 0.1 mrad: plenty to draw, and a third shorter than the default
TENSION_DIGITS = 2  # 0.01 N


@dataclass(frozen=True)
class Watched:
    """What an observer may read, and never write: the robot, the scene's world, the log."""

    robot: MujocoRobot
    world: World
    log: EventLog


class Observer(Protocol):
    """Watches a run: ``begin`` once the scene has settled, ``period`` after every control
    period with the periods simulated so far and the current tick, ``end`` after the
    criteria are measured (``result`` is None when the run could not finish, e.g. a bug)."""

    def begin(self, run: Watched) -> None: ...

    def period(self, periods: int, tick: int) -> None: ...

    def end(self, result: RunResult | None) -> None: ...


def every(rate_hz: float, period: float) -> int:
    """Control periods between samples at ``rate_hz`` per simulated second (at least 1)."""
    return max(1, round(1.0 / (rate_hz * period)))


def fan_out(observers: list[Observer]) -> Callable[[int, int], None] | None:
    """One callback for the runner; None (no per-period cost) without observers.

    An observer that fails (a video that cannot be written, a viewer gone) stops the run
    cleanly, as an abort that names it: the log and the summary are still written.
    """
    if not observers:
        return None

    def period(periods: int, tick: int) -> None:
        for observer in observers:
            try:
                observer.period(periods, tick)
            except Exception as e:
                raise RunAborted(f"{describe(observer)} failed: {first_line(e)}", None, tick) from e

    return period


def describe(observer: object) -> str:
    """What an observer is, for messages: its ``what`` if it says, else its class name."""
    return str(getattr(observer, "what", type(observer).__name__))


def first_line(e: BaseException) -> str:
    return (str(e).strip().splitlines() or [type(e).__name__])[0]


class StateLog:
    """Writes ``state`` records into the log at ``rate_hz`` (``--log-states``), for replay.

    A record holds ``t``, ``tick``, the whole ``qpos`` (the arm, the hand, and every free
    object) and the 32 tendon ``tension``s, which cannot be recomputed from positions. The
    engine owns it: the engine and the runner are the log's only writers. With ``lanes``
    (the script's event lanes), a ``lanes`` record comes first, so that a replayed recording
    draws the same lanes.
    """

    what = "the state log"  # how messages name it

    def __init__(self, rate_hz: float = STATE_HZ, lanes: LanePlan | None = None) -> None:
        self.rate_hz, self.lanes = rate_hz, lanes

    def begin(self, run: Watched) -> None:
        self.robot: MujocoRobot = run.robot
        self.log: EventLog = run.log
        self.every = every(self.rate_hz, run.robot.period)
        if self.lanes is not None:
            record = self.lanes.as_record()
            self.log.write(record.pop("kind"), **record)
        self._write(0, 0)

    def period(self, periods: int, tick: int) -> None:
        if periods % self.every == 0:
            self._write(periods, tick)

    def _write(self, periods: int, tick: int) -> None:
        d, ix = self.robot.data, self.robot.index
        self.log.write(
            "state",
            tick=tick,
            t=periods * self.robot.period,
            qpos=np.round(d.qpos, STATE_DIGITS),
            tension=np.round(tendon_tensions(d, ix), TENSION_DIGITS),
        )

    def end(self, result: RunResult | None) -> None:
        """Nothing to close: the log belongs to the run."""
