"""Link emulation: a WebSocket proxy that delays, jitters, throttles, cuts or blackholes.

``dial link --listen ADDR --to URL SPEC`` runs it as a process between any client and
server; ``dial run --remote URL --link SPEC`` runs the same proxy inside the operator, on a
free loopback port. SPEC: ``delay=2s jitter=300ms bandwidth=2400bps cut=T:D blackhole=T
seed=N`` (times from the first connection through the link). Jitter keeps the order of the
messages, as TCP does; it is drawn from a generator seeded with ``seed``, so a test can
repeat a run.
"""

from __future__ import annotations

import math
import random
import re
from dataclasses import dataclass
from functools import partial

import trio
from trio_websocket import (
    ConnectionClosed,
    HandshakeError,
    WebSocketConnection,
    WebSocketRequest,
    open_websocket_url,
    serve_websocket,
)

from dial.errors import OptionError
from dial.remote.protocol import CLOSE_S, MAX_FRAME

FRAME_OVERHEAD = 8  # bytes a WebSocket frame adds to its payload, about (header, mask)
_TIME = re.compile(r"^(\d+(?:\.\d*)?|\.\d+)(ms|s)?$")
_RATE = re.compile(r"^(\d+(?:\.\d*)?|\.\d+)(bps|kbps|Mbps)?$")
_RATES = {None: 1.0, "bps": 1.0, "kbps": 1e3, "Mbps": 1e6}
EXPECTED = (
    "expected 'delay=2s jitter=300ms bandwidth=2400bps cut=T:D blackhole=T seed=N' "
    "(any of them; times in s or ms)"
)


@dataclass(frozen=True)
class LinkSpec:
    """What the emulated link does: one-way delay and jitter (s), bandwidth (bit/s, None:
    unlimited), a cut (start, length in s), a blackhole (start in s), the jitter's seed."""

    delay: float = 0.0
    jitter: float = 0.0
    bandwidth: float | None = None
    cut: tuple[float, float] | None = None
    blackhole: float | None = None
    seed: int = 0

    def text(self) -> str:
        parts = [f"delay={self.delay:g}s", f"jitter={self.jitter:g}s"]
        if self.bandwidth is not None:
            parts.append(f"bandwidth={self.bandwidth:g}bps")
        if self.cut is not None:
            parts.append(f"cut={self.cut[0]:g}:{self.cut[1]:g}")
        if self.blackhole is not None:
            parts.append(f"blackhole={self.blackhole:g}")
        return " ".join([*parts, f"seed={self.seed}"])


def _time(key: str, value: str) -> float:
    m = _TIME.match(value)
    if m is None:
        raise OptionError(f"--link: {key}={value}: expected a time such as 2s or 300ms")
    return float(m.group(1)) / (1000.0 if m.group(2) == "ms" else 1.0)


def parse_link(spec: str) -> LinkSpec:
    """A SPEC as :class:`LinkSpec`; a bad one is an :class:`OptionError` naming what was
    expected."""
    fields: dict[str, object] = {}
    for word in spec.split():
        key, eq, value = word.partition("=")
        if not eq or not value or key in fields:
            raise OptionError(f"--link: '{word}': {EXPECTED}")
        if key in ("delay", "jitter", "blackhole"):
            fields[key] = _time(key, value)
        elif key == "bandwidth":
            m = _RATE.match(value)
            rate = float(m.group(1)) * _RATES[m.group(2)] if m else 0.0
            if rate <= 0:
                raise OptionError(f"--link: bandwidth={value}: expected a rate such as 2400bps")
            fields[key] = rate
        elif key == "cut":
            start, colon, length = value.partition(":")
            if not colon:
                raise OptionError(f"--link: cut={value}: expected cut=T:D (start, length)")
            fields[key] = (_time(key, start), _time(key, length))
        elif key == "seed" and value.isascii() and value.isdigit() and len(value) < 10:
            fields[key] = int(value)
        else:
            raise OptionError(f"--link: '{word}': {EXPECTED}")
    return LinkSpec(**fields)  # type: ignore[arg-type]


class _Direction:
    """One way through the link: its bandwidth's queue, its delay and jitter, in order."""

    def __init__(self, spec: LinkSpec, seed: int) -> None:
        self.spec = spec
        self.rng = random.Random(seed)
        self.busy_until = 0.0  # trio time the last message finishes going onto the wire
        self.last = 0.0  # when the last message is delivered: order is kept
        self.bytes = 0
        self.messages = 0

    def deliver_at(self, now: float, size: int) -> float:
        spec = self.spec
        start = max(now, self.busy_until)
        if spec.bandwidth is not None:
            start += (size + FRAME_OVERHEAD) * 8.0 / spec.bandwidth
        self.busy_until = start
        jitter = self.rng.uniform(-spec.jitter, spec.jitter) if spec.jitter > 0 else 0.0
        self.last = max(self.last, start + max(0.0, spec.delay + jitter))
        self.bytes += size
        self.messages += 1
        return self.last


