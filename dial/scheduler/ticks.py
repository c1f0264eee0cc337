"""The tick clock: one block at a time, tick by tick (DESIGN 2.5, 2.7).

A block's runs start in line order at their tick; every tick's control periods go through
:class:`~dial.scheduler.periods.Periods`; a fixed-length run ends with its last executing
tick, and an indeterminate one still going stretches it. The robot watches the monitors of
a watched span; when one fires, the block is preempted and its ``@on`` reaction runs next.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from typing import NamedTuple

from dial.errors import DialError
from dial.parser.script import Run, Script, TBlock, TOn, Watch
from dial.robot.protocol import Clocked, Course, Fired, Monitor
from dial.scheduler.active import ActiveRun
from dial.scheduler.periods import ABORT_ON, Observe, Periods, Progress
from dial.scheduler.primitive import Ended, Outcome, Sensor
from dial.scheduler.records import Records
from dial.scheduler.signals import StopRequest
from dial.scheduler.types import PrimitiveFactory, RunInfo, S

__all__ = ["Observe", "Preempted", "Progress", "TickLoop"]


class _Plan(NamedTuple):
    """A block's runs and watched spans by the block tick they start (or end) in."""

    starts: dict[int, list[Run]]
    watch_from: dict[int, list[Watch]]
    watch_to: dict[int, list[Watch]]


@dataclass(frozen=True)
class Preempted:
    """A monitor of the block fired: ``reaction`` is the ``@on`` that runs next."""

    reaction: TOn
    tick: int


