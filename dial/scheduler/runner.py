"""The runner: walks a checked script's timeline, block by block, on a robot.

Read it top-down: :meth:`Runner.run` sets up and always cleans up; :meth:`Runner._walk`
follows the timeline (blocks, repeats, branches, calls, and the reactions of DESIGN 2.7);
each block is run by the :class:`~dial.scheduler.ticks.TickLoop`, which owns the tick
clock and the table of active runs. Every record goes through
:class:`~dial.scheduler.records.Records`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Generic

import trio

from dial.errors import DialError
from dial.parser.ast import Condition
from dial.parser.script import (
    Run,
    Script,
    Step,
    TAbort,
    TBlock,
    TCall,
    TIf,
    TRepeat,
    TResume,
    TRetry,
)
from dial.scheduler.log import EventLog
from dial.scheduler.records import Records
from dial.scheduler.signals import StopRequest, catch_stop_signals
from dial.scheduler.ticks import Observe, Progress, TickLoop
from dial.scheduler.types import Interrupted, Outcome, PrimitiveFactory, Robot, RunAborted, S

Ending = TResume | TRetry | TAbort  # how a reaction ends, once one of these is executed


@dataclass(frozen=True)
class RunSummary:
    """What a finished, aborted or interrupted run reports.

    ``error`` is why the script stopped early (None when it ran to its end);
    ``interrupted`` names the signal that stopped it (``SIGINT``/``SIGTERM``), if any.
    """

    ok: bool
    error: RunAborted | None
    sim_time: float
    ticks: int
    periods: int
    tick_length: float
    outcomes: dict[str, int]
    interrupted: str | None = None


def periods_per_tick(tick: float, period: float) -> int:
    """Ticks are whole numbers of control periods."""
    if not math.isfinite(tick) or round(tick / period) < 1:
        raise DialError(f"tick length {tick:g} s is shorter than the control period {period:g} s")
    return round(tick / period)


class Runner(Generic[S]):
    """Run a checked script's timeline against a robot."""

    def __init__(
        self,
        robot: Robot[S],
        factory: PrimitiveFactory[S],
        tick: float,
        log: EventLog | None = None,
        *,
        progress: Progress | None = None,
        observe: Observe | None = None,
        pace: float | None = None,
        stop: StopRequest | None = None,
    ) -> None:
        self.robot = robot
        self.n = periods_per_tick(tick, robot.period)
        self.log = log or EventLog()
        self.stop = stop or StopRequest()
        self._factory = factory
        self._options = (progress, observe, pace)
        self.loop: TickLoop[S] | None = None

    async def run(self, script: Script) -> RunSummary:
        """Run the script to its end, its abort or a stop signal; every effector then holds."""
        records = Records(self.log, script.path)
        progress, observe, pace = self._options
        loop = self.loop = TickLoop(
            self.robot, self._factory, self.n, records, self.stop, observe, progress, pace
        )
        error: RunAborted | None = None
        interrupted: str | None = None
        if pace is not None:
            loop.t0 = trio.current_time()
        try:
            with catch_stop_signals(self.stop):
                if self.stop.signal is not None:  # it came while the scene was being prepared
                    raise Interrupted(self.stop.signal)
                await self._walk(loop, script, script.timeline)
        except RunAborted as e:
            error = e
            records.error(e.event, e.tick, loop.sim_time, str(e))
        except Interrupted as e:
            interrupted = e.signal_name
            records.interrupted(e.signal_name, loop.tick, loop.sim_time)
        finally:
            try:
                loop.stop_runs()  # stop always runs, in order, on every path
            finally:
                self.robot.hold_all()  # on abort, interrupt or bug: the arm never drops
        return RunSummary(
            error is None and interrupted is None,
            error,
            loop.sim_time,
            loop.tick,
            loop.periods,
            self.n * self.robot.period,
            dict(sorted(loop.counts.items())),
            interrupted,
        )

    # -- the timeline walk ------------------------------------------------------------------------
    async def _walk(
        self, loop: TickLoop[S], script: Script, steps: tuple[Step, ...]
    ) -> Ending | None:
        """Run ``steps`` in order; return the reaction ending that stopped them, if any."""
        for step in steps:
            ending: Ending | None = None
            if isinstance(step, TBlock):
                await self._block(loop, script, step)
            elif isinstance(step, TRepeat):
                ending = await self._repeat(loop, script, step)
            elif isinstance(step, TIf):
                branch = step.then if self._test(loop, script, step.condition) else step.orelse
                ending = await self._walk(loop, script, branch)
            elif isinstance(step, TCall):
                loop.records.call(step.script.path, loop.tick, loop.sim_time)
                await self._walk(loop, step.script, step.script.timeline)
            else:
                return step  # @resume, @retry or @abort: the reaction ends here
            if ending is not None:
                return ending
        return None

    async def _block(self, loop: TickLoop[S], script: Script, block: TBlock) -> None:
        """A block, and its reactions each time a monitor preempts it (DESIGN 2.7)."""
        retries = 0
        while True:
            preempted = await loop.block(script, block)
            if preempted is None:
                return
            on = preempted.reaction
            ending = await self._walk(loop, script, on.body)
            where = f"the monitor '@on {on.condition}' (line {on.line} of {script.path})"
            if isinstance(ending, TAbort):
                raise RunAborted(
                    f"@abort on line {ending.line} of {script.path}: {ending.message} "
                    f"({where} fired at tick {preempted.tick})",
                    on.condition.event,
                    loop.tick,
                )
            if not isinstance(ending, TRetry):
                return  # @resume, or the reaction's end: go on after the block
            retries += 1
            if retries > ending.max:
                raise RunAborted(
                    f"'@retry max {ending.max}' on line {ending.line} of {script.path} reached "
                    f"its max: the block on line {block.line} was preempted {retries} times "
                    f"by {where}",
                    on.condition.event,
                    loop.tick,
                )

    async def _repeat(self, loop: TickLoop[S], script: Script, step: TRepeat) -> Ending | None:
        for _ in range(step.count):
            if step.kind == "while" and not self._test(loop, script, step.condition):
                return None
            ending = await self._walk(loop, script, step.body)
            if ending is not None:
                return ending
            if step.kind == "until" and self._test(loop, script, step.condition):
                return None
        if step.kind == "count" or (
            step.kind == "while" and not self._test(loop, script, step.condition)
        ):
            return None
        raise RunAborted(
            f"'@repeat {step.kind} {step.condition}' on line {step.line} of {script.path} "
            f"reached its max of {step.count} iterations",
            None,
            loop.tick,
        )

    def _test(self, loop: TickLoop[S], script: Script, cond: Condition | None) -> bool:
        """A condition: did the latest run of its event end ``done`` (sensing it now if it is
        condition-only)?"""
        assert cond is not None, "until/while loops have a condition"
        if cond.event in script.condition_only:
            line = script.events[cond.event].definition.line
            loop.sense(script, Run(cond.event, line, 1, 1, 1, frozenset()))
        value = (loop.latest.get((script.path, cond.event)) is Outcome.DONE) != cond.negated
        loop.records.condition(script.path, cond, value, loop.tick, loop.sim_time)
        return value
