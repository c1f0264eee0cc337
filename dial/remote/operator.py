"""``dial run SCRIPT --remote URL``: the operator's side (docs/remote.md).

It sends the checked script (``--split script``) or walks its timeline and sends block
after block (``--split block``, :mod:`dial.remote.walk`), writes every record the robot
reports into its own log, with link records of its own (``sent``, ``acknowledged``,
``reported``, ``late``, ``lost``, ``diverged``), shows progress, and ends with the robot's
summary and criteria. It predicts the robot on its own believed world
(:mod:`dial.remote.predict`) and records where the reports leave the prediction.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, TextIO

import trio

from dial.engine.result import Criteria, RunResult
from dial.errors import DialError
from dial.parser.script import Script
from dial.remote.channel import Channel
from dial.remote.link import Link, serve_link
from dial.remote.options import OperatorOptions
from dial.remote.predict import Predictor, start_prediction
from dial.remote.protocol import Message
from dial.remote.walk import run_split
from dial.scene.of_script import script_world
from dial.scheduler.log import EventLog, Record
from dial.scheduler.runner import Tally
from dial.scheduler.signals import StopRequest
from dial.scheduler.types import RunAborted

if TYPE_CHECKING:
    from dial.remote.record import RemoteRecorder

PREDICTION_WAIT_S = 10.0  # how long a finished run waits for its prediction to catch up
STOP_WAIT_S = 1.0  # after the watchdog time, how long a stopped robot may take to report


@dataclass
class RemoteResult:
    """What the operator reports: the robot's run as measured there, and the link's figures."""

    result: RunResult | None
    record: Record  # the summary record (``--json``), with the link's figures
    message: str | None = None  # why the run did not complete (lost, rejected, stopped)
    interrupted: str | None = None


class OperatorLog:
    """The operator's log: the robot's records as reported, and link records."""

    def __init__(self, sink: TextIO | None) -> None:
        self.log = EventLog(sink, "the log")
        self.start = time.monotonic()
        self.robot: list[Record] = []  # the robot's records, in order

    def link(self, kind: str, /, **fields: object) -> None:
        self.log.write(kind, **fields, wall=round(time.monotonic() - self.start, 3))

    def reported(self, record: Record) -> None:
        self.robot.append(record)
        self.log.append(record)


class Operator:
    """One remote run: the channel, the reports, the split's commands, the end."""

    def __init__(self, script: Script, options: OperatorOptions) -> None:
        self.script, self.options = script, options
        self.out = OperatorLog(options.log)
        self.results: dict[int, Message] = {}
        self.arrived = trio.Event()  # a result, a refusal or the end arrived
        self.finished: Message | None = None
        self.summary: Record | None = None
        self.rejected: str | None = None
        self.running: dict[tuple[str, int], str] = {}  # (event, line) -> event, for progress
        # (script, event) -> the outcome of its latest run, as reported (what a condition reads)
        self.latest: dict[tuple[str, str], str] = {}
        self.predictor: Predictor | None = None
        self.recorder: RemoteRecorder | None = None  # --record, --rerun: the robots drawn

        self.channel = Channel(
            options.url,
            options.token,
            self._report,
            self._telemetry,
            self.out.link,
            None if options.link is None else options.link.bandwidth,
        )

    def link(self, kind: str, /, **fields: object) -> None:
        """A link record in the operator's log (a ``diverged`` one also in the recording)."""
        self.out.link(kind, **fields)
        if kind == "diverged" and self.recorder is not None:
            self.recorder.diverged(fields)

    # -- reports ---------------------------------------------------------------------------------
    def _report(self, msg: Message) -> None:
        if msg.type == "records":
            for item in msg.items("records"):
                if isinstance(item, dict):
                    self._record(item)
            return
        if msg.type == "finished":
            self.finished = msg
        elif msg.type == "refused":
            code = msg.text("code")
            self.out.link(
                "late" if code == "late" else "refused",
                seq=msg.integer("seq"),
                id=msg.text("id"),
                code=code,
                message=msg.text("message"),
            )
            if code == "rejected":
                self.rejected = msg.text("message")
            self.results[msg.integer("seq")] = msg
        else:
            fields = {k: v for k, v in msg.fields.items() if k in ("tick", "value")}
            self.out.link("reported", seq=msg.integer("seq"), id=msg.text("id"), **fields)
            self.results[msg.integer("seq")] = msg
        self.arrived.set()
        self.arrived = trio.Event()

    def _record(self, record: Record) -> None:
        if record.get("kind") == "summary":
            self.summary = record  # the operator writes the summary last, with the link's
            return
        self.out.reported(record)
        kind = record.get("kind")
        line = record.get("line")
        key = (str(record.get("event")), line if isinstance(line, int) else 0)
        where = (str(record.get("script", self.script.path)), str(record.get("event")))
        if kind == "start":
            self.running[key] = str(record.get("event"))
        elif kind == "end":
            self.running.pop(key, None)
            self.latest[where] = str(record.get("outcome"))
        elif kind == "monitor":  # what a condition on the watched event sees afterwards
            self.latest[where] = (
                "missed" if str(record.get("condition")).startswith("!") else "done"
            )
        elif kind == "tick" and self.options.progress is not None:
            t = record.get("t1")
            tick = record.get("tick")
            if isinstance(t, float | int) and isinstance(tick, int):
                self.options.progress(tick, float(t), sorted(self.running.values()))
        if self.predictor is not None:
            self.predictor.reported(record)
        if self.recorder is not None:
            self.recorder.record(record)

    def _telemetry(self, msg: Message) -> None:
        if self.predictor is not None:
            self.predictor.telemetry(msg)
        if self.recorder is not None:
            self.recorder.sample(msg.fields)

    async def result_of(self, seq: int) -> Message:
        """Wait for the robot's result (or refusal) of command ``seq``."""
        while seq not in self.results:
            if self.finished is not None:
                raise _Finished
            await self.arrived.wait()
        return self.results[seq]

    async def wait_finished(self) -> None:
        while self.finished is None:
            await self.arrived.wait()

    async def next_report(self) -> None:
        """Wait for the next result, refusal or end (raise if the run is over)."""
        if self.finished is not None:
            raise _Finished
        await self.arrived.wait()


