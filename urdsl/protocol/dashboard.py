"""The dashboard server's line protocol (port 29999): one command per line, one reply line.

The server greets with ``Connected: Universal Robots Dashboard Server``; replies are matched
by prefix (UR_FACTS.md §6), never by whole-line equality, as their details vary by version.
:func:`interpret` turns a reply to a known command into ``(ok, value)``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import ProtocolError

__all__ = ["GREETING", "encode_command", "LineDecoder", "Reply", "interpret", "MAX_LINE"]

GREETING = "Connected: Universal Robots Dashboard Server"

MAX_LINE = 4096
"""Longest reply line accepted (bytes): replies are short status lines; a longer line means
the peer is not a dashboard server."""

# command -> (success prefixes, value after the prefix is the answer)
_REPLIES: dict[str, tuple[tuple[str, ...], bool]] = {
    "power on": (("Powering on",), False),
    "power off": (("Powering off",), False),
    "brake release": (("Brake releasing",), False),
    "play": (("Starting program",), False),
    "stop": (("Stopped",), False),
    "pause": (("Pausing program",), False),
    "quit": (("Disconnected",), False),
    "shutdown": (("Shutting down",), False),
    "running": (("Program running: ",), True),
    "robotmode": (("Robotmode: ",), True),
    "safetymode": (("Safetymode: ",), True),
    "safetystatus": (("Safetystatus: ",), True),
    "programstate": (("STOPPED", "PLAYING", "PAUSED"), False),
    "get loaded program": (("Loaded program: ",), True),
    "is in remote control": (("true", "false"), False),
    "unlock protective stop": (("Protective stop releasing",), False),
    "close safety popup": (("closing safety popup",), False),
    "polyscopeversion": (("URSoftware",), False),
    "load": (("Loading program: ",), True),
}


def encode_command(command: str) -> bytes:
    """One command line. Commands are single lines of text."""
    if "\n" in command or "\r" in command:
        raise ProtocolError("a dashboard command is one line")
    return (command.strip() + "\n").encode("utf-8")


@dataclass(frozen=True)
class Reply:
    """A reply to ``command``: ``ok`` when it is the documented success reply, ``value`` the
    answer it carries (``"RUNNING"`` for ``robotmode``), ``text`` the whole line."""

    command: str
    text: str
    ok: bool
    value: str | None


def interpret(command: str, line: str) -> Reply:
    """Match ``line`` against the documented replies to ``command``."""
    key = command.strip().lower()
    word = "load" if key.startswith("load ") and not key.startswith("load installation") \
        else key
    expected = _REPLIES.get(word)
    if expected is None:  # commands without a documented reply table: any non-error line
        failed = line.startswith(("could not understand", "Failed to execute", "Error"))
        return Reply(command, line, not failed, line)
    prefixes, has_value = expected
    for prefix in prefixes:
        if line.startswith(prefix):
            value = line[len(prefix):].strip() if has_value else line.strip()
            return Reply(command, line, True, value)
    return Reply(command, line, False, None)


class LineDecoder:
    """Lines from a byte stream (``\\n``-terminated, a trailing ``\\r`` dropped)."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[str]:
        self._buffer += data
        lines = []
        while True:
            end = self._buffer.find(b"\n")
            if end < 0:
                if len(self._buffer) > MAX_LINE:
                    self._buffer = bytearray()
                    raise ProtocolError(f"a dashboard reply longer than {MAX_LINE} bytes")
                return lines
            line = bytes(self._buffer[:end]).rstrip(b"\r")
            del self._buffer[:end + 1]
            lines.append(line.decode("utf-8", errors="replace"))
