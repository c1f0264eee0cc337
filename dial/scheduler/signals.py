"""SIGINT and SIGTERM become a stop request that the runner polls once per control period.

Why not trio's signal receiver: it wakes a task, so the driver would have to yield to trio
every period to notice it, and a checkpoint costs more than a period's scheduling work.
Why not trio's default KeyboardInterrupt: it is raised wherever the main thread is,
e.g. inside a native IK solve, which can turn it into an unrelated error. Here a signal
only sets a flag; the run stops at the next period boundary, every effector holds, and
the log is written to its end. A second signal while the run cleans up changes nothing.

:func:`catch_stop_signals` is the one place that installs the handlers. Whoever starts a
run calls it, and only the outermost call installs them: the command line for the whole of
``dial run`` (its check, the run, its report), else :func:`dial.engine.run` for the run;
an inner call shares the outer one's request. The runner only polls the request it is given.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

_NAMES = {signal.SIGINT: "SIGINT", signal.SIGTERM: "SIGTERM"}
# 128 + the signal number, as shells report; "quit" is a paused run's quit command.
EXIT_STATUS = {"SIGINT": 130, "SIGTERM": 143, "quit": 130}


class StopRequest:
    """The first stop signal that arrived, if any (``None`` while the run may go on)."""

    def __init__(self) -> None:
        self.signal: str | None = None

    def request(self, name: str) -> None:
        if self.signal is None:
            self.signal = name


_owner: StopRequest | None = None  # the request the installed handlers feed, if any


@contextmanager
def catch_stop_signals() -> Iterator[StopRequest]:
    """Turn SIGINT and SIGTERM into a stop request for the duration (main thread only); inside
    another call, share its request."""
    global _owner
    if _owner is not None:
        yield _owner
        return
    stop = StopRequest()
    if threading.current_thread() is not threading.main_thread():
        yield stop  # worker threads cannot own signals; their process's owner handles them
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        stop.request(_NAMES.get(signal.Signals(signum), "a signal"))

    previous = {s: signal.signal(s, handler) for s in _NAMES}
    _owner = stop
    try:
        yield stop
    finally:
        _owner = None
        for s, old in previous.items():
            signal.signal(s, old)
