"""Sending a program to the controller, and following it until it finishes or fails.

The course sends a script with a raw socket and hears nothing back: a program with a typo
fails silently. :func:`send_program` does it properly:

1. **check** the program offline (the verifier; refused on errors unless ``check=False``);
2. **print** it with the one printer, wrapped into ``def urdsl_program():`` … ``end`` when it
   is bare statements (:mod:`urdsl.robot.program`);
3. connect to the **primary interface** (30001) first, so that no message is missed — only
   the primary interface carries robot messages such as runtime exceptions;
4. **send** the text on the port asked for (30001, 30002 or 30003);
5. **follow** it: the program counts as *started* when the robot state says a program runs
   (or a key message, or its own text output, says so), as *finished* when it stops again,
   and as *failed* when the controller reports a runtime exception (its line and column are
   mapped back to the user's file, through the wrapping) or a protective stop ends it.

Waiting is bounded by ``timeout``: a program still running then is reported as
``"timeout"`` (it goes on on the robot; urdsl only stops watching).

Three entry points: :func:`send` (check, send, follow — what ``urdsl send`` and
``Robot.send`` do), :func:`send_program` (send the text and return; check and follow on
request) and :func:`run_program` (send and follow).
"""

from __future__ import annotations

import re
import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..protocol import primary as p
from ..protocol.errors import ProtocolError
from ..script import nodes as n
from .connection import Connection, interface_of_port, where
from .errors import CheckFailedError, ConnectionLost, ControllerProtocolError, RobotTimeout
from .primary_state import PrimaryStream
from .program import Location, PreparedProgram, prepare_text, prepare_tree

__all__ = [
    "send_program", "send", "send_prepared", "SendResult", "ControllerError", "Checker",
    "default_checker", "monitor_port_for", "START_WINDOW", "END_GRACE", "run_program",
]

START_WINDOW = 2.0
"""Seconds to wait for a sign that the program started (the controller starts a received
program within milliseconds; the state that shows it comes at 10 Hz)."""

END_GRACE = 0.3
"""Seconds to keep listening after the state says the program stopped: a runtime exception
message may come just after the state message that shows the stop."""

SCRIPT_PORTS = (30001, 30002, 30003)
"""Ports that take URScript (docs/controller-facts.md §7)."""

READ_BEFORE_CLOSE = 79
"""Bytes to read on a separate sending connection before closing it: UR's manual says a
script sent on a socket closed at once may be discarded, and to read at least 79 bytes."""

START_RATE = 50_000
"""Bytes of program per second a controller is assumed to take in and compile at least:
the wait for a sign of the start (:data:`START_WINDOW`) grows by one second per this many
bytes (``urdsl sim`` takes 1.5 s for a 100,000-line program of 1.2 MB on an idle core, 6 s
on a loaded one; a real controller is not faster). The wait ends at once when the start
shows, and never outlasts the send's ``timeout``."""

SEND_RATE = 1_000_000
"""Bytes per second a link to the controller is assumed to carry at least: the bound on the
wait for the controller to take a whole program before the sending connection closes."""

ACK_GRACE = 0.5
"""Seconds to keep a sending connection open after the controller acknowledged every byte
(where the system tells, Linux), for it to read them and close first."""

Checker = Callable[[n.Module, str, str], Any]
"""``checker(tree, filename, robot) -> report`` with ``report.has_errors`` and
``report.render_text()`` (the verifier's :class:`urdsl.verify.report.Report`)."""


def default_checker(tree: n.Module, filename: str, robot: str) -> Any:
    """The offline verifier (:func:`urdsl.verify.run.check_tree`) for ``robot``."""
    from ..verify.run import CheckOptions, check_tree

    return check_tree(tree, filename, CheckOptions(robot=robot))


def monitor_port_for(port: int) -> int:
    """The primary port that reports on a program sent to ``port``: 30001 for the standard
    script ports; the same port otherwise (a test server or a simulator with moved ports
    passes ``monitor_port`` explicitly)."""
    return 30001 if port in SCRIPT_PORTS else port


