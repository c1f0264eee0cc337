"""A fake robot and fake primitives, for testing the scheduler on virtual time.

The fake robot's effectors are single numbers: a fixed-length run writes its
tick-time progress (0 to 1) into each of its effectors, so tests can see a
trajectory hold its set-point while a tick is stretched. Indeterminate and
sensing runs follow a scripted :class:`Behaviour`.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import trio
import trio.testing

from dial.instructions.types import EFFECTORS
from dial.parser.check import check_text
from dial.parser.script import Script
from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner, RunSummary
from dial.scheduler.types import Ended, InstantPrimitive, Now, Outcome, Primitive, RunInfo


@dataclass(frozen=True)
class FakeSnapshot:
    periods: int
    commands: Mapping[str, float]


class FakeRobot:
    """Effectors are numbers; ``advance`` sleeps one period on trio's clock."""

    def __init__(self, period: float = 0.01, fault_at: Mapping[int, str] | None = None) -> None:
        self._period = period
        self.commands: dict[str, float] = dict.fromkeys(EFFECTORS, 0.0)
        self.trace: list[dict[str, float]] = []  # commands applied in each period
        self.periods = 0
        self.held = False
        self.fault_at = dict(fault_at or {})

    @property
    def period(self) -> float:
        return self._period

    def snapshot(self) -> FakeSnapshot:
        return FakeSnapshot(self.periods, MappingProxyType(dict(self.commands)))

    async def advance(self) -> str | None:
        self.trace.append(dict(self.commands))
        self.periods += 1
        await trio.sleep(self._period)
        return self.fault_at.get(self.periods)

    def hold_all(self) -> None:
        self.held = True


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


class _Motion(Primitive):
    def __init__(self, robot: FakeRobot, info: RunInfo) -> None:
        self.robot, self.info = robot, info

    def start(self, snapshot: Any) -> None:
        pass

    def step(self, snapshot: Any, now: Now) -> Ended | None:
        for effector in self.info.event.effectors:
            self.robot.commands[effector] = now.progress
        return None


class _Wait(Primitive):
    def __init__(self, info: RunInfo, behaviour: Behaviour, outcome: Outcome) -> None:
        self.info, self.behaviour, self.outcome = info, behaviour, outcome

    def start(self, snapshot: Any) -> None:
        pass

    def step(self, snapshot: Any, now: Now) -> Ended | None:
        duration = self.behaviour.duration
        if duration is not None and now.elapsed >= duration - 1e-9:
            return Ended(self.outcome, self.behaviour.message)
        return None


class _Sense(InstantPrimitive):
    def __init__(self, outcome: Outcome, message: str) -> None:
        self.outcome, self.message = outcome, message

    def sense(self, snapshot: Any) -> Ended:
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

    def __call__(self, info: RunInfo) -> Primitive:
        name = info.event.name
        behaviour = self.behaviours.get(name, Behaviour())
        length = info.event.instruction.length
        if length == "fixed":
            return _Motion(self.robot, info)
        outcome = self._next(name, behaviour)
        if length == "zero" or info.instant:
            return _Sense(outcome, behaviour.message)
        return _Wait(info, behaviour, outcome)


@dataclass
class FakeResult:
    summary: RunSummary
    log: EventLog
    robot: FakeRobot
    trio_time: float

    def starts(self, event: str) -> list[tuple[int, float]]:
        """(tick, time) of each start of ``event``."""
        return [(r["tick"], r["t"]) for r in self.log.of("start") if r["event"] == event]

    def ends(self, event: str) -> list[tuple[int, float, str]]:
        """(tick, time, outcome) of each end of ``event``."""
        return [
            (r["tick"], r["t"], r["outcome"]) for r in self.log.of("end") if r["event"] == event
        ]

    def stretches(self) -> dict[int, int]:
        """Absolute tick -> periods it was stretched by, for stretched ticks."""
        return {r["tick"]: r["stretch"] for r in self.log.of("tick") if r["stretch"]}


def run_fake(
    script: str | Script,
    tick: float = 0.1,
    behaviours: Mapping[str, Behaviour] | None = None,
    period: float = 0.01,
    path: str = "fake.dial",
    fault_at: Mapping[int, str] | None = None,
) -> FakeResult:
    """Check ``script`` (text or checked script) and run it on a fake robot, on virtual time."""
    if isinstance(script, str):
        checked = check_text(script, path)
        assert checked is not None
        script = checked
    robot = FakeRobot(period, fault_at)
    log = EventLog()
    runner = Runner(robot, FakeFactory(robot, behaviours or {}), tick, log)
    clock = trio.testing.MockClock(autojump_threshold=0)
    summary = trio.run(runner.run, script, clock=clock)
    return FakeResult(summary, log, robot, clock.current_time())
