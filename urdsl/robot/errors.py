"""The exceptions of the socket layer.

Every message names the interface and ``host:port`` and says what happened in words a user
can act on ("connection refused by 127.0.0.1:30002 (secondary): is the controller (or
`urdsl sim`) running, and is that the right port?"). The CLI prints the message and exits 1;
it never shows a traceback for them.
"""

from __future__ import annotations

__all__ = [
    "RobotError", "ConnectError", "ConnectionLost", "RobotTimeout", "ControllerProtocolError",
    "CheckFailedError",
]


class RobotError(Exception):
    """Base of every socket-layer error: something between urdsl and the controller failed.

    ``host``, ``port`` and ``interface`` (``"primary"``, ``"rtde"``, …) say where.
    """

    def __init__(self, message: str, *, host: str = "", port: int = 0,
                 interface: str = "") -> None:
        super().__init__(message)
        self.message = message
        self.host = host
        self.port = port
        self.interface = interface


class ConnectError(RobotError):
    """No connection could be made: refused, unreachable, or no answer within the timeout."""


class ConnectionLost(RobotError):
    """The controller closed or reset a connection that was working (mid-stream)."""


class RobotTimeout(RobotError):
    """The controller sent nothing (or not what was awaited) within the time allowed."""


class ControllerProtocolError(RobotError):
    """The controller sent bytes that do not follow the protocol (a
    :class:`urdsl.protocol.ProtocolError` with the place it came from)."""


class CheckFailedError(Exception):
    """The offline check found errors, so the program was not sent. ``report`` is the
    verifier's report (``report.render_text()`` shows the findings)."""

    def __init__(self, report, filename: str) -> None:
        super().__init__(f"{filename}: the check found errors; nothing was sent "
                         "(use --no-check to send anyway)")
        self.report = report
        self.filename = filename
