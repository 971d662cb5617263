"""Cutting the script text that arrives on ports 30001-30003 into programs (no sockets).

The controller's rules (docs/controller-facts.md §7): a program starts with ``def name():`` or
``sec name():`` in column 0 and ends with ``end`` in column 0; lines outside such a block
("bare lines") run as a one-off program. Text arrives in arbitrary TCP chunks, so a block is
buffered until its ``end`` line, and bare lines are handed over one complete line at a time,
grouped per chunk (the lines of one ``send`` run together).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

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

    Raises ``ValueError`` when a block grows past :data:`MAX_SCRIPT_BYTES`.
    """

    def __init__(self, limit: int = MAX_SCRIPT_BYTES) -> None:
        self.limit = limit
        self._partial = b""
        self._block: list[str] | None = None
        self._block_kind = ""
        self._block_size = 0

    def feed(self, data: bytes) -> list[ScriptChunk]:
        data = self._partial + data
        lines = data.split(b"\n")
        self._partial = lines.pop()
        if len(self._partial) > self.limit:
            raise ValueError(f"a line longer than {self.limit} bytes")
        out: list[ScriptChunk] = []
        bare: list[str] = []
        for raw in lines:
            line = raw.decode("utf-8", errors="replace").rstrip("\r")
            if self._block is not None:
                self._block.append(line)
                self._block_size += len(raw) + 1
                if self._block_size > self.limit:
                    self._block = None
                    raise ValueError(f"a program larger than {self.limit} bytes")
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
