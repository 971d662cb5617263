"""The realtime interface (ports 30003/30013): fixed-layout packets pushed at 125 Hz (CB3) or
500 Hz (e-Series).

A packet is an ``int32`` total size (including itself) followed by big-endian doubles — every
field is a double, even modes and bit masks, which are decoded as ints here. The layout is a
declarative table per software generation (UR_FACTS.md §3); a packet is decoded by its size
field: the longest prefix of whole fields that fits is decoded by name and anything after it
is kept as ``tail`` bytes. Controllers newer than these tables only append fields, so an
unknown size still decodes everything known.

=========  =====  =====================================================================
software   bytes  fields
=========  =====  =====================================================================
1.6        756    time … I_actual, tool accelerometer, TCP force, tool vector, …
1.7        764    + robot mode
1.8        812    + joint modes
3.0–3.1    1044   3.x/5.x order (tool vector actual at byte 444)
3.2–3.4    1060   + digital outputs, program state
3.5–3.9    1108   + elbow position and velocity (also 5.0–5.3)
3.10–3.13  1116   + safety status (also 5.4–5.9)
5.10+      1220   + payload mass, CoG, inertia
=========  =====  =====================================================================
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass, field

from .errors import ProtocolError

__all__ = ["Field", "LAYOUT_1X", "LAYOUT_3X", "RealtimeState", "decode", "encode",
           "RealtimeDecoder", "MAX_PACKET", "SIZES"]

MAX_PACKET = 4096
"""Largest packet accepted (bytes). The biggest documented layout is 1220 bytes; room for
fields newer controllers may append, small enough that a corrupt size is caught at once
rather than after buffering megabytes."""


@dataclass(frozen=True)
class Field:
    """``count`` doubles named ``name``; ``integer`` fields hold modes or bit masks."""

    name: str
    count: int = 1
    integer: bool = False


def _fields(*spec) -> tuple[Field, ...]:
    return tuple(Field(*item) if isinstance(item, tuple) else Field(item) for item in spec)


_COMMON = (
    "time", ("q_target", 6), ("qd_target", 6), ("qdd_target", 6), ("i_target", 6),
    ("m_target", 6), ("q_actual", 6), ("qd_actual", 6), ("i_actual", 6),
)

LAYOUT_3X = _fields(
    *_COMMON, ("i_control", 6), ("tool_vector_actual", 6), ("tcp_speed_actual", 6),
    ("tcp_force", 6), ("tool_vector_target", 6), ("tcp_speed_target", 6),
    ("digital_input_bits", 1, True), ("motor_temperatures", 6), "controller_timer",
    "test_value", ("robot_mode", 1, True), ("joint_modes", 6, True), ("safety_mode", 1, True),
    ("reserved_1", 6), ("tool_accelerometer", 3), ("reserved_2", 6), "speed_scaling",
    "linear_momentum_norm", "reserved_3", "reserved_4", "v_main", "v_robot", "i_robot",
    ("v_actual", 6), ("digital_outputs", 1, True), ("program_state", 1, True),
    ("elbow_position", 3), ("elbow_velocity", 3), ("safety_status", 1, True),
    ("reserved_5", 3), "payload_mass", ("payload_cog", 3), ("payload_inertia", 6),
)
"""Software 3.0 and later, e-Series included (UR_FACTS.md §3.1)."""

LAYOUT_1X = _fields(
    *_COMMON, ("tool_accelerometer", 3), ("unused", 15), ("tcp_force", 6),
    ("tool_vector_actual", 6), ("tcp_speed_actual", 6), ("digital_input_bits", 1, True),
    ("motor_temperatures", 6), "controller_timer", "test_value", ("robot_mode", 1, True),
    ("joint_modes", 6, True),
)
"""CB2, software 1.6–1.8 (UR_FACTS.md §3.2): a different order after I_actual."""

SIZES = {756: "1.6", 764: "1.7", 812: "1.8", 1044: "3.0", 1060: "3.2", 1108: "3.5",
         1116: "3.10", 1220: "5.10"}
"""Known packet sizes and the first software version that sends them."""

_NAMES_3X = {f.name for f in LAYOUT_3X}


@dataclass(frozen=True)
class RealtimeState:
    """One decoded packet: ``fields`` by name (floats, ints, or tuples of them), the packet
    ``size``, the ``layout`` ("1.x" or "3.x") and the undecoded ``tail`` bytes."""

    size: int
    layout: str
    fields: dict = field(repr=False)
    tail: bytes = b""

    def __getattr__(self, name: str):
        fields = object.__getattribute__(self, "fields")
        if name in fields:
            return fields[name]
        raise AttributeError(f"this {self.layout} realtime packet ({self.size} bytes) has no "
                             f"field {name!r}")

    @property
    def tcp_pose(self) -> tuple[float, ...]:
        """The actual TCP pose (m, rotation vector rad): byte 444 on 3.x/5.x, 588 on 1.x."""
        return self.fields["tool_vector_actual"]


def _layout_for(size: int, layout: str | None) -> tuple[str, tuple[Field, ...]]:
    if layout is None:
        layout = "1.x" if size < 1044 else "3.x"
    if layout not in ("1.x", "3.x"):
        raise ProtocolError(f"unknown realtime layout {layout!r}: '1.x' or '3.x'")
    return layout, (LAYOUT_1X if layout == "1.x" else LAYOUT_3X)


def decode(packet: bytes, layout: str | None = None) -> RealtimeState:
    """Decode one whole packet. ``layout`` forces "1.x" or "3.x" (by default: 1.x below 1044
    bytes, the smallest 3.x packet)."""
    if len(packet) < 4:
        raise ProtocolError(f"a realtime packet starts with a 4-byte size; got {len(packet)} "
                            "bytes")
    (size,) = struct.unpack_from(">i", packet, 0)
    if size != len(packet):
        raise ProtocolError(f"the size field says {size} bytes, the packet has {len(packet)}")
    if size < 12 or (size - 4) % 8:
        raise ProtocolError(f"a realtime packet of {size} bytes is not a size field and whole "
                            "doubles")
    name, table = _layout_for(size, layout)
    count = (size - 4) // 8
    unpack, plan, used = _plan(name, table, count)
    values = unpack(packet, 4)
    fields = {key: (values[start] if scalar else values[start:end]) if not integer else
              (int(values[start]) if scalar else tuple(int(v) for v in values[start:end]))
              for key, start, end, scalar, integer in plan}
    return RealtimeState(size, name, fields, bytes(packet[4 + 8 * used:]))


_PLANS: dict = {}


def _plan(name: str, table: tuple[Field, ...], count: int):
    """For a layout and a packet of ``count`` doubles: one compiled unpacker and the slice of
    every whole field that fits (cached: a stream has one size)."""
    key = (name, count)
    if key not in _PLANS:
        plan, position = [], 0
        for entry in table:
            if position + entry.count > count:
                break
            plan.append((entry.name, position, position + entry.count, entry.count == 1,
                         entry.integer))
            position += entry.count
        _PLANS[key] = (struct.Struct(f">{count}d").unpack_from, tuple(plan), position)
    return _PLANS[key]


def encode(fields: dict, size: int = 1220, layout: str | None = None) -> bytes:
    """A packet of ``size`` bytes with ``fields`` by name (missing fields are 0.0)."""
    if size < 12 or (size - 4) % 8 or size > MAX_PACKET:
        raise ProtocolError(f"no realtime packet has {size} bytes")
    name, table = _layout_for(size, layout)
    known = {entry.name for entry in table}
    unknown = set(fields) - known
    if unknown:
        raise ProtocolError(f"the {name} realtime layout has no field {sorted(unknown)[0]!r}")
    count = (size - 4) // 8
    values: list[float] = []
    written = set()
    for entry in table:
        if len(values) + entry.count > count:
            missing = sorted(set(fields) - written)
            if missing:
                raise ProtocolError(f"field {missing[0]!r} does not fit in a {size}-byte "
                                    f"{name} realtime packet")
            break
        written.add(entry.name)
        value = fields.get(entry.name, 0.0 if entry.count == 1 else (0.0,) * entry.count)
        items = (value,) if entry.count == 1 else tuple(value)
        if len(items) != entry.count:
            raise ProtocolError(f"{entry.name} has {entry.count} values, got {len(items)}")
        values.extend(float(v) for v in items)
    values.extend([0.0] * (count - len(values)))
    return struct.pack(f">i{count}d", size, *values)


class RealtimeDecoder:
    """Packets from a byte stream, however the stream is split.

    ``feed`` returns every complete packet; :meth:`latest` only the newest — what a client
    that must not act on stale state wants (a slow reader drains the socket's backlog and
    keeps the last packet).
    """

    def __init__(self, layout: str | None = None) -> None:
        self.layout = layout
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[RealtimeState]:
        self._buffer += data
        return [decode(bytes(packet), self.layout) for packet in self._packets()]

    def latest(self, data: bytes = b"") -> RealtimeState | None:
        """The newest complete packet in the stream so far (older ones are dropped)."""
        self._buffer += data
        newest = None
        for packet in self._packets():
            newest = packet
        return None if newest is None else decode(bytes(newest), self.layout)

    def _packets(self) -> Iterator[bytearray]:
        buffer = self._buffer
        while len(buffer) >= 4:
            (size,) = struct.unpack_from(">i", buffer, 0)
            if not 12 <= size <= MAX_PACKET:
                self._buffer = bytearray()
                raise ProtocolError(f"realtime size field {size} is outside 12..{MAX_PACKET} "
                                    "bytes: the stream is not realtime packets")
            if len(buffer) < size:
                return
            packet = buffer[:size]
            del buffer[:size]
            yield packet
