"""Declarative binary tables: a list of named, typed fields compiled to one ``struct``.

A :class:`Table` is written as data — ``Row("timestamp", "Q")``, ``Row("q", "d", 6)``,
``Group(6, (Row("q_actual", "d"), Row("jointMode", "B")))`` for per-joint records that the
controller interleaves — and gives ``unpack(data, offset) -> dict`` and ``pack(values)``.
Offsets follow from the table; nobody writes one by hand. All formats are big-endian, as on
every UR socket.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping
from dataclasses import dataclass

from .errors import ProtocolError

__all__ = ["Row", "Group", "Table", "read_text", "text_bytes"]

@dataclass(frozen=True)
class Row:
    """``count`` values of the struct format character ``fmt`` named ``name``.

    ``count > 1`` gives a tuple. ``?`` gives ``bool``; integer formats give ``int``;
    ``f``/``d`` give ``float``.
    """

    name: str
    fmt: str
    count: int = 1


@dataclass(frozen=True)
class Group:
    """``count`` records of ``rows`` stored one after the other (record 0's fields, then
    record 1's, …); each row becomes a tuple of ``count`` values (one per joint)."""

    count: int
    rows: tuple[Row, ...]


class Table:
    """A compiled field table."""

    def __init__(self, items: tuple[Row | Group, ...]) -> None:
        self.items = items
        fmt = [">"]
        plan: list[tuple[str, int, int, int, str]] = []  # name, start, stride, count, fmt
        index = 0
        self.offsets: dict[str, int] = {}
        byte = 0
        for item in items:
            if isinstance(item, Row):
                fmt.append(f"{item.count}{item.fmt}")
                plan.append((item.name, index, 1, item.count, item.fmt))
                self.offsets[item.name] = byte
                index += item.count
                byte += struct.calcsize(f">{item.count}{item.fmt}")
            else:
                stride = len(item.rows)
                record = "".join(row.fmt for row in item.rows)
                fmt.append(record * item.count)
                for k, row in enumerate(item.rows):
                    plan.append((row.name, index + k, stride, item.count, row.fmt))
                    self.offsets[row.name] = byte + struct.calcsize(">" + record[:k])
                index += stride * item.count
                byte += struct.calcsize(">" + record) * item.count
        self.struct = struct.Struct("".join(fmt))
        self.size = self.struct.size
        self._plan = tuple(plan)
        self._values = index
        self.names = tuple(name for name, *_ in plan)

    def unpack(self, data: bytes | memoryview, offset: int = 0) -> dict[str, object]:
        """The fields at ``offset`` (the caller has checked there are ``size`` bytes)."""
        values = self.struct.unpack_from(data, offset)
        out: dict[str, object] = {}
        for name, start, stride, count, _ in self._plan:
            if stride == 1 and count == 1:
                out[name] = values[start]
            elif stride == 1:
                out[name] = values[start:start + count]
            else:
                out[name] = values[start:start + stride * count:stride]
        return out

    def pack(self, values: Mapping[str, object], what: str) -> bytes:
        """The bytes of ``values`` (every field of the table must be there)."""
        flat: list[object] = [None] * self._values
        for name, start, stride, count, _ in self._plan:
            value = values.get(name)
            if value is None:
                raise ProtocolError(f"cannot encode {what}: field {name} is not set",
                                    interface="primary")
            if count == 1 and stride == 1:
                flat[start] = value
                continue
            if len(value) != count:  # type: ignore[arg-type]
                raise ProtocolError(f"cannot encode {what}: field {name} needs {count} values, "
                                    f"got {len(value)}", interface="primary")  # type: ignore
            for k, element in enumerate(value):  # type: ignore[union-attr]
                flat[start + k * stride] = element
        try:
            return self.struct.pack(*flat)
        except struct.error as exc:
            raise ProtocolError(f"cannot encode {what}: {exc}", interface="primary") from None


def read_text(data: bytes) -> str:
    """Controller text as ``str``; bytes that are not UTF-8 survive as surrogate escapes, so
    that encoding the text again gives the same bytes."""
    return data.decode("utf-8", errors="surrogateescape")


def text_bytes(text: str, what: str, interface: str) -> bytes:
    """The bytes of ``text`` as the controller sends it (UTF-8)."""
    try:
        return text.encode("utf-8", errors="surrogateescape")
    except UnicodeEncodeError as exc:
        raise ProtocolError(f"{what} cannot be encoded: {exc.reason} at character {exc.start}",
                            interface=interface) from None
