"""The one error of the protocol layer."""

from __future__ import annotations

__all__ = ["ProtocolError"]


class ProtocolError(Exception):
    """Bytes that do not follow the protocol: the message names the field, offset or size."""
