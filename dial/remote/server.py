"""``dial serve``: the robot's network side (docs/remote.md).

One WebSocket server, one controlling operator at a time (observers may read the status),
one :class:`~dial.remote.session.Session` per operator's session. Every message is
checked before anything acts on it; a bad one gets an ``error`` reply and the server keeps
serving. A session outlives a cut connection for ``--watchdog`` seconds: an operator that
reconnects with its session number within that time takes it up again and receives the
reports it missed. With no message from the operator for that long the robot holds every
effector and logs ``link lost``.
"""

from __future__ import annotations

import contextlib
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import IO

import trio
from trio_websocket import ConnectionClosed, WebSocketConnection, WebSocketRequest, serve_websocket

from dial.remote.protocol import (
    CLOSE_S,
    COMMANDS,
    MAX_FRAME,
    TO_ROBOT,
    VERSION,
    Message,
    ProtocolError,
    decode,
    encode,
    error,
)
from dial.remote.robot import robot_main
from dial.remote.session import Session
from dial.remote.telemetry import RobotConfig, telemetry_every
from dial.remote.tokens import same_token


@dataclass(eq=False)
class Conn:
    """One WebSocket connection to the server."""

    ws: WebSocketConnection
    role: str | None = None  # after hello: "operator" or "observer"
    session: Session | None = None  # the session an operator controls
    sent: int = 0  # reports sent so far
    telemetry: str | None = None  # the last sample sent
    closing: bool = False
    woken: trio.Event = field(default_factory=trio.Event)

    async def send(self, text: str) -> None:
        await self.ws.send_message(text)

    def close(self) -> None:
        """Close this connection soon (its sender closes it, also while it is silent)."""
        self.closing = True
        self.woken.set()


