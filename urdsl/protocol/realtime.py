"""The realtime ("Matlab") interface, ports 30003 / 30013, for every controller version.

The controller pushes one packet per control cycle (CB3: every 8 ms, 125 Hz; e-Series: every
2 ms, 500 Hz). A packet is a big-endian ``int32`` total size (counting its own 4 bytes)
followed by IEEE doubles — all of them doubles, even robot mode, joint modes and the digital
I/O bit masks, which this module hands out as ``int``.

The layout grew by appending fields, and the size field tells which layout a packet has:

=========  ======  ===================================================================
layout     bytes   software versions
=========  ======  ===================================================================
``1.6``    756     CB2 1.6 (its own field order: TCP force at 540, tool vector at 588)
``1.7``    764     CB2 1.7 (+ robot mode)
``1.8``    812     CB2 1.8 (+ joint modes)
``3.0``    1044    CB3 3.0–3.1 (new order: tool vector actual at 444, target at 588)
``3.2``    1060    CB3 3.2–3.4 (+ digital outputs, program state)
``3.5``    1108    CB3 3.5–3.9 and e-Series 5.0–5.3 (+ elbow position, velocity)
``3.10``   1116    CB3 3.10–3.13 and e-Series 5.4–5.8 (+ safety status)
``5.10``   1220    e-Series 5.10+ (+ payload mass, centre of gravity, inertia)
=========  ======  ===================================================================

Sizes collide between CB3 and e-Series (1108, 1116): the fields are the same, only the
version label differs, so a decoder labels such packets with the CB3 name unless it is told
the version (``RealtimeDecoder(version="5.4")``). CB3 3.14+ and e-Series 5.9 send at least the
1116-byte layout; what they append is not confirmed in UR's tables, so those bytes are kept
raw in :attr:`RealtimeState.tail`, as are the bytes after any known layout. A packet whose size
lies between two layouts is decoded with the longer layout that fits, the rest kept raw.

Layouts are tables (:data:`LAYOUTS`): one row per field with name, kind and count. Offsets
are computed from the tables, never written by hand; ``layout.offset("q_actual") == 252``.
"""

from __future__ import annotations

import operator
import struct
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from types import FunctionType, MappingProxyType
from typing import Any, NamedTuple

from ..versions import ControllerVersion
from .errors import ProtocolError

__all__ = [
    "RealtimeField", "RealtimeLayout", "LAYOUTS", "SIZES", "RealtimeState", "RealtimeDecoder",
    "decode_realtime", "encode_realtime", "realtime_state", "layout_for_version",
    "layout_for_size", "PORT", "READ_ONLY_PORT", "MIN_SIZE", "MAX_SIZE",
]

PORT = 30003
READ_ONLY_PORT = 30013

_HEADER = struct.Struct(">i")


@dataclass(frozen=True)
class RealtimeField:
    """One row of a layout table: ``count`` doubles named ``name``.

    ``kind`` is ``"double"`` for measured values or ``"int"`` for integers the controller
    sends as doubles (modes, bit masks): those decode to ``int``.
    """

    name: str
    kind: str
    count: int = 1


def _d(name: str, count: int = 1) -> RealtimeField:
    return RealtimeField(name, "double", count)


def _i(name: str, count: int = 1) -> RealtimeField:
    return RealtimeField(name, "int", count)


# --- the tables (UR "Realtime Client Interface" guide; docs/controller-facts.md §10) --------------

