"""The engine's side of a debugging session: what ``state`` shows, what ``save`` writes."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from dial.backend.driver import MujocoRobot
from dial.debug import Break, Console, Session
from dial.debug.display import ActiveView, PausedView, state_text
from dial.engine import state
from dial.engine.observe import Observer
from dial.parser.script import Script
from dial.primitives.context import Context
from dial.scheduler.position import TimelinePath
from dial.scheduler.signals import StopRequest
from dial.scheduler.ticks import TickLoop


def session(
    top: Script,
    loop_of: Callable[[], TickLoop[Any] | None],
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
    """A session whose ``state`` reads this robot and whose ``save`` writes state files;
    ``loop_of()``: the runner's tick loop, once the run has started (the hooks are called
    only then)."""

    def loop() -> TickLoop[Any]:
        running = loop_of()
        assert running is not None, "a hook is called while the run goes on"
        return running

    def where() -> str:
        return f"tick {loop().tick}, t = {loop().sim_time:.3f} s"

    def save(target: Path, number: int, path: TimelinePath, script: Script) -> None:
        # The path runs from the top script, whoever's block it is.
        state.save(target, top, path, number - 1, loop(), robot, ctx, settings)

    def on_pause() -> None:  # the viewers show the paused state
        for observer in observers:
            show = getattr(observer, "show_now", None)
            if show is not None:
                show()

    def describe() -> str:
        return state_text(paused_view(top, loop(), robot))

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