@dataclass(frozen=True)
class ControllerError:
    """Why the controller stopped the program: its message ``text``, where it says the
    error is in the text it received (``line``, ``column``, 1-based; 0 when it gave none)
    and where that is in the user's file (``location``; ``None`` for lines urdsl added)."""

    kind: str  # "runtime exception", "protective stop", "safety", "error"
    text: str
    line: int = 0
    column: int = 0
    location: Location | None = None
    sent_line: str | None = None

    def render(self) -> str:
        """``file:line:col: error: text``, the user's line and a caret — or, for lines that
        are not the user's, the line as sent."""
        head = f"{self.text} ({self.kind} on the controller)"
        if self.location is not None:
            location = self.location
            lines = [f"{location}: error: {head}"]
            if location.source_line is not None:
                lines.append("  " + location.source_line.expandtabs(1))
                lines.append("  " + " " * max(location.column - 1, 0) + "^")
            return "\n".join(lines)
        if self.line:
            lines = [f"<sent program>:{self.line}:{self.column}: error: {head}"]
            if self.sent_line is not None:
                lines.append("  " + self.sent_line)
            return "\n".join(lines)
        return f"error: {head}"


@dataclass
class SendResult:
    """What happened to a sent program.

    ``status``: ``"sent"`` (not followed), ``"finished"`` (ran and stopped without an
    error), ``"failed"`` (``error`` says why), ``"timeout"`` (still running when the wait
    ended), ``"not observed"`` (followed, but no sign of a start was seen: a program that
    runs in under 0.1 s leaves none in the 10 Hz state). ``duration`` (s) from the start
    seen to the end seen; ``messages`` are the texts the program printed (``textmsg``) and
    other controller texts, in order.
    """

    host: str
    port: int
    program: str
    bytes_sent: int
    status: str = "sent"
    started: bool = False
    duration: float | None = None
    error: ControllerError | None = None
    messages: list[str] = field(default_factory=list)
    controller_version: str | None = None
    prepared: PreparedProgram | None = field(default=None, repr=False)
    report: Any = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """False only when the controller reported a failure."""
        return self.status != "failed"

    def summary(self) -> str:
        """One line for people: what happened, with the duration when known."""
        place = where(self.host, self.port)
        if self.status == "finished":
            took = f" after {self.duration:.2f} s" if self.duration is not None else ""
            return f"{self.program}: finished{took} on {place}"
        if self.status == "failed":
            return f"{self.program}: failed on {place}"
        if self.status == "timeout":
            return (f"{self.program}: still running on {place} when urdsl stopped waiting "
                    "(it goes on; use --timeout to wait longer)")
        if self.status == "not observed":
            return f"{self.program}: sent to {place}; no start was seen"
        return f"{self.program}: sent to {place} ({self.bytes_sent} bytes)"


