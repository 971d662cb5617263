"""PolyScope's files are often gzip-compressed (``.urp``, ``.installation``, ``.variables``):
one reader for all of them, bounded, so that no file (a damaged one, or a "zip bomb" a
repository or a colleague hands over) makes urdsl hold more than :data:`LIMIT` bytes.

>>> import gzip
>>> inflate(gzip.compress(b"<URProgram/>"))
b'<URProgram/>'
>>> inflate(b"count=0")  # plain text is returned as it is
b'count=0'
"""

from __future__ import annotations

import zlib

__all__ = ["LIMIT", "InflateError", "inflate", "is_gzip"]

LIMIT = 64 * 1024 * 1024
"""Most bytes a file may hold once decompressed (64 MiB). The largest real PolyScope files
in the labelled set (bench/realworld) are a few megabytes of XML."""

_MAGIC = b"\x1f\x8b"


class InflateError(ValueError):
    """The gzip data cannot be read; ``reason`` says why in words a message can end with
    ("the gzip data is truncated", "larger than 64 MiB uncompressed")."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def is_gzip(data: bytes) -> bool:
    """Whether ``data`` starts as a gzip stream does."""
    return data[:2] == _MAGIC


def inflate(data: bytes, limit: int | None = None) -> bytes:
    """``data`` decompressed when it is gzip (every member of a multi-member stream), else
    as it is. Raises :class:`InflateError` for corrupt or truncated data and for data that
    would decompress to more than ``limit`` bytes (found after reading at most ``limit + 1``
    bytes: memory stays bounded); ``limit`` None: :data:`LIMIT`."""
    if not is_gzip(data):
        return data
    limit = LIMIT if limit is None else limit
    out = bytearray()
    rest = data
    while rest:
        engine = zlib.decompressobj(16 + zlib.MAX_WBITS)
        try:
            out += engine.decompress(rest, limit + 1 - len(out))
        except zlib.error as error:
            raise InflateError(f"the gzip data is corrupt ({error})") from None
        if len(out) > limit:
            raise InflateError(f"larger than {limit / 2**20:.3g} MiB uncompressed")
        if not engine.eof:  # the input ended inside the stream (the limit was not reached)
            raise InflateError("the gzip data is truncated")
        rest = engine.unused_data.lstrip(b"\x00")  # gzip's own trailing zero padding
        if rest and not is_gzip(rest):
            break  # trailing garbage after the stream: gzip ignores it too
    return bytes(out)
