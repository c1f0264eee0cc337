"""A fake robot and fake primitives, for testing the scheduler on virtual time.

The fake robot's effectors are single numbers: a fixed-length run writes its
tick-time progress (0 to 1) into each of its effectors, so tests can see a
trajectory hold its set-point while a tick is stretched. Indeterminate and
sensing runs follow a scripted :class:`Behaviour`; a watched event's condition holds in
the periods its ``holds`` entry lists, so tests pin the period a monitor fires in.
"""

from __future__ import annotations

import itertools
from collections.abc import Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import NamedTuple

import trio
import trio.testing

from dial.instructions.types import EFFECTORS
from dial.parser.check import check_text
from dial.parser.script import Script
from dial.robot.protocol import Course, Fired, Monitor, Report, StopFlag, advance_through
from dial.scheduler.log import EventLog, Record
from dial.scheduler.primitive import Ended, Now, Outcome, Primitive, Sensor, progress_after
from dial.scheduler.runner import Runner, Tally
from dial.scheduler.types import RunInfo


class FakeSnapshot(NamedTuple):
    periods: int
    commands: Mapping[str, float]


class FakeRobot:
    """Effectors are numbers that follow their commands at once.

    ``fault_at``: period -> a safety-monitor message reported in that period. ``holds``:
    watched event -> the periods (1-based) in which its condition holds.
    """

    def __init__(
        self,
        period: float = 0.01,
        fault_at: Mapping[int, str] | None = None,
        holds: Mapping[str, Collection[int]] | None = None,
    ) -> None:
        self._period = period
        self.commands: dict[str, float] = dict.fromkeys(EFFECTORS, 0.0)
        self.trace: list[dict[str, float]] = []  # commands applied in each period
        self.periods = 0
        self.held = False
        self.holds_at: list[tuple[int, frozenset[str]]] = []  # (period, effectors) held
        self.fault_at = dict(fault_at or {})
        self.conditions = dict(holds or {})
        self.monitors: dict[int, Monitor] = {}
        self.watched: list[tuple[int, str, bool]] = []  # (period, event, negated), as watched
        self._keys = itertools.count(1)
        self.stops: list[str] = []  # events whose run was stopped, in order
        self.coasts: list[tuple[int, int]] = []  # each coast's first period and length asked
        self.lag = 0.0  # trio (mock clock) s that each period takes: a slow robot

    @property
    def period(self) -> float:
        return self._period

    def snapshot(self) -> FakeSnapshot:
        return FakeSnapshot(self.periods, MappingProxyType(self.commands.copy()))

    def advance(self) -> Report | None:
        if self.lag:
            clock = trio.lowlevel.current_clock()
            assert isinstance(clock, trio.testing.MockClock)
            clock.jump(self.lag)
        self.trace.append(self.commands.copy())
        self.periods = periods = self.periods + 1
        fault = self.fault_at.get(periods) if self.fault_at else None
        if not self.monitors:
            return None if fault is None else Report(fault)
        fired = tuple(
            Fired(key, periods * self._period, periods)
            for key, m in self.monitors.items()
            if (periods in self.conditions.get(m.event, ())) != m.negated
        )
        return Report(fault, (), fired) if fault is not None or fired else None

    def coast(
        self, writes: Sequence[Course], periods: int, stop: StopFlag
    ) -> tuple[int, Report | None]:
        self.coasts.append((self.periods + 1, periods))
        return advance_through(self, writes, periods, stop)

    def hold_all(self) -> None:
        self.held = True

    def hold(self, effectors: frozenset[str]) -> None:
        self.holds_at.append((self.periods, effectors))

    def watch(self, monitor: Monitor) -> int:
        key = next(self._keys)
        self.monitors[key] = monitor
        self.watched.append((self.periods + 1, monitor.event, monitor.negated))
        return key

    def unwatch(self, key: int) -> None:
        self.monitors.pop(key, None)


@dataclass(frozen=True)
class Behaviour:
    """What a fake indeterminate or sensing run does.

    ``duration``: simulated seconds until an indeterminate run ends (None:
    never, so it times out). ``outcomes``: the outcomes of successive runs or
    condition tests of the event, the last one repeating.
    """

    duration: float | None = 0.0
    outcomes: Sequence[Outcome] = (Outcome.DONE,)
    message: str = ""


_DEFAULT = Behaviour()