class _Follower:
    """Reads the primary interface and decides started / finished / failed."""

    def __init__(self, connection: Connection, prepared: PreparedProgram,
                 result: SendResult, report: Callable[[str, str], None] | None) -> None:
        self.report = report or (lambda kind, text: None)
        self.connection = connection
        self.prepared = prepared
        self.result = result
        self.stream = PrimaryStream()
        self.start_time: float | None = None
        self.stop_time: float | None = None
        self.safety: ControllerError | None = None

    def feed(self, data: bytes) -> list:
        try:
            states, messages = self.stream.feed(data)
        except ProtocolError as error:
            raise ControllerProtocolError(
                f"{self.connection.where} sent bytes that are not the primary protocol: "
                f"{error}", host=self.connection.host, port=self.connection.port,
                interface="primary") from None
        self.result.controller_version = self.stream.version
        return messages

    def wait_ready(self, timeout: float) -> None:
        """Read until the first robot state arrived (so the state before sending is known)."""
        deadline = time.monotonic() + timeout
        while self.stream.states == 0:
            left = deadline - time.monotonic()
            if left <= 0:
                raise RobotTimeout(f"{self.connection.where} sent no robot state within "
                                   f"{timeout:g} s: is this the primary interface?",
                                   host=self.connection.host, port=self.connection.port,
                                   interface="primary")
            try:
                self.feed(self.connection.recv(left))
            except RobotTimeout:
                continue

    def _started(self, now: float) -> None:
        if not self.result.started:
            self.result.started = True
            self.start_time = now
            self.report("started", f"{self.result.program}: started")

    def _message(self, text: str) -> None:
        self.result.messages.append(text)
        self.report("message", text)

    def handle(self, messages: list, now: float) -> None:
        result = self.result
        for message in messages:
            if isinstance(message, p.RuntimeExceptionMessage):
                location = self.prepared.locate(message.line, message.column)
                result.error = ControllerError(
                    "runtime exception", _clean(message.text), message.line, message.column,
                    location, self.prepared.sent_line(message.line) if message.line else None)
            elif isinstance(message, p.KeyMessage):
                title = message.title.upper()
                if "PROGRAM" in title and "STARTED" in title:
                    self._started(now)
                elif "PROGRAM" in title and "STOPPED" in title and result.started:
                    self.stop_time = self.stop_time or now
                self._message(f"{message.title} {message.text}".strip())
            elif isinstance(message, p.SafetyModeMessage):
                if message.safety_mode_type not in (0, 1, 2):  # not NORMAL or REDUCED
                    from .state import SAFETY_MODES

                    name = SAFETY_MODES.get(message.safety_mode_type,
                                            f"safety mode {message.safety_mode_type}")
                    self.safety = ControllerError(
                        "protective stop" if message.safety_mode_type == 3 else "safety",
                        f"{name} (C{message.code}A{message.argument})")
            elif isinstance(message, (p.TextMessage, p.PopupMessage)):
                self._started(now)  # the program's own output (textmsg, popup)
                text = message.text if isinstance(message, p.TextMessage) else \
                    f"popup: {message.title} {message.text}".strip()
                self._message(text)
            elif isinstance(message, p.ErrorCodeMessage) and message.report_level >= 3:
                self.safety = self.safety or ControllerError(
                    "error", f"{message.text} (C{message.code}A{message.argument})".strip())
                self._message(message.text)

    def follow(self, timeout: float, start_timeout: float = START_WINDOW) -> None:
        """Read until the program ended or failed, or ``timeout`` s passed."""
        result = self.result
        begin = time.monotonic()
        deadline = begin + timeout
        states_seen = self.stream.states
        while result.error is None:
            now = time.monotonic()
            left = deadline - now
            if self.stop_time is not None:
                left = min(left, self.stop_time + END_GRACE - now)
            elif not result.started:
                left = min(left, begin + min(start_timeout, timeout) - now)
            if left <= 0:
                break
            try:
                data = self.connection.recv(left)
            except RobotTimeout:
                continue
            messages = self.feed(data)
            now = time.monotonic()
            self.handle(messages, now)
            if self.stream.states > states_seen:
                states_seen = self.stream.states
                running = self.stream.program_running
                if running:
                    self._started(now)
                elif running is False and result.started and self.stop_time is None:
                    self.stop_time = now
        if result.error is not None:
            result.status = "failed"
        elif self.stop_time is not None:
            if self.safety is not None:
                result.error = self.safety
                result.status = "failed"
            else:
                result.status = "finished"
        elif result.started:
            result.status = "timeout"
        else:
            result.status = "not observed"
        if result.started and self.start_time is not None:
            end = self.stop_time if self.stop_time is not None else time.monotonic()
            result.duration = max(end - self.start_time, 0.0)


def _clean(text: str) -> str:
    """The controller's exception text without a leading ``<origin>:line:col:`` of its own
    (urdsl sim prefixes one; the mapped place replaces it)."""
    return re.sub(r"^<[^>\n]*>:\d+:\d+:\s*", "", text.strip())


