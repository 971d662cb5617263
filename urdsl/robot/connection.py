"""Sockets to a controller: connecting and reading with time limits and clear errors.

Every wait here is bounded: a connection attempt by ``timeout``, every read loop by a
deadline. Errors name ``host:port`` and what failed, for the user to act on.
"""

from __future__ import annotations

import socket
import time

__all__ = ["RobotConnectionError", "connect", "read_until", "Deadline"]


class RobotConnectionError(Exception):
    """A controller could not be reached or went away (the message names host:port)."""


def connect(host: str, port: int, timeout: float = 5.0) -> socket.socket:
    """A TCP connection to ``host:port``, with ``timeout`` (s) for connecting and each read."""
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except TimeoutError:
        raise RobotConnectionError(f"{host}:{port}: no answer within {timeout:g} s (is the "
                                   "robot on, and is this its address?)") from None
    except ConnectionRefusedError:
        raise RobotConnectionError(f"{host}:{port}: connection refused (is the controller "
                                   "running, and does it offer this interface?)") from None
    except OSError as error:
        raise RobotConnectionError(f"{host}:{port}: {error.strerror or error}") from None
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock


class Deadline:
    """A point in time (monotonic) that loops check against."""

    def __init__(self, seconds: float) -> None:
        self.end = time.monotonic() + seconds

    @property
    def left(self) -> float:
        return max(self.end - time.monotonic(), 0.0)

    @property
    def passed(self) -> bool:
        return time.monotonic() >= self.end


def read_until(sock: socket.socket, deadline: Deadline, what: str, host: str,
               port: int) -> bytes:
    """Bytes from ``sock`` (at least one), waiting at most until ``deadline``."""
    left = deadline.left
    if left <= 0:
        raise RobotConnectionError(f"{host}:{port}: timed out waiting for {what}")
    sock.settimeout(min(left, 1.0))
    try:
        data = sock.recv(1 << 16)
    except TimeoutError:
        return b""
    except OSError as error:
        raise RobotConnectionError(f"{host}:{port}: {error.strerror or error} while waiting "
                                   f"for {what}") from None
    if not data:
        raise RobotConnectionError(f"{host}:{port}: the controller closed the connection "
                                   f"while urdsl waited for {what}")
    return data
