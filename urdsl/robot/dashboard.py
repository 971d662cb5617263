"""A dashboard server client (port 29999): one command, one reply line."""

from __future__ import annotations

from ..protocol.dashboard import GREETING, LineDecoder, Reply, encode_command, interpret
from .connection import Deadline, RobotConnectionError, connect, read_until

__all__ = ["DashboardClient"]


class DashboardClient:
    """``with DashboardClient(host) as dash: dash.command("robotmode").value``."""

    def __init__(self, host: str, port: int = 29999, timeout: float = 5.0) -> None:
        self.host, self.port, self.timeout = host, port, timeout
        self._sock = connect(host, port, timeout)
        self._lines = LineDecoder()
        greeting = self._line("the greeting")
        if not greeting.startswith(GREETING.split(":")[0]):
            self.close()
            raise RobotConnectionError(f"{host}:{port}: not a dashboard server (it said "
                                       f"{greeting[:60]!r})")

    def _line(self, what: str) -> str:
        deadline = Deadline(self.timeout)
        pending: list[str] = []
        while not pending:
            pending = self._lines.feed(read_until(self._sock, deadline, what, self.host,
                                                  self.port))
        self._queued = pending[1:]
        return pending[0]

    def command(self, text: str) -> Reply:
        self._sock.sendall(encode_command(text))
        return interpret(text, self._line(f"the reply to {text!r}"))

    def close(self) -> None:
        self._sock.close()

    def __enter__(self) -> DashboardClient:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