def send_prepared(prepared: PreparedProgram, host: str, port: int = 30002, *,
                  timeout: float = 5.0, follow: bool = True, monitor_port: int | None = None,
                  connect_timeout: float = 5.0, start_timeout: float | None = None,
                  report: Callable[[str, str], None] | None = None) -> SendResult:
    """Send an already prepared (and checked) program; follow it unless ``follow=False``.

    ``timeout`` (s) bounds the wait for the program to finish; ``connect_timeout`` (s) each
    connect and the wait for the first robot state. ``monitor_port`` is the primary port to
    follow on (default :func:`monitor_port_for`); ``start_timeout`` (s, default
    :data:`START_WINDOW`) how long to wait for a sign of the start. ``report(kind, text)``
    is told as things happen: ``"sent"``, ``"started"``, ``"message"`` (a text from the controller).
    """
    data = prepared.text.encode("utf-8")
    result = SendResult(host, port, prepared.name, len(data), prepared=prepared)
    monitor: Connection | None = None
    sender: Connection | None = None
    try:
        if follow:
            mport = monitor_port_for(port) if monitor_port is None else monitor_port
            monitor = Connection.open(host, mport, interface="primary" if mport != port
                                      else interface_of_port(port) or "primary",
                                      timeout=connect_timeout)
            follower = _Follower(monitor, prepared, result, report)
            follower.wait_ready(connect_timeout)
            sender = monitor if mport == port else Connection.open(
                host, port, timeout=connect_timeout)
        else:
            sender = Connection.open(host, port, timeout=connect_timeout)
        sender.send(data, connect_timeout)
        if report is not None:
            report("sent", f"sent {result.program!r} ({prepared.text.count(chr(10))} lines, "
                   f"{len(data)} bytes) to {sender.where}")
        if sender is not monitor:
            _finish_sending(sender, len(data), connect_timeout)
            sender.close()
        if follow:
            try:
                follower.follow(timeout, START_WINDOW + len(data) / START_RATE
                                if start_timeout is None else start_timeout)
            except ConnectionLost as error:
                raise ConnectionLost(f"the program was sent, but {error.message} while urdsl "
                                     "followed it", host=error.host, port=error.port,
                                     interface=error.interface) from None
    finally:
        if sender is not None:
            sender.close()
        if monitor is not None:
            monitor.close()
    return result


def _finish_sending(connection: Connection, size: int, timeout: float) -> None:
    """End a connection that only sent a program (``size`` bytes) without losing any of it.

    Closing a socket while bytes it received are unread makes the kernel reset the
    connection: what is still queued for sending is thrown away, and the controller sees
    a reset instead of the program's end (a 100,000-line program then never ran). So: mark
    the end of the stream (half-close: the controller reads every byte, then the end), keep
    reading and discarding what the controller sends (its version message and states, at
    least :data:`READ_BEFORE_CLOSE` bytes as UR asks), and close only once the controller
    closed its side, or every byte was acknowledged :data:`ACK_GRACE` s ago, or after
    ``timeout`` s plus the time :data:`SEND_RATE` allows for ``size`` bytes."""
    sock = connection.sock
    try:
        sock.shutdown(socket.SHUT_WR)
    except OSError:
        return  # the connection is gone already
    deadline = time.monotonic() + timeout + size / SEND_RATE
    got = 0
    acknowledged_at: float | None = None
    while True:
        now = time.monotonic()
        if now >= deadline:
            return
        if got >= READ_BEFORE_CLOSE and _unacknowledged(sock) == 0:
            acknowledged_at = acknowledged_at or now
            if now - acknowledged_at >= ACK_GRACE:
                return
        try:
            got += len(connection.recv(min(deadline - now, 0.05)))
        except RobotTimeout:
            continue
        except ConnectionLost:
            return  # the controller closed its side: it has read everything


def _unacknowledged(sock: socket.socket) -> int | None:
    """Bytes sent on ``sock`` that the peer has not acknowledged yet (Linux: TIOCOUTQ), or
    None where the system does not tell."""
    try:
        import fcntl
        import termios

        buffer = fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0\0\0\0")
    except (ImportError, AttributeError, OSError):
        return None
    return int.from_bytes(buffer, sys.byteorder, signed=True)


