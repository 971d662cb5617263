"""Socket plumbing shared by every client: bounded connect, read and write, reconnects.

A :class:`Connection` is a TCP connection to one controller port with

* a connect that gives up after ``timeout`` seconds, retried ``attempts`` times with a
  backoff that doubles from ``backoff`` up to ``backoff_cap`` seconds (so that a controller
  that is still booting, or `urdsl sim` that is still starting, is waited for, but never
  forever);
* reads with a deadline (:meth:`Connection.recv`), and a non-blocking *drain*
  (:meth:`Connection.drain`) that takes everything the kernel has buffered — the basis of
  latest-sample reading: the controller pushes state at up to 500 Hz, and a client that
  reads more slowly than that must skip the old packets, not queue behind them;
* errors that name the interface and ``host:port`` (:mod:`urdsl.robot.errors`).

No protocol knowledge lives here: decoders from :mod:`urdsl.protocol` turn the bytes into
messages.
"""

from __future__ import annotations

import errno
import select
import socket
import time
from collections.abc import Callable

from .errors import ConnectError, ConnectionLost, RobotTimeout

__all__ = [
    "Connection", "DEFAULT_PORTS", "interface_of_port", "where", "MAX_DRAIN", "RECV_SIZE",
]

DEFAULT_PORTS = {
    "dashboard": 29999, "primary": 30001, "secondary": 30002, "realtime": 30003,
    "rtde": 30004, "primary_ro": 30011, "secondary_ro": 30012, "realtime_ro": 30013,
}
"""The controller's standard ports (docs/controller-facts.md §7)."""

_NAMES = {
    29999: "dashboard", 30001: "primary", 30002: "secondary", 30003: "realtime",
    30004: "RTDE", 30011: "primary, read-only", 30012: "secondary, read-only",
    30013: "realtime, read-only",
}

RECV_SIZE = 65536
"""Bytes asked of the kernel per ``recv`` call: 64 KiB holds 50 realtime packets (1220 B)."""

MAX_DRAIN = 16 * 1024 * 1024
"""Most bytes one :meth:`Connection.drain` takes: 27 s of the realtime interface at 500 Hz
(610 kB/s). A drain stops there so that a peer that sends faster than we can read cannot
keep us in the loop forever; the rest is taken by the next drain."""


def interface_of_port(port: int) -> str:
    """The interface a standard port belongs to (``"secondary"`` for 30002), or ``""``."""
    return _NAMES.get(port, "")


def where(host: str, port: int, interface: str = "") -> str:
    """``host:port (interface)`` for messages."""
    interface = interface or interface_of_port(port)
    return f"{host}:{port} ({interface})" if interface else f"{host}:{port}"


