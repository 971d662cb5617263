"""Sending URScript programs, and following what the controller does with them.

:func:`send_program` writes the text to a script port (30001–30003) and returns; the
controller runs a ``def … end`` program at once, replacing what runs. :func:`run_program`
also listens on the primary interface (30001) — connected *before* the program is sent, so
that nothing is missed — and reports whether the program started, finished or failed, with
the controller's runtime exception (line and column in the text as sent).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..protocol.primary import (
    PrimaryDecoder,
    RobotModeData,
    RobotState,
    RuntimeExceptionMessage,
    TextMessage,
)
from .connection import Deadline, RobotConnectionError, connect, read_until

__all__ = ["send_program", "run_program", "SendResult"]

SCRIPT_PORTS = (30001, 30002, 30003)


@dataclass
class SendResult:
    """What happened to a sent program. ``status``: ``"sent"`` (not followed), ``"finished"``,
    ``"failed"`` (``error`` holds the runtime exception), ``"timeout"`` (still running when
    the wait ended), ``"not started"``. ``messages``: the controller's text messages."""

    status: str
    error: RuntimeExceptionMessage | None = None
    # "not observed": no error, but never seen running (done within one 100 ms state period)
    messages: list[str] = field(default_factory=list)
    started: bool = False


def _payload(text: str) -> bytes:
    if not text.endswith("\n"):
        text += "\n"
    return text.encode("utf-8")


def send_program(text: str, host: str, port: int = 30002, *, timeout: float = 5.0
                 ) -> SendResult:
    """Send URScript ``text`` (newline-terminated) to ``host:port``; do not wait for it."""
    sock = connect(host, port, timeout)
    try:
        sock.sendall(_payload(text))
    except OSError as error:
        raise RobotConnectionError(f"{host}:{port}: sending failed: {error}") from None
    finally:
        sock.close()
    return SendResult("sent")


def run_program(text: str, host: str, port: int = 30002, *, timeout: float = 60.0,
                primary_port: int = 30001, start_timeout: float = 5.0) -> SendResult:
    """Send ``text`` and follow the primary interface until the program finishes or fails,
    at most ``timeout`` s (``start_timeout`` s for it to start)."""
    watch = connect(host, primary_port, min(timeout, 5.0))
    try:
        decoder = PrimaryDecoder()
        first = Deadline(min(timeout, 5.0))  # the controller sends its state at 10 Hz
        while not any(isinstance(m, RobotState) for m in decoder.feed(
                read_until(watch, first, "the robot state", host, primary_port))):
            pass
        send_program(text, host, port, timeout=min(timeout, 5.0))
        result = SendResult("not observed")
        deadline = Deadline(timeout)
        start_by = Deadline(min(start_timeout, timeout))
        while not deadline.passed:
            data = read_until(watch, deadline, "the program to finish", host, primary_port)
            for message in decoder.feed(data):
                if isinstance(message, RuntimeExceptionMessage):
                    result.status, result.error = "failed", message
                    return result
                if isinstance(message, TextMessage):
                    result.messages.append(message.text)
                elif isinstance(message, RobotState):
                    mode = message.get(RobotModeData)
                    if mode is not None and mode.program_running:
                        result.started = True
                    elif mode is not None and result.started:
                        result.status = "finished"
                        return result
            if not result.started and start_by.passed:
                return result  # never seen running: finished within one state period, or
                # the controller did not take it (a real one says why in a message)
        result.status = "timeout" if result.started else "not observed"
        return result
    except RobotConnectionError as error:
        if "timed out waiting for the program" in str(error):
            return SendResult("timeout", started=True)
        raise
    finally:
        watch.close()