class Link:
    """The emulated link's state, shared by the connections through it."""

    def __init__(self, spec: LinkSpec, target: str) -> None:
        self.spec, self.target = spec, target
        self.up = _Direction(spec, spec.seed)  # client -> server
        self.down = _Direction(spec, spec.seed + 1)  # server -> client
        self.t0: float | None = None  # the first connection
        self.cut_scope: trio.CancelScope | None = None

    def elapsed(self) -> float:
        return 0.0 if self.t0 is None else trio.current_time() - self.t0

    def cut_now(self) -> bool:
        cut = self.spec.cut
        return cut is not None and cut[0] <= self.elapsed() < cut[0] + cut[1]

    def blackholed(self) -> bool:
        hole = self.spec.blackhole
        return hole is not None and self.t0 is not None and self.elapsed() >= hole

    async def handle(self, request: WebSocketRequest) -> None:
        """One client connection: open one to the server and pump both ways until either
        closes, the cut starts, or forever through a blackhole."""
        if self.t0 is None:
            self.t0 = trio.current_time()
        if self.cut_now():
            await request.reject(503, body=b"the link is cut")
            return
        client = await request.accept()
        try:
            async with (
                open_websocket_url(
                    self.target, max_message_size=MAX_FRAME, disconnect_timeout=CLOSE_S
                ) as server,
                trio.open_nursery() as nursery,
            ):
                nursery.start_soon(self._watch_cut, nursery.cancel_scope)
                nursery.start_soon(self._pump, client, server, self.up, nursery.cancel_scope)
                nursery.start_soon(self._pump, server, client, self.down, nursery.cancel_scope)
        except* (ConnectionClosed, HandshakeError, OSError, trio.BrokenResourceError):
            pass  # either end went away, or the server refused: the client sees it closed
        finally:
            with trio.CancelScope(shield=True), trio.move_on_after(CLOSE_S):
                await client.aclose()

    async def _watch_cut(self, scope: trio.CancelScope) -> None:
        cut = self.spec.cut
        if cut is None or self.elapsed() >= cut[0]:
            await trio.sleep_forever()
            return
        await trio.sleep(cut[0] - self.elapsed())
        scope.cancel()  # the connection drops: both ends see it closed

    async def _pump(
        self,
        source: WebSocketConnection,
        dest: WebSocketConnection,
        way: _Direction,
        scope: trio.CancelScope,
    ) -> None:
        send, receive = trio.open_memory_channel[tuple[float, str | bytes]](math.inf)
        async with trio.open_nursery() as nursery:
            nursery.start_soon(self._deliver, receive, dest, scope)
            try:
                while True:
                    message = await source.get_message()
                    if self.blackholed():
                        continue  # nothing flows; the connection stays open
                    size = len(message.encode() if isinstance(message, str) else message)
                    await send.send((way.deliver_at(trio.current_time(), size), message))
            except ConnectionClosed:
                await send.aclose()
                await trio.sleep(0)
        scope.cancel()

    async def _deliver(
        self,
        receive: trio.MemoryReceiveChannel[tuple[float, str | bytes]],
        dest: WebSocketConnection,
        scope: trio.CancelScope,
    ) -> None:
        """Deliver each message at its time; an end gone away ends the connection (what
        was still on its way is lost, as on a real link)."""
        async for at, message in receive:
            await trio.sleep_until(at)
            if self.blackholed():
                continue
            try:
                await dest.send_message(message)
            except (ConnectionClosed, trio.BrokenResourceError):
                scope.cancel()
                return


async def serve_link(
    link: Link,
    host: str,
    port: int,
    *,
    task_status: trio.TaskStatus[int] = trio.TASK_STATUS_IGNORED,
) -> None:
    """Serve ``link`` on ``host:port`` (0: a free port, reported through ``task_status``)."""
    async with trio.open_nursery() as nursery:
        server = await nursery.start(
            partial(
                serve_websocket,
                link.handle,
                host,
                port,
                None,
                max_message_size=MAX_FRAME,
                disconnect_timeout=CLOSE_S,
            )
        )
        task_status.started(server.port)