_HEAD = (  # identical in every version: offsets 4 .. 396
    _d("time"), _d("q_target", 6), _d("qd_target", 6), _d("qdd_target", 6),
    _d("i_target", 6), _d("m_target", 6), _d("q_actual", 6), _d("qd_actual", 6),
    _d("i_actual", 6),
)
_V1_6 = _HEAD + (
    _d("tool_accelerometer_values", 3), _d("reserved_420", 15), _d("tcp_force", 6),
    _d("tool_vector_actual", 6), _d("tcp_speed_actual", 6), _i("digital_input_bits"),
    _d("motor_temperatures", 6), _d("controller_timer"), _d("test_value"),
)
_V1_7 = _V1_6 + (_i("robot_mode"),)
_V1_8 = _V1_7 + (_i("joint_modes", 6),)
_V3_0 = _HEAD + (
    _d("i_control", 6), _d("tool_vector_actual", 6), _d("tcp_speed_actual", 6),
    _d("tcp_force", 6), _d("tool_vector_target", 6), _d("tcp_speed_target", 6),
    _i("digital_input_bits"), _d("motor_temperatures", 6), _d("controller_timer"),
    _d("test_value"), _i("robot_mode"), _i("joint_modes", 6), _i("safety_mode"),
    _d("reserved_820", 6), _d("tool_accelerometer_values", 3), _d("reserved_892", 6),
    _d("speed_scaling"), _d("linear_momentum_norm"), _d("reserved_956"), _d("reserved_964"),
    _d("v_main"), _d("v_robot"), _d("i_robot"), _d("v_actual", 6),
)
_V3_2 = _V3_0 + (_i("digital_outputs"), _i("program_state"))
_V3_5 = _V3_2 + (_d("elbow_position", 3), _d("elbow_velocity", 3))
_V3_10 = _V3_5 + (_i("safety_status"),)
_V5_10 = _V3_10 + (
    _d("reserved_1116", 3), _d("payload_mass"), _d("payload_cog", 3), _d("payload_inertia", 6),
)


Vector = tuple[float, ...]


class RealtimeState(NamedTuple):
    """One realtime packet, every field by name (SI units: rad, rad/s, m, N, A, V, °C, s).

    Fields a version does not send are ``None``. Modes and bit masks are ``int``; vectors are
    tuples (joint vectors base … wrist 3; poses x, y, z, rx, ry, rz in the Base frame).
    ``version`` names the layout (or the version the decoder was told); ``size`` is the
    packet's size field; ``tail`` holds the bytes after the known layout, undecoded.

    Immutable and tuple-backed (a named tuple): a decoder builds it in one step, and reading
    a field is an index into the tuple. The tuple's order is ``version``, ``size``, the
    measured values, the integer fields, ``tail``; use the names. Equal only to another
    :class:`RealtimeState` with the same fields.
    """

    version: str = "5.10"
    size: int = 0
    # the measured values (doubles), in packet order
    time: float | None = None
    q_target: Vector | None = None
    qd_target: Vector | None = None
    qdd_target: Vector | None = None
    i_target: Vector | None = None
    m_target: Vector | None = None
    q_actual: Vector | None = None
    qd_actual: Vector | None = None
    i_actual: Vector | None = None
    i_control: Vector | None = None
    tool_vector_actual: Vector | None = None
    tcp_speed_actual: Vector | None = None
    tcp_force: Vector | None = None
    tool_vector_target: Vector | None = None
    tcp_speed_target: Vector | None = None
    motor_temperatures: Vector | None = None
    controller_timer: float | None = None
    test_value: float | None = None
    reserved_820: Vector | None = None
    tool_accelerometer_values: Vector | None = None
    reserved_892: Vector | None = None
    speed_scaling: float | None = None
    linear_momentum_norm: float | None = None
    reserved_956: float | None = None
    reserved_964: float | None = None
    v_main: float | None = None
    v_robot: float | None = None
    i_robot: float | None = None
    v_actual: Vector | None = None
    elbow_position: Vector | None = None
    elbow_velocity: Vector | None = None
    reserved_1116: Vector | None = None
    payload_mass: float | None = None
    payload_cog: Vector | None = None
    payload_inertia: Vector | None = None
    reserved_420: Vector | None = None
    # the integers the controller sends as doubles (modes, bit masks), in packet order
    digital_input_bits: int | None = None
    robot_mode: int | None = None
    joint_modes: tuple[int, ...] | None = None
    safety_mode: int | None = None
    digital_outputs: int | None = None
    program_state: int | None = None
    safety_status: int | None = None
    tail: bytes = b""

    def __eq__(self, other: object) -> bool:
        return type(other) is RealtimeState and tuple.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    __hash__ = tuple.__hash__

    @property
    def tcp_pose(self) -> Vector | None:
        """The actual TCP pose (x, y, z, rx, ry, rz) [m, rad] in the Base frame."""
        return self.tool_vector_actual

    @property
    def layout(self) -> RealtimeLayout:
        """The layout of this packet's known fields."""
        return LAYOUTS[self.version] if self.version in LAYOUTS else \
            layout_for_version(self.version)