class Server:
    """The robot's server: sessions, their watchdogs, and every connection's messages."""

    def __init__(self, robot: RobotConfig, token: str, log: IO[str] | None) -> None:
        self.robot, self.token, self.log = robot, token, log
        self.session: Session | None = None
        self.controller: Conn | None = None
        self.last_heard = 0.0  # trio time of the controller's last message
        self.conns: set[Conn] = set()
        self.heartbeat = min(0.25, robot.watchdog / 4.0)
        self._trio_token: trio.lowlevel.TrioToken | None = None
        self._nursery: trio.Nursery | None = None

    async def serve(
        self, host: str, port: int, *, task_status: trio.TaskStatus[int] = trio.TASK_STATUS_IGNORED
    ) -> None:
        self._trio_token = trio.lowlevel.current_trio_token()
        try:
            async with trio.open_nursery() as nursery:
                self._nursery = nursery
                listener = await nursery.start(
                    partial(
                        serve_websocket, self.handle, host, port, None, max_message_size=MAX_FRAME
                    )
                )
                task_status.started(listener.port)
        finally:
            self.shutdown()

    def shutdown(self) -> None:
        """Stop the robot (every effector holds) and end its thread."""
        s = self.session
        if s is not None:
            s.stop.request("the server stopped")
            s.closing.set()
            if s.thread is not None:
                s.thread.join(timeout=5.0)

    def wake(self) -> None:
        """Wake every connection's sender (thread-safe: the robot thread calls it)."""
        if self._trio_token is not None:
            with contextlib.suppress(trio.RunFinishedError):
                self._trio_token.run_sync_soon(self._wake_all)

    def _wake_all(self) -> None:
        for conn in self.conns:
            conn.woken.set()

    # -- one connection -----------------------------------------------------------------------
    async def handle(self, request: WebSocketRequest) -> None:
        """One connection; whatever goes wrong in it, the server keeps serving."""
        try:
            await self._handle(request)
        except Exception as e:  # a bug must not take the robot's server down
            what = "; ".join(str(x) for x in getattr(e, "exceptions", [e]))
            print(f"dial serve: a connection failed: {type(e).__name__}: {what}", file=sys.stderr)

    async def _handle(self, request: WebSocketRequest) -> None:
        conn = Conn(await request.accept())
        self.conns.add(conn)
        try:
            async with trio.open_nursery() as nursery:
                nursery.start_soon(self._sender, conn)
                with contextlib.suppress(ConnectionClosed, trio.BrokenResourceError):
                    while not conn.closing:
                        await self._receive(conn, await conn.ws.get_message())
                nursery.cancel_scope.cancel()
        except (ConnectionClosed, trio.BrokenResourceError):
            pass
        finally:
            self.conns.discard(conn)
            if self.controller is conn:
                self.controller = None  # the session waits for its operator: the watchdog runs
                s = conn.session
                if s is not None and s.active:  # a cut, a dead operator: said in the log
                    s.link_record("disconnected", session=s.number, tick=s.tick)
            with trio.CancelScope(shield=True), trio.move_on_after(CLOSE_S):
                await conn.ws.aclose()

    async def _receive(self, conn: Conn, raw: str | bytes) -> None:
        try:
            msg = decode(raw, TO_ROBOT)
        except ProtocolError as e:
            await conn.send(error(e.code, str(e)))
            return
        if conn is self.controller:
            self.last_heard = trio.current_time()
        if msg.type == "hello":
            await self._hello(conn, msg)
        elif conn.role is None:
            await conn.send(error("order", f"'{msg.type}' before 'hello': say hello first"))
        elif msg.type == "status":
            await conn.send(encode("status", **self.status()))
        elif msg.type == "ping":
            await conn.send(encode("pong", id=msg.text("id")))
        elif msg.type in COMMANDS:
            await self._command(conn, msg)

    async def _sender(self, conn: Conn) -> None:
        """Reports (each once, in order), the latest telemetry, and heartbeats; until the
        connection closes, or is to be closed: then close it."""
        with contextlib.suppress(ConnectionClosed, trio.BrokenResourceError):
            await self._send_all(conn)
        conn.closing = True
        with trio.move_on_after(CLOSE_S):
            await conn.ws.aclose()

    async def _send_all(self, conn: Conn) -> None:
        due = trio.current_time()
        while not conn.closing:
            conn.woken = trio.Event()  # before sending: a wake meanwhile is not lost
            s = conn.session
            if s is not None and conn is self.controller:
                for report in s.reports_from(conn.sent):
                    await conn.send(report)
                    conn.sent += 1
                if s.telemetry is not None and s.telemetry is not conn.telemetry:
                    conn.telemetry = s.telemetry
                    await conn.send(s.telemetry)
            if trio.current_time() >= due:
                await conn.send(encode("heartbeat", tick=self._tick()))
                due = trio.current_time() + self.heartbeat
            with trio.move_on_at(due):
                await conn.woken.wait()

    # -- hello, sessions ------------------------------------------------------------------------
    async def _hello(self, conn: Conn, msg: Message) -> None:
        if conn.role is not None:
            await conn.send(error("order", "a second 'hello' on one connection"))
            return
        if not same_token(msg.text("token"), self.token):
            await self._close(conn, "token", "wrong token: nothing runs")
            return
        role = msg.text("role")
        if role not in ("operator", "observer"):
            await conn.send(error("invalid", "'hello': 'role' must be operator or observer"))
            return
        s = self.session
        if role == "operator":
            if "session" in msg.fields:
                if not await self._resume(conn, msg):
                    return
            elif s is not None and s.active:
                why = f"the robot is controlled by session {s.number}: one operator at a time"
                await self._close(conn, "busy", why)
                return
            else:
                await self._new_session(conn, msg)
        conn.role = role
        number = 0 if self.session is None else self.session.number
        await conn.send(
            encode(
                "welcome",
                session=number if role == "operator" else 0,
                role=role,
                robot=self._robot_info(),
                resumed="session" in msg.fields,
            )
        )
        conn.woken.set()

    async def _resume(self, conn: Conn, msg: Message) -> bool:
        s, number = self.session, msg.integer("session")
        if s is None or s.number != number:  # the latest session, even over: its reports
            why = f"session {number} is over: the robot has served another since"
            await self._close(conn, "no_session", why)
            return False
        old = self.controller
        if old is not None and old is not conn:
            old.close()  # the same operator again, after a cut its old socket missed
            with trio.CancelScope(shield=True), trio.move_on_after(CLOSE_S):
                await old.ws.aclose()
        conn.session, conn.sent = s, msg.integer("have")
        self.controller, self.last_heard = conn, trio.current_time()
        s.link_record("session", session=s.number, resumed=True, have=conn.sent)
        return True

    async def _new_session(self, conn: Conn, msg: Message) -> None:
        old = self.session
        if old is not None:
            old.closing.set()
            if old.thread is not None:
                await trio.to_thread.run_sync(old.thread.join)
        number = 1 if old is None else old.number + 1
        s = self.session = Session(number, self.log, self.wake)
        s.bandwidth = msg.number("bandwidth") if "bandwidth" in msg.fields else None
        conn.session, conn.sent = s, 0
        self.controller, self.last_heard = conn, trio.current_time()
        s.link_record("session", session=number, resumed=False)
        assert self._nursery is not None
        self._nursery.start_soon(self._watchdog, s)

    async def _watchdog(self, s: Session) -> None:
        """Hold the robot when the operator has been silent for --watchdog seconds."""
        limit = self.robot.watchdog
        while s.active:
            left = self.last_heard + limit - trio.current_time()
            if left <= 0:
                self._lose(s, f"link lost: no message from the operator for {limit:g} s")
                return
            await trio.sleep(min(left, 0.005))

    def _lose(self, s: Session, why: str) -> None:
        s.link_record("lost", message=why, tick=self._tick())
        s.stop.request("link lost")
        s.state = "lost"  # the robot holds at its next control period
        if s.thread is None:  # nothing ran: the session ends here
            s.report("finished", summary={"ok": False, "interrupted": "link lost"})
        print(f"dial serve: session {s.number}: {why}; every effector holds", file=sys.stderr)
        if self.controller is not None:
            self.controller.close()
            self.controller = None

    async def _close(self, conn: Conn, code: str, why: str) -> None:
        await conn.send(error(code, why))
        conn.close()

    # -- commands ------------------------------------------------------------------------------
    async def _command(self, conn: Conn, msg: Message) -> None:
        s = conn.session
        if conn.role != "operator" or s is None or conn is not self.controller:
            await conn.send(error("order", f"'{msg.type}' from a connection that controls nothing"))
            return
        seq, ident = msg.integer("seq"), msg.text("id")
        if seq <= s.highest:  # sent again after a cut: acknowledged again, run once
            if s.ids.get(seq) != ident:
                await conn.send(error("invalid", f"seq {seq} was command '{s.ids.get(seq)}'"))
            else:
                await conn.send(encode("ack", seq=seq, id=ident))
            return
        if seq != s.highest + 1:
            await conn.send(error("invalid", f"seq {seq}: the next command is {s.highest + 1}"))
            return
        s.highest, s.ids[seq] = seq, ident
        s.link_record("received", seq=seq, id=ident, command=msg.type, tick=msg.fields.get("tick"))
        await conn.send(encode("ack", seq=seq, id=ident))
        self._take(s, msg)

    def _take(self, s: Session, msg: Message) -> None:
        seq, ident = msg.integer("seq"), msg.text("id")
        if msg.type == "stop":
            s.stop.request("the operator's stop")
            if s.thread is None and s.active:
                s.state = "stopped"
                s.report("finished", summary={"ok": False, "interrupted": "the operator's stop"})
        elif msg.type in ("run", "open"):
            if s.thread is not None or not s.active:
                s.report(
                    "refused", seq=seq, id=ident, code="invalid", message="one script a session"
                )
                return
            s.split = "script" if msg.type == "run" else "block"
            every = telemetry_every(0.01, self.robot.pace, s.bandwidth)
            s.thread = _thread(robot_main, s, self.robot, msg, every)
        elif s.thread is None or s.split != "block":
            why = f"'{msg.type}' needs a block session ('open' first)"
            s.report("refused", seq=seq, id=ident, code="invalid", message=why)
        else:
            s.commands.put(msg)

    # -- status --------------------------------------------------------------------------------
    def _tick(self) -> int:
        return 0 if self.session is None else self.session.tick

    def status(self) -> dict[str, object]:
        s = self.session
        return {
            "state": "idle" if s is None else s.state,
            "session": 0 if s is None else s.number,
            "controlled": self.controller is not None,
            **({} if s is None else s.status),
            "robot": self._robot_info(),
        }

    def _robot_info(self) -> dict[str, object]:
        r = self.robot
        return {
            "scene": r.scene,
            "pace": r.pace,
            "watchdog": r.watchdog,
            "period": 0.01,
            "protocol": VERSION,
        }


def _thread(
    target: Callable[[Session, RobotConfig, Message, int], None],
    s: Session,
    robot: RobotConfig,
    msg: Message,
    every: int,
) -> threading.Thread:
    thread = threading.Thread(
        target=target, args=(s, robot, msg, every), daemon=True, name="dial-robot"
    )
    thread.start()
    return thread
