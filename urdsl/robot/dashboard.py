"""Dashboard server client (port 29999): load, play, stop, robot mode, power, brakes, …

The line protocol, the documented replies and their meaning live in
:mod:`urdsl.protocol.dashboard`; this module adds the socket: connect, consume the welcome
line, send one command at a time and wait (bounded) for its reply.

>>> with Dashboard("127.0.0.1") as dashboard:          # doctest: +SKIP
...     dashboard.command("robotmode").value
'RUNNING'
"""

from __future__ import annotations

import time

from ..protocol.dashboard import (
    COMMANDS,
    PORT,
    DashboardClient,
    DashboardReply,
    DashboardWelcome,
    decode_command,
)
from ..protocol.errors import ProtocolError
from .connection import Connection
from .errors import ControllerProtocolError, RobotTimeout

__all__ = ["Dashboard", "PORT", "parse_command_words", "wait_for_mode"]

LOAD_TIMEOUT = 30.0
"""Seconds a ``load`` may take: from 3.3 on the server answers when the program is loaded,
which takes seconds for a large program."""


def parse_command_words(words: list[str] | str) -> tuple[str, str | None]:
    """``["load", "pick.urp"]`` → ``("load", "pick.urp")``; ``"power on"`` → ``("power on",
    None)``. Raises ``ValueError`` for an unknown command, with the closest known one."""
    line = words if isinstance(words, str) else " ".join(words)
    line = line.strip()
    command = decode_command(line)
    if not command.known:
        close = sorted(n for n in COMMANDS if n.lower() == line.lower()
                       or n.lower().startswith(line.lower().split(" ")[0]))
        hint = f"; did you mean {' or '.join(repr(c) for c in close[:3])}?" if close else ""
        raise ValueError(f"unknown dashboard command {line!r}{hint}")
    spec = COMMANDS[command.name]
    if spec.argument is not None and not command.argument:
        raise ValueError(f"{command.name!r} needs an argument: {command.name} "
                         f"<{spec.argument}>")
    return command.name, command.argument


class Dashboard:
    """A connection to the dashboard server. ``timeout`` (s) bounds the connect, the welcome
    line and each reply (``load`` gets at least :data:`LOAD_TIMEOUT`)."""

    def __init__(self, host: str, port: int = PORT, *, timeout: float = 5.0,
                 attempts: int = 1) -> None:
        self.host = host
        self.port = port
        self.timeout = timeout
        self.connection = Connection.open(host, port, interface="dashboard", timeout=timeout,
                                          attempts=attempts)
        self._client = DashboardClient()
        self.welcome = ""
        try:
            events = self._events(timeout, "the welcome line")
            welcome = events[0]
            assert isinstance(welcome, DashboardWelcome)
            self.welcome = welcome.text
        except BaseException:
            self.connection.close()
            raise

    def _events(self, timeout: float, awaiting: str) -> list:
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise RobotTimeout(f"{self.connection.where} sent no {awaiting} within "
                                   f"{timeout:g} s", host=self.host, port=self.port,
                                   interface="dashboard")
            try:
                data = self.connection.recv(left)
            except RobotTimeout:
                continue
            try:
                events = self._client.receive_data(data)
            except ProtocolError as error:
                raise ControllerProtocolError(f"{self.connection.where}: {error}",
                                              host=self.host, port=self.port,
                                              interface="dashboard") from None
            if events:
                return events

    def command(self, name: str, argument: str | None = None,
                timeout: float | None = None) -> DashboardReply:
        """Send one command (a key of :data:`urdsl.protocol.dashboard.COMMANDS`) and return
        the server's reply; ``reply.ok`` tells whether it is a documented success."""
        timeout = self.timeout if timeout is None else timeout
        if name == "load":
            timeout = max(timeout, LOAD_TIMEOUT)
        try:
            data = self._client.send(name, argument)
        except ProtocolError as error:
            raise ValueError(str(error)) from None
        self.connection.send(data, timeout)
        reply = self._events(timeout, f"reply to {name!r}")[0]
        assert isinstance(reply, DashboardReply)
        return reply

    def run(self, line: str, timeout: float | None = None) -> DashboardReply:
        """A command given as its text, e.g. ``run("load pick.urp")``."""
        name, argument = parse_command_words(line)
        return self.command(name, argument, timeout)

    def close(self) -> None:
        self.connection.close()

    def __enter__(self) -> Dashboard:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def wait_for_mode(dashboard: Dashboard, modes: set[str], timeout: float,
                  poll: float = 0.25) -> str:
    """Ask ``robotmode`` every ``poll`` s until it is one of ``modes``; return it. Raises
    :class:`RobotTimeout` with the last mode seen after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    mode = "?"
    while True:
        reply = dashboard.command("robotmode")
        mode = str(reply.value) if reply.ok else reply.text
        if mode in modes:
            return mode
        if time.monotonic() + poll > deadline:
            raise RobotTimeout(f"{dashboard.connection.where}: robot mode is still {mode} after "
                               f"{timeout:g} s (waited for {' or '.join(sorted(modes))})",
                               host=dashboard.host, port=dashboard.port, interface="dashboard")
        time.sleep(poll)
