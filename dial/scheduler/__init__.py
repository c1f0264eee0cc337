"""The trio block runner: DIAL timing semantics against a small robot protocol."""

from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner, RunSummary, periods_per_tick
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

__all__ = [
    "Ended",
    "EventLog",
    "InstantPrimitive",
    "Now",
    "Outcome",
    "Primitive",
    "PrimitiveFactory",
    "Robot",
    "RunAborted",
    "RunInfo",
    "RunSummary",
    "Runner",
    "periods_per_tick",
]
