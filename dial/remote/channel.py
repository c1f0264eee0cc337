"""The operator's end of the link: connect, say hello, send commands until acknowledged,
receive every report once, heartbeat, reconnect after a cut, and notice a lost robot.

Commands are numbered (``seq``) and named (``id``); each stays in :attr:`Channel.unacked`
until the robot acknowledges it, and is sent again, with the same number, after a
reconnect (the robot runs a number once). Reports are numbered too (``n``): the hello of a
reconnect says how many have arrived, and the robot sends the rest.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import trio
from trio_websocket import ConnectionClosed, HandshakeError, WebSocketConnection, open_websocket_url

from dial.errors import DialError
from dial.remote.protocol import (
    CLOSE_S,
    MAX_FRAME,
    TO_OPERATOR,
    Message,
    ProtocolError,
    decode,
    encode,
)

CONNECT_S = 15.0  # how long the first connection may take (hello and welcome included)
RETRY_S = 0.1  # between reconnection attempts
RECONNECT_S = 1.0  # the least time a reconnection attempt may take
HEARTBEAT_S = 0.25
GONE = (OSError, HandshakeError, ConnectionClosed, trio.BrokenResourceError)
FATAL = frozenset({"token", "busy", "no_session", "version"})


class RobotLost(DialError):
    """The robot is gone (killed, blackholed, or it lost the link): a one-line message."""


@dataclass
class Channel:
    """One operator's link to one robot session."""

    url: str
    token: str
    on_report: Callable[[Message], None]  # records, results, refusals, the end; each once
    on_telemetry: Callable[[Message], None]
    link_record: Callable[..., None]  # (kind, **fields): a link record in the operator's log
    bandwidth: float | None = None
    shown: str = ""  # the robot's URL as messages name it (``url`` may be a local link's)
    session: int | None = None
    robot: dict[str, object] = field(default_factory=dict)
    have: int = 0  # reports received
    unacked: dict[int, str] = field(default_factory=dict)  # seq -> encoded command
    seq: int = 0
    sent_bytes: int = 0
    received_bytes: int = 0
    telemetry: int = 0  # samples received
    rtt: float | None = None
    lost: str | None = None
    done: bool = False  # the session is over: stop reconnecting
    _ws: WebSocketConnection | None = None
    _heard: float = 0.0  # trio time of the robot's last message
    _welcome: trio.Event = field(default_factory=trio.Event)
    _pong: trio.Event = field(default_factory=trio.Event)

    @property
    def watchdog(self) -> float:
        value = self.robot.get("watchdog", 1.0)
        return float(value) if isinstance(value, int | float) else 1.0

    async def run(self, outer: trio.CancelScope) -> None:
        """Keep the link up until :attr:`done`. When the robot has been silent for its
        watchdog time (or did not answer within CONNECT_S), or refused the session, set
        :attr:`lost` and cancel ``outer``: the operator's run stops there."""
        self._heard = trio.current_time()
        async with trio.open_nursery() as nursery:
            nursery.start_soon(self._heartbeats)
            nursery.start_soon(self._watch, nursery.cancel_scope)
            while not self.done and self.lost is None:
                with contextlib.suppress(*GONE):  # reconnect until the watchdog says lost
                    await self._connect()
                if not self.done and self.lost is None:
                    await trio.sleep(RETRY_S)
            nursery.cancel_scope.cancel()
        if self.lost is not None:
            outer.cancel()

    async def wait_welcome(self) -> None:
        await self._welcome.wait()

    def _attempt_s(self) -> float:
        """How long one connection attempt may take: CONNECT_S for the first; after a cut
        a few round trips (at least RECONNECT_S). An attempt whose connection the far end
        accepts and then drops before the handshake's reply (a gateway, a half-up link)
        fails only at this timeout (trio-websocket waits for the reply): it must leave
        time for more attempts within the watchdog time."""
        if self.rtt is None or not self._welcome.is_set():
            return CONNECT_S
        return max(RECONNECT_S, 3.0 * self.rtt)

    async def _connect(self) -> None:
        async with open_websocket_url(
            self.url,
            max_message_size=MAX_FRAME,
            connect_timeout=self._attempt_s(),
            disconnect_timeout=CLOSE_S,
        ) as ws:
            hello: dict[str, object] = {"token": self.token, "role": "operator"}
            if self.session is not None:
                hello.update(session=self.session, have=self.have)
            if self.bandwidth is not None:
                hello["bandwidth"] = self.bandwidth
            self._ws = ws
            try:
                await self._send(encode("hello", **hello))
                for text in list(self.unacked.values()):  # after a cut: in order, same seq
                    await self._send(text)
                while not self.done:
                    self._receive(await ws.get_message())
            finally:
                self._ws = None

    async def _send(self, text: str) -> None:
        ws = self._ws
        if ws is None:
            return
        try:
            await ws.send_message(text)
        except (ConnectionClosed, trio.BrokenResourceError):
            return
        self.sent_bytes += len(text.encode("utf-8"))

    def _receive(self, raw: str | bytes) -> None:
        self.received_bytes += len(raw if isinstance(raw, bytes) else raw.encode("utf-8"))
        self._heard = trio.current_time()
        try:
            msg = decode(raw, TO_OPERATOR)
        except ProtocolError as e:
            self.link_record("error", code=e.code, message=str(e))
            return
        kind = msg.type
        if kind == "welcome":
            self.session = msg.integer("session")
            self.robot = dict(msg.obj("robot"))
            self.link_record("connected", session=self.session, resumed=msg.fields["resumed"])
            self._welcome.set()
        elif kind == "ack":
            if self.unacked.pop(msg.integer("seq"), None) is not None:
                self.link_record("acknowledged", seq=msg.integer("seq"), id=msg.text("id"))
        elif kind == "pong":
            self._pong.set()
        elif kind == "telemetry":
            self.telemetry += 1
            self.on_telemetry(msg)
        elif kind == "error":
            self.link_record("error", code=msg.text("code"), message=msg.text("message"))
            if msg.text("code") in FATAL:
                self.lost = f"the robot refused: {msg.text('message')}"
        elif "n" in msg.fields:
            n = msg.integer("n")
            if n == self.have:  # each report once, in order
                self.have += 1
                self.on_report(msg)

    async def command(self, type_: str, /, **fields: object) -> int:
        """Send a command (numbered, named, kept until acknowledged); its seq."""
        self.seq += 1
        seq, ident = self.seq, f"c{self.seq}"
        text = encode(type_, seq=seq, id=ident, **fields)
        self.unacked[seq] = text
        self.link_record("sent", seq=seq, id=ident, command=type_, tick=fields.get("tick"))
        await self._send(text)
        return seq

    async def measure_rtt(self) -> float:
        """The round trip of a ping, through the link as it is now (s)."""
        self._pong = trio.Event()
        start = trio.current_time()
        await self._send(encode("ping", id="rtt"))
        await self._pong.wait()
        self.rtt = trio.current_time() - start
        return self.rtt

    async def _heartbeats(self) -> None:
        while True:
            await self._send(encode("heartbeat"))
            await trio.sleep(HEARTBEAT_S)

    async def _watch(self, scope: trio.CancelScope) -> None:
        """A robot silent for its watchdog time (CONNECT_S before the first welcome) is lost."""
        while not self.done and self.lost is None:
            limit = self.watchdog if self._welcome.is_set() else CONNECT_S
            silent = trio.current_time() - self._heard
            if silent > limit and not self._welcome.is_set():
                self.lost = f"no robot answered at {self.shown or self.url} within {CONNECT_S:g} s"
            elif silent > limit:
                where = self.shown or self.url
                self.lost = f"lost the robot at {where}: no message for {silent:.1f} s"
            await trio.sleep(0.02)
        scope.cancel()


def wall_clock() -> float:
    return time.monotonic()
