"""The link emulation in-process (dial/remote/link.py) between a client and an echo server
of the test's own: delay both ways, a cut that drops the connection and refuses new ones
while it lasts, then lets them through again."""

from __future__ import annotations

from functools import partial

import pytest
import trio
from trio_websocket import (
    ConnectionClosed,
    HandshakeError,
    WebSocketRequest,
    open_websocket_url,
    serve_websocket,
)

from dial.remote.link import Link, parse_link, serve_link


async def _echo(request: WebSocketRequest) -> None:
    ws = await request.accept()
    with pytest.raises(ConnectionClosed):
        while True:
            await ws.send_message(await ws.get_message())


async def _round_trip(url: str) -> float:
    async with open_websocket_url(url) as ws:
        start = trio.current_time()
        await ws.send_message("ping")
        assert await ws.get_message() == "ping"
        return trio.current_time() - start


def test_a_cut_drops_the_connection_refuses_new_ones_then_lets_them_through() -> None:
    spec = parse_link("delay=0.1s cut=0.6:2")

    async def main() -> None:
        async with trio.open_nursery() as nursery:
            echo = await nursery.start(partial(serve_websocket, _echo, "127.0.0.1", 0, None))
            link = Link(spec, f"ws://127.0.0.1:{echo.port}")
            port = await nursery.start(serve_link, link, "127.0.0.1", 0)
            url = f"ws://127.0.0.1:{port}"
            t0 = trio.current_time()
            async with open_websocket_url(url) as ws:
                await ws.send_message("one")
                assert await ws.get_message() == "one"
                assert trio.current_time() - t0 >= 0.2  # a delay each way
                with pytest.raises(ConnectionClosed):  # the cut at 0.6 s
                    while True:
                        await ws.send_message("more")
                        await ws.get_message()
            dropped = link.elapsed()
            assert 0.6 <= dropped < 1.6, dropped
            with pytest.raises(HandshakeError):  # refused while the cut lasts
                async with open_websocket_url(url):
                    pass
            assert link.elapsed() < 2.6
            await trio.sleep(2.6 - link.elapsed())
            assert await _round_trip(url) >= 0.2  # through again, delayed as before
            nursery.cancel_scope.cancel()

    trio.run(main)