def _int_error(layout: RealtimeLayout, values: tuple[float, ...]) -> ProtocolError:
    """The error for the first integer field that holds no integer; ``values`` is the
    packet unpacked whole (the size field, then the doubles)."""
    for name, begin, end in layout._ints:
        for index in range(begin, end):
            value = values[1 + index]
            if value != value or value in (_INF, -_INF) or int(value) != value:
                offset = _HEADER.size + 8 * index
                return ProtocolError(f"field {name} at offset {offset} should hold an "
                                     f"integer, got {value!r}", interface="realtime",
                                     offset=offset)
    raise AssertionError("no bad integer field")  # pragma: no cover


_INF = float("inf")


class RealtimeLayout:
    """A packet layout: its table, total size in bytes and the offset of every field."""

    def __init__(self, name: str, table: tuple[RealtimeField, ...]) -> None:
        self.name = name
        self.table = table
        self.doubles = sum(f.count for f in table)
        self.size = _HEADER.size + 8 * self.doubles
        self.struct = struct.Struct(f">{self.doubles}d")
        self._offsets: dict[str, int] = {}
        # (name, first, end) index into the packet's doubles of every field, and of the
        # integer fields alone (modes and bit masks sent as doubles)
        self._spans: tuple[tuple[str, int, int], ...] = ()
        self._ints: tuple[tuple[str, int, int], ...] = ()
        spans = []
        index = 0
        for item in table:
            self._offsets[item.name] = _HEADER.size + 8 * index
            spans.append((item.name, index, index + item.count))
            index += item.count
        self._spans = tuple(spans)
        self._ints = tuple(span for span, item in zip(spans, table, strict=True)
                           if item.kind == "int")
        self.names = tuple(f.name for f in table)
        self._compile()
        # the encoder of a RealtimeState: every field by name, its tail appended
        self._write = self._packer(
            {name: f"s.{name}" for name in self.names}, {}, "s.tail",
            lambda state: _pack_checked(self, partial(getattr, state), state.tail))

    def _compile(self) -> None:
        """Build this layout's decoders: one ``unpack`` of the whole packet (size field and
        doubles), one conversion of the integer fields (checked: each double must hold an
        integer), and the :class:`RealtimeState` assembled from a few C-level
        ``itemgetter`` calls (one per run of fields taken from the same source) — no loop
        over fields per packet. The source is generated from the table.

        ``_read(data, start, label, size, tail)`` decodes the packet at ``start`` of a
        buffer; ``_whole(data)`` a bytes object that is exactly one packet of this layout
        (``None`` when its size field disagrees: the caller takes the general path)."""
        ints = {name: (begin, end) for name, begin, end in self._ints}
        int_slot = {}  # name -> (first, end) in the converted integers
        k = 0
        for name, begin, end in self._ints:
            int_slot[name] = (k, k + end - begin)
            k += end - begin
        # indices into the whole packet unpacked: the size field is value 0, double k is k + 1
        floats = {name: (begin + 1, end + 1) for name, begin, end in self._spans
                  if name not in ints}
        # each field of the state: (source, key); sources: f doubles, n integers, None absent
        plan: list[tuple[str, object]] = []
        for name in RealtimeState._fields:
            if name in ("version", "size", "tail"):
                plan.append(({"version": "label"}.get(name, name), None))
                continue
            table, source = (floats, "f") if name in floats else (int_slot, "n")
            span = table.get(name)
            if span is None:
                plan.append(("None", None))
            else:
                begin, end = span
                plan.append((source, begin if end - begin == 1 else slice(begin, end)))
        whole = struct.Struct(f">i{self.doubles}d")
        namespace: dict[str, object] = {
            "unpack_from": whole.unpack_from, "unpack": whole.unpack, "int_error": _int_error,
            "layout": self, "new": tuple.__new__, "State": RealtimeState,
            "trunc": float.__trunc__, "NAME": self.name, "EMPTY": b""}
        items = []
        run: list[tuple[str, object]] = []

        def flush() -> None:
            if not run:
                return
            source = run[0][0]
            if source in ("f", "n") and len(run) > 1:
                getter = f"get{len(namespace)}"
                namespace[getter] = operator.itemgetter(*(key for _, key in run))
                items.append(f"*{getter}({source})")
            elif source in ("f", "n"):
                key = run[0][1]
                items.append(f"{source}[{key}]" if isinstance(key, int)
                             else f"{source}[{key.start}:{key.stop}]")  # type: ignore
            else:
                items.extend(source for _ in run)
            run.clear()

        for entry in plan:
            if run and run[0][0] != entry[0]:
                flush()
            run.append(entry)
        flush()
        int_indices = [1 + i for _, begin, end in self._ints for i in range(begin, end)]
        if len(int_indices) > 1:
            namespace["get_ints"] = operator.itemgetter(*int_indices)
            fetch = "get_ints(f)"
        else:  # itemgetter of one key would return a bare value
            fetch = f"(f[{int_indices[0]}],)"
        # i != n: the float's comparison handles an int directly (n != i tries int's first)
        body = (
            f"    i = {fetch}\n"
            "    try:\n"
            "        n = tuple(map(trunc, i))\n"
            "    except (ValueError, OverflowError):\n"
            "        n = None\n"
            "    if i != n:\n"
            "        raise int_error(layout, f)\n"
            f"    return new(State, ({', '.join(items)}))\n")
        source = (
            "def read(data, start, label, size, tail):\n"
            "    f = unpack_from(data, start)\n" + body
            + f"\ndef whole(data, label=NAME, size={self.size}, tail=EMPTY):\n"
            "    f = unpack(data)\n"
            "    if f[0] != size:\n"
            "        return None\n" + body)
        exec(source, namespace)  # noqa: S102 - generated from the layout table above
        self._read = namespace["read"]
        self._whole = namespace["whole"]
        self._source = source

    def _whole_labelled(self, label: str) -> Callable[[bytes], RealtimeState | None]:
        """``_whole`` labelling its states ``label`` (a version the decoder was told)."""
        whole = self._whole
        return FunctionType(whole.__code__, whole.__globals__, whole.__name__,
                            (label, *whole.__defaults__[1:]))

    def packer(self, carried: Mapping[str, Callable[[Any], object]]) -> Callable[[Any], bytes]:
        """This layout's encoder for the caller's own objects (the simulator's snapshots).

        ``carried[name](s)`` is the value field ``name`` carries for an object ``s``: a number,
        or a sequence of the field's count (a tuple, a numpy array); every field not named is
        sent as 0, and names this layout does not send are left out. The function returned
        packs a whole packet (size field included) with this layout's one precompiled struct
        call, generated from the table; a value that does not fit raises
        :class:`ProtocolError` naming the field. A name that no layout has raises
        ``KeyError`` here.
        """
        unknown = sorted(set(carried) - _ALL_NAMES)
        if unknown:
            raise KeyError(f"no realtime layout has the field(s) {', '.join(unknown)}")
        namespace: dict[str, object] = {}
        expressions = {}
        for index, (name, value) in enumerate(carried.items()):
            if name in self._offsets:
                namespace[f"c{index}"] = value
                expressions[name] = f"c{index}(s)"
        return self._packer(expressions, namespace, None, _carried_fallback(self, carried))

    def _packer(self, expressions: Mapping[str, str], namespace: dict[str, object],
                tail: str | None, fallback: Callable[[Any], bytes]) -> Callable[[Any], bytes]:
        """Generate ``write(s)``: one ``struct`` call packing each field's
        ``expressions[name]`` in table order, vectors spread and their lengths checked (a
        short vector beside a long one would shift the fields behind it with the total still
        right); a field without an expression is pad bytes in the format (0.0 is eight zero
        bytes), so it costs no argument. ``tail`` is an expression for bytes appended and
        counted in the size field. ``fallback(s)`` packs field by field, or raises the error
        naming the field that does not fit."""
        lines = ["def write(s):", "    try:"]
        codes = [">i"]
        args: list[str] = []
        vectors: list[tuple[str, int]] = []
        for index, item in enumerate(self.table):
            expression = expressions.get(item.name)
            if expression is None:
                codes.append(f"{8 * item.count}x")
                continue
            codes.append(f"{item.count}d")
            if item.count == 1:
                args.append(expression)
            else:
                lines.append(f"        v{index} = {expression}")
                vectors.append((f"v{index}", item.count))
                args.append(f"*v{index}")
        if vectors:
            lines.append(f"        if ({', '.join(f'len({v})' for v, _ in vectors)},) != "
                         f"{tuple(count for _, count in vectors)}:")
            lines.append("            return fallback(s)")
        size, trailer = str(self.size), ""
        if tail is not None:
            lines.append(f"        tail = {tail}")
            size, trailer = f"{self.size} + len(tail)", " + tail"
        lines += [f"        return pack({', '.join([size, *args])}){trailer}",
                  "    except (TypeError, ValueError, OverflowError, struct_error):",
                  "        return fallback(s)"]
        namespace.update(pack=struct.Struct("".join(codes)).pack, fallback=fallback,
                         struct_error=struct.error)
        exec("\n".join(lines) + "\n", namespace)  # noqa: S102 - generated from the table
        return namespace["write"]  # type: ignore[return-value]

    def slot(self, name: str) -> slice:
        """Where field ``name`` sits in the packet's array of doubles (after the size field);
        a KeyError for a field this layout does not send."""
        start = (self.offset(name) - _HEADER.size) // 8
        count = next(f.count for f in self.table if f.name == name)
        return slice(start, start + count)

    def offset(self, name: str) -> int:
        """Byte offset of a field from the start of the packet (the size field is at 0)."""
        try:
            return self._offsets[name]
        except KeyError:
            raise KeyError(f"the {self.name} realtime layout has no field {name!r}") from None

    def __repr__(self) -> str:
        return f"RealtimeLayout({self.name!r}, {self.size} bytes)"


