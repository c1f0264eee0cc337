"""One operator's session with the robot: what its network side and its robot side share.

The robot runs in a thread of its own (with its own trio loop, paced to the wall clock);
the server's network runs in the main thread. They meet here, and only here:

- ``commands``: what the operator sent, in order, for the robot to take at tick boundaries;
- ``stop``: polled by the robot every control period (link lost, the operator's stop);
- the **report stream**: the robot's log records, its results and refusals, and the end,
  each report numbered ``n`` so that an operator that reconnects after a cut asks for the
  ones it has not seen;
- the latest telemetry sample and the state that ``status`` shows.
"""

from __future__ import annotations

import io
import json
import queue
import threading
import time
from collections.abc import Callable
from typing import IO

from dial.remote.protocol import Message, encode
from dial.scheduler.log import Record
from dial.scheduler.signals import StopRequest

PERIOD = 0.01  # s, the control period

# Record kinds that only the link writes, at the robot and at the operator: they hold wall
# times, and a comparison of a remote robot's log with a local run's leaves them out
# (docs/remote.md, Records).
LINK_RECORDS = frozenset(
    {
        *("session", "disconnected", "received", "lost"),  # the robot's
        *("connected", "rtt", "lead", "sent", "acknowledged", "reported"),  # the operator's
        *("late", "refused", "diverged", "error"),
    }
)


class Session:
    """The state of one session, shared by the network thread and the robot thread."""

    def __init__(self, number: int, log: IO[str] | None, wake: Callable[[], None]) -> None:
        self.number = number
        self.commands: queue.SimpleQueue[Message] = queue.SimpleQueue()
        self.stop = StopRequest()
        self.state = "ready"  # ready, running, finished, lost, stopped, rejected
        self.highest = 0  # the highest command seq received
        self.ids: dict[int, str] = {}  # seq -> id, to refuse a seq re-used for another id
        self.reports: list[str] = []  # encoded, numbered by their index
        self.telemetry: str | None = None  # the latest sample, encoded
        self.status: dict[str, object] = {"tick": 0, "t": 0.0}
        self.started = time.monotonic()
        self.closing = threading.Event()  # the robot thread ends (a new session, shutdown)
        self.thread: threading.Thread | None = None
        self.split: str | None = None  # "script" or "block", once the script is sent
        self.bandwidth: float | None = None  # bit/s the operator says its link has
        self.block = (0, 0)  # the latest block the robot started: (number, its first period)
        self._pending: list[Record] = []
        self._lock = threading.Lock()
        self._log = log
        self._wake = wake

    # -- the robot's log: written to the server's file and streamed to the operator ----------
    def record(self, record: Record) -> None:
        """A log record, in order: to the log file and into the report stream."""
        if record.get("kind") == "block":
            number, t = record.get("number"), record.get("t")
            if isinstance(number, int) and isinstance(t, int | float):
                self.block = (number, round(t / PERIOD))
        with self._lock:
            if self._log is not None:
                self._log.write(json.dumps(record, separators=(",", ":")) + "\n")
                self._log.flush()
            self._pending.append(record)
        self._wake()

    def link_record(self, kind: str, **fields: object) -> None:
        """A link record (see LINK_RECORDS): with the wall time since the session began."""
        wall = round(time.monotonic() - self.started, 3)
        self.record({"kind": kind, **fields, "wall": wall})

    def report(self, type_: str, **fields: object) -> None:
        """A result, refusal or end: after the records written before it."""
        with self._lock:
            self._flush()
            self.reports.append(encode(type_, n=len(self.reports), **fields))
        self._wake()

    def reports_from(self, n: int) -> list[str]:
        """The reports numbered ``n`` on (the pending records made into one first)."""
        with self._lock:
            self._flush()
            return self.reports[n:]

    def _flush(self) -> None:
        if self._pending:
            self.reports.append(encode("records", n=len(self.reports), records=self._pending))
            self._pending = []

    def sample(self, message: str, status: dict[str, object]) -> None:
        """The latest telemetry sample (older unsent ones are dropped: decimation)."""
        self.telemetry = message
        self.status = status
        self._wake()

    @property
    def tick(self) -> int:
        """The robot's tick at its latest telemetry sample."""
        tick = self.status.get("tick", 0)
        return tick if isinstance(tick, int) else 0

    @property
    def active(self) -> bool:
        """The robot is, or is about to be, under this session's control."""
        return self.state in ("ready", "running")


class Tee(io.StringIO):
    """The run's log sink: each JSON line the engine writes goes to :meth:`Session.record`."""

    def __init__(self, session: Session) -> None:
        super().__init__()
        self.session = session
        self._partial = ""

    def write(self, text: str) -> int:
        lines = (self._partial + text).split("\n")
        self._partial = lines.pop()
        for line in lines:
            if line:
                self.session.record(json.loads(line))
        return len(text)

    def flush(self) -> None:
        pass
