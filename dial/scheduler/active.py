"""The table of active runs: what a started run carries while the tick loop steps it."""

from __future__ import annotations

from typing import Generic

from dial.parser.script import Script
from dial.scheduler.primitive import Ended, Primitive
from dial.scheduler.types import RunInfo, S


class ActiveRun(Generic[S]):
    """One started run in the table: its primitive and where it sits in time."""

    __slots__ = (
        "ended",
        "fixed",
        "info",
        "prim",
        "script",
        "span",
        "start_clock",
        "start_period",
        "start_tick",
        "timeout",
    )

    def __init__(
        self, script: Script, info: RunInfo, prim: Primitive[S], tick: int, periods: int, clock: int
    ) -> None:
        self.script, self.info, self.prim = script, info, prim
        # Read every period: worked out once, here.
        self.span, self.fixed, self.timeout = info.span, info.fixed, info.timeout
        self.start_tick = tick
        self.start_period, self.start_clock = periods, clock  # periods, tick-time periods
        self.ended: Ended | None = None
