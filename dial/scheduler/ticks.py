"""The tick clock and the table of active runs: one block at a time (DESIGN 2.5, 2.7).

Every control period the loop hands each active run the same immutable snapshot, in a
fixed order (start tick, then line), lets the robot advance, logs what the robot reports,
and stops the runs that ended, in the same order. Nothing here awaits per run: a run is
a synchronous step object, so trio's task order cannot reach a result.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, NamedTuple, cast

import trio

from dial.errors import DialError
from dial.parser.script import Run, Script, TBlock, TOn, Watch
from dial.scheduler.active import ActiveRun, RunPlan
from dial.scheduler.position import Hooks, Resume
from dial.scheduler.records import Records
from dial.scheduler.signals import StopRequest
from dial.scheduler.types import (
    Ended,
    Fired,
    Interrupted,
    Monitor,
    Now,
    Outcome,
    Primitive,
    PrimitiveFactory,
    Report,
    Robot,
    RunAborted,
    RunInfo,
    S,
    Sensor,
)

ABORT_ON = frozenset({Outcome.TIMEOUT, Outcome.ERROR})
OUTCOME_TEXT = {o: o.value for o in Outcome}  # a dict lookup is cheaper than Enum.value
YIELD_EVERY = 64  # periods between trio checkpoints when not paced (other tasks, I/O)

Progress = Callable[[int, float, list[str]], None]  # (tick, sim time, running events)
Observe = Callable[[int, int], None]  # (periods so far, tick), after every period


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


class TickLoop(Generic[S]):
    """Runs blocks against a robot: the tick clock, the active runs, monitors, preemption."""

    def __init__(
        self,
        robot: Robot[S],
        factory: PrimitiveFactory[S],
        n: int,
        records: Records,
        stop: StopRequest,
        observe: Observe | None = None,
        progress: Progress | None = None,
        pace: float | None = None,
    ) -> None:
        self.robot, self.factory, self.n = robot, factory, n
        self.period = robot.period
        self.records, self.stop = records, stop
        self.observe, self.progress, self.pace = observe, progress, pace
        self.periods = 0  # control periods simulated so far
        self.clock = 0  # tick time, in periods: stands still while a tick is stretched
        self.tick = 0  # absolute ticks started so far
        self.active: list[ActiveRun[S]] = []  # this block's unstopped runs, in step order
        self.latest: dict[tuple[str, str], Outcome] = {}  # (script, event) -> last outcome
        self.counts: dict[str, int] = defaultdict(int)
        self.abort: RunAborted | None = None
        self._ending = False  # some run ended this period: stop it after the period
        self._plans: dict[int, _Plan] = {}
        self._runs: dict[tuple[str, int], RunPlan] = {}
        self.hooks: Hooks | None = None
        self._snap: S | None = None
        self.t0 = 0.0  # trio time at the first period, for pacing

    @property
    def sim_time(self) -> float:
        return self.periods * self.period

    def progress_of(self, a: ActiveRun[S]) -> float:
        """A run's progress in tick time now (0 to 1)."""
        return 1.0 if a.span == self.n else min(1.0, (self.clock - a.start_clock) / a.span)

    def restore(self, resume: Resume) -> None:
        """Take up the clocks, outcomes and counts of a run saved at a block boundary."""
        self.periods, self.clock, self.tick = resume.periods, resume.clock, resume.tick
        self.latest.update(resume.latest)
        self.counts.update(resume.counts)

    # -- one block ------------------------------------------------------------------------------
    async def block(self, script: Script, block: TBlock) -> Preempted | None:
        """Run ``block`` tick by tick; return the reaction to run if a monitor preempted it."""
        plan = self._plan(block)
        monitors: dict[int, tuple[int, Watch]] = {}  # robot key -> (reaction index, watch)
        try:
            for k in range(1, block.length + 1):
                self.tick += 1
                t0 = self.sim_time
                if self.hooks is not None:
                    await self.hooks.before_tick(self.tick, script, plan.starts.get(k, ()))
                    self._raise_pending()  # a signal while paused
                for watch in plan.watch_from.get(k, ()):
                    self._arm(script, block, watch, monitors)
                for run in plan.starts.get(k, ()):
                    self._start(script, run)
                self._raise_pending()
                stretch = 0
                for _ in range(self.n):
                    self.clock += 1
                    if fired := await self._period(stretched=False):
                        return await self._preempted(script, block, fired, monitors, k, t0, stretch)
                # An indeterminate run still going at the end of its last tick stretches it.
                stretching = self._finish(k)
                while stretching:
                    stretch += 1
                    if fired := await self._period(stretched=True):
                        return await self._preempted(script, block, fired, monitors, k, t0, stretch)
                    stretching = any(a.info.run.exec_end == k for a in self.active)
                for watch in plan.watch_to.get(k, ()):
                    self._disarm(monitors, watch)
                self._tick_done(k, t0, stretch, preempted=False)
            return None
        finally:
            for key in monitors:
                self.robot.disarm(key)

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
    def _run_plan(self, script: Script, run: Run) -> RunPlan:
        key = (script.path, id(run))
        plan = self._runs.get(key)
        if plan is None:
            event = script.events[run.event]
            info = RunInfo(event, run, script.path, self.n, self.period)
            plan = self._runs[key] = RunPlan.of(info)
        return plan

    def _snapshot(self) -> S:
        """The robot's snapshot, taken once per state: starts, senses and the next period's
        steps share it until the robot advances or a run's finish or stop writes a slot."""
        if self._snap is None:
            self._snap = self.robot.snapshot()
        return self._snap

    def _start(self, script: Script, run: Run) -> None:
        """Start a run in line order; a sensing run happens at once."""
        plan = self._run_plan(script, run)
        prim = self.factory(plan.info)
        self.counts["runs"] += 1
        self.records.start(script.path, run, self.tick, self.sim_time)
        if plan.info.event.instruction.length == "zero":
            self._sense(script, run, cast("Sensor[S]", prim))
            return
        prim_s = cast("Primitive[S]", prim)  # quoted: Primitive[S] at run time costs 0.3 us
        active = ActiveRun(script, plan, prim_s, self.tick, self.periods, self.clock)
        self.active.append(active)  # from here on, its stop runs whatever happens
        try:
            active.prim.start(self._snapshot())
        except DialError as e:
            self._end(active, Ended(Outcome.ERROR, str(e)), self.sim_time)

    def sense(self, script: Script, run: Run) -> None:
        """Sense a condition-only event now, with zero duration (no start record)."""
        info = RunInfo(script.events[run.event], run, script.path, self.n, self.period, True)
        sensor = cast("Sensor[S]", self.factory(info))
        self._sense(script, run, sensor)

    def _sense(self, script: Script, run: Run, sensor: Sensor[S]) -> None:
        try:
            ended = sensor.sense(self._snapshot())
        except DialError as e:
            ended = Ended(Outcome.ERROR, str(e))
        self._record_end(script, run, ended, self.sim_time)
        if ended.outcome in ABORT_ON:
            raise self._aborted(script, run, ended)

    # -- control periods ----------------------------------------------------------------------
    async def _period(self, stretched: bool) -> tuple[Fired, ...]:
        fired = self._step(stretched)
        if self.pace is not None:  # --realtime: never changes what happens, only when
            await trio.sleep_until(self.t0 + self.periods * self.period * self.pace)
        elif self.periods % YIELD_EVERY == 0:
            await trio.lowlevel.checkpoint()
        if self.hooks is not None and self.hooks.each_period:
            await self.hooks.after_period(self.periods)
            self._raise_pending()
        return fired

    def _step(self, stretched: bool) -> tuple[Fired, ...]:
        """Step every active run in order, advance the robot, stop the runs that ended."""
        snapshot = self._snapshot()
        periods = self.periods + 1
        t_end = periods * self.period
        tick, clock, n = self.tick, self.clock, self.n
        for a in self.active:
            if a.ended is not None:
                continue
            elapsed = (periods - a.start_period) * self.period
            # A one-tick run is a GOTO MOVE: the set-point jumps at once.
            progress = 1.0 if a.span == n else min(1.0, (clock - a.start_clock) / a.span)
            try:
                ended = a.prim.step(snapshot, Now(t_end, tick, progress, elapsed, stretched))
            except DialError as e:
                ended = Ended(Outcome.ERROR, str(e))
            if ended is None and a.timeout is not None and elapsed >= a.timeout - 1e-9:
                ended = Ended(Outcome.TIMEOUT, f"no result after {a.timeout:g} s")
            if ended is not None:
                self._end(a, ended, t_end)
        report = self.robot.advance()
        self._snap = None
        self.periods = periods
        fired = () if report is None else self._report(report)
        if self.observe is not None:
            self.observe(periods, tick)
        self._raise_pending()
        return fired

    def _report(self, report: Report) -> tuple[Fired, ...]:
        for happening in report.happenings:
            self.records.happening(happening, self.tick)
        if report.fault is not None and self.abort is None:
            running = ", ".join(a.info.event.name for a in self.active if a.ended is None)
            self.abort = RunAborted(
                f"safety monitor: {report.fault} (running: {running or 'no event'})",
                None,
                self.tick,
            )
        return report.fired

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

    # -- ending runs ----------------------------------------------------------------------------
    def _end(self, a: ActiveRun[S], ended: Ended, t: float) -> None:
        a.ended = ended
        self._ending = True
        self._record_end(a.script, a.info.run, ended, t)
        if ended.outcome in ABORT_ON and self.abort is None:
            self.abort = self._aborted(a.script, a.info.run, ended)

    def _record_end(self, script: Script, run: Run, ended: Ended, t: float) -> None:
        self.latest[(script.path, run.event)] = ended.outcome
        self.counts[OUTCOME_TEXT[ended.outcome]] += 1
        self.records.end(script.path, run, ended, self.tick, t)

    def _raise_pending(self) -> None:
        """Stop the runs that ended; then stop the script if a signal or an abort says so."""
        if self._ending:
            self.stop_runs(ended_only=True)
        if self.stop.signal is not None:
            raise Interrupted(self.stop.signal)
        if self.abort is not None:
            raise self.abort

    def stop_runs(self, ended_only: bool = False) -> None:
        """Call ``stop`` of the (ended) active runs, in order: every one, even if one raises."""
        self._ending = False
        self._snap = None  # a stop (or the finish before it) may have written a slot
        keep = [a for a in self.active if ended_only and a.ended is None]
        stopping = [a for a in self.active if not (ended_only and a.ended is None)]
        self.active = keep
        error: BaseException | None = None
        for a in stopping:
            try:
                a.prim.stop()
            except BaseException as e:  # the others still stop; the first error goes on
                error = error or e
        if error is not None:
            raise error

    def _aborted(self, script: Script, run: Run, ended: Ended) -> RunAborted:
        line = script.events[run.event].definition.line
        why = f": {ended.message}" if ended.message else ""
        return RunAborted(
            f"event '{run.event}' (defined on line {line} of {script.path}) ended "
            f"{ended.outcome.value} at tick {self.tick}{why}",
            run.event,
            self.tick,
        )

    # -- monitors and preemption (DESIGN 2.7) -------------------------------------------------
    def _arm(
        self, script: Script, block: TBlock, watch: Watch, monitors: dict[int, tuple[int, Watch]]
    ) -> None:
        event = script.events[watch.event]
        for index, on in enumerate(block.reactions):
            if on.condition.event == watch.event:
                key = self.robot.arm(Monitor(event, on.condition.negated))
                monitors[key] = (index, watch)

    def _disarm(self, monitors: dict[int, tuple[int, Watch]], watch: Watch) -> None:
        for key in [k for k, (_, w) in monitors.items() if w is watch]:
            self.robot.disarm(key)
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
