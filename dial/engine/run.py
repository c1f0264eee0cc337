"""Run a checked script in its scene: set up, run the timeline, measure, summarise.

This is the one place that joins the layers: the parser's script, the scheduler's runner,
the primitives and the MuJoCo backend. The engine writes the ``scene``, ``state`` and
``summary`` records; the runner writes the rest.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

import trio

from dial.backend.driver import MujocoRobot
from dial.disturb import Disturbance
from dial.engine.beliefs import believed_world, journal
from dial.engine.observe import Observer, StateLog, Watched, describe, fan_out, first_line
from dial.engine.result import RunResult, measure_criteria
from dial.engine.setup import Factory, prepare
from dial.engine.state import RunSettings, StateFile
from dial.errors import DialError, OptionError
from dial.parser.lanes import LanePlan
from dial.parser.script import Script
from dial.primitives.context import Context
from dial.robot.snapshot import Snapshot
from dial.scheduler.log import EventLog
from dial.scheduler.position import Resume
from dial.scheduler.runner import Runner, Tally
from dial.scheduler.signals import StopRequest, catch_stop_signals
from dial.scheduler.ticks import Progress, TickLoop
from dial.scheduler.types import DEFAULT_TICK

if TYPE_CHECKING:  # a run that pauses or saves brings the debugger: others do without it
    from dial.debug import Break, Console, Session

MAX_TICK = 60.0  # s, as @tick's range


@dataclass
class RunOptions:
    """How to run a script; the fields of ``dial run``'s options (see ``dial run --help``)."""

    tick: float | None = None  # s; default: the script's @tick, else DEFAULT_TICK
    speed: float = 1.0  # divides the tick
    seed: int = 0
    perturb_mm: float = 0.0
    disturb: Sequence[Disturbance] = ()
    realtime: bool = False
    pace: float | None = None  # wall s per simulated s (--realtime is 1); None: unpaced
    log: TextIO | None = None  # the JSON Lines sink, written and flushed record by record
    log_states: bool = False
    progress: Progress | None = None
    observers: list[Observer] = field(default_factory=list)
    # Debugging (DESIGN 6.1): where to pause, where commands come from, what to save.
    breaks: Sequence[Break] = ()
    step: bool = False
    console: Console | None = None
    save_at: tuple[int, Path] | None = None  # (block number, state file)
    resume: StateFile | None = None  # a state file to go on from (its settings win)
    stop: StopRequest | None = None  # polled every period (a remote session's); else signals'
    follow_grasps: bool = True  # grasped objects follow the hand in the world model


def tick_length(script: Script, options: RunOptions) -> float:
    """The tick the run uses, in s: ``--tick``, else ``@tick``, else the default; / speed.

    The options alone are checked once, by :func:`dial.api.run`; here only what depends on
    the script too: ``@tick`` divided by ``--speed`` may leave the range."""
    tick = options.tick if options.tick is not None else (script.tick or DEFAULT_TICK)
    length = tick / options.speed if options.speed > 0 else math.inf
    if not (math.isfinite(length) and 0 < length <= MAX_TICK):
        by = f" (--speed {options.speed:g})" if options.speed != 1.0 else ""
        raise OptionError(
            f"the tick must be above 0 s and at most {MAX_TICK:g} s, got {length:g} s{by}"
        )
    return length