class _Finished(Exception):
    """The robot's run ended before the walk did (an abort at the robot, a stop)."""


def remote_result(script: Script, op: Operator, wall: float) -> RunResult | None:
    """The robot's run, as a :class:`RunResult` built from its reports (None if it never
    ended)."""
    s = op.summary
    if s is None:
        return None
    error = s.get("error")
    outcomes = s.get("outcomes")
    summary = Tally(
        ok=error is None and s.get("interrupted") is None,
        error=None if error is None else RunAborted(str(error)),
        sim_time=float(str(s.get("sim_time", 0.0))),
        ticks=int(str(s.get("ticks", 0))),
        periods=round(float(str(s.get("sim_time", 0.0))) / 0.01),
        tick_length=float(str(s.get("tick", op.options.tick))),
        outcomes=dict(outcomes) if isinstance(outcomes, dict) else {},
        interrupted=None if s.get("interrupted") is None else str(s.get("interrupted")),
    )
    success = _strings(s.get("success"))
    details = _strings(s.get("criteria"))
    log = EventLog()
    log.records = list(op.out.robot)
    return RunResult(
        summary,
        script_world(script),
        Criteria(
            {k: v is True for k, v in success.items()}, {k: str(v) for k, v in details.items()}
        ),
        {},
        wall,
        0.0,
        int(str(s.get("physics_steps", 0))),
        log,
    )


def _strings(value: object) -> dict[str, object]:
    return {str(k): v for k, v in value.items()} if isinstance(value, dict) else {}


