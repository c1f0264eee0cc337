"""The block runner: DIAL timing semantics on a trio driver loop.

One task, the driver, owns time. Every control period it hands each active run
an immutable snapshot in a fixed order (start tick, line, mark), lets the robot
advance, and ends runs whose step said so. The driver starts each run, in
line order; the run's trio task then handles the rest of its lifecycle (wait
for its end, stop on end or cancellation), and the driver waits for those
tasks at fixed points, so trio's task order never reaches a result.
"""

from __future__ import annotations

import math
import signal
import threading
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import trio

from dial.errors import DialError
from dial.parser.ast import Condition
from dial.parser.script import Run, Script, Step, TBlock, TCall, TIf, TRepeat
from dial.scheduler.log import EventLog
from dial.scheduler.types import (
    Ended,
    InstantPrimitive,
    Now,
    Outcome,
    Primitive,
    PrimitiveFactory,
    Robot,
    RunAborted,
    RunInfo,
)

ABORT_ON = frozenset({Outcome.TIMEOUT, Outcome.ERROR})


@dataclass(eq=False)
class _Active:
    key: tuple[int, int, int]
    script: Script
    info: RunInfo
    prim: Primitive
    tick: int  # absolute tick it started in
    start_period: int
    start_clock: int  # tick-time periods at its start
    span: int  # executing ticks, in periods
    fixed: bool
    timeout: float | None
    ended: Ended | None = None
    start_error: str | None = None
    end_signal: trio.Event = field(default_factory=trio.Event)
    cleaned: trio.Event = field(default_factory=trio.Event)


@dataclass(frozen=True)
class RunSummary:
    """What a finished (or aborted) run reports."""

    ok: bool
    error: RunAborted | None
    sim_time: float
    ticks: int
    periods: int
    tick_length: float
    outcomes: dict[str, int]


def periods_per_tick(tick: float, period: float) -> int:
    """Ticks are whole numbers of control periods."""
    n = round(tick / period)
    if n < 1 or not math.isfinite(tick):
        raise DialError(f"tick length {tick:g} s is shorter than the control period {period:g} s")
    return n


