"""A fake robot with a physical limit, for testing tick tuning without physics.

The fake robot of :mod:`dial.testing.fake` follows every command at once, so any
tick length succeeds. Here each effector moves toward its command at no more
than ``max_speed`` (command units per simulated second). A fixed-length motion
commands progress 0 to 1 over its ``#``/``=`` ticks; when those ticks are too
short, the effector ends short of the goal and the criterion ``reached_goal``
fails. For ``go #===`` (four ticks of T seconds) the effector reaches
``min(1, 4 * T * max_speed)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import trio
import trio.testing

from dial.instructions.types import EFFECTORS
from dial.parser.check import load
from dial.parser.script import Script
from dial.robot.protocol import Report
from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner, Tally
from dial.testing.fake import FakeFactory, FakeRobot
from dial.tune.grid import Trial
from dial.tune.trial import TrialRun


class LimitedRobot(FakeRobot):
    """Effectors are numbers that follow their commands at a bounded speed."""

    def __init__(
        self,
        max_speed: float,
        period: float = 0.01,
        fault_at: Mapping[int, str] | None = None,
    ) -> None:
        super().__init__(period, fault_at)
        self.max_speed = max_speed
        self.positions: dict[str, float] = dict.fromkeys(EFFECTORS, 0.0)

    def advance(self) -> Report | None:
        reach = self.max_speed * self.period
        for effector, command in self.commands.items():
            here = self.positions[effector]
            self.positions[effector] = here + min(reach, max(-reach, command - here))
        return super().advance()

    def shortfall(self) -> float:
        """The largest distance between an effector and its command."""
        return max(abs(self.commands[e] - self.positions[e]) for e in EFFECTORS)


@dataclass(frozen=True)
class LimitedResult:
    summary: Tally
    robot: LimitedRobot
    reached_goal: bool


def run_limited(
    script: Script,
    tick: float,
    max_speed: float = 1.0,
    tolerance: float = 0.02,
    fault_at: Mapping[int, str] | None = None,
) -> LimitedResult:
    """Run ``script`` on a :class:`LimitedRobot` on virtual time; check every goal was reached."""
    robot = LimitedRobot(max_speed, fault_at=fault_at)
    runner = Runner(robot, FakeFactory(robot), tick, EventLog())
    clock = trio.testing.MockClock(autojump_threshold=0)
    summary = trio.run(runner.run, script, clock=clock)
    return LimitedResult(summary, robot, robot.shortfall() <= tolerance)


def limited_backend(
    trial: Trial,
    max_speed: float = 1.0,
    tolerance: float = 0.02,
    fault_at: Mapping[int, str] | None = None,
) -> TrialRun:
    """A ``dial.tune`` backend on the limited fake robot (``--perturb`` has no effect here).

    Bind the keywords with :func:`functools.partial` to keep it picklable.
    """
    script = load(Path(trial.script), display=trial.display)
    result = run_limited(script, trial.tick, max_speed, tolerance, fault_at)
    summary = result.summary
    error = str(summary.error) if summary.error is not None else None
    return TrialRun(
        {"reached_goal": result.reached_goal}, summary.sim_time, summary.tick_length, error
    )
