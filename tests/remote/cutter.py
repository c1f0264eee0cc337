"""A TCP relay on a free loopback port that a test cuts when it chooses: every connection
through it drops at once, and while the cut lasts a new one is closed as soon as it is
accepted. (``--link cut=T:D`` cuts at a time fixed in advance; a test that must cut in the
middle of a block cuts when the robot's log says the block runs.)"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress


class Cutter:
    def __init__(self, port: int) -> None:
        self.target = ("127.0.0.1", port)
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.listener.settimeout(0.2)  # accept() wakes up to see that it is closed
        self.url = f"ws://127.0.0.1:{self.listener.getsockname()[1]}"
        self.until = 0.0  # time.monotonic() at which the cut ends
        self.open: set[socket.socket] = set()
        self.lock = threading.Lock()
        self.closed = False

    def cut(self, seconds: float) -> None:
        """Drop every connection now; refuse new ones for ``seconds``."""
        with self.lock:
            self.until = time.monotonic() + seconds
            for sock in self.open:
                with suppress(OSError):
                    sock.shutdown(socket.SHUT_RDWR)

    def serve(self) -> None:
        while not self.closed:
            try:
                client, _ = self.listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            client.settimeout(None)
            if time.monotonic() < self.until:
                client.close()
                continue
            try:
                server = socket.create_connection(self.target, timeout=5)
            except OSError:
                client.close()
                continue
            server.settimeout(None)
            with self.lock:
                self.open |= {client, server}
            for a, b in ((client, server), (server, client)):
                threading.Thread(target=self._pump, args=(a, b), daemon=True).start()

    def _pump(self, source: socket.socket, dest: socket.socket) -> None:
        with suppress(OSError):
            while data := source.recv(65536):
                dest.sendall(data)
        for sock in (source, dest):  # one end gone: the other side sees it closed too
            with suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
        with self.lock:
            self.open.discard(source)
        source.close()

    def close(self) -> None:
        self.closed = True
        self.cut(0.0)
        self.listener.close()


@contextmanager
def cutter(url: str) -> Iterator[Cutter]:
    """A relay to ``url`` (ws://127.0.0.1:PORT), stopped at the end (its threads end)."""
    relay = Cutter(int(url.rsplit(":", 1)[1]))
    thread = threading.Thread(target=relay.serve, daemon=True)
    thread.start()
    try:
        yield relay
    finally:
        relay.close()
        thread.join(timeout=5)