LAYOUTS: MappingProxyType[str, RealtimeLayout] = MappingProxyType({
    name: RealtimeLayout(name, table) for name, table in (
        ("1.6", _V1_6), ("1.7", _V1_7), ("1.8", _V1_8), ("3.0", _V3_0), ("3.2", _V3_2),
        ("3.5", _V3_5), ("3.10", _V3_10), ("5.10", _V5_10),
    )
})
"""Every known layout by its name (the first software version that sends it)."""

SIZES: MappingProxyType[int, RealtimeLayout] = MappingProxyType(
    {layout.size: layout for layout in LAYOUTS.values()})
"""Layouts by packet size."""

_BY_SIZE = sorted(LAYOUTS.values(), key=lambda layout: layout.size)

MIN_SIZE = _BY_SIZE[0].size
"""Smallest packet accepted: the 1.6 layout (756 bytes); older CB2 software is not known."""

MAX_SIZE = 8192
"""Largest packet accepted, in bytes.

The largest documented packet has 1220 bytes (5.10+) and each release so far appended at
most ~100 bytes. Allowing 8 KiB keeps room for future fields (kept raw) while a corrupt or
desynchronised size field — almost any 4 random bytes read as int32 exceed it — is
rejected at once instead of making the decoder wait for megabytes that never come.
"""


