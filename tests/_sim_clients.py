"""Plain socket clients of a running :class:`urdsl.sim.VirtualController` for the tests
(loopback only; every read bounded by ``TIMEOUT``)."""

from __future__ import annotations

import socket
import time

TIMEOUT = 5.0
"""Seconds any one connect or read may take."""


def connect(sim, interface: str, timeout: float = TIMEOUT) -> socket.socket:
    """A connection to one of the sim's served ports (``sim.servers.ports[interface]``)."""
    sock = socket.create_connection(("127.0.0.1", sim.servers.ports[interface]), timeout)
    sock.settimeout(timeout)
    return sock


class Dashboard:
    """A dashboard client: one line out, one line back; ``welcome`` is the greeting."""

    def __init__(self, sim):
        self.sock = connect(sim, "dashboard")
        self.file = self.sock.makefile("rb")
        self.welcome = self.line()

    def line(self) -> str:
        return self.file.readline().decode("utf-8", "replace").rstrip("\n")

    def ask(self, command: str) -> str:
        self.sock.sendall(command.encode() + b"\n")
        return self.line()

    def close(self):
        self.file.close()
        self.sock.close()


def read_exactly(sock: socket.socket, count: int) -> bytes:
    """``count`` bytes from ``sock`` (each recv bounded by the socket's timeout)."""
    data = b""
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return data


def wait_until(predicate, timeout: float = TIMEOUT) -> bool:
    """Whether ``predicate()`` became true within ``timeout`` s (polled every 20 ms)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.02)
    return False
