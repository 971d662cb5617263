"""The primary and secondary interfaces (ports 30001 / 30002; read-only 30011 / 30012).

Both stream messages at 10 Hz: the primary interface robot state and every robot message
(text, runtime exceptions, popups, …), the secondary robot state and the version message.
The first message after connecting is always the VERSION robot message.

Framing: ``int32 size`` (the whole message, header included) · ``uint8 type`` · body.

* ROBOT_STATE (16): a sequence of sub-packages, each ``uint32 size`` (its own 5-byte header
  included) · ``uint8 type`` · payload. Decoded into :class:`RobotState` with one typed
  object per sub-package (:class:`RobotModeData`, :class:`JointData`, …).
* ROBOT_MESSAGE (20): ``uint64 timestamp`` · ``int8 source`` · ``uint8 robot message type``
  · body. Decoded into :class:`VersionMessage`, :class:`TextMessage`,
  :class:`RuntimeExceptionMessage` (with line and column), :class:`PopupMessage`,
  :class:`KeyMessage`, :class:`SafetyModeMessage`, :class:`ErrorCodeMessage`,
  :class:`RequestValueMessage`, :class:`ProgramLabelMessage`.
* Any other message type, sub-package type or robot-message type is skipped by its size and
  kept raw (:class:`UnknownMessage`, :class:`UnknownPackage`, :class:`UnknownRobotMessage`),
  so that a newer controller never breaks the decoder and the simulator can send it back.

Sub-packages changed between software versions by appending fields. Each one is a table per
layout (``VARIANTS``, named after the first version that sends it: ``"3.0"``, ``"3.2"``,
``"3.5"``, ``"5.0"``); the payload size picks the layout — for every sub-package the sizes of
its CB3 and e-Series layouts differ, so no version hint is needed — and bytes beyond the
longest known layout are kept in ``extra``. CB2 (1.x) layouts are not decoded.

Text fields are UTF-8; bytes that are not survive as surrogate escapes, so that encoding a
decoded message gives back the same bytes.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, TypeVar

from ._binary import Group, Row, Table, read_text, text_bytes
from .errors import ProtocolError
from .script_framing import MAX_SCRIPT_BYTES, ScriptChunk, ScriptFramer

__all__ = [
    "PRIMARY_PORT", "SECONDARY_PORT", "ROBOT_STATE", "ROBOT_MESSAGE", "MAX_MESSAGE",
    "SubPackage", "RobotModeData", "JointData", "ToolData", "MasterboardData", "CartesianInfo",
    "KinematicsInfo", "ConfigurationData", "ForceModeData", "AdditionalInfo",
    "CalibrationData", "SafetyData", "ToolCommunicationInfo", "ToolModeInfo", "UnknownPackage",
    "RobotState", "RobotMessage", "TextMessage", "ProgramLabelMessage", "PopupMessage",
    "VersionMessage", "SafetyModeMessage", "ErrorCodeMessage", "KeyMessage",
    "RequestValueMessage", "RuntimeExceptionMessage", "UnknownRobotMessage", "UnknownMessage",
    "PrimaryMessage", "decode_primary", "encode_primary", "PrimaryDecoder", "PrimaryServer",
    "SUB_PACKAGES", "ROBOT_MESSAGES", "STATE_PERIOD",
]

PRIMARY_PORT = 30001
SECONDARY_PORT = 30002

ROBOT_STATE = 16
ROBOT_MESSAGE = 20

_HEADER = struct.Struct(">iB")  # message: int32 size, uint8 type
_SUB_HEADER = struct.Struct(">IB")  # sub-package: uint32 size, uint8 type
_MESSAGE_HEAD = struct.Struct(">QbB")  # robot message: timestamp, source, robot message type

STATE_PERIOD = 0.1
"""Period of the robot state on the primary and secondary interfaces (s): 10 Hz on CB3 and
e-Series (docs/controller-facts.md §7)."""

MAX_MESSAGE = 1 << 20
"""Largest message accepted, in bytes.

