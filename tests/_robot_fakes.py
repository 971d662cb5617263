"""Small fake controller servers for the robot client tests.

Each server listens on 127.0.0.1 on a free port (port 0) and runs a handler function in a
thread per accepted connection. Everything is bounded: the listener accepts at most
``connections`` clients, sockets time out, and closing the server joins its threads with a
timeout. Nothing here listens on or connects to any other address.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable

LOOPBACK = "127.0.0.1"
IO_TIMEOUT = 10.0  # s: no fake server socket blocks longer than this


class FakeServer:
    """``handler(sock, index)`` serves the ``index``-th connection (0-based). Use as a context
    manager; ``port`` is the port to connect to; ``errors`` collects handler exceptions."""

    def __init__(self, handler: Callable[[socket.socket, int], None], *,
                 connections: int = 1, port: int = 0) -> None:
        self.handler = handler
        self.connections = connections
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind((LOOPBACK, port))
        self.listener.listen(8)
        self.listener.settimeout(0.2)
        self.port = self.listener.getsockname()[1]
        self.errors: list[BaseException] = []
        self.stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._accept_thread = threading.Thread(target=self._accept, daemon=True)

    def _accept(self) -> None:
        accepted = 0
        while accepted < self.connections and not self.stop.is_set():
            try:
                sock, _ = self.listener.accept()
            except (TimeoutError, OSError):
                continue
            sock.settimeout(IO_TIMEOUT)
            thread = threading.Thread(target=self._serve, args=(sock, accepted), daemon=True)
            accepted += 1
            self._threads.append(thread)
            thread.start()

    def _serve(self, sock: socket.socket, index: int) -> None:
        try:
            self.handler(sock, index)
        except (ConnectionError, TimeoutError, BrokenPipeError):
            pass  # the client went away: that is what several tests do on purpose
        except BaseException as error:  # noqa: BLE001 - reported by the test
            self.errors.append(error)
        finally:
            try:
                sock.close()
            except OSError:
                pass

    def __enter__(self) -> FakeServer:
        self._accept_thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        self._accept_thread.join(timeout=IO_TIMEOUT)
        for thread in self._threads:
            thread.join(timeout=IO_TIMEOUT)
        self.listener.close()


def free_port() -> int:
    """A port on 127.0.0.1 where nothing listens (bound, then released)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))
        return sock.getsockname()[1]


def recv_exactly(sock: socket.socket, count: int) -> bytes:
    data = bytearray()
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            raise ConnectionError("client closed")
        data += chunk
    return bytes(data)


def recv_until_closed(sock: socket.socket, limit: int = 1 << 20) -> bytes:
    """Everything the client sends until it closes (bounded by ``limit`` bytes)."""
    data = bytearray()
    while len(data) < limit:
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
    return bytes(data)