def _checked(tree: n.Module, filename: str, check: bool, robot: str,
             checker: Checker | None) -> Any:
    if not check:
        return None
    report = (checker or default_checker)(tree, filename, robot)
    if report.has_errors:
        raise CheckFailedError(report, filename)
    return report


def send(program: Any, host: str, port: int = 30002, *, timeout: float = 5.0,
         filename: str | None = None, check: bool = True, robot: str = "ur5e",
         checker: Checker | None = None, follow: bool = True,
         monitor_port: int | None = None, connect_timeout: float = 5.0,
         start_timeout: float | None = None) -> SendResult:
    """Check, send and follow ``program``: URScript text, a parsed
    :class:`urdsl.script.nodes.Module`, or a DSL :class:`urdsl.dsl.Program` (whose
    statements keep the lines of the Python file that built them, so controller errors
    point there).

    Raises :class:`CheckFailedError` (nothing sent) when the check finds errors,
    :class:`urdsl.script.diagnostics.ScriptSyntaxError` for text that is not URScript, and
    the :mod:`urdsl.robot.errors` for network failures. See :func:`send_prepared` for the
    other parameters.
    """
    if isinstance(program, str):
        name = filename or "<program>"
        prepared = prepare_text(program, name)
    elif isinstance(program, n.Module):
        name = filename or "<program>"
        prepared = prepare_tree(program, name)
    elif hasattr(program, "tree") and callable(program.tree):
        name = filename or f"<program {getattr(program, 'name', '')}>"
        prepared = prepare_tree(program.tree(), name)
    else:
        raise TypeError(f"cannot send a {type(program).__name__}: give URScript text, a "
                        "syntax tree or a urdsl.dsl.Program")
    report = _checked(prepared.tree, name, check, robot, checker)
    result = send_prepared(prepared, host, port, timeout=timeout, follow=follow,
                           monitor_port=monitor_port, connect_timeout=connect_timeout,
                           start_timeout=start_timeout)
    result.report = report
    return result


def send_program(text: str, host: str, port: int = 30002, *, timeout: float = 5.0,
                 filename: str = "<program>", check: bool = False, robot: str = "ur5e",
                 checker: Checker | None = None, follow: bool = False,
                 monitor_port: int | None = None) -> SendResult:
    """Send the URScript ``text`` (printed, wrapped if bare statements) and return
    (``status == "sent"``); ``timeout`` (s) bounds the connect and the write.

    ``check=True`` checks it first (raises :class:`CheckFailedError`, nothing sent);
    ``follow=True`` follows it as :func:`run_program` does, ``timeout`` then bounding the
    wait for its end.

    >>> send_program(program.script(), "127.0.0.1").status      # doctest: +SKIP
    'sent'
    """
    return send(text, host, port, timeout=timeout, filename=filename, check=check,
                robot=robot, checker=checker, follow=follow, monitor_port=monitor_port,
                connect_timeout=timeout)


def run_program(text: str, host: str, port: int = 30002, *, timeout: float = 60.0,
                primary_port: int = 30001, start_timeout: float = START_WINDOW,
                filename: str = "<program>", check: bool = False, robot: str = "ur5e",
                checker: Checker | None = None, connect_timeout: float = 5.0) -> SendResult:
    """Send ``text`` and follow it on ``primary_port`` until it finished or failed, at most
    ``timeout`` s (``start_timeout`` s for a sign that it started). A runtime exception's
    place is mapped to ``filename``'s lines (``result.error.location``).

    >>> run_program(program.script(), "127.0.0.1").status       # doctest: +SKIP
    'finished'
    """
    return send(text, host, port, timeout=timeout, filename=filename, check=check,
                robot=robot, checker=checker, follow=True, monitor_port=primary_port,
                connect_timeout=connect_timeout, start_timeout=start_timeout)