class Runner:
    """Run a checked script's timeline against a robot."""

    def __init__(
        self,
        robot: Robot,
        factory: PrimitiveFactory,
        tick: float,
        log: EventLog | None = None,
        abort_on: frozenset[Outcome] = ABORT_ON,
        on_tick: Callable[[int, float, list[str]], None] | None = None,
        observe: Callable[[int, int], None] | None = None,
    ) -> None:
        self.robot = robot
        self.factory = factory
        self.period = robot.period
        self.n = periods_per_tick(tick, self.period)
        self.log = log or EventLog()
        self.abort_on = abort_on
        self.on_tick = on_tick  # progress display: (tick, sim time, running events)
        # Read-only watchers (recording, video, viewers): (periods so far, tick), after each period.
        self.observe = observe
        self.periods = 0  # simulated control periods so far
        self.clock = 0  # tick time, in periods: stands still while a tick is stretched
        self.tick = 0  # absolute ticks started so far
        self.active: list[_Active] = []
        self.latest: dict[tuple[str, str], Outcome] = {}
        self.counts: dict[str, int] = defaultdict(int)
        self._order = 0
        self._abort: RunAborted | None = None
        self._nursery: trio.Nursery | None = None
        self._root = ""

    @property
    def sim_time(self) -> float:
        return self.periods * self.period

    async def run(self, script: Script) -> RunSummary:
        """Run the script; an abort is reported in the summary, an interrupt re-raised."""
        self._root = script.path
        error: RunAborted | None = None
        interrupted = False
        signalled: list[bool] = []
        try:
            async with trio.open_nursery() as nursery:
                self._nursery = nursery
                if threading.current_thread() is threading.main_thread():
                    # Listening before the first run starts (its start may solve IK for long).
                    await nursery.start(self._await_interrupt, nursery.cancel_scope, signalled)
                try:
                    await self._steps(script, script.timeline)
                except RunAborted as e:
                    error = e
                    self.log.write(
                        "error", event=e.event, tick=e.tick, t=self.sim_time, message=str(e)
                    )
                except KeyboardInterrupt:  # off the main thread, trio raises it anywhere
                    interrupted = True
                finally:
                    self.robot.hold_all()  # on abort, interrupt or bug: the arm never drops
                    nursery.cancel_scope.cancel()
        finally:
            self._nursery = None
        if interrupted or signalled:
            self.log.write("interrupted", tick=self.tick, t=self.sim_time)
            raise KeyboardInterrupt
        return RunSummary(
            error is None,
            error,
            self.sim_time,
            self.tick,
            self.periods,
            self.n * self.period,
            dict(sorted(self.counts.items())),
        )

    @staticmethod
    async def _await_interrupt(
        scope: trio.CancelScope, signalled: list[bool], task_status: Any = trio.TASK_STATUS_IGNORED
    ) -> None:
        """Turn Ctrl-C into a cancellation at the next checkpoint.

        Left to trio, the KeyboardInterrupt is raised wherever the main thread happens to
        be, e.g. inside a native IK solve, which can turn it into an unrelated error.
        """
        with trio.open_signal_receiver(signal.SIGINT) as signals:
            task_status.started()
            async for _ in signals:
                signalled.append(True)
                scope.cancel()
                return

    # -- structure --------------------------------------------------------------------------
    async def _steps(self, script: Script, steps: tuple[Step, ...]) -> None:
        for step in steps:
            if isinstance(step, TBlock):
                await self._block(script, step)
            elif isinstance(step, TRepeat):
                await self._repeat(script, step)
            elif isinstance(step, TIf):
                branch = step.then if self._test(script, step.condition) else step.orelse
                await self._steps(script, branch)
            elif isinstance(step, TCall):
                self.log.write("call", script=step.script.path, tick=self.tick, t=self.sim_time)
                await self._steps(step.script, step.script.timeline)

    async def _repeat(self, script: Script, step: TRepeat) -> None:
        if step.kind == "count":
            for _ in range(step.count):
                await self._steps(script, step.body)
            return
        assert step.condition is not None
        for _ in range(step.count):
            if step.kind == "while" and not self._test(script, step.condition):
                return
            await self._steps(script, step.body)
            if step.kind == "until" and self._test(script, step.condition):
                return
        if step.kind == "while" and not self._test(script, step.condition):
            return
        raise RunAborted(
            f"'@repeat {step.kind} {step.condition}' on line {step.line} of {script.path} "
            f"reached its max of {step.count} iterations",
            None,
            self.tick,
        )

    def _test(self, script: Script, cond: Condition) -> bool:
        if cond.event in script.condition_only:
            event = script.events[cond.event]
            run = Run(cond.event, event.definition.line, 1, 1, 1, frozenset())
            info = RunInfo(event, run, script.path, self.n, self.period, instant=True)
            self._instant(script, run, self.factory(info), condition=True)
        value = self.latest.get((script.path, cond.event)) is Outcome.DONE
        value = value != cond.negated
        self.log.write(
            "condition",
            condition=str(cond),
            value=value,
            tick=self.tick,
            t=self.sim_time,
            **self._callee(script),
        )
        return value

    def _info(self, script: Script, run: Run) -> RunInfo:
        return RunInfo(script.events[run.event], run, script.path, self.n, self.period)

    # -- blocks and ticks ---------------------------------------------------------------------
    async def _block(self, script: Script, block: TBlock) -> None:
        starts: dict[int, list[Run]] = defaultdict(list)
        for run in block.runs:  # already in (start tick, line) order
            starts[run.start].append(run)
        mine: list[_Active] = []
        for k in range(1, block.length + 1):
            self.tick += 1
            t0 = self.sim_time
            for run in starts.get(k, ()):
                active = await self._start(script, run)
                if active is not None:
                    mine.append(active)
            for _ in range(self.n):
                self.clock += 1
                await self._period(stretched=False)
            for a in [a for a in mine if a.fixed and a.ended is None and a.info.run.exec_end == k]:
                ended = self._guard(lambda a=a: a.prim.finish(self.robot.snapshot()))
                self._end(a, ended, self.sim_time)
            await self._reap()
            stretch = 0
            while any(a.ended is None and a.info.run.exec_end == k for a in mine):
                stretch += 1
                await self._period(stretched=True)
            mine = [a for a in mine if a.ended is None]
            if self.on_tick is not None:
                self.on_tick(self.tick, self.sim_time, [a.info.event.name for a in self.active])
            self.log.write(
                "tick", tick=self.tick, block_tick=k, t0=t0, t1=self.sim_time, stretch=stretch
            )

    async def _start(self, script: Script, run: Run) -> _Active | None:
        info = self._info(script, run)
        event = info.event
        prim = self.factory(info)
        self.counts["runs"] += 1
        if isinstance(prim, InstantPrimitive):
            self._instant(script, run, prim, condition=False)
            return None
        self._order += 1
        timeout = event.args.get("timeout")
        active = _Active(
            key=(self.tick, run.line, self._order),
            script=script,
            info=info,
            prim=prim,
            tick=self.tick,
            start_period=self.periods,
            start_clock=self.clock,
            span=(run.exec_end - run.start + 1) * self.n,
            fixed=event.instruction.length == "fixed",
            timeout=float(timeout) if isinstance(timeout, int | float) else None,
        )
        self._write_start(script, run)
        # Started here, in line order, not in the lifecycle task: no handshake with a new
        # task per run (a trio round trip costs more than most starts).
        try:
            prim.start(self.robot.snapshot())
        except DialError as e:
            active.start_error = str(e)
        except BaseException:
            prim.stop()  # stop always runs, as it would in the lifecycle task
            raise
        assert self._nursery is not None
        self._nursery.start_soon(self._lifecycle, active)
        self.active.append(active)
        if active.start_error is not None:
            self._end(active, Ended(Outcome.ERROR, active.start_error), self.sim_time)
            await self._reap()
        return active

    @staticmethod
    async def _lifecycle(active: _Active) -> None:
        """A started run's task: wait for its end, then stop it (always, also on cancel)."""
        try:
            await active.end_signal.wait()
        finally:
            active.prim.stop()
            active.cleaned.set()

    def _instant(self, script: Script, run: Run, prim: Primitive, condition: bool) -> None:
        assert isinstance(prim, InstantPrimitive)
        if not condition:
            self._write_start(script, run)
        ended = self._guard(lambda: prim.sense(self.robot.snapshot()))
        self._record_end(script, run, ended, self.sim_time)
        if ended.outcome in self.abort_on:
            raise self._aborted(script, run, ended)

    def _write_start(self, script: Script, run: Run) -> None:
        self.log.write(
            "start",
            event=run.event,
            line=run.line,
            tick=self.tick,
            t=self.sim_time,
            **self._callee(script),
        )

    def _callee(self, script: Script) -> dict[str, str]:
        """``script`` for the records of a called script's events: names repeat across files."""
        return {"script": script.path} if script.path != self._root else {}

    # -- control periods ------------------------------------------------------------------------
    async def _period(self, stretched: bool) -> None:
        snapshot = self.robot.snapshot()
        t_end = (self.periods + 1) * self.period
        for a in self.active:
            if a.ended is not None:
                continue
            elapsed = (self.periods + 1 - a.start_period) * self.period
            # A one-tick run is a GOTO MOVE: the set-point jumps at once.
            progress = 1.0 if a.span == self.n else min(1.0, (self.clock - a.start_clock) / a.span)
            now = Now(t_end, self.tick, progress, elapsed, stretched)
            ended = self._guard(lambda a=a, now=now: a.prim.step(snapshot, now))
            if (
                ended is None
                and not a.fixed
                and a.timeout is not None
                and elapsed >= a.timeout - 1e-9
            ):
                ended = Ended(Outcome.TIMEOUT, f"no result after {a.timeout:g} s")
            if ended is not None:
                self._end(a, ended, t_end)
        fault = await self.robot.advance()
        self.periods += 1
        if self.observe is not None:
            self.observe(self.periods, self.tick)
        await self._reap()
        if fault is not None and self._abort is None:
            running = ", ".join(a.info.event.name for a in self.active) or "no event"
            self._abort = RunAborted(
                f"safety monitor: {fault} (running: {running})", None, self.tick
            )
        if self._abort is not None:
            raise self._abort

    @staticmethod
    def _guard(call: Any) -> Any:
        """Run a primitive callback; a DialError it raises becomes an ``error`` outcome."""
        try:
            return call()
        except DialError as e:
            return Ended(Outcome.ERROR, str(e))

    def _end(self, a: _Active, ended: Ended, t: float) -> None:
        a.ended = ended
        self._record_end(a.script, a.info.run, ended, t)
        a.end_signal.set()
        if ended.outcome in self.abort_on and self._abort is None:
            self._abort = self._aborted(a.script, a.info.run, ended)

    def _record_end(self, script: Script, run: Run, ended: Ended, t: float) -> None:
        self.latest[(script.path, run.event)] = ended.outcome
        self.counts[ended.outcome.value] += 1
        fields: dict[str, Any] = {"outcome": ended.outcome.value}
        if ended.message:
            fields["message"] = ended.message
        if ended.data:
            fields["data"] = dict(ended.data)
        fields.update(self._callee(script))
        self.log.write("end", event=run.event, line=run.line, tick=self.tick, t=t, **fields)

    def _aborted(self, script: Script, run: Run, ended: Ended) -> RunAborted:
        line = script.events[run.event].definition.line
        why = f": {ended.message}" if ended.message else ""
        return RunAborted(
            f"event '{run.event}' (defined on line {line} of {script.path}) ended "
            f"{ended.outcome.value} at tick {self.tick}{why}",
            run.event,
            self.tick,
        )

    async def _reap(self) -> None:
        """Wait, in a fixed order, for the lifecycle tasks of ended runs to clean up."""
        done = [a for a in self.active if a.ended is not None]
        for a in done:
            await a.cleaned.wait()
        if done:
            self.active = [a for a in self.active if a.ended is None]