class TickLoop(Periods[S]):
    """Runs blocks against a robot: the tick clock, the active runs, monitors, preemption."""

    def __init__(
        self,
        robot: Clocked[S],
        factory: PrimitiveFactory[S],
        n: int,
        records: Records,
        stop: StopRequest,
        observe: Observe | None = None,
        progress: Progress | None = None,
        pace: float | None = None,
    ) -> None:
        super().__init__(robot, n, records, stop, observe, pace)
        self.factory, self.progress = factory, progress
        self._plans: dict[int, _Plan] = {}
        self._runs: dict[tuple[str, int], RunInfo] = {}

    # -- one block ------------------------------------------------------------------------------
    async def block(self, script: Script, block: TBlock) -> Preempted | None:
        """Run ``block`` tick by tick; return the reaction to run if a monitor preempted it."""
        plan = self._plan(block)
        monitors: dict[int, tuple[int, Watch]] = {}  # robot key -> (reaction index, watch)
        try:
            k = 0
            while k < block.length:
                k += 1
                self.tick += 1
                t0 = self.sim_time
                if self.hooks is not None:
                    await self.hooks.before_tick(self.tick, script, plan.starts.get(k, ()))
                    self._raise_pending()  # a signal while paused
                for watch in plan.watch_from.get(k, ()):
                    self._watch(script, block, watch, monitors)
                for run in plan.starts.get(k, ()):
                    self._start(script, run)
                self._raise_pending()
                stretch, left = 0, self.n
                while left:
                    quiet = self._quiet(plan, k, block.length) if left == self.n else 0
                    writes = self._courses((quiet + 1) * self.n) if quiet else None
                    if writes is not None:  # this tick and quiet ones after it at once
                        fired, k, t0, left = await self._glide(writes, quiet + 1, k, t0)
                    else:
                        fired, done = await self._periods(left)
                        left -= done
                    if fired:
                        return await self._preempted(script, block, fired, monitors, k, t0, stretch)
                # An indeterminate run still going at the end of its last tick stretches it.
                stretching = self._finish(k)
                while stretching:
                    stretch += 1
                    if fired := await self._period(stretched=True):
                        return await self._preempted(script, block, fired, monitors, k, t0, stretch)
                    stretching = any(a.info.run.exec_end == k for a in self.active)
                for watch in plan.watch_to.get(k, ()):
                    self._unwatch(monitors, watch)
                self._tick_done(k, t0, stretch, preempted=False)
            return None
        finally:
            for key in monitors:
                self.robot.unwatch(key)

    def _quiet(self, plan: _Plan, k: int, length: int) -> int:
        """How many ticks after tick ``k`` can be coasted along with it: while no run starts
        or ends, and no watched span begins or ends, a tick boundary only writes its record."""
        if k >= length or k + 1 in plan.starts or k + 1 in plan.watch_from or k in plan.watch_to:
            return 0  # the first boundary is not quiet (the common case with short runs)
        if self.observe is not None or self.hooks is not None or self.pace is not None:
            return 0
        runs = [a for a in self.active if a.ended is None]
        if not all(a.prim.open_loop for a in runs):
            return 0
        ends = {a.info.run.exec_end for a in runs}
        j = k
        while j < length and j not in ends and j not in plan.watch_to:
            if j + 1 in plan.starts or j + 1 in plan.watch_from:
                break
            j += 1
        return j - k

    async def _glide(
        self, writes: list[Course], ticks: int, k: int, t0: float
    ) -> tuple[tuple[Fired, ...], int, float, int]:
        """Coast through ``ticks`` ticks from tick ``k`` (quiet ones, see :meth:`_quiet`),
        writing each finished tick's record at its place; stop after a period the robot
        reports on, in the tick it belongs to. Returns what fired, that tick, its start time,
        and its periods left."""
        n, start = self.n, self.periods
        done, report = self.robot.coast(writes, ticks * n, self.stop)
        for _ in range((done - 1) // n):  # the ticks finished before the last period's
            self.periods += n
            self.clock += n
            self._tick_done(k, t0, 0, preempted=False)
            k, t0 = k + 1, self.sim_time
            self.tick += 1
        rest = done - (self.periods - start)
        fired = self._coasted(rest, report)
        await self._yield_since(start)
        return fired, k, t0, n - rest

    def _plan(self, block: TBlock) -> _Plan:
        plan = self._plans.get(id(block))
        if plan is None:
            starts: dict[int, list[Run]] = defaultdict(list)
            for run in block.runs:  # already in (start tick, line) order
                starts[run.start].append(run)
            watch_from: dict[int, list[Watch]] = defaultdict(list)
            watch_to: dict[int, list[Watch]] = defaultdict(list)
            for watch in block.watches:
                watch_from[watch.start].append(watch)
                watch_to[watch.end].append(watch)
            plan = self._plans[id(block)] = _Plan(starts, watch_from, watch_to)
        return plan

    def _tick_done(self, k: int, t0: float, stretch: int, preempted: bool) -> None:
        self.active = [a for a in self.active if a.ended is None]
        if self.progress is not None:
            self.progress(self.tick, self.sim_time, [a.info.event.name for a in self.active])
        self.records.tick(self.tick, k, t0, self.sim_time, stretch, preempted)

    # -- starting and sensing runs ------------------------------------------------------------
    def _info(self, script: Script, run: Run) -> RunInfo:
        """The run's place, worked out once per run of the timeline."""
        key = (script.path, id(run))
        info = self._runs.get(key)
        if info is None:
            event = script.events[run.event]
            info = self._runs[key] = RunInfo(event, run, script.path, self.n, self.period)
        return info

    def _start(self, script: Script, run: Run) -> None:
        """Start a run in line order; a sensing run happens at once."""
        info = self._info(script, run)
        self.counts["runs"] += 1
        if info.event.instruction.length == "zero":
            sensor = self.factory.sensor(info)
            self.records.start(script.path, run, self.tick, self.sim_time)
            self._sense(script, run, sensor)
            return
        prim = self.factory.primitive(info)
        self.records.start(script.path, run, self.tick, self.sim_time)
        active = ActiveRun(script, info, prim, self.tick, self.periods, self.clock)
        self.active.append(active)  # from here on, its stop runs whatever happens
        try:
            active.prim.start(self._snapshot())
        except DialError as e:
            self._end(active, Ended(Outcome.ERROR, str(e)), self.sim_time)

    def sense(self, script: Script, run: Run) -> None:
        """Sense a condition-only event now, with zero duration (no start record)."""
        info = RunInfo(script.events[run.event], run, script.path, self.n, self.period)
        self._sense(script, run, self.factory.sensor(info))

    def _sense(self, script: Script, run: Run, sensor: Sensor[S]) -> None:
        try:
            ended = sensor.sense(self._snapshot())
        except DialError as e:
            ended = Ended(Outcome.ERROR, str(e))
        self._record_end(script, run, ended, self.sim_time)
        if ended.outcome in ABORT_ON:
            raise self._aborted(script, run, ended)

    def _finish(self, k: int) -> bool:
        """End the fixed-length runs whose last executing tick ``k`` was; whether an
        indeterminate one is still going, so that the tick stretches."""
        stretching = False
        for a in self.active:
            if a.ended is not None or a.info.run.exec_end != k:
                continue
            if not a.fixed:
                stretching = True
                continue
            try:
                ended = a.prim.finish(self._snapshot())
            except DialError as e:
                ended = Ended(Outcome.ERROR, str(e))
            self._end(a, ended, self.sim_time)
        self._raise_pending()
        return stretching

    # -- monitors and preemption (DESIGN 2.7) -------------------------------------------------
    def _watch(
        self, script: Script, block: TBlock, watch: Watch, monitors: dict[int, tuple[int, Watch]]
    ) -> None:
        for index, on in enumerate(block.reactions):
            if on.condition.event == watch.event:
                monitor = Monitor(watch.event, watch.contact, on.condition.negated)
                monitors[self.robot.watch(monitor)] = (index, watch)

    def _unwatch(self, monitors: dict[int, tuple[int, Watch]], watch: Watch) -> None:
        for key in [k for k, (_, w) in monitors.items() if w is watch]:
            self.robot.unwatch(key)
            del monitors[key]

    async def _preempted(
        self,
        script: Script,
        block: TBlock,
        fired: tuple[Fired, ...],
        monitors: dict[int, tuple[int, Watch]],
        k: int,
        t0: float,
        stretch: int,
    ) -> Preempted:
        preempted = self._preempt(script, block, fired, monitors, k, t0, stretch)
        if self.hooks is not None:
            cond = preempted.reaction.condition
            await self.hooks.after_monitor(cond.event, str(cond), self.tick)
            self._raise_pending()
        return preempted

    def _preempt(
        self,
        script: Script,
        block: TBlock,
        fired: tuple[Fired, ...],
        monitors: dict[int, tuple[int, Watch]],
        k: int,
        t0: float,
        stretch: int,
    ) -> Preempted:
        """End the block at this period: its unended runs are preempted and hold still."""
        # Several monitors may fire in one period: the first '@on' in file order wins.
        index, first = min((monitors[f.key][0], f) for f in fired if f.key in monitors)
        on = block.reactions[index]
        cond = on.condition
        self.records.monitor(
            script.path, cond, on.line, self.tick, first.time, self.periods, first.step
        )
        # What a condition on the watched event sees afterwards: whether it held when fired.
        self.latest[(script.path, cond.event)] = Outcome.MISSED if cond.negated else Outcome.DONE
        held: set[str] = set()
        for a in self.active:
            if a.ended is None:
                message = f"by the monitor '@on {cond}' on line {on.line}"
                self._end(a, Ended(Outcome.PREEMPTED, message), self.sim_time)
                held |= a.info.event.effectors
        self.stop_runs(ended_only=True)
        self.robot.hold(frozenset(held))
        self._snap = None
        self._tick_done(k, t0, stretch, preempted=True)
        return Preempted(on, self.tick)
