"""The runner's log records, in one place: what each kind holds (docs/recording.md).

Only the runner (through :class:`Records`) and the engine (the ``scene`` and ``summary``
records) write the log. The robot reports what it observed (contacts, thread releases,
warnings) as :class:`~dial.scheduler.types.Happening` values and the runner writes them.
A called script's records carry ``script``: event names repeat across files.
"""

from __future__ import annotations

from dial.parser.ast import Condition
from dial.parser.script import Run
from dial.robot.protocol import Happening
from dial.scheduler.log import DIGITS, EventLog, Record, clean
from dial.scheduler.primitive import Ended, Outcome

_OUTCOME_TEXT = {o: o.value for o in Outcome}  # a dict lookup is cheaper than Enum.value


class Records:
    """Writes the runner's records into an :class:`EventLog`."""

    def __init__(self, log: EventLog, root: str) -> None:
        self.log = log
        self.root = root  # the top script's path: its records carry no ``script``

    def _whose(self, path: str) -> dict[str, str]:
        return {} if path == self.root else {"script": path}

    # start and end are a run's two records: built directly, as the hot path they are.
    def start(self, path: str, run: Run, tick: int, t: float) -> None:
        record: Record = {"kind": "start", "event": run.event, "line": run.line, "tick": tick}
        record["t"] = round(t, DIGITS) + 0.0
        if path != self.root:
            record["script"] = path
        self.log.append(record)

    def end(self, path: str, run: Run, ended: Ended, tick: int, t: float) -> None:
        for warning in ended.warnings:
            self.log.write(
                "warning",
                event=run.event,
                line=run.line,
                tick=tick,
                t=t,
                message=warning,
                **self._whose(path),
            )
        record: Record = {"kind": "end", "event": run.event, "line": run.line, "tick": tick}
        record["t"] = round(t, DIGITS) + 0.0
        record["outcome"] = _OUTCOME_TEXT[ended.outcome]
        if ended.message:
            record["message"] = ended.message
        if ended.data:
            record["data"] = clean(ended.data)
        if path != self.root:
            record["script"] = path
        self.log.append(record)

    def tick(
        self, tick: int, block_tick: int, t0: float, t1: float, stretch: int, preempted: bool
    ) -> None:
        record: Record = {"kind": "tick", "tick": tick, "block_tick": block_tick}
        record["t0"] = round(t0, DIGITS) + 0.0
        record["t1"] = round(t1, DIGITS) + 0.0
        record["stretch"] = stretch
        if preempted:
            record["preempted"] = True
        self.log.append(record)

    def block(self, path: str, number: int, line: int, tick: int, t: float) -> None:
        """The ``number``-th block the run starts (``--save-at block:N`` counts the same)."""
        record: Record = {"kind": "block", "number": number, "line": line, "tick": tick}
        record["t"] = round(t, DIGITS) + 0.0
        if path != self.root:
            record["script"] = path
        self.log.append(record)

    def condition(self, path: str, cond: Condition, value: bool, tick: int, t: float) -> None:
        self.log.write(
            "condition", condition=str(cond), value=value, tick=tick, t=t, **self._whose(path)
        )

    def call(self, target: str, tick: int, t: float) -> None:
        self.log.write("call", script=target, tick=tick, t=t)

    def monitor(
        self, path: str, cond: Condition, line: int, tick: int, t: float, period: int, step: int
    ) -> None:
        self.log.write(
            "monitor",
            event=cond.event,
            condition=str(cond),
            line=line,
            tick=tick,
            t=t,
            period=period,
            step=step,
            **self._whose(path),
        )

    def happening(self, happening: Happening, tick: int) -> None:
        self.log.write(happening.kind, **happening.fields, tick=tick)

    def error(self, event: str | None, tick: int, t: float, message: str) -> None:
        self.log.write("error", event=event, tick=tick, t=t, message=message)

    def interrupted(self, signal: str, tick: int, t: float) -> None:
        self.log.write("interrupted", tick=tick, t=t, signal=signal)