class _Motion(Primitive[FakeSnapshot]):
    def __init__(self, robot: FakeRobot, info: RunInfo) -> None:
        self.commands, self.effectors = robot.commands, info.event.effectors
        self.stops = robot.stops
        self.name = info.event.name
        self.span, self.n = info.span, info.periods_per_tick

    def step(self, snapshot: FakeSnapshot, now: Now) -> Ended | None:
        for effector in self.effectors:
            self.commands[effector] = now.progress
        return None

    open_loop = True

    def course(self, first: int, count: int) -> Course:
        span, n = self.span, self.n
        progress = [progress_after(k, span, n) for k in range(first, first + count)]

        def write(k: int) -> None:
            for effector in self.effectors:
                self.commands[effector] = progress[k]

        return write

    def stop(self) -> None:
        self.stops.append(self.name)


class _Wait(Primitive[FakeSnapshot]):
    def __init__(
        self, robot: FakeRobot, info: RunInfo, behaviour: Behaviour, outcome: Outcome
    ) -> None:
        self.behaviour, self.outcome = behaviour, outcome
        self.stops, self.name = robot.stops, info.event.name

    def step(self, snapshot: FakeSnapshot, now: Now) -> Ended | None:
        duration = self.behaviour.duration
        if duration is not None and now.elapsed >= duration - 1e-9:
            return Ended(self.outcome, self.behaviour.message)
        return None

    def stop(self) -> None:
        self.stops.append(self.name)


class _Sense:
    def __init__(self, outcome: Outcome, message: str) -> None:
        self.outcome, self.message = outcome, message

    def sense(self, snapshot: FakeSnapshot) -> Ended:
        return Ended(self.outcome, self.message, {"periods": snapshot.periods})


@dataclass
class FakeFactory:
    robot: FakeRobot
    behaviours: Mapping[str, Behaviour] = field(default_factory=dict)
    _calls: dict[str, Iterator[Outcome]] = field(default_factory=dict)

    def _next(self, event: str, behaviour: Behaviour) -> Outcome:
        if event not in self._calls:
            outs = list(behaviour.outcomes)
            self._calls[event] = itertools.chain(outs, itertools.repeat(outs[-1]))
        return next(self._calls[event])

    def primitive(self, info: RunInfo) -> Primitive[FakeSnapshot]:
        if info.event.instruction.length == "fixed":
            return _Motion(self.robot, info)
        behaviour = self.behaviours.get(info.event.name, _DEFAULT)
        return _Wait(self.robot, info, behaviour, self._next(info.event.name, behaviour))

    def sensor(self, info: RunInfo) -> Sensor[FakeSnapshot]:
        behaviour = self.behaviours.get(info.event.name, _DEFAULT)
        return _Sense(self._next(info.event.name, behaviour), behaviour.message)


@dataclass
class FakeResult:
    summary: Tally
    log: EventLog
    robot: FakeRobot
    trio_time: float

    def starts(self, event: str) -> list[tuple[int, float]]:
        """(tick, time) of each start of ``event``."""
        return [_tick_t(r) for r in self.log.of("start") if r["event"] == event]

    def ends(self, event: str) -> list[tuple[int, float, str]]:
        """(tick, time, outcome) of each end of ``event``."""
        return [(*_tick_t(r), str(r["outcome"])) for r in self.log.of("end") if r["event"] == event]

    def stretches(self) -> dict[int, int]:
        """Absolute tick -> periods it was stretched by, for stretched ticks."""
        return {
            int(str(r["tick"])): int(str(r["stretch"])) for r in self.log.of("tick") if r["stretch"]
        }


def _tick_t(record: Record) -> tuple[int, float]:
    tick, t = record["tick"], record["t"]
    assert isinstance(tick, int) and isinstance(t, float | int)
    return tick, float(t)


def run_fake(
    script: str | Script,
    tick: float = 0.1,
    behaviours: Mapping[str, Behaviour] | None = None,
    period: float = 0.01,
    path: str = "fake.dial",
    fault_at: Mapping[int, str] | None = None,
    holds: Mapping[str, Collection[int]] | None = None,
    paced: bool = True,
    lag: float = 0.0,
) -> FakeResult:
    """Check ``script`` (text or checked script) and run it on a fake robot.

    ``paced``: the runner keeps pace with trio's clock, a ``MockClock`` here, as
    ``--realtime`` does with the wall clock; so trio's (virtual) time ends equal to the
    simulated time. Unpaced, it runs as ``dial run`` does, as fast as it can. ``lag``: the
    (virtual) time each period takes the robot; over a period, a paced run falls behind.
    """
    if isinstance(script, str):
        checked = check_text(script, path)
        assert checked is not None
        script = checked
    robot = FakeRobot(period, fault_at, holds)
    robot.lag = lag
    log = EventLog()
    factory = FakeFactory(robot, behaviours or {})
    runner = Runner(robot, factory, tick, log, pace=1.0 if paced else None)
    clock = trio.testing.MockClock(autojump_threshold=0)
    summary = trio.run(runner.run, script, clock=clock)
    return FakeResult(summary, log, robot, clock.current_time())