def summary_record(op: Operator, wall: float) -> Record:
    """The robot's summary, with the operator's wall time and the link's figures."""
    record: Record = dict(op.summary or {"ok": False})
    record.pop("kind", None)
    record["robot_wall_time"] = record.get("wall_time")
    record["wall_time"] = round(wall, 3)
    ch = op.channel
    record["remote"] = {
        "url": op.options.url,
        "split": op.options.split,
        "session": ch.session,
        "sent_bytes": ch.sent_bytes,
        "received_bytes": ch.received_bytes,
        "telemetry": ch.telemetry,
        "rtt": None if ch.rtt is None else round(ch.rtt, 3),
        "link": None if op.options.link is None else op.options.link.text(),
        "lead": next((r.get("seconds") for r in op.out.log.of("lead")), None),
        "diverged": len(op.out.log.of("diverged")),
        "late": len(op.out.log.of("late")),
    }
    return record


async def operate(script: Script, options: OperatorOptions, stop: StopRequest) -> RemoteResult:
    """Run ``script`` at the remote robot; a stop signal stops the robot (it holds)."""
    op = Operator(script, options)
    if options.record is not None or options.rerun:  # before connecting: a viewer takes time
        from dial.remote.record import remote_recorder

        op.recorder = remote_recorder(script, options.record, options.rerun)
    start = time.perf_counter()
    message: str | None = None
    try:
        async with trio.open_nursery() as nursery:
            if options.link is not None:
                link = Link(options.link, options.url)
                port = await nursery.start(serve_link, link, "127.0.0.1", 0)
                op.channel.url, op.channel.shown = f"ws://127.0.0.1:{port}/", options.url
            with trio.CancelScope() as work:
                nursery.start_soon(op.channel.run, work)
                nursery.start_soon(_watch_stop, op, stop, work)
                message = await _session(script, op)
            op.channel.done = True
            nursery.cancel_scope.cancel()
    finally:
        if op.recorder is not None:
            op.recorder.over()  # nothing more comes: the recording may close
    wall = time.perf_counter() - start
    _end_prediction(op)
    if op.channel.lost is not None and op.finished is None:
        message = op.channel.lost
        op.out.link("lost", message=message)
    if message is None and op.summary is not None and op.summary.get("interrupted") == "link lost":
        message = f"the robot lost the link at tick {op.summary.get('ticks')}: it holds"
    record = summary_record(op, wall)
    op.out.log.write("summary", **record)
    result = remote_result(script, op, wall)
    return RemoteResult(result, record, message or op.rejected, stop.signal)


def _end_prediction(op: Operator) -> None:
    """Give a finished run's prediction time to get there, stop it; the recording closes
    in the prediction's thread, or here when that thread never began it (one writer)."""
    predictor, recorder = op.predictor, op.recorder
    if predictor is not None:
        predictor.finish(PREDICTION_WAIT_S if op.finished is not None else 0.0)
    thread = None if predictor is None else predictor.thread
    if recorder is not None and (thread is None or not thread.is_alive()):
        recorder.close()


async def _session(script: Script, op: Operator) -> str | None:
    options = op.options
    await op.channel.wait_welcome()
    if options.predict:
        watching = [] if op.recorder is None else [op.recorder]
        op.predictor = start_prediction(script, options.tick, op.link, options.diverge_mm, watching)
    try:
        await run_split(script, op)
        if op.rejected is not None:  # the script does not check in the robot's world
            return op.rejected
        await op.wait_finished()
    except _Finished:
        pass
    except DialError as e:  # the robot refused a command: stop it, say why
        await op.channel.command("stop")
        with trio.move_on_after(op.channel.watchdog + STOP_WAIT_S):
            await op.wait_finished()
        return str(e)
    return op.rejected


async def _watch_stop(op: Operator, stop: StopRequest, work: trio.CancelScope) -> None:
    """Ctrl-C at the operator stops the robot: every effector holds; then give up waiting
    after the watchdog time and a second."""
    while stop.signal is None:
        await trio.sleep(0.05)
    await op.channel.command("stop")
    with trio.move_on_after(op.channel.watchdog + STOP_WAIT_S):
        await op.wait_finished()
    work.cancel()


def dumps(record: Record) -> str:
    return json.dumps(record)
