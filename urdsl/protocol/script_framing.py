"""The controller's side of script text on ports 30001-30003: cutting it into programs.

The controller's rules (docs/controller-facts.md §7): a program starts with ``def name():`` or
``sec name():`` in column 0 and ends with ``end`` in column 0; lines outside such a block
("bare lines") run as a one-off program. Text arrives in arbitrary TCP chunks, so a block is
buffered until its ``end`` line, and bare lines are handed over one complete line at a time,
grouped per chunk (the lines of one ``send`` run together). No sockets: the virtual
controller and the test fakes feed it what they receive.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .errors import ProtocolError

__all__ = ["ScriptFramer", "ScriptChunk", "MAX_SCRIPT_BYTES"]

MAX_SCRIPT_BYTES = 64 * 1024 * 1024
"""Largest program accepted on one connection (bytes). A 100,000-line program is ~3 MB; the
limit only keeps a client that never sends ``end`` from exhausting memory."""

_OPEN = re.compile(r"^(def|sec)\s+[A-Za-z_][A-Za-z0-9_]*\s*\(")
_END = re.compile(r"^end\s*(#.*)?$")


@dataclass(frozen=True)
class ScriptChunk:
    """One program cut from the stream: ``kind`` is ``"def"``, ``"sec"`` or ``"bare"``."""

    kind: str
    text: str


class ScriptFramer:
    """Feed bytes with :meth:`feed`; it returns the complete programs in them, in order.

    Raises :class:`ProtocolError` (of ``interface``: the port's, ``"primary"`` by default)
    when a line or a block grows past ``limit`` bytes (:data:`MAX_SCRIPT_BYTES`); the stream
    cannot be trusted after that, the connection should be closed.
    """

    def __init__(self, limit: int = MAX_SCRIPT_BYTES, interface: str = "primary") -> None:
        self.limit = limit
        self.interface = interface
        self._partial: list[bytes] = []  # the pieces of a line without its newline yet
        self._partial_size = 0
        self._block: list[str] | None = None
        self._block_kind = ""
        self._block_size = 0

    def feed(self, data: bytes) -> list[ScriptChunk]:
        """The programs ``data`` completes (any TCP chunk: part of a line, many lines)."""
        if b"\n" not in data:  # a piece of a line: kept without copying what came before
            self._partial_size += len(data)
            self._partial.append(bytes(data))
            if self._partial_size > self.limit:
                raise ProtocolError(f"a line longer than {self.limit} bytes",
                                    interface=self.interface)
            return []
        self._partial.append(bytes(data))
        lines = b"".join(self._partial).split(b"\n")
        last = lines.pop()
        self._partial = [last] if last else []
        self._partial_size = len(last)
        if self._partial_size > self.limit:
            raise ProtocolError(f"a line longer than {self.limit} bytes",
                                interface=self.interface)
        out: list[ScriptChunk] = []
        bare: list[str] = []
        for raw in lines:
            line = raw.decode("utf-8", errors="replace").rstrip("\r")
            if self._block is not None:
                self._block.append(line)
                self._block_size += len(raw) + 1
                if self._block_size > self.limit:
                    self._block = None
                    raise ProtocolError(f"a program larger than {self.limit} bytes",
                                        interface=self.interface)
                if _END.match(line):
                    out.append(ScriptChunk(self._block_kind, "\n".join(self._block) + "\n"))
                    self._block = None
                continue
            match = _OPEN.match(line)
            if match:
                if bare:
                    out.append(ScriptChunk("bare", "\n".join(bare) + "\n"))
                    bare = []
                self._block = [line]
                self._block_kind = match.group(1)
                self._block_size = len(raw) + 1
                continue
            if line.strip():
                bare.append(line)
        if bare:
            out.append(ScriptChunk("bare", "\n".join(bare) + "\n"))
        return out

    @property
    def pending(self) -> bool:
        """True while a ``def``/``sec`` block has started but not ended."""
        return self._block is not None
