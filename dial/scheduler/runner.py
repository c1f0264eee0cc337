"""The runner: walks a checked script's timeline, block by block, on a robot.

Read it top-down: :meth:`Runner.run` sets up and always cleans up; :meth:`Runner._walk`
follows the timeline (blocks, repeats, branches, calls, and the reactions of DESIGN 2.7);
each block is run by the :class:`~dial.scheduler.ticks.TickLoop`, which owns the tick
clock and the table of active runs. Every record goes through
:class:`~dial.scheduler.records.Records`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Generic

import trio

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
from dial.robot.protocol import Clocked
from dial.scheduler.log import EventLog
from dial.scheduler.position import Frame, Hooks, Resume, TimelinePath
from dial.scheduler.primitive import Outcome
from dial.scheduler.records import Records
from dial.scheduler.signals import StopRequest
from dial.scheduler.ticks import Observe, Progress, TickLoop
from dial.scheduler.types import Interrupted, PrimitiveFactory, RunAborted, S, periods_per_tick

Ending = TResume | TRetry | TAbort  # how a reaction ends, once one of these is executed


@dataclass(frozen=True)
class Tally:
    """The runner's tally of a script's run, finished, aborted or interrupted: its ticks,
    periods and simulated time, and how many of its events' runs ended each way.

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


class Runner(Generic[S]):
    """Run a checked script's timeline against a robot."""

    def __init__(
        self,
        robot: Clocked[S],
        factory: PrimitiveFactory[S],
        tick: float,
        log: EventLog | None = None,
        *,
        progress: Progress | None = None,
        observe: Observe | None = None,
        pace: float | None = None,
        stop: StopRequest | None = None,
        hooks: Hooks | None = None,
    ) -> None:
        self.robot = robot
        self.n = periods_per_tick(tick, robot.period)
        self.log = log or EventLog()
        self.stop = stop or StopRequest()
        self.hooks = hooks
        self.blocks = 0  # blocks started so far (a repeated or retried block each time)
        self._factory = factory
        self._options = (progress, observe, pace)
        self._path: list[Frame] = []  # where the walk is now
        self.loop: TickLoop[S] | None = None

    async def run(self, script: Script, resume: Resume | None = None) -> Tally:
        """Run the script to its end, its abort or a stop signal; every effector then holds.

        ``resume``: go on from a saved block boundary instead of the first block.
        """
        records = Records(self.log, script.path)
        progress, observe, pace = self._options
        loop = self.loop = TickLoop(
            self.robot, self._factory, self.n, records, self.stop, observe, progress, pace
        )
        loop.hooks = self.hooks
        if resume is not None:
            loop.restore(resume)
            self.blocks = resume.blocks
        error: RunAborted | None = None
        interrupted: str | None = None
        if pace is not None:
            loop.t0 = trio.current_time()
        try:
            if self.stop.signal is not None:  # it came while the scene was being prepared
                raise Interrupted(self.stop.signal)
            await self._main(loop, script, resume.path if resume is not None else ())
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
        return Tally(
            error is None and interrupted is None,
            error,
            loop.sim_time,
            loop.tick,
            loop.periods,
            self.n * self.robot.period,
            dict(sorted(loop.counts.items())),
            interrupted,
        )

    async def _main(self, loop: TickLoop[S], script: Script, path: TimelinePath) -> None:
        """The run's body: the timeline's walk (a remote robot takes blocks from its operator
        instead, dial/remote/blocks.py)."""
        await self._walk(loop, script, script.timeline, path)

    # -- the timeline walk ------------------------------------------------------------------------
    async def _walk(
        self, loop: TickLoop[S], script: Script, steps: tuple[Step, ...], resume: TimelinePath = ()
    ) -> Ending | None:
        """Run ``steps`` in order (from ``resume`` on, if given); return the reaction ending
        that stopped them, if any."""
        first = resume[0].step if resume else 0
        for i in range(first, len(steps)):
            at, inner = (resume[0], resume[1:]) if resume and i == first else (Frame(i), ())
            self._path.append(at)
            try:
                ending = await self._step(loop, script, steps[i], at, inner)
            finally:
                self._path.pop()
            if ending is not None:
                return ending
        return None

    async def _step(
        self, loop: TickLoop[S], script: Script, step: Step, at: Frame, inner: TimelinePath
    ) -> Ending | None:
        if isinstance(step, TBlock):
            await self._block(loop, script, step, at, inner)
        elif isinstance(step, TRepeat):
            return await self._repeat(loop, script, step, at, inner)
        elif isinstance(step, TIf):
            if inner:  # resumed inside the branch it took: its condition was tested then
                then = at.detail == 0
            else:
                then = self._test(loop, script, step.condition)
                self._path[-1] = Frame(at.step, 0 if then else 1)
            return await self._walk(loop, script, step.then if then else step.orelse, inner)
        elif isinstance(step, TCall):
            if not inner:
                loop.records.call(step.script.path, loop.tick, loop.sim_time)
            await self._walk(loop, step.script, step.script.timeline, inner)
        else:
            return step  # @resume, @retry or @abort: the reaction ends here
        return None

    async def _block(
        self, loop: TickLoop[S], script: Script, block: TBlock, at: Frame, inner: TimelinePath
    ) -> None:
        """A block, and its reactions each time a monitor preempts it (DESIGN 2.7)."""
        retries = at.detail
        reacting = at.reaction  # resumed inside a reaction of this block
        while True:
            if reacting < 0:
                self._path[-1] = Frame(at.step, retries)
                self.blocks += 1
                if self.hooks is not None:
                    await self.hooks.before_block(self.blocks, tuple(self._path), script, block)
                loop.records.block(
                    script.path, self.blocks, block.line, loop.tick + 1, loop.sim_time
                )
                preempted = await loop.block(script, block)
                if preempted is None:
                    return
                reacting, fired_at = block.reactions.index(preempted.reaction), preempted.tick
            else:
                fired_at = loop.tick
            on = block.reactions[reacting]
            self._path[-1] = Frame(at.step, retries, reacting)
            ending = await self._walk(loop, script, on.body, inner)
            inner, reacting = (), -1
            where = f"the monitor '@on {on.condition}' (line {on.line} of {script.path})"
            if isinstance(ending, TAbort):
                raise RunAborted(
                    f"@abort on line {ending.line} of {script.path}: {ending.message} "
                    f"({where} fired at tick {fired_at})",
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

    async def _repeat(
        self, loop: TickLoop[S], script: Script, step: TRepeat, at: Frame, inner: TimelinePath
    ) -> Ending | None:
        for k in range(at.detail, step.count):
            self._path[-1] = Frame(at.step, k)
            resumed = bool(inner) and k == at.detail  # its while-test was done before the save
            if (
                step.kind == "while"
                and not resumed
                and not self._test(loop, script, step.condition)
            ):
                return None
            ending = await self._walk(loop, script, step.body, inner if resumed else ())
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
