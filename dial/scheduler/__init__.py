"""The block runner: DIAL timing semantics against a small robot protocol.

Each name below is imported from its module when first used (PEP 562): the runner brings
trio, which the modules that only need the types (the primitives, the preview, ``dial
world``) do without.
"""

from typing import TYPE_CHECKING

from dial.lazy import lazy_names

if TYPE_CHECKING:
    from dial.scheduler.log import EventLog, LogError
    from dial.scheduler.primitive import DONE, Allotment, Ended, Now, Outcome, Primitive, Sensor
    from dial.scheduler.runner import Runner, Tally
    from dial.scheduler.signals import EXIT_STATUS, StopRequest, catch_stop_signals
    from dial.scheduler.types import (
        Interrupted,
        PrimitiveFactory,
        RunAborted,
        RunInfo,
        periods_per_tick,
    )

_HOMES = {
    "dial.scheduler.log": ("EventLog", "LogError"),
    "dial.scheduler.primitive": (
        *("DONE", "Allotment", "Ended", "Now", "Outcome", "Primitive", "Sensor"),
    ),
    "dial.scheduler.runner": ("Runner", "Tally"),
    "dial.scheduler.signals": ("EXIT_STATUS", "StopRequest", "catch_stop_signals"),
    "dial.scheduler.types": (
        *("Interrupted", "PrimitiveFactory", "RunAborted", "RunInfo", "periods_per_tick"),
    ),
}
_HOME = {name: module for module, names in _HOMES.items() for name in names}

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

__getattr__ = lazy_names(__name__, _HOME)