A full robot-state message is about 1.4 KB and text messages carry a line or two; the
largest messages seen in practice are program-state messages listing global variables
(a few KB). 1 MiB is far above all of them while a corrupt or desynchronised size field
(4 random bytes read as int32 exceed it with probability > 99.9 %) fails at once instead of
making the decoder buffer up to 2 GiB.
"""

T = TypeVar("T")


def _error(message: str, offset: int | None = None) -> ProtocolError:
    return ProtocolError(message, interface="primary", offset=offset)


# --- robot state sub-packages ---------------------------------------------------------------


@dataclass(frozen=True, kw_only=True)
class SubPackage:
    """Base of the typed robot-state sub-packages.

    ``variant`` names the layout (the first software version that sends it); ``extra``
    holds payload bytes beyond that layout, undecoded.
    """

    TYPE: ClassVar[int] = -1
    NAME: ClassVar[str] = "sub-package"
    VARIANTS: ClassVar[tuple[tuple[str, Table], ...]] = ()

    variant: str = ""
    extra: bytes = b""

    @classmethod
    def _choose(cls, size: int, offset: int) -> tuple[str, Table]:
        best = None
        for label, table in cls.VARIANTS:
            if table.size == size:
                return label, table
            if table.size < size and (best is None or table.size > best[1].size):
                best = (label, table)
        if best is None:
            label, table = min(cls.VARIANTS, key=lambda v: v[1].size)
            raise _error(f"{cls.NAME} sub-package at offset {offset} has {size + 5} bytes; the "
                         f"shortest known layout ({label}) has {table.size + 5}", offset)
        return best

    @classmethod
    def decode(cls: type[T], payload: bytes, offset: int = 0) -> T:
        """The sub-package from its payload (the bytes after its 5-byte header);
        ``offset`` locates the sub-package in its message, for error messages."""
        label, table = cls._choose(len(payload), offset)  # type: ignore[attr-defined]
        values = table.unpack(payload)
        return cls(variant=label, extra=bytes(payload[table.size:]), **values)

    def _table(self) -> Table:
        for label, table in self.VARIANTS:
            if label == self.variant:
                return table
        known = ", ".join(label for label, _ in self.VARIANTS)
        raise _error(f"cannot encode {self.NAME}: unknown layout {self.variant!r} "
                     f"(known: {known})")

    def payload(self) -> bytes:
        """The bytes after the sub-package header."""
        table = self._table()
        return table.pack({name: getattr(self, name) for name in table.names},
                          self.NAME) + self.extra

    def encode(self) -> bytes:
        """The sub-package with its header."""
        body = self.payload()
        return _SUB_HEADER.pack(len(body) + _SUB_HEADER.size, self.TYPE) + body


def _variants(*layouts: tuple[str, tuple[Row | Group, ...]]) -> tuple[tuple[str, Table], ...]:
    """Layouts that extend each other: each label adds its rows to the previous ones."""
    out = []
    rows: tuple[Row | Group, ...] = ()
    for label, more in layouts:
        rows = rows + more
        out.append((label, Table(rows)))
    return tuple(out)


def _rows(spec: str) -> tuple[Row, ...]:
    """Rows from ``"name:fmt name:fmt:count …"``."""
    rows = []
    for word in spec.split():
        parts = word.split(":")
        rows.append(Row(parts[0], parts[1], int(parts[2]) if len(parts) > 2 else 1))
    return tuple(rows)


Vector = tuple[float, ...]


@dataclass(frozen=True, kw_only=True)
class RobotModeData(SubPackage):
    """ROBOT_MODE_DATA (0). ``timestamp`` counts controller time; ``robot_mode`` (−1 …
    8: NO_CONTROLLER … UPDATING_FIRMWARE, 7 = RUNNING), ``control_mode`` (0 position,
    1 teach, 2 force, 3 torque) are ints; speed fractions are 0..1."""

    TYPE = 0
    NAME = "robot mode data"
    VARIANTS = _variants(
        ("3.0", _rows("timestamp:Q is_real_robot_connected:? is_real_robot_enabled:? "
                      "is_robot_power_on:? is_emergency_stopped:? is_protective_stopped:? "
                      "is_program_running:? is_program_paused:? robot_mode:b control_mode:B "
                      "target_speed_fraction:d speed_scaling:d")),
        ("3.2", _rows("target_speed_fraction_limit:d")),
        ("3.5", _rows("reserved:B")),
    )

    timestamp: int = 0
    is_real_robot_connected: bool = False
    is_real_robot_enabled: bool = False
    is_robot_power_on: bool = False
    is_emergency_stopped: bool = False
    is_protective_stopped: bool = False
    is_program_running: bool = False
    is_program_paused: bool = False
    robot_mode: int = 0
    control_mode: int = 0
    target_speed_fraction: float = 0.0
    speed_scaling: float = 0.0
    target_speed_fraction_limit: float | None = None
    reserved: int | None = None


@dataclass(frozen=True, kw_only=True)
class JointData(SubPackage):
    """JOINT_DATA (1): per joint (base … wrist 3) position [rad], target position [rad],
    speed [rad/s], current [A], voltage [V], motor and micro temperatures [°C] and
    ``joint_mode`` (253 RUNNING, 255 IDLE, …)."""

    TYPE = 1
    NAME = "joint data"
    VARIANTS = _variants(("3.0", (Group(6, _rows(
        "q_actual:d q_target:d qd_actual:d i_actual:f v_actual:f t_motor:f t_micro:f "
        "joint_mode:B")),)))

    q_actual: Vector = ()
    q_target: Vector = ()
    qd_actual: Vector = ()
    i_actual: Vector = ()
    v_actual: Vector = ()
    t_motor: Vector = ()
    t_micro: Vector = ()
    joint_mode: tuple[int, ...] = ()


@dataclass(frozen=True, kw_only=True)
class ToolData(SubPackage):
    """TOOL_DATA (2): tool analog inputs (``analog_in[2]``/``[3]``) [V or A], tool voltage
    [V], output voltage setting [V], current [A], temperature [°C], ``tool_mode``."""

    TYPE = 2
    NAME = "tool data"
    VARIANTS = _variants(("3.0", _rows(
        "analog_input_range_2:B analog_input_range_3:B analog_input_2:d analog_input_3:d "
        "tool_voltage_48v:f tool_output_voltage:B tool_current:f tool_temperature:f "
        "tool_mode:B")))

    analog_input_range_2: int = 0
    analog_input_range_3: int = 0
    analog_input_2: float = 0.0
    analog_input_3: float = 0.0
    tool_voltage_48v: float = 0.0
    tool_output_voltage: int = 0
    tool_current: float = 0.0
    tool_temperature: float = 0.0
    tool_mode: int = 0


_MASTERBOARD_HEAD = Table(_rows(
    "digital_input_bits:I digital_output_bits:I analog_input_range_0:B analog_input_range_1:B "
    "analog_input_0:d analog_input_1:d analog_output_domain_0:b analog_output_domain_1:b "
    "analog_output_0:d analog_output_1:d masterboard_temperature:f robot_voltage_48v:f "
    "robot_current:f master_io_current:f safety_mode:B in_reduced_mode:? "
    "euromap67_installed:?"))
_EUROMAP = Table(_rows("euromap_input_bits:I euromap_output_bits:I euromap_voltage_24v:f "
                       "euromap_current:f"))


@dataclass(frozen=True, kw_only=True)
class MasterboardData(SubPackage):
    """MASTERBOARD_DATA (3): control-box I/O (bit masks as ints, analog values in V or A),
    temperature [°C], 48 V supply [V] and currents [A], ``safety_mode``; the Euromap 67
    fields only when ``euromap67_installed``. 3.2+ adds the operational-mode selector and
    three-position enabling device inputs, e-Series one reserved byte more.

    The variant's table (``VARIANTS``) describes the part after the Euromap fields.
    """

    TYPE = 3
    NAME = "masterboard data"
    VARIANTS = _variants(
        ("3.0", _rows("reserved_1:I")),
        ("3.2", _rows("operational_mode_selector_input:B three_position_enabling_device_input:?")),
        ("5.0", _rows("reserved_2:B")),
    )

    digital_input_bits: int = 0
    digital_output_bits: int = 0
    analog_input_range_0: int = 0
    analog_input_range_1: int = 0
    analog_input_0: float = 0.0
    analog_input_1: float = 0.0
    analog_output_domain_0: int = 0
    analog_output_domain_1: int = 0
    analog_output_0: float = 0.0
    analog_output_1: float = 0.0
    masterboard_temperature: float = 0.0
    robot_voltage_48v: float = 0.0
    robot_current: float = 0.0
    master_io_current: float = 0.0
    safety_mode: int = 0
    in_reduced_mode: bool = False
    euromap67_installed: bool = False
    euromap_input_bits: int | None = None
    euromap_output_bits: int | None = None
    euromap_voltage_24v: float | None = None
    euromap_current: float | None = None
    reserved_1: int = 0
    operational_mode_selector_input: int | None = None
    three_position_enabling_device_input: bool | None = None
    reserved_2: int | None = None

    @classmethod
    def decode(cls, payload: bytes, offset: int = 0) -> MasterboardData:
        head = _MASTERBOARD_HEAD
        if len(payload) < head.size:
            raise _error(f"masterboard data sub-package at offset {offset} has "
                         f"{len(payload) + 5} bytes; it needs at least {head.size + 5 + 4}",
                         offset)
        values = head.unpack(payload)
        pos = head.size
        if values["euromap67_installed"]:
            if len(payload) < pos + _EUROMAP.size:
                raise _error(f"masterboard data at offset {offset} says a Euromap 67 interface "
                             f"is installed but has no room for its {_EUROMAP.size} bytes",
                             offset + 5 + pos)
            values.update(_EUROMAP.unpack(payload, pos))
            pos += _EUROMAP.size
        label, table = cls._choose(len(payload) - pos, offset)
        values.update(table.unpack(payload, pos))
        return cls(variant=label, extra=bytes(payload[pos + table.size:]), **values)

    def payload(self) -> bytes:
        head = _MASTERBOARD_HEAD.pack({n: getattr(self, n) for n in _MASTERBOARD_HEAD.names},
                                      self.NAME)
        if self.euromap67_installed:
            head += _EUROMAP.pack({n: getattr(self, n) for n in _EUROMAP.names}, self.NAME)
        table = self._table()
        return head + table.pack({n: getattr(self, n) for n in table.names},
                                 self.NAME) + self.extra


@dataclass(frozen=True, kw_only=True)
class CartesianInfo(SubPackage):
    """CARTESIAN_INFO (4): the TCP pose (x, y, z, rx, ry, rz) [m, rad] in the Base frame;
    from 3.2 also the active TCP offset from the flange."""

    TYPE = 4
    NAME = "cartesian info"
    VARIANTS = _variants(("3.0", _rows("tcp_pose:d:6")), ("3.2", _rows("tcp_offset:d:6")))

    tcp_pose: Vector = ()
    tcp_offset: Vector | None = None


@dataclass(frozen=True, kw_only=True)
class KinematicsInfo(SubPackage):
    """KINEMATICS_INFO (5): the robot's calibration — per joint checksum and the
    calibrated DH parameters θ [rad], a [m], d [m], α [rad] (nominal plus the robot's
    deltas) — and ``calibration_status``. Size 225 bytes, so the status is a uint32
    (UR's table says uint8, which would leave 3 bytes unexplained)."""

    TYPE = 5
    NAME = "kinematics info"
    VARIANTS = _variants(("3.0", _rows(
        "checksum:I:6 dh_theta:d:6 dh_a:d:6 dh_d:d:6 dh_alpha:d:6 calibration_status:I")))

    checksum: tuple[int, ...] = ()
    dh_theta: Vector = ()
    dh_a: Vector = ()
    dh_d: Vector = ()
    dh_alpha: Vector = ()
    calibration_status: int = 0


@dataclass(frozen=True, kw_only=True)
class ConfigurationData(SubPackage):
    """CONFIGURATION_DATA (6): joint position limits [rad], speed [rad/s] and acceleration
    [rad/s²] limits, default joint/tool speeds and accelerations, equivalent radius [m],
    the DH parameters a, d [m], α, θ [rad], masterboard version, controller box type,
    ``robot_type`` (1 UR5, 2 UR10, 3 UR3, 4 UR16, …) and sub-type. e-Series appends two
    reserved int16."""

    TYPE = 6
    NAME = "configuration data"
    VARIANTS = _variants(
        ("3.0", (Group(6, _rows("joint_min_limit:d joint_max_limit:d")),
                 Group(6, _rows("joint_max_speed:d joint_max_acceleration:d")))
         + _rows("v_joint_default:d a_joint_default:d v_tool_default:d a_tool_default:d "
                 "eq_radius:d dh_a:d:6 dh_d:d:6 dh_alpha:d:6 dh_theta:d:6 "
                 "masterboard_version:i controller_box_type:i robot_type:i robot_sub_type:i")),
        ("5.0", _rows("reserved_1:h reserved_2:h")),
    )

    joint_min_limit: Vector = ()
    joint_max_limit: Vector = ()
    joint_max_speed: Vector = ()
    joint_max_acceleration: Vector = ()
    v_joint_default: float = 0.0
    a_joint_default: float = 0.0
    v_tool_default: float = 0.0
    a_tool_default: float = 0.0
    eq_radius: float = 0.0
    dh_a: Vector = ()
    dh_d: Vector = ()
    dh_alpha: Vector = ()
    dh_theta: Vector = ()
    masterboard_version: int = 0
    controller_box_type: int = 0
    robot_type: int = 0
    robot_sub_type: int = 0
    reserved_1: int | None = None
    reserved_2: int | None = None


@dataclass(frozen=True, kw_only=True)
class ForceModeData(SubPackage):
    """FORCE_MODE_DATA (7): the TCP wrench (Fx, Fy, Fz [N], Tx, Ty, Tz [N·m]) and the
    robot's dexterity."""

    TYPE = 7
    NAME = "force mode data"
    VARIANTS = _variants(("3.0", _rows("wrench:d:6 robot_dexterity:d")))

    wrench: Vector = ()
    robot_dexterity: float = 0.0


@dataclass(frozen=True, kw_only=True)
class AdditionalInfo(SubPackage):
    """ADDITIONAL_INFO (8): the freedrive ("teach") button on the pendant — pressed,
    enabled; e-Series adds freedrive enabled by I/O and a reserved byte. (CB3's documents
    call the first two ``teachButtonPressed`` / ``teachButtonEnabled``.)"""

    TYPE = 8
    NAME = "additional info"
    VARIANTS = _variants(
        ("3.2", _rows("freedrive_button_pressed:? freedrive_button_enabled:?")),
        ("5.0", _rows("io_enabled_freedrive:? reserved:B")),
    )

    freedrive_button_pressed: bool = False
    freedrive_button_enabled: bool = False
    io_enabled_freedrive: bool | None = None
    reserved: int | None = None


@dataclass(frozen=True, kw_only=True)
class _RawPackage(SubPackage):
    """A sub-package UR documents as internal: its payload is kept as bytes."""

    payload_bytes: bytes = b""

    @classmethod
    def decode(cls: type[T], payload: bytes, offset: int = 0) -> T:
        return cls(variant="raw", payload_bytes=bytes(payload))

    def payload(self) -> bytes:
        return self.payload_bytes


@dataclass(frozen=True, kw_only=True)
class CalibrationData(_RawPackage):
    """CALIBRATION_DATA (9): UR internal ("should be skipped"); kept raw."""

    TYPE = 9
    NAME = "calibration data"


@dataclass(frozen=True, kw_only=True)
class SafetyData(_RawPackage):
    """SAFETY_DATA (10): UR internal; kept raw."""

    TYPE = 10
    NAME = "safety data"


@dataclass(frozen=True, kw_only=True)
class ToolCommunicationInfo(SubPackage):
    """TOOL_COMM_INFO (11, e-Series): the tool's RS-485 settings — enabled, baud rate,
    parity (0 none, 1 odd, 2 even), stop bits, RX/TX idle characters."""

    TYPE = 11
    NAME = "tool communication info"
    VARIANTS = _variants(("5.0", _rows(
        "is_enabled:? baud_rate:I parity:I stop_bits:I rx_idle_chars:f tx_idle_chars:f")))

    is_enabled: bool = False
    baud_rate: int = 0
    parity: int = 0
    stop_bits: int = 0
    rx_idle_chars: float = 0.0
    tx_idle_chars: float = 0.0


@dataclass(frozen=True, kw_only=True)
class ToolModeInfo(SubPackage):
    """TOOL_MODE_INFO (12, e-Series): tool output mode and the modes of the two tool
    digital outputs."""

    TYPE = 12
    NAME = "tool mode info"
    VARIANTS = _variants(("5.0", _rows(
        "output_mode:B digital_output_mode_0:B digital_output_mode_1:B")))

    output_mode: int = 0
    digital_output_mode_0: int = 0
    digital_output_mode_1: int = 0


@dataclass(frozen=True, kw_only=True)
class UnknownPackage(SubPackage):
    """A sub-package of a type this module does not know, kept raw."""

    NAME = "unknown sub-package"

    type: int = 0
    payload_bytes: bytes = b""

    def payload(self) -> bytes:
        return self.payload_bytes

    def encode(self) -> bytes:
        return _SUB_HEADER.pack(len(self.payload_bytes) + _SUB_HEADER.size,
                                self.type) + self.payload_bytes


SUB_PACKAGES: dict[int, type[SubPackage]] = {cls.TYPE: cls for cls in (
    RobotModeData, JointData, ToolData, MasterboardData, CartesianInfo, KinematicsInfo,
    ConfigurationData, ForceModeData, AdditionalInfo, CalibrationData, SafetyData,
    ToolCommunicationInfo, ToolModeInfo)}
"""The typed sub-package classes by package type."""

P = TypeVar("P", bound=SubPackage)


@dataclass(frozen=True)
class RobotState:
    """A ROBOT_STATE message (16): its sub-packages in the order they came.

    ``state.get(JointData)`` gives one sub-package (or ``None`` if this message has none);
    the properties name the common ones.
    """

    packages: tuple[SubPackage, ...] = ()

    TYPE: ClassVar[int] = ROBOT_STATE

    def get(self, kind: type[P]) -> P | None:
        """The first sub-package of class ``kind``, or ``None``."""
        for package in self.packages:
            if type(package) is kind:
                return package
        return None

    @property
    def robot_mode_data(self) -> RobotModeData | None:
        return self.get(RobotModeData)

    @property
    def joint_data(self) -> JointData | None:
        return self.get(JointData)

    @property
    def cartesian_info(self) -> CartesianInfo | None:
        return self.get(CartesianInfo)

    @property
    def masterboard_data(self) -> MasterboardData | None:
        return self.get(MasterboardData)

    @property
    def kinematics_info(self) -> KinematicsInfo | None:
        return self.get(KinematicsInfo)

    @property
    def configuration_data(self) -> ConfigurationData | None:
        return self.get(ConfigurationData)

    def encode(self) -> bytes:
        body = b"".join(package.encode() for package in self.packages)
        return _frame(ROBOT_STATE, body)

    @classmethod
    def decode_body(cls, body: bytes) -> RobotState:
        packages = []
        pos = 0
        while pos < len(body):
            offset = _HEADER.size + pos
            if len(body) - pos < _SUB_HEADER.size:
                raise _error(f"robot state: {len(body) - pos} bytes left at offset {offset}, "
                             "too few for a 5-byte sub-package header", offset)
            size, kind = _SUB_HEADER.unpack_from(body, pos)
            if size < _SUB_HEADER.size or size > len(body) - pos:
                raise _error(f"robot state: sub-package of type {kind} at offset {offset} "
                             f"says {size} bytes; {len(body) - pos} remain in the message",
                             offset)
            payload = body[pos + _SUB_HEADER.size:pos + size]
            decoder = SUB_PACKAGES.get(kind)
            if decoder is None:
                packages.append(UnknownPackage(variant="raw", type=kind,
                                               payload_bytes=bytes(payload)))
            else:
                packages.append(decoder.decode(payload, offset))
            pos += size
        return cls(tuple(packages))


# --- robot messages ---------------------------------------------------------------------


@dataclass(frozen=True, kw_only=True)
class RobotMessage:
    """Base of the ROBOT_MESSAGE (20) kinds: ``timestamp`` (controller clock) and
    ``source`` (−2 robot interface, −3 RT machine, …, 7 controller, 8 RTDE)."""

    TYPE: ClassVar[int] = ROBOT_MESSAGE
    KIND: ClassVar[int] = -1
    NAME: ClassVar[str] = "robot message"
    MIN_BODY: ClassVar[int] = 0

    timestamp: int = 0
    source: int = 0

    @classmethod
    def _decode(cls, head: dict, body: bytes, offset: int) -> RobotMessage:
        raise NotImplementedError

    def _body(self) -> bytes:
        raise NotImplementedError

    def encode(self) -> bytes:
        try:
            head = _MESSAGE_HEAD.pack(self.timestamp, self.source, self.KIND)
        except struct.error as exc:
            raise _error(f"cannot encode {self.NAME}: {exc}") from None
        return _frame(ROBOT_MESSAGE, head + self._body())


def _pack(fmt: str, what: str, *values: object) -> bytes:
    try:
        return struct.pack(fmt, *values)
    except struct.error as exc:
        raise _error(f"cannot encode {what}: {exc}") from None


def _sized_text(text: str, what: str, size_format: str, limit: int) -> bytes:
    data = text_bytes(text, what, "primary")
    if len(data) > limit:
        raise _error(f"{what} is {len(data)} bytes; its size field holds at most {limit}")
    return struct.pack(size_format, len(data)) + data


@dataclass(frozen=True, kw_only=True)
class TextMessage(RobotMessage):
    """TEXT (0): a line of text (``textmsg`` output, …)."""

    KIND = 0
    NAME = "text message"
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        return cls(**head, text=read_text(body))

    def _body(self):
        return text_bytes(self.text, "text", "primary")


@dataclass(frozen=True, kw_only=True)
class ProgramLabelMessage(RobotMessage):
    """PROGRAM_LABEL (1): ``id`` and text of the program label reached."""

    KIND = 1
    NAME = "program label message"
    MIN_BODY = 4
    id: int = 0
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        (label,) = struct.unpack_from(">i", body)
        return cls(**head, id=label, text=read_text(body[4:]))

    def _body(self):
        return _pack(">i", self.NAME, self.id) + text_bytes(self.text, "text", "primary")


_POPUP = struct.Struct(">II???")


@dataclass(frozen=True, kw_only=True)
class PopupMessage(RobotMessage):
    """POPUP (2): a popup shown on the pendant — ``request_id``, ``requested_type``
    (0 bool … 5 joint vector, 8 none: a plain popup), warning/error/blocking flags, title
    and text."""

    KIND = 2
    NAME = "popup message"
    MIN_BODY = _POPUP.size + 1
    request_id: int = 0
    requested_type: int = 8
    warning: bool = False
    error: bool = False
    blocking: bool = False
    title: str = ""
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        request_id, requested_type, warning, error, blocking = _POPUP.unpack_from(body)
        title_size = body[_POPUP.size]
        start = _POPUP.size + 1
        if len(body) < start + title_size:
            raise _error(f"popup message at offset {offset}: title of {title_size} bytes "
                         f"does not fit in the {len(body) - start} bytes left", offset)
        return cls(**head, request_id=request_id, requested_type=requested_type,
                   warning=warning, error=error, blocking=blocking,
                   title=read_text(body[start:start + title_size]),
                   text=read_text(body[start + title_size:]))

    def _body(self):
        return (_pack(">II???", self.NAME, self.request_id, self.requested_type, self.warning,
                      self.error, self.blocking)
                + _sized_text(self.title, "popup title", ">B", 255)
                + text_bytes(self.text, "popup text", "primary"))


def _printable(data: bytes) -> bool:
    return all(0x20 <= b < 0x7F for b in data)


@dataclass(frozen=True, kw_only=True)
class VersionMessage(RobotMessage):
    """VERSION (3), the first message on every connection: project name (``URControl``),
    major, minor, bugfix and build number, build date.

    Before 3.12 the message had no build number (``build_number`` is then ``None``); the two
    are told apart by the four bytes after the bugfix number, which are text (the date) in
    the old layout — so a build number whose four bytes are all printable ASCII
    (≥ 0x20202020, far above real build numbers) cannot be represented.
    """

    KIND = 3
    NAME = "version message"
    MIN_BODY = 1
    project_name: str = "URControl"
    major: int = 0
    minor: int = 0
    bugfix: int = 0
    build_number: int | None = 0
    build_date: str = ""

    @property
    def version(self) -> tuple[int, int, int]:
        """(major, minor, bugfix)."""
        return (self.major, self.minor, self.bugfix)

    @classmethod
    def _decode(cls, head, body, offset):
        (name_size,) = struct.unpack_from(">b", body)
        if name_size < 0 or len(body) < 1 + name_size + 6:
            raise _error(f"version message at offset {offset}: project name of {name_size} "
                         f"bytes and the version numbers do not fit in {len(body)} bytes",
                         offset)
        pos = 1 + name_size
        major, minor, bugfix = struct.unpack_from(">BBi", body, pos)
        pos += 6
        rest = body[pos:]
        build: int | None = None
        if len(rest) >= 4 and not _printable(rest[:4]):
            (build,) = struct.unpack_from(">i", rest)
            rest = rest[4:]
        return cls(**head, project_name=read_text(body[1:1 + name_size]), major=major,
                   minor=minor, bugfix=bugfix, build_number=build, build_date=read_text(rest))

    def _body(self):
        out = _sized_text(self.project_name, "project name", ">b", 127)
        out += _pack(">BBi", self.NAME, self.major, self.minor, self.bugfix)
        date = text_bytes(self.build_date, "build date", "primary")
        if self.build_number is not None:
            number = _pack(">i", self.NAME, self.build_number)
            if _printable(number):
                raise _error(f"build number {self.build_number} would read as text (the "
                             "pre-3.12 layout); it cannot be encoded")
            out += number
        elif len(date) >= 4 and not _printable(date[:4]):
            raise _error("a version message without build number (pre-3.12) needs a build "
                         "date that starts with four printable characters")
        return out + date


@dataclass(frozen=True, kw_only=True)
class SafetyModeMessage(RobotMessage):
    """SAFETY_MODE (5): ``code``, ``argument``, ``safety_mode_type`` (1 NORMAL … 3
    PROTECTIVE_STOP …) and a report value whose type ``report_data_type`` gives
    (2 int32, 3 float32, otherwise uint32)."""

    KIND = 5
    NAME = "safety mode message"
    MIN_BODY = 17
    code: int = 0
    argument: int = 0
    safety_mode_type: int = 0
    report_data_type: int = 0
    report_data: int | float = 0

    @classmethod
    def _decode(cls, head, body, offset):
        code, argument, mode, data_type = struct.unpack_from(">iiBI", body)
        fmt = {2: ">i", 3: ">f"}.get(data_type, ">I")
        (data,) = struct.unpack_from(fmt, body, 13)
        return cls(**head, code=code, argument=argument, safety_mode_type=mode,
                   report_data_type=data_type, report_data=data)

    def _body(self):
        fmt = {2: ">i", 3: ">f"}.get(self.report_data_type, ">I")
        return (_pack(">iiBI", self.NAME, self.code, self.argument, self.safety_mode_type,
                      self.report_data_type) + _pack(fmt, self.NAME, self.report_data))


@dataclass(frozen=True, kw_only=True)
class ErrorCodeMessage(RobotMessage):
    """ERROR_CODE (6, "robot comm message"): ``code`` and ``argument`` (the C…A… codes of
    the pendant's log), ``report_level`` (0 debug … 4 fault), data type and value, text."""

    KIND = 6
    NAME = "error code message"
    MIN_BODY = 20
    code: int = 0
    argument: int = 0
    report_level: int = 0
    data_type: int = 0
    data: int = 0
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        code, argument, level, data_type, data = struct.unpack_from(">iiiII", body)
        return cls(**head, code=code, argument=argument, report_level=level,
                   data_type=data_type, data=data, text=read_text(body[20:]))

    def _body(self):
        return (_pack(">iiiII", self.NAME, self.code, self.argument, self.report_level,
                      self.data_type, self.data) + text_bytes(self.text, "text", "primary"))


@dataclass(frozen=True, kw_only=True)
class KeyMessage(RobotMessage):
    """KEY (7): ``code``, ``argument``, title and text of a key event (program started,
    stopped, …)."""

    KIND = 7
    NAME = "key message"
    MIN_BODY = 9
    code: int = 0
    argument: int = 0
    title: str = ""
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        code, argument, title_size = struct.unpack_from(">iiB", body)
        if len(body) < 9 + title_size:
            raise _error(f"key message at offset {offset}: title of {title_size} bytes does "
                         f"not fit in the {len(body) - 9} bytes left", offset)
        return cls(**head, code=code, argument=argument,
                   title=read_text(body[9:9 + title_size]), text=read_text(body[9 + title_size:]))

    def _body(self):
        return (_pack(">ii", self.NAME, self.code, self.argument)
                + _sized_text(self.title, "key title", ">B", 255)
                + text_bytes(self.text, "key text", "primary"))


@dataclass(frozen=True, kw_only=True)
class RequestValueMessage(RobotMessage):
    """REQUEST_VALUE (9): the program asks the operator for a value (``request_id``,
    ``requested_type`` 0 bool, 1 int, 2 float, 3 string, 4 pose, 5 joint vector) with a
    prompt ``text``."""

    KIND = 9
    NAME = "request value message"
    MIN_BODY = 8
    request_id: int = 0
    requested_type: int = 0
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        request_id, requested_type = struct.unpack_from(">II", body)
        return cls(**head, request_id=request_id, requested_type=requested_type,
                   text=read_text(body[8:]))

    def _body(self):
        return (_pack(">II", self.NAME, self.request_id, self.requested_type)
                + text_bytes(self.text, "text", "primary"))


@dataclass(frozen=True, kw_only=True)
class RuntimeExceptionMessage(RobotMessage):
    """RUNTIME_EXCEPTION (10): the running program failed at ``line``:``column`` (1-based,
    in the script the controller received) with ``text`` (e.g. ``name 'x' is not
    defined``)."""

    KIND = 10
    NAME = "runtime exception message"
    MIN_BODY = 8
    line: int = 0
    column: int = 0
    text: str = ""

    @classmethod
    def _decode(cls, head, body, offset):
        line, column = struct.unpack_from(">II", body)
        return cls(**head, line=line, column=column, text=read_text(body[8:]))

    def _body(self):
        return (_pack(">II", self.NAME, self.line, self.column)
                + text_bytes(self.text, "text", "primary"))


@dataclass(frozen=True, kw_only=True)
class UnknownRobotMessage(RobotMessage):
    """A robot message of a kind this module does not decode, kept raw."""

    NAME = "unknown robot message"
    kind: int = 0
    body: bytes = b""

    def encode(self) -> bytes:
        head = _pack(">QbB", self.NAME, self.timestamp, self.source, self.kind)
        return _frame(ROBOT_MESSAGE, head + self.body)


ROBOT_MESSAGES: dict[int, type[RobotMessage]] = {cls.KIND: cls for cls in (
    TextMessage, ProgramLabelMessage, PopupMessage, VersionMessage, SafetyModeMessage,
    ErrorCodeMessage, KeyMessage, RequestValueMessage, RuntimeExceptionMessage)}
"""The typed robot-message classes by robot message type."""


def _decode_robot_message(body: bytes) -> RobotMessage:
    if len(body) < _MESSAGE_HEAD.size:
        raise _error(f"robot message of {len(body) + _HEADER.size} bytes is shorter than its "
                     f"{_MESSAGE_HEAD.size + _HEADER.size}-byte header", _HEADER.size)
    timestamp, source, kind = _MESSAGE_HEAD.unpack_from(body)
    rest = body[_MESSAGE_HEAD.size:]
    head = {"timestamp": timestamp, "source": source}
    cls = ROBOT_MESSAGES.get(kind)
    if cls is None:
        return UnknownRobotMessage(**head, kind=kind, body=bytes(rest))
    offset = _HEADER.size + _MESSAGE_HEAD.size
    if len(rest) < cls.MIN_BODY:
        raise _error(f"{cls.NAME} of {len(body) + _HEADER.size} bytes: its fields need at "
                     f"least {cls.MIN_BODY + offset}", offset)
    return cls._decode(head, bytes(rest), offset)


@dataclass(frozen=True)
class UnknownMessage:
    """A message of a type other than robot state (16) or robot message (20) — e.g. 5
    MODBUS_INFO, 22 HMC, 23 safety setup broadcast, 25 program state — kept raw."""

    type: int
    body: bytes = b""

    def encode(self) -> bytes:
        return _frame(self.type, self.body)


PrimaryMessage = RobotState | RobotMessage | UnknownMessage


def _frame(kind: int, body: bytes) -> bytes:
    size = _HEADER.size + len(body)
    if size > MAX_MESSAGE:
        raise _error(f"message of {size} bytes exceeds the {MAX_MESSAGE}-byte limit")
    try:
        return _HEADER.pack(size, kind) + body
    except struct.error as exc:
        raise _error(f"cannot encode message type {kind}: {exc}") from None


def _check_size(size: int) -> None:
    if size < _HEADER.size or size > MAX_MESSAGE:
        raise _error(f"message size field says {size} bytes; a primary message has "
                     f"{_HEADER.size}..{MAX_MESSAGE}", 0)


def _decode_body(kind: int, body: bytes) -> PrimaryMessage:
    if kind == ROBOT_STATE:
        return RobotState.decode_body(body)
    if kind == ROBOT_MESSAGE:
        return _decode_robot_message(body)
    return UnknownMessage(kind, bytes(body))


def decode_primary(message: bytes) -> PrimaryMessage:
    """Decode exactly one complete message (size field included)."""
    if len(message) < _HEADER.size:
        raise _error(f"{len(message)} bytes cannot hold the 5-byte message header", 0)
    size, kind = _HEADER.unpack_from(message)
    _check_size(size)
    if size != len(message):
        raise _error(f"size field says {size} bytes but the message has {len(message)}", 0)
    return _decode_body(kind, memoryview(message)[_HEADER.size:].tobytes())


def encode_primary(message: PrimaryMessage) -> bytes:
    """The bytes of any message (the simulator's side)."""
    return message.encode()


class PrimaryDecoder:
    """Turns the primary/secondary byte stream into messages.

    ``receive_data(bytes)`` buffers what arrived; ``next_message()`` returns the next
    complete message or ``None`` (h11's ``next_event`` pattern). ``feed(bytes)`` does both
    and returns every complete message.

    A malformed message inside correct framing raises :class:`ProtocolError` once and is
    consumed: calling ``next_message()`` again continues with the following message. A
    broken size field loses the framing: the decoder then refuses all further input.

    ``version`` is (major, minor, bugfix) from the last :class:`VersionMessage`, or ``None``.
    """

    def __init__(self) -> None:
        self._buffer = bytearray()
        self._broken: ProtocolError | None = None
        self.version: tuple[int, int, int] | None = None

    @property
    def pending(self) -> int:
        """Bytes of an incomplete message held back."""
        return len(self._buffer)

    def receive_data(self, data: bytes) -> None:
        """Add received bytes."""
        if self._broken is not None:
            raise _error(f"stream already failed ({self._broken.message}); reconnect")
        self._buffer += data

    def next_message(self) -> PrimaryMessage | None:
        """The next complete message, or ``None`` until more bytes arrive."""
        if self._broken is not None:
            raise _error(f"stream already failed ({self._broken.message}); reconnect")
        if len(self._buffer) < _HEADER.size:
            return None
        size, kind = _HEADER.unpack_from(self._buffer)
        try:
            _check_size(size)
        except ProtocolError as exc:
            self._broken = exc
            raise
        if len(self._buffer) < size:
            return None
        body = bytes(self._buffer[_HEADER.size:size])
        del self._buffer[:size]
        message = _decode_body(kind, body)
        if isinstance(message, VersionMessage):
            self.version = message.version
        return message

    def __iter__(self) -> Iterator[PrimaryMessage]:
        while (message := self.next_message()) is not None:
            yield message

    def feed(self, data: bytes) -> list[PrimaryMessage]:
        """Add received bytes; return every message they complete, oldest first."""
        self.receive_data(data)
        return list(self)



# --- the controller's side ------------------------------------------------------------------


class PrimaryServer:
    """The controller's side of one primary or secondary connection (ports 30001 / 30002,
    read-only 30011 / 30012): no socket, no clock. The host (the virtual controller, a
    test's fake controller) writes the bytes the methods return and passes its own time.

    * :meth:`greeting`: the connection's first bytes, the VERSION robot message, then the
      robot state it starts with (the controller's first one carries kinematics and
      configuration).
    * :meth:`receive_data`: the client's script text cut into programs as the controller cuts
      it (:class:`~urdsl.protocol.script_framing.ScriptFramer`); a read-only port takes none.
      Raises :class:`ProtocolError` for a program or line over ``script_limit`` bytes.
    * :meth:`state_due`: whether the periodic robot state is due at the host's time ``now``
      (s), every ``period`` s (10 Hz), on a grid of the host's clock, so that a host serving
      many connections encodes each state once.
    * :meth:`robot_message`: a robot message's bytes on the primary interface; the
      secondary carries none (``b""``).

    Messages are objects (:class:`RobotState`, :class:`RobotMessage`) or bytes already
    encoded (a host serving many clients encodes once).
    """

    def __init__(self, version: VersionMessage | bytes, *, interface: str = "primary",
                 read_only: bool = False, period: float = STATE_PERIOD,
                 script_limit: int = MAX_SCRIPT_BYTES) -> None:
        if interface not in ("primary", "secondary"):
            raise ValueError(f"interface is 'primary' or 'secondary', not {interface!r}")
        if not period > 0:
            raise ValueError(f"the state period must be > 0 s, not {period!r}")
        self.interface = interface
        self.read_only = read_only
        self.period = period
        self._version = _message_bytes(version)
        self.framer = None if read_only else ScriptFramer(script_limit, interface)
        """The script text's framer (``None`` on a read-only port); ``framer.pending``: a
        program has begun and not ended (cut off, never run, if the connection ends now)."""
        self._next_slot: int | None = None  # the grid point (in periods) of the next state

    def greeting(self, state: RobotState | bytes | None = None,
                 now: float | None = None) -> bytes:
        """The VERSION message, then ``state`` when given. With ``now`` (s) the periodic
        state counts from there (the next is due at the next grid point after ``now``);
        without, the first :meth:`state_due` call is due."""
        if now is not None:
            self._next_slot = self._slot(now) + 1
        return self._version + (b"" if state is None else _message_bytes(state))

    def receive_data(self, data: bytes) -> list[ScriptChunk]:
        """The programs ``data`` completes, in order (none on a read-only port)."""
        return [] if self.framer is None else self.framer.feed(data)

    def state_due(self, now: float) -> bool:
        """True when the robot state is due at ``now`` (s); the next one is then due at the
        following grid point (states a host missed by falling behind are not owed)."""
        slot = self._slot(now)
        if self._next_slot is not None and slot < self._next_slot:
            return False
        self._next_slot = slot + 1
        return True

    def until_state(self, now: float) -> float:
        """Seconds from ``now`` until the robot state is due (0 when it is)."""
        if self._next_slot is None or self._slot(now) >= self._next_slot:
            return 0.0
        return max(self._next_slot * self.period - now, 0.0)

    def robot_message(self, message: RobotMessage | bytes) -> bytes:
        """``message``'s bytes on the primary interface; ``b""`` on the secondary."""
        return _message_bytes(message) if self.interface == "primary" else b""

    def _slot(self, now: float) -> int:
        """The grid point at or before ``now`` (a billionth of a period forgiven: 5.1 s is in the
        51st period of 0.1 s, though 5.1 / 0.1 < 51 in floating point)."""
        return math.floor(now / self.period + 1e-9)


def _message_bytes(message: PrimaryMessage | bytes) -> bytes:
    return bytes(message) if isinstance(message, bytes | bytearray) else message.encode()
