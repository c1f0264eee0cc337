"""Where a paused run reads its commands: a terminal, a stream of lines, or a list (tests).

Reading blocks, so it happens in a worker thread (trio carries the I/O); a stop signal
while waiting for a command ends the wait, as the run itself would end.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from contextlib import suppress
from typing import Protocol, TextIO

import trio

from dial.scheduler.signals import StopRequest


class Console(Protocol):
    """A paused run's commands in, its answers out."""

    async def read(self, prompt: str, stop: StopRequest) -> str | None:
        """The next command line, or None at the end of the input (or on a stop signal)."""

    def write(self, text: str) -> None: ...


async def _in_thread(read: Callable[[], str | None], stop: StopRequest) -> str | None:
    result: list[str | None] = []

    async def reader(scope: trio.CancelScope) -> None:
        result.append(await trio.to_thread.run_sync(read, abandon_on_cancel=True))
        scope.cancel()

    async with trio.open_nursery() as nursery:
        nursery.start_soon(reader, nursery.cancel_scope)
        while stop.signal is None:
            await trio.sleep(0.05)
        nursery.cancel_scope.cancel()  # a stop signal came while waiting
    return result[0] if result else None


class LineConsole:
    """Commands line by line from a stream that is not a terminal (a scripted session):
    each is echoed after the prompt, so the transcript reads like a terminal session."""

    def __init__(self, stream: TextIO | None = None, out: TextIO | None = None) -> None:
        self.stream, self.out = stream or sys.stdin, out or sys.stdout

    async def read(self, prompt: str, stop: StopRequest) -> str | None:
        line = await _in_thread(self.stream.readline, stop)
        if not line:
            return None
        self.write(f"{prompt}{line.rstrip()}\n")
        return line.strip()

    def write(self, text: str) -> None:
        self.out.write(text)
        self.out.flush()


class TerminalConsole:
    """Commands typed at a terminal, with readline's line editing and history."""

    def __init__(self) -> None:
        with suppress(ImportError):  # not on every platform
            import readline  # noqa: F401 - input() gains line editing once it is loaded

    async def read(self, prompt: str, stop: StopRequest) -> str | None:
        def ask() -> str | None:
            try:
                return input(prompt)
            except EOFError:
                return None

        line = await _in_thread(ask, stop)
        return None if line is None else line.strip()

    def write(self, text: str) -> None:
        sys.stdout.write(text)
        sys.stdout.flush()


class ScriptedConsole:
    """Commands from a list, answers collected in ``transcript`` (tests, notebooks)."""

    def __init__(self, commands: Iterable[str]) -> None:
        self.commands = iter(commands)
        self.transcript: list[str] = []

    async def read(self, prompt: str, stop: StopRequest) -> str | None:
        line = next(self.commands, None)
        if line is not None:
            self.transcript.append(prompt + line + "\n")
        return line

    def write(self, text: str) -> None:
        self.transcript.append(text)