class Connection:
    """One TCP connection to a controller port (see the module docstring).

    Use :meth:`open` to connect; the object is a context manager that closes the socket.
    ``received`` counts the bytes read so far (for messages such as "closed after 12 kB").
    """

    def __init__(self, sock: socket.socket, host: str, port: int, interface: str = "") -> None:
        self.sock = sock
        self.host = host
        self.port = port
        self.interface = interface or interface_of_port(port)
        self.received = 0
        self.closed = False

    # -- connect ------------------------------------------------------------------------------

    @classmethod
    def open(cls, host: str, port: int, *, interface: str = "", timeout: float = 5.0,
             attempts: int = 1, backoff: float = 0.25, backoff_cap: float = 2.0,
             sleep: Callable[[float], None] = time.sleep) -> Connection:
        """Connect to ``host:port``.

        ``timeout`` (s) bounds each attempt; a refused or timed-out attempt is retried
        until ``attempts`` were made, waiting ``backoff`` s, then twice that, …, at most
        ``backoff_cap`` s between attempts. Raises :class:`ConnectError` naming the place
        and the likely cause.
        """
        if timeout <= 0:
            raise ValueError("timeout must be > 0 s")
        attempts = max(1, int(attempts))
        interface = interface or interface_of_port(port)
        delay = backoff
        last: ConnectError | None = None
        for attempt in range(attempts):
            if attempt:
                sleep(min(delay, backoff_cap))
                delay = min(delay * 2, backoff_cap)
            try:
                sock = socket.create_connection((host, port), timeout=timeout)
            except OSError as error:
                last = _connect_error(error, host, port, interface, timeout)
                if not _retryable(error):
                    break
                continue
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            return cls(sock, host, port, interface)
        assert last is not None
        if attempts > 1 and _retryable_message(last):
            last = ConnectError(f"{last.message} (tried {attempts} times)", host=host,
                                port=port, interface=interface)
        raise last

    def reopen(self, *, timeout: float = 5.0, attempts: int = 5, backoff: float = 0.25,
               backoff_cap: float = 2.0) -> Connection:
        """A new connection to the same place (after :class:`ConnectionLost`), with retries."""
        self.close()
        return Connection.open(self.host, self.port, interface=self.interface, timeout=timeout,
                               attempts=attempts, backoff=backoff, backoff_cap=backoff_cap)

    # -- read and write -----------------------------------------------------------------------

    @property
    def where(self) -> str:
        return where(self.host, self.port, self.interface)

    def send(self, data: bytes, timeout: float = 5.0) -> None:
        """Write all of ``data`` within ``timeout`` s."""
        self._check_open()
        self.sock.settimeout(timeout)
        try:
            self.sock.sendall(data)
        except TimeoutError:
            raise RobotTimeout(f"{self.where} did not take {len(data)} bytes within "
                               f"{timeout:g} s", **self._place()) from None
        except OSError as error:
            raise self._lost(error) from None

    def recv(self, timeout: float) -> bytes:
        """Some bytes (at least one), waiting at most ``timeout`` s. Raises
        :class:`RobotTimeout` when nothing came, :class:`ConnectionLost` when the
        controller closed the connection."""
        self._check_open()
        self.sock.settimeout(max(timeout, 0.0) or 1e-6)
        try:
            data = self.sock.recv(RECV_SIZE)
        except TimeoutError:
            raise RobotTimeout(f"{self.where} sent nothing for {timeout:g} s",
                               **self._place()) from None
        except OSError as error:
            raise self._lost(error) from None
        if not data:
            raise self._lost(None)
        self.received += len(data)
        return data

    def readable(self, timeout: float) -> bool:
        """Whether bytes (or the end of the stream) can be read within ``timeout`` s."""
        self._check_open()
        ready, _, _ = select.select([self.sock], [], [], max(timeout, 0.0))
        return bool(ready)

    def drain(self, limit: int = MAX_DRAIN) -> bytes:
        """Every byte the kernel holds for us right now (up to ``limit``), without waiting.

        Returns ``b""`` when nothing is buffered. Raises :class:`ConnectionLost` when the
        controller closed the connection and nothing was left to read; if it closed after
        sending, the bytes come first and the next call raises.
        """
        self._check_open()
        chunks: list[bytes] = []
        total = 0
        self.sock.settimeout(0.0)
        try:
            while total < limit:
                try:
                    data = self.sock.recv(min(RECV_SIZE, limit - total))
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as error:
                    if chunks:
                        break  # hand out what came; the next call reports the error
                    raise self._lost(error) from None
                if not data:
                    if chunks:
                        break
                    raise self._lost(None)
                chunks.append(data)
                total += len(data)
        finally:
            if not self.closed:
                self.sock.settimeout(None)
        self.received += total
        return b"".join(chunks)

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            try:
                self.sock.close()
            except OSError:
                pass

    def __enter__(self) -> Connection:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- helpers ------------------------------------------------------------------------------

    def _place(self) -> dict:
        return {"host": self.host, "port": self.port, "interface": self.interface}

    def _check_open(self) -> None:
        if self.closed:
            raise ConnectionLost(f"the connection to {self.where} is closed", **self._place())

    def _lost(self, error: OSError | None) -> ConnectionLost:
        if error is None:
            what = "closed the connection"
        elif error.errno in (errno.ECONNRESET, errno.EPIPE):
            what = "reset the connection"
        else:
            what = f"connection failed: {error.strerror or error}"
        return ConnectionLost(f"{self.where} {what} (after {_amount(self.received)} received)",
                              **self._place())


def _amount(count: int) -> str:
    if count < 10_000:
        return f"{count} bytes"
    return f"{count / 1000:.0f} kB"


def _retryable(error: OSError) -> bool:
    return isinstance(error, (ConnectionRefusedError, TimeoutError)) or error.errno in (
        errno.ECONNREFUSED, errno.ETIMEDOUT, errno.EHOSTUNREACH, errno.ENETUNREACH)


def _retryable_message(error: ConnectError) -> bool:
    return "refused" in error.message or "no answer" in error.message


def _connect_error(error: OSError, host: str, port: int, interface: str,
                   timeout: float) -> ConnectError:
    place = where(host, port, interface)
    if isinstance(error, socket.gaierror):
        text = f"unknown host {host!r}: {error.strerror}"
    elif isinstance(error, ConnectionRefusedError) or error.errno == errno.ECONNREFUSED:
        text = (f"connection refused by {place}: is the controller (or `urdsl sim`) running, "
                f"and is {port} the right port?")
    elif isinstance(error, TimeoutError) or error.errno == errno.ETIMEDOUT:
        text = (f"no answer from {place} within {timeout:g} s: is the robot on, and on the "
                "same network as this computer?")
    elif error.errno in (errno.EHOSTUNREACH, errno.ENETUNREACH):
        text = f"cannot reach {place}: {error.strerror} (check the IP address and the cable)"
    else:
        text = f"cannot connect to {place}: {error.strerror or error}"
    return ConnectError(text, host=host, port=port, interface=interface)