for _layout in LAYOUTS.values():  # every table row must be a field of RealtimeState
    assert set(_layout.names) <= set(RealtimeState._fields), \
        set(_layout.names) - set(RealtimeState._fields)
del _layout

_ALL_NAMES = frozenset(name for layout in LAYOUTS.values() for name in layout.names)


def layout_for_size(size: int) -> RealtimeLayout:
    """The layout for a packet of ``size`` bytes: exact match, else the longest that fits."""
    layout = SIZES.get(size)
    if layout is not None:
        return layout
    if size < MIN_SIZE:
        raise ProtocolError(f"packet size {size} is smaller than the smallest known layout "
                            f"(1.6, {MIN_SIZE} bytes)", interface="realtime", offset=0)
    best = _BY_SIZE[0]
    for candidate in _BY_SIZE:
        if candidate.size <= size:
            best = candidate
    return best


def _version_tuple(version: str) -> tuple[int, int]:
    """``(major, minor)`` of ``version`` (:class:`urdsl.versions.ControllerVersion` parses)."""
    try:
        return ControllerVersion.parse(version).feature
    except ValueError:
        raise ProtocolError(f"controller version {version!r} is not of the form 'major.minor'",
                            interface="realtime") from None


def layout_for_version(version: str) -> RealtimeLayout:
    """The layout a controller of software ``version`` (``"3.12"``, ``"5.11.1"``) sends."""
    major, minor = _version_tuple(version)
    if major == 1 and 6 <= minor <= 8:
        return LAYOUTS[f"1.{minor}"]
    if major == 1 and minor > 8:
        return LAYOUTS["1.8"]
    if major == 3:
        for floor, name in ((10, "3.10"), (5, "3.5"), (2, "3.2"), (0, "3.0")):
            if minor >= floor:
                return LAYOUTS[name]
    if major == 5:
        # 5.9 sends at least 3.10's fields; its tail is not confirmed (kept raw).
        for floor, name in ((10, "5.10"), (4, "3.10"), (0, "3.5")):
            if minor >= floor:
                return LAYOUTS[name]
    if major > 5:
        return LAYOUTS["5.10"]
    raise ProtocolError(f"no known realtime layout for controller version {version!r} "
                        "(known: 1.6–1.8, 3.x, 5.x)", interface="realtime")


