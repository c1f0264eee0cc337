"""The engine's side of a debugging session: what ``state`` shows, what ``save`` writes."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from dial.backend.driver import MujocoRobot
from dial.debug import Break, Console, Session
from dial.debug.display import ActiveView, PausedView, state_text
from dial.engine import state
from dial.engine.observe import Observer
from dial.parser.script import Script
from dial.primitives.context import Context
from dial.scheduler.position import Path as TimelinePath
from dial.scheduler.runner import Runner
from dial.scheduler.signals import StopRequest
from dial.scheduler.ticks import TickLoop


def session(
    top: Script,
    runner: Runner[Any],
    robot: MujocoRobot,
    ctx: Context,
    stop: StopRequest,
    settings: state.RunSettings,
    observers: Sequence[Observer],
    console: Console | None,
    breaks: Sequence[Break],
    step: bool,
    save_at: tuple[int, Path] | None,
) -> Session:
    """A session whose ``state`` reads this robot and whose ``save`` writes state files."""

    def where() -> str:
        assert runner.loop is not None
        return f"tick {runner.loop.tick}, t = {runner.loop.sim_time:.3f} s"

    def save(target: Path, number: int, path: TimelinePath, script: Script) -> None:
        assert runner.loop is not None  # the path runs from the top script, whoever's block
        state.save(target, top, path, number - 1, runner.loop, robot, ctx, settings)

    def on_pause() -> None:  # the viewers show the paused state
        for observer in observers:
            show = getattr(observer, "show_now", None)
            if show is not None:
                show()

    def describe() -> str:
        assert runner.loop is not None
        return state_text(paused_view(top, runner.loop, robot))

    return Session(
        stop, console, breaks, step, save_at, save, describe, where, on_pause, top=top.path
    )


def paused_view(top: Script, loop: TickLoop[Any], robot: MujocoRobot) -> PausedView:
    """The paused run as ``state`` shows it: the loop's runs and outcomes, the sensors."""
    snap = robot.snapshot()
    active = [
        ActiveView(
            a.info.event.name,
            a.info.run.line,
            a.start_tick,
            loop.progress_of(a),
            (loop.periods - a.start_period) * loop.period,
        )
        for a in loop.active
        if a.ended is None
    ]
    latest = [
        (e if s == top.path else f"{Path(s).stem}.{e}", o.value)
        for (s, e), o in loop.latest.items()
    ]
    return PausedView(
        loop.tick,
        loop.periods,
        loop.sim_time,
        active,
        latest,
        snap.tool_pos,
        snap.tool_rot,
        snap.hand_q,
        snap.differentials,
        snap.tactile,
    )
