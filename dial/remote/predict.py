"""Prediction: the operator runs the script on its own believed world, with physics, ahead
of the delayed telemetry, and says where the robot's reports leave it.

The predicted run is a local run (no perturbation, no disturbance: what the operator
believes), unpaced, in a thread of its own. It keeps the tool's position at every control
period and its log. A reported sample is compared with the prediction at the same place
in the same block (the robot may have waited between blocks, ``--split block``): when the
tool is more than ``--diverge`` mm away, or a run ends with another outcome, or a monitor
fires that the prediction did not see, the operator writes a ``diverged`` record naming
the event and the tick (once per departure: a tool back within the bound may diverge again).
"""

from __future__ import annotations

import math
import threading
from collections import defaultdict
from collections.abc import Callable, Sequence

from dial.engine.observe import Observer, Watched
from dial.engine.result import RunResult
from dial.parser.script import Script
from dial.remote.protocol import Message
from dial.scheduler.log import EventLog, Record
from dial.scheduler.signals import StopRequest

PERIOD = 0.01  # s, the control period (both sides)


class Predictor:
    """The predicted run (an observer of the local run) and the comparison with reports."""

    what = "the prediction"

    def __init__(self, write: Callable[..., None], diverge_mm: float) -> None:
        self.write, self.diverge_mm = write, diverge_mm  # write(kind, **fields): a link record
        self.tool: list[tuple[float, float, float]] = []  # mm, per control period from 0
        self.log: EventLog | None = None
        self.done = threading.Event()
        self.stop = StopRequest()  # the operator's run is over: the prediction stops too
        self.thread: threading.Thread | None = None
        self.error: str | None = None
        self.seen: dict[tuple[str, str, int], int] = defaultdict(int)  # reported ends, monitors
        self.off = False  # the tool is away from the prediction now
        self.running: dict[tuple[str, int], str] = {}
        self._starts: dict[int, int] = {}  # the prediction's blocks: number -> first period
        # Reports not compared yet: (a record or a sample, the robot's running events then).
        self._pending: list[tuple[Record | None, Message | None, str | None]] = []
        self._scanned = 0  # its log records looked at so far

    # -- the predicted run (in its thread) ------------------------------------------------------
    def begin(self, run: Watched) -> None:
        self.robot, self.log = run.robot, run.log
        self._sample()

    def period(self, periods: int, tick: int) -> None:
        self._sample()

    def end(self, result: RunResult | None) -> None:
        self.done.set()  # its log is complete (a recorder after it may go on drawing reports)

    def _sample(self) -> None:
        d, ix = self.robot.data, self.robot.index
        x, y, z = (float(v) * 1000.0 for v in d.site_xpos[ix.tool_site])
        self.tool.append((x, y, z))

    def _predicted(self, kind: str) -> list[Record]:
        return [] if self.log is None else [r for r in self.log.records if r["kind"] == kind]

    # -- the reports (in the operator's trio thread) --------------------------------------------
    # Each report waits in order until the prediction has got as far (it may lag behind a
    # robot that runs fast, e.g. while it is being recorded): behind is not wrong.
    def reported(self, record: Record) -> None:
        kind = record.get("kind")
        key = (str(record.get("event")), _int(record.get("line")))
        if kind == "start":
            self.running[key] = str(record.get("event"))
        elif kind in ("end", "monitor"):
            self._pending.append((record, None, self._events()))
            if kind == "end":
                self.running.pop(key, None)
            self._drain()

    def telemetry(self, msg: Message) -> None:
        self._pending.append((None, msg, self._events()))
        self._drain()

    def _events(self) -> str | None:
        events = sorted(set(self.running.values()))
        return ", ".join(events) if events else None

    def _drain(self) -> None:
        while self._pending:
            record, msg, events = self._pending[0]
            decided = self._compare(record) if record is not None else self._sample_at(msg, events)
            if not decided:
                return
            self._pending.pop(0)

    def _compare(self, record: Record) -> bool:
        """The k-th end (monitor) of an event's line against the prediction's k-th."""
        kind = str(record.get("kind"))
        key = (kind, str(record.get("event")), _int(record.get("line")))
        k = self.seen[key]
        same = [
            r
            for r in self._predicted(kind)
            if r.get("event") == key[1] and _int(r.get("line")) == key[2]
        ]
        if k >= len(same) and not self.done.is_set():
            return False
        self.seen[key] += 1
        predicted = same[k].get("outcome", "fired") if k < len(same) else "nothing"
        reported = record.get("outcome", "fired")
        if predicted != reported:
            self.write(
                "diverged",
                what="outcome" if kind == "end" else "monitor",
                event=key[1],
                line=key[2],
                tick=record.get("tick"),
                reported=reported,
                predicted=predicted,
            )
        return True

    def _sample_at(self, msg: Message | None, events: str | None) -> bool:
        """A sample at ``since`` periods into the robot's block ``block``, against the
        prediction as far into its block (at most to its next block's start)."""
        assert msg is not None
        done = self.done.is_set()
        block, offset = msg.integer("block"), msg.integer("since")
        predicted = self._block_start(block)
        if predicted is None:
            return done or block == 0  # not there yet; or never will be, or before block 1
        following = self._block_start(block + 1)
        at = predicted + offset if following is None else min(predicted + offset, following)
        if at >= len(self.tool):
            if not done:
                return False
            at = len(self.tool) - 1
        tool = [float(v) for v in msg.items("tool") if isinstance(v, int | float)]
        if len(tool) != 3:
            return True
        distance = math.dist(tool, self.tool[at])
        limit = self.diverge_mm
        if distance > limit and not self.off:
            self.write(
                "diverged",
                what="tool",
                event=events,
                tick=msg.integer("tick"),
                t=msg.number("t"),
                distance_mm=round(distance, 2),
                limit_mm=limit,
            )
        self.off = distance > limit
        return True

    def finish(self, wait: float) -> None:
        """At the run's end: give the prediction up to ``wait`` s to get there, compare what
        is left, and stop it."""
        if self.thread is not None:
            self.thread.join(timeout=wait)
        self._drain()
        self.halt()

    def halt(self) -> None:
        """Stop the predicted run at its next control period and wait for its thread (a
        thread left in MuJoCo while Python exits would crash it)."""
        self.stop.request("the remote run ended")
        if self.thread is not None:
            self.thread.join(timeout=10.0)

    def _block_start(self, number: int) -> int | None:
        """The first period of the prediction's block ``number`` (None: not reached)."""
        records = [] if self.log is None else self.log.records
        while self._scanned < len(records):
            r = records[self._scanned]
            self._scanned += 1
            if r["kind"] == "block" and isinstance(r.get("number"), int):
                t = r.get("t")
                self._starts[int(str(r["number"]))] = round(float(str(t)) / PERIOD)
        return self._starts.get(number)


def _int(value: object) -> int:
    return value if isinstance(value, int) else 0


def start_prediction(
    script: Script,
    tick: float,
    write: Callable[..., None],
    diverge_mm: float,
    observers: Sequence[Observer] = (),
) -> Predictor:
    """Start the predicted run in a thread; the predictor compares as reports arrive."""
    predictor = Predictor(write, diverge_mm)

    def predict() -> None:
        from dial.engine.run import RunOptions
        from dial.engine.run import run as run_engine

        try:
            watching = [predictor, *observers]
            options = RunOptions(tick=tick, observers=watching, stop=predictor.stop)
            run_engine(script, options)
        except Exception as e:  # the prediction is advice: the remote run goes on without it
            predictor.error = str(e)
        finally:
            predictor.done.set()

    predictor.thread = threading.Thread(target=predict, daemon=True, name="dial-prediction")
    predictor.thread.start()
    return predictor