def _decode_at(data: bytes | bytearray | memoryview, start: int, size: int,
               version: str | None) -> RealtimeState:
    if version is None:
        layout = layout_for_size(size)
        label = layout.name
    else:
        layout = layout_for_version(version)
        label = version
        if size < layout.size:
            raise ProtocolError(f"a version {version} packet has at least {layout.size} bytes "
                                f"({layout.name} layout), this one has {size}",
                                interface="realtime", offset=0)
    tail = bytes(data[start + layout.size:start + size]) if size > layout.size else b""
    return layout._read(data, start, label, size, tail)


def _check_size(size: int) -> None:
    if size < MIN_SIZE or size > MAX_SIZE:
        raise ProtocolError(f"packet size field says {size} bytes; a realtime packet has "
                            f"{MIN_SIZE}..{MAX_SIZE} (known layouts: "
                            f"{', '.join(str(s) for s in sorted(SIZES))})",
                            interface="realtime", offset=0)


def decode_realtime(packet: bytes, version: str | None = None) -> RealtimeState:
    """Decode exactly one complete packet (size field included).

    ``version`` (``"5.4"``) overrides the version label and layout chosen from the size.
    Raises :class:`ProtocolError` when the bytes are not one whole packet.
    """
    if len(packet) < _HEADER.size:
        raise ProtocolError(f"{len(packet)} bytes cannot hold the 4-byte size field",
                            interface="realtime", offset=0)
    (size,) = _HEADER.unpack_from(packet, 0)
    _check_size(size)
    if size != len(packet):
        raise ProtocolError(f"size field says {size} bytes but the packet has {len(packet)}",
                            interface="realtime", offset=0)
    return _decode_at(packet, 0, size, version)


def realtime_state(version: str = "5.10", **values: object) -> RealtimeState:
    """A state of ``version``'s layout with the given fields and zeros for the others.

    For the simulator: ``realtime_state("3.10", q_actual=(0, -1.57, 0, -1.57, 0, 0))``.
    Unknown field names, or names the version's layout does not send, raise ``TypeError``.
    """
    layout = layout_for_version(version)
    known = set(layout.names)
    unknown = set(values) - known - {"tail"}
    if unknown:
        raise TypeError(f"the {layout.name} realtime layout has no field(s) "
                        f"{', '.join(sorted(unknown))}")
    full: dict[str, object] = {}
    for item in layout.table:
        zero: object = 0 if item.kind == "int" else 0.0
        default = zero if item.count == 1 else (zero,) * item.count
        value = values.get(item.name, default)
        if item.count > 1:
            value = tuple(int(v) if item.kind == "int" else float(v) for v in value)
        else:
            value = int(value) if item.kind == "int" else float(value)
        full[item.name] = value
    tail = bytes(values.get("tail", b""))  # type: ignore[call-overload]
    return RealtimeState(version=version, size=layout.size + len(tail), tail=tail,
                         **full)  # type: ignore[arg-type]


def encode_realtime(state: RealtimeState, version: str | None = None) -> bytes:
    """The packet the controller sends for ``state`` (the simulator's side).

    ``version`` defaults to ``state.version``. Every field of that version's layout must be
    set (use :func:`realtime_state` to start from zeros); ``state.tail`` is appended and
    counted in the size field.
    """
    data = layout_for_version(version or state.version)._write(state)
    if len(data) > MAX_SIZE:
        raise ProtocolError(f"packet of {len(data)} bytes exceeds {MAX_SIZE}",
                            interface="realtime")
    return data


def _pack_checked(layout: RealtimeLayout, value_of: Callable[[str], Any], tail: bytes) -> bytes:
    """The packet of ``layout`` with ``value_of(name)`` for each field, converted and checked
    field by field: the slow path behind the generated encoders, for values they could not
    pack (numbers of other types) and for the error naming the field that does not fit."""
    values: list[float] = []
    for item in layout.table:
        value = value_of(item.name)
        offset = layout.offset(item.name)
        if value is None:
            raise ProtocolError(f"cannot encode a {layout.name} packet: field {item.name} "
                                "is not set", interface="realtime", offset=offset)
        try:
            if item.count == 1:
                values.append(float(value))
                continue
            count = len(value)
            if count == item.count:
                values.extend(float(v) for v in value)
                continue
        except (TypeError, ValueError, OverflowError):
            raise ProtocolError(f"field {item.name} needs {_numbers(item.count)}, got "
                                f"{value!r:.80}", interface="realtime", offset=offset) from None
        raise ProtocolError(f"field {item.name} needs {item.count} values, got {count}",
                            interface="realtime", offset=offset)
    return _HEADER.pack(layout.size + len(tail)) + layout.struct.pack(*values) + tail


