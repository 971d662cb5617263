"""The one exception of the protocol layer.

Every codec in :mod:`urdsl.protocol` raises :class:`ProtocolError` for bytes it cannot accept:
a truncated packet, a size field that cannot be right, an unknown message where the protocol
allows none, a reply that does not answer the request. The message names the interface, the
field and the byte offset (counted from the start of the packet), so that a user reading it
can compare with the controller's documentation. Socket layers turn it into a clear message
("the controller at H sent a realtime packet of 12 bytes; the smallest known is 756").
"""

from __future__ import annotations

__all__ = ["ProtocolError"]


class ProtocolError(Exception):
    """Bytes or a message that do not follow the protocol.

    ``interface`` is ``"realtime"``, ``"primary"``, ``"rtde"`` or ``"dashboard"``;
    ``offset`` is the byte offset of the offending field inside its packet, when known.
    """

    def __init__(self, message: str, *, interface: str = "", offset: int | None = None) -> None:
        text = f"{interface}: {message}" if interface else message
        super().__init__(text)
        self.message = message
        self.interface = interface
        self.offset = offset
