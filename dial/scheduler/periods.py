"""The control periods of the tick loop: the active runs stepped in order, or coasted.

Every control period the loop hands each active run the same immutable snapshot, in a
fixed order (start tick, then line), lets the robot advance, logs what the robot reports,
and stops the runs that ended, in the same order. Nothing here awaits per run: a run is
a synchronous step object, so trio's task order cannot reach a result.

When every active run is open-loop (:attr:`~dial.scheduler.types.Primitive.open_loop`: its
set-points depend on its progress alone), the rest of the tick needs no snapshot and no
step: the loop takes the runs' courses for those periods at once and the robot *coasts*
through them (:meth:`~dial.robot.protocol.Clocked.coast`), stopping early after any period
whose report says something. The periods, records and physics are the same as stepping
them one by one; only the cost differs (see docs/architecture.md).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from typing import Generic

import trio

from dial.errors import DialError
from dial.parser.script import Run, Script
from dial.robot.protocol import Clocked, Course, Fired, Report
from dial.scheduler.active import ActiveRun
from dial.scheduler.position import Hooks, Resume
from dial.scheduler.primitive import Ended, Now, Outcome, progress_after
from dial.scheduler.records import Records
from dial.scheduler.signals import StopRequest
from dial.scheduler.types import Interrupted, RunAborted, S

ABORT_ON = frozenset({Outcome.TIMEOUT, Outcome.ERROR})
OUTCOME_TEXT = {o: o.value for o in Outcome}  # a dict lookup is cheaper than Enum.value
YIELD_EVERY = 64  # periods between trio checkpoints when not paced (other tasks, I/O)
# Coasting starts from this many periods left in the tick: taking the courses costs about
# what stepping a few periods one by one does.
COAST_FROM = 4

Progress = Callable[[int, float, list[str]], None]  # (tick, sim time, running events)
Observe = Callable[[int, int], None]  # (periods so far, tick), after every period


class Periods(Generic[S]):
    """The clocks, the table of active runs, and their control periods (the tick loop's
    half that every period runs through; :class:`~dial.scheduler.ticks.TickLoop` adds
    blocks, starts, monitors and preemption)."""

    def __init__(
        self,
        robot: Clocked[S],
        n: int,
        records: Records,
        stop: StopRequest,
        observe: Observe | None,
        pace: float | None,
    ) -> None:
        self.robot, self.n = robot, n  # n: control periods per tick
        self.period = robot.period
        self.records, self.stop = records, stop
        self.observe, self.pace = observe, pace
        self.periods = 0  # control periods simulated so far
        self.clock = 0  # tick time, in periods: stands still while a tick is stretched
        self.tick = 0  # absolute ticks started so far
        self.active: list[ActiveRun[S]] = []  # this block's unstopped runs, in step order
        self.latest: dict[tuple[str, str], Outcome] = {}  # (script, event) -> last outcome
        self.counts: dict[str, int] = defaultdict(int)
        self.abort: RunAborted | None = None
        self._ending = False  # some run ended this period: stop it after the period
        self.hooks: Hooks | None = None
        self._snap: S | None = None
        self.t0 = 0.0  # trio time at the first period, for pacing

    @property
    def sim_time(self) -> float:
        return self.periods * self.period

    def progress_of(self, a: ActiveRun[S]) -> float:
        """A run's progress in tick time now (0 to 1)."""
        return progress_after(self.clock - a.start_clock, a.span, self.n)

    def restore(self, resume: Resume) -> None:
        """Take up the clocks, outcomes and counts of a run saved at a block boundary."""
        self.periods, self.clock, self.tick = resume.periods, resume.clock, resume.tick
        self.latest.update(resume.latest)
        self.counts.update(resume.counts)

    def _snapshot(self) -> S:
        """The robot's snapshot, taken once per state: starts, senses and the next period's
        steps share it until the robot advances or a run's finish or stop writes a slot."""
        if self._snap is None:
            self._snap = self.robot.snapshot()
        return self._snap

    # -- control periods ----------------------------------------------------------------------
    async def _periods(self, most: int) -> tuple[tuple[Fired, ...], int]:
        """Step one period of the tick; or, when every active run is open-loop, coast through
        up to ``most`` at once (a paced run: only through periods already due). Returns what
        fired and how many periods passed."""
        if self.pace is not None:
            most = min(most, self._due())
        writes = self._courses(most)
        if writes is None:
            self.clock += 1
            return await self._period(stretched=False), 1
        before = self.periods
        fired = self._coast(writes, most)
        await self._yield_since(before)
        return fired, self.periods - before

    def _courses(self, most: int) -> list[Course] | None:
        """The open-loop runs' courses for the next ``most`` periods, or None to step them."""
        if most < COAST_FROM:
            return None
        if self.hooks is not None and self.hooks.each_period:
            return None
        runs = [a for a in self.active if a.ended is None]
        if not all(a.prim.open_loop for a in runs):
            return None
        return [a.prim.course(self.clock - a.start_clock + 1, most) for a in runs]

    def _due(self) -> int:
        """A paced run's periods whose wall-clock end has passed: a robot behind the clock
        (a loaded machine, a small --pace) would step them without sleeping between them, so
        it may as well coast through them. The periods are the same either way, and none is
        simulated ahead of the clock: a stop still holds the robot within a period of its
        request, and a command on time for a robot that keeps pace is on time for this one."""
        assert self.pace is not None
        behind = (trio.current_time() - self.t0) / (self.period * self.pace)
        return int(behind) - self.periods

    def _coast(self, writes: list[Course], most: int) -> tuple[Fired, ...]:
        """Periods as :meth:`_step` takes them, with the open-loop runs' set-points written
        from their courses; it stops after a period whose report says anything."""
        observe = self.observe
        if observe is None:  # the robot's own loop: nothing to do between its periods
            return self._coasted(*self.robot.coast(writes, most, self.stop))
        for k in range(most):
            for write in writes:
                write(k)
            report = self.robot.advance()
            if report is not None:
                return self._coasted(1, report, observe)
            self.periods += 1
            self.clock += 1
            observe(self.periods, self.tick)
            if self.stop.signal is not None:
                break
        return self._coasted(0, None)

    def _coasted(
        self, periods: int, report: Report | None, observe: Observe | None = None
    ) -> tuple[Fired, ...]:
        """Count the last ``periods`` coasted and log what the robot reported after the last
        of them (then ``observe`` it), as :meth:`_step` does; stop the script if need be."""
        self.periods += periods
        self.clock += periods
        fired = () if report is None else self._report(report)
        if observe is not None:
            observe(self.periods, self.tick)
        self._snap = None
        self._raise_pending()
        return fired

    async def _yield_since(self, periods: int) -> None:
        """Let trio's other tasks run if a multiple of YIELD_EVERY periods passed since."""
        if self.periods // YIELD_EVERY != periods // YIELD_EVERY:
            await trio.lowlevel.checkpoint()

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
            progress = progress_after(clock - a.start_clock, a.span, n)
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
