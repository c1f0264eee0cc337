"""The block runner: DIAL timing semantics against a small robot protocol."""

from dial.scheduler.log import EventLog, LogError
from dial.scheduler.primitive import DONE, Allotment, Ended, Now, Outcome, Primitive, Sensor
from dial.scheduler.runner import Runner, Tally, periods_per_tick
from dial.scheduler.signals import EXIT_STATUS, StopRequest, catch_stop_signals
from dial.scheduler.types import Interrupted, PrimitiveFactory, RunAborted, RunInfo

__all__ = [
    "DONE",
    "EXIT_STATUS",
    "Allotment",
    "Ended",
    "EventLog",
    "Interrupted",
    "LogError",
    "Now",
    "Outcome",
    "Primitive",
    "PrimitiveFactory",
    "RunAborted",
    "RunInfo",
    "Runner",
    "Sensor",
    "StopRequest",
    "Tally",
    "catch_stop_signals",
    "periods_per_tick",
]