def run(script: Script, options: RunOptions) -> RunResult:
    """Run ``script`` to its end (or its abort, or a stop signal) and measure the criteria.

    SIGINT and SIGTERM stop the run at the next control period, from the scene's loading on:
    every effector holds, and the log ends with ``interrupted`` and ``summary``.
    """
    with catch_stop_signals() as signals:
        stop = options.stop if options.stop is not None else signals
        log = EventLog(options.log)
        settings = _settings(script, options)
        drawn = bool(options.observers)  # an observer may draw: it gets the scene's textures
        robot, ctx = prepare(
            script,
            log,
            settings.perturb_mm,
            settings.seed,
            settings.disturb,
            textures=drawn,
            follow=options.follow_grasps,
        )
        resume = _resume(script, options.resume, robot, ctx, log)
        states = [StateLog(lanes=LanePlan.from_script(script))] if options.log_states else []
        begun: list[Observer] = []
        result: RunResult | None = None
        try:  # observers end also on an error: a recording keeps what was seen
            for observer in states + list(options.observers):
                observer.begin(Watched(robot, ctx.world, log))
                begun.append(observer)
            runner: Runner[Snapshot]

            def loop_of() -> TickLoop[Snapshot] | None:  # called once the run has started
                return runner.loop

            hooks = _debugging(script, loop_of, robot, ctx, stop, settings, begun, options)
            runner = Runner(
                robot,
                Factory(ctx),
                settings.tick,
                log,
                progress=options.progress,
                observe=fan_out(begun),
                pace=1.0 if options.realtime else options.pace,
                stop=stop,
                hooks=hooks,
            )
            ctx.world_model.journal = journal(log, runner)
            start, cpu = time.perf_counter(), time.process_time()
            summary = trio.run(runner.run, script, resume)
            wall, cpu = time.perf_counter() - start, time.process_time() - cpu
            result = _result(summary, robot, ctx, log, settings, hooks, (wall, cpu))
            log.write("summary", **result.as_record())
            return result
        finally:
            _end(begun, result)


def _result(
    summary: Tally,
    robot: MujocoRobot,
    ctx: Context,
    log: EventLog,
    settings: RunSettings,
    hooks: Session | None,
    times: tuple[float, float],
) -> RunResult:
    """The run's result, after the world model's closing ``world`` record."""
    believed_world(log, ctx, robot, summary.ticks)
    return RunResult(
        summary,
        ctx.world,
        measure_criteria(ctx.world, robot.model, robot.data, ctx.results),
        dict(ctx.results),
        *times,
        robot.steps,
        log,
        [float(x) for x in robot.data.qpos],
        tuple(d.text for d in settings.disturb),
        tuple(hooks.saved) if hooks is not None else (),
        hooks.unsaved if hooks is not None else None,
        {body: ctx.world_model.entry(body) for body in ctx.world.objects.values()},
    )


def _resume(
    script: Script, saved: StateFile | None, robot: MujocoRobot, ctx: Context, log: EventLog
) -> Resume | None:
    """Put a saved state back (checking the script against it) and log the ``resume``."""
    if saved is None:
        return None
    resume = saved.check(script)
    saved.restore(robot, ctx)
    log.write(
        "resume",
        file=str(saved.source),
        block=resume.blocks + 1,
        tick=resume.tick,
        t=resume.periods * robot.period,
    )
    return resume


def _settings(script: Script, options: RunOptions) -> RunSettings:
    """The tick, seed, perturbation and disturbances: a resumed run takes its state file's."""
    if options.resume is not None:
        return options.resume.settings
    return RunSettings(
        tick_length(script, options),
        options.seed,
        options.perturb_mm,
        tuple(options.disturb),
    )


def _debugging(
    script: Script,
    loop_of: Callable[[], TickLoop[Snapshot] | None],
    robot: MujocoRobot,
    ctx: Context,
    stop: StopRequest,
    settings: RunSettings,
    observers: list[Observer],
    options: RunOptions,
) -> Session | None:
    """The session's hooks, if the run pauses or saves; None keeps the runner's hot path lean."""
    if not (options.breaks or options.step or options.save_at):
        return None
    from dial.engine.debugging import session

    return session(
        script,
        loop_of,
        robot,
        ctx,
        stop,
        settings,
        observers,
        options.console,
        options.breaks,
        options.step,
        options.save_at,
    )


def _end(observers: list[Observer], result: RunResult | None) -> None:
    """End every observer, whatever the others do; then say which failed (the log and the
    summary are written by then)."""
    failed = []
    for observer in observers:
        try:
            observer.end(result)
        except Exception as e:
            failed.append(f"{describe(observer)} failed: {first_line(e)}")
    if failed:
        raise DialError("; ".join(failed))