def _numbers(count: int) -> str:
    return "a number" if count == 1 else f"{count} numbers"


def _carried_fallback(layout: RealtimeLayout,
                      carried: Mapping[str, Callable[[Any], object]]) -> Callable[[Any], bytes]:
    def zero(item: RealtimeField) -> object:
        return 0.0 if item.count == 1 else (0.0,) * item.count

    zeros = {item.name: zero(item) for item in layout.table}
    return lambda s: _pack_checked(
        layout, lambda name: carried[name](s) if name in carried else zeros[name], b"")


class RealtimeDecoder:
    """Turns the realtime byte stream into :class:`RealtimeState` objects.

    TCP delivers a byte stream, not packets: ``feed`` accepts any chunk (half a packet, three
    and a half packets) and returns the packets it completes, oldest first. ``latest`` is the
    drain a state reader wants: it returns only the newest complete packet and skips the
    older ones without decoding them (``skipped`` counts them), so a slow reader never
    acts on a stale sample from the socket's queue.

    After a :class:`ProtocolError` the stream cannot be trusted (packet boundaries are
    lost); the decoder refuses further input, and the connection has to be reopened.
    """

    def __init__(self, version: str | None = None) -> None:
        if version is None:
            exact = {layout.size: layout._whole for layout in LAYOUTS.values()}
        else:
            layout = layout_for_version(version)  # fail early on a version we do not know
            exact = {layout.size: layout._whole_labelled(version)}
        self.version = version
        # the common case: a chunk that is one whole packet of a layout's exact size → the
        # decoder of that layout (which checks the size field itself)
        self._exact = exact
        self._buffer = bytearray()
        self._error: ProtocolError | None = None
        self.decoded = 0
        self.skipped = 0

    @property
    def pending(self) -> int:
        """Bytes of an incomplete packet held back."""
        return len(self._buffer)

    def _frames(self) -> list[tuple[int, int]]:
        """(start, size) of every complete packet in the buffer; checks each size field."""
        frames = []
        buffer = self._buffer
        pos = 0
        end = len(buffer)
        while end - pos >= _HEADER.size:
            (size,) = _HEADER.unpack_from(buffer, pos)
            try:
                _check_size(size)
            except ProtocolError as exc:
                self._error = exc
                raise
            if end - pos < size:
                break
            frames.append((pos, size))
            pos += size
        return frames

    def _take(self, data: bytes) -> list[tuple[int, int]]:
        if self._error is not None:
            raise ProtocolError(f"stream already failed ({self._error.message}); reconnect",
                                interface="realtime")
        self._buffer += data
        return self._frames()

    def _decode(self, start: int, size: int) -> RealtimeState:
        try:
            return _decode_at(self._buffer, start, size, self.version)
        except ProtocolError as exc:
            self._error = exc
            raise

    def feed(self, data: bytes) -> list[RealtimeState]:
        """Add received bytes; return every packet they complete, oldest first."""
        if self._error is None and not self._buffer:
            # the common case: exactly one whole packet of a known layout, decoded in place
            whole = self._exact.get(len(data))
            if whole is not None:
                try:
                    state = whole(data)
                except ProtocolError as exc:
                    self._error = exc
                    raise
                if state is not None:  # None: the size field says otherwise
                    self.decoded += 1
                    return [state]
        frames = self._take(data)
        states = [self._decode(start, size) for start, size in frames]
        if frames:
            last_start, last_size = frames[-1]
            del self._buffer[:last_start + last_size]
        self.decoded += len(states)
        return states

    def latest(self, data: bytes = b"") -> RealtimeState | None:
        """Add received bytes; return the newest complete packet only (or ``None``).

        Older complete packets are dropped undecoded (their sizes are still checked).
        """
        frames = self._take(data)
        if not frames:
            return None
        start, size = frames[-1]
        state = self._decode(start, size)
        del self._buffer[:start + size]
        self.skipped += len(frames) - 1
        self.decoded += 1
        return state
