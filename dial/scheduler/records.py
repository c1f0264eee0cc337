"""The runner's log records, in one place: what each kind holds (docs/recording.md).

Only the runner (through :class:`Records`) and the engine (the ``scene`` and ``summary``
records) write the log. The robot reports what it observed (contacts, thread releases,
warnings) as :class:`~dial.scheduler.types.Happening` values and the runner writes them.
A called script's records carry ``script``: event names repeat across files.
"""

from __future__ import annotations

from dial.parser.ast import Condition
from dial.parser.script import Run
from dial.scheduler.log import EventLog
from dial.scheduler.types import Ended, Happening


class Records:
    """Writes the runner's records into an :class:`EventLog`."""

    def __init__(self, log: EventLog, root: str) -> None:
        self.log = log
        self.root = root  # the top script's path: its records carry no ``script``

    def _whose(self, path: str) -> dict[str, str]:
        return {} if path == self.root else {"script": path}

    def start(self, path: str, run: Run, tick: int, t: float) -> None:
        if path == self.root:
            self.log.write("start", event=run.event, line=run.line, tick=tick, t=t)
        else:
            self.log.write("start", event=run.event, line=run.line, tick=tick, t=t, script=path)

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
        fields: dict[str, object] = {"outcome": ended.outcome.value}
        if ended.message:
            fields["message"] = ended.message
        if ended.data:
            fields["data"] = dict(ended.data)
        if path != self.root:
            fields["script"] = path
        self.log.write("end", event=run.event, line=run.line, tick=tick, t=t, **fields)

    def tick(
        self, tick: int, block_tick: int, t0: float, t1: float, stretch: int, preempted: bool
    ) -> None:
        extra = {"preempted": True} if preempted else {}
        self.log.write(
            "tick", tick=tick, block_tick=block_tick, t0=t0, t1=t1, stretch=stretch, **extra
        )

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

    def happening(self, happening: Happening) -> None:
        self.log.write(happening.kind, **happening.fields)

    def error(self, event: str | None, tick: int, t: float, message: str) -> None:
        self.log.write("error", event=event, tick=tick, t=t, message=message)

    def interrupted(self, signal: str, tick: int, t: float) -> None:
        self.log.write("interrupted", tick=tick, t=t, signal=signal)
