"""The table of active runs: what a started run carries while the tick loop steps it."""

from __future__ import annotations

from typing import Generic, NamedTuple

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
        self, script: Script, plan: RunPlan, prim: Primitive[S], tick: int, periods: int, clock: int
    ) -> None:
        self.script, self.info, self.prim = script, plan.info, prim
        self.span, self.fixed, self.timeout = plan.span, plan.fixed, plan.timeout
        self.start_tick = tick
        self.start_period, self.start_clock = periods, clock  # periods, tick-time periods
        self.ended: Ended | None = None


class RunPlan(NamedTuple):
    """What a run's place in the script fixes, worked out once per run of the timeline."""

    info: RunInfo
    span: int  # its executing ticks, in periods
    fixed: bool  # fixed-length: it ends with its last executing tick
    timeout: float | None  # s; only indeterminate runs time out

    @classmethod
    def of(cls, info: RunInfo) -> RunPlan:
        event = info.event
        fixed = event.instruction.length == "fixed"
        return cls(info, info.span, fixed, None if fixed else event.args.time_limit())
