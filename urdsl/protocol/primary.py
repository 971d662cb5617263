"""The primary and secondary interfaces (ports 30001/30002, read-only 30011/30012).

Framing (UR_FACTS.md §4.1): ``int32 size`` (the whole message, header included) · ``uint8
type`` · body. Type 16 is the robot state, a sequence of sub-packages ``uint32 size`` · ``uint8
type`` · data; type 20 a robot message (version, text, runtime exception, …). Unknown message
types and sub-packages are skipped by their size and kept as raw bytes; known sub-packages
longer than their documented layout (newer software appends fields) keep the extra bytes.

Decoding follows CB3 3.x and e-Series 5.x; where the layouts differ by version (robot mode
data 38/46/47 bytes) the sub-package size tells which.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass, field

from .errors import ProtocolError

__all__ = [
    "ROBOT_STATE", "ROBOT_MESSAGE", "PrimaryDecoder", "decode_message", "RobotState",
    "RobotModeData", "JointData", "ToolData", "MasterboardData", "CartesianInfo",
    "KinematicsInfo", "ForceModeData", "RawPackage", "VersionMessage", "TextMessage",
    "RuntimeExceptionMessage", "KeyMessage", "PopupMessage", "SafetyModeMessage",
    "LabelMessage", "ErrorCodeMessage", "RawMessage", "encode_robot_state",
    "encode_robot_message", "MAX_MESSAGE",
]

ROBOT_STATE = 16
ROBOT_MESSAGE = 20

MAX_MESSAGE = 1 << 20
"""Largest message accepted (bytes). A robot state is about 1.5 kB, messages carry texts of
a few hundred bytes; 1 MiB leaves room for anything a controller sends and catches a corrupt
size before buffering more."""


# ---- robot state sub-packages ---------------------------------------------------------------


@dataclass(frozen=True)
class RobotModeData:
    """Sub-package 0. ``robot_mode``: −1…8 (UR_FACTS §4.4); speeds are fractions."""

    timestamp: int
    real_robot_connected: bool
    real_robot_enabled: bool
    robot_power_on: bool
    emergency_stopped: bool
    protective_stopped: bool
    program_running: bool
    program_paused: bool
    robot_mode: int
    control_mode: int
    target_speed_fraction: float
    speed_scaling: float
    target_speed_fraction_limit: float | None = None
    extra: bytes = b""


_ROBOT_MODE = struct.Struct(">Q???????bBdd")


@dataclass(frozen=True)
class JointData:
    """Sub-package 1: per joint q actual/target (rad), qd actual (rad/s), current (A),
    voltage (V), motor and micro temperatures (°C), joint mode."""

    q_actual: tuple[float, ...]
    q_target: tuple[float, ...]
    qd_actual: tuple[float, ...]
    current: tuple[float, ...]
    voltage: tuple[float, ...]
    motor_temperature: tuple[float, ...]
    micro_temperature: tuple[float, ...]
    joint_mode: tuple[int, ...]
    extra: bytes = b""


_JOINT = struct.Struct(">dddffffB")


@dataclass(frozen=True)
class ToolData:
    """Sub-package 2: tool analog inputs, voltage (V), output voltage, current (A),
    temperature (°C), mode."""

    analog_input_range: tuple[int, int]
    analog_input: tuple[float, float]
    voltage_48v: float
    output_voltage: int
    current: float
    temperature: float
    mode: int
    extra: bytes = b""


_TOOL = struct.Struct(">BBddfBffB")


@dataclass(frozen=True)
class MasterboardData:
    """Sub-package 3 (its fixed front part): I/O bit masks, analog I/O, safety mode."""

    digital_input_bits: int
    digital_output_bits: int
    analog_input_range: tuple[int, int]
    analog_input: tuple[float, float]
    analog_output_domain: tuple[int, int]
    analog_output: tuple[float, float]
    temperature: float
    robot_voltage_48v: float
    robot_current: float
    io_current: float
    safety_mode: int
    in_reduced_mode: bool
    extra: bytes = b""


_MASTERBOARD = struct.Struct(">IIBBddbbddffffB?")


@dataclass(frozen=True)
class CartesianInfo:
    """Sub-package 4: the TCP pose in Base (m, rotation vector rad) and the TCP offset."""

    tcp_pose: tuple[float, ...]
    tcp_offset: tuple[float, ...] | None = None
    extra: bytes = b""


@dataclass(frozen=True)
class KinematicsInfo:
    """Sub-package 5: calibration checksums and the calibrated DH parameters (rad, m)."""

    checksums: tuple[int, ...]
    dh_theta: tuple[float, ...]
    dh_a: tuple[float, ...]
    dh_d: tuple[float, ...]
    dh_alpha: tuple[float, ...]
    calibration_status: int
    extra: bytes = b""


_KINEMATICS = struct.Struct(">6I24dI")


@dataclass(frozen=True)
class ForceModeData:
    """Sub-package 7: the wrench (N, N·m) and robot dexterity."""

    wrench: tuple[float, ...]
    dexterity: float
    extra: bytes = b""


@dataclass(frozen=True)
class RawPackage:
    """A sub-package kept as bytes (configuration, additional info, safety, tool
    communication, calibration, unknown types)."""

    type: int
    data: bytes


@dataclass(frozen=True)
class RobotState:
    """Message 16: the sub-packages by type (a typed object or :class:`RawPackage`)."""

    packages: dict = field(default_factory=dict)

    def get(self, kind: type):
        """The sub-package of class ``kind``, or None."""
        return next((p for p in self.packages.values() if isinstance(p, kind)), None)


def _decode_package(kind: int, data: bytes):
    try:
        if kind == 0 and len(data) >= _ROBOT_MODE.size:
            values = _ROBOT_MODE.unpack_from(data)
            rest = data[_ROBOT_MODE.size:]
            limit = None
            if len(rest) >= 8:  # 3.2+ adds the target speed fraction limit
                (limit,) = struct.unpack_from(">d", rest)
                rest = rest[8:]
            return RobotModeData(*values, limit, bytes(rest))
        if kind == 1 and len(data) >= 6 * _JOINT.size:
            joints = [_JOINT.unpack_from(data, i * _JOINT.size) for i in range(6)]
            columns = list(zip(*joints, strict=True))
            return JointData(*(tuple(c) for c in columns), bytes(data[6 * _JOINT.size:]))
        if kind == 2 and len(data) >= _TOOL.size:
            v = _TOOL.unpack_from(data)
            return ToolData((v[0], v[1]), (v[2], v[3]), v[4], v[5], v[6], v[7], v[8],
                            bytes(data[_TOOL.size:]))
        if kind == 3 and len(data) >= _MASTERBOARD.size:
            v = _MASTERBOARD.unpack_from(data)
            return MasterboardData(v[0], v[1], (v[2], v[3]), (v[4], v[5]), (v[6], v[7]),
                                   (v[8], v[9]), v[10], v[11], v[12], v[13], v[14], v[15],
                                   bytes(data[_MASTERBOARD.size:]))
        if kind == 4 and len(data) >= 48:
            pose = struct.unpack_from(">6d", data)
            offset = struct.unpack_from(">6d", data, 48) if len(data) >= 96 else None
            return CartesianInfo(pose, offset, bytes(data[96 if offset else 48:]))
        if kind == 5 and len(data) >= _KINEMATICS.size - 3:
            if len(data) >= _KINEMATICS.size:
                v = _KINEMATICS.unpack_from(data)
                status, used = v[30], _KINEMATICS.size
            else:  # the documented uint8 calibration status
                v = struct.unpack_from(">6I24dB", data)
                status, used = v[30], _KINEMATICS.size - 3
            return KinematicsInfo(v[0:6], v[6:12], v[12:18], v[18:24], v[24:30], status,
                                  bytes(data[used:]))
        if kind == 7 and len(data) >= 56:
            v = struct.unpack_from(">7d", data)
            return ForceModeData(v[:6], v[6], bytes(data[56:]))
    except struct.error as error:  # pragma: no cover - lengths are checked above
        raise ProtocolError(f"robot state sub-package {kind}: {error}") from None
    return RawPackage(kind, bytes(data))


def _decode_state(body: bytes) -> RobotState:
    packages: dict = {}
    offset = 0
    while offset < len(body):
        if len(body) - offset < 5:
            raise ProtocolError(f"robot state: {len(body) - offset} stray bytes at offset "
                                f"{offset + 5} (a sub-package header has 5)")
        size, kind = struct.unpack_from(">IB", body, offset)
        if size < 5 or offset + size > len(body):
            raise ProtocolError(f"robot state sub-package {kind} at offset {offset + 5} says "
                                f"{size} bytes; {len(body) - offset} are left")
        packages[kind] = _decode_package(kind, body[offset + 5:offset + size])
        offset += size
    return RobotState(packages)


# ---- robot messages ------------------------------------------------------------------------


@dataclass(frozen=True)
class VersionMessage:
    timestamp: int
    source: int
    project: str
    major: int
    minor: int
    bugfix: int
    build: int
    build_date: str


@dataclass(frozen=True)
class TextMessage:
    timestamp: int
    source: int
    text: str


@dataclass(frozen=True)
class LabelMessage:
    timestamp: int
    source: int
    id: int
    text: str


@dataclass(frozen=True)
class PopupMessage:
    timestamp: int
    source: int
    request_id: int
    popup_type: int
    warning: bool
    error: bool
    blocking: bool
    title: str
    text: str


@dataclass(frozen=True)
class SafetyModeMessage:
    timestamp: int
    source: int
    code: int
    argument: int
    safety_mode: int
    report_data_type: int
    report_data: bytes


@dataclass(frozen=True)
class ErrorCodeMessage:
    timestamp: int
    source: int
    code: int
    argument: int
    report_level: int
    data_type: int
    data: int
    text: str


@dataclass(frozen=True)
class KeyMessage:
    timestamp: int
    source: int
    code: int
    argument: int
    title: str
    text: str


@dataclass(frozen=True)
class RuntimeExceptionMessage:
    """A URScript runtime error: ``line`` and ``column`` in the program as sent."""

    timestamp: int
    source: int
    line: int
    column: int
    text: str


@dataclass(frozen=True)
class RawMessage:
    """A message (or robot message) type urdsl does not decode, kept as bytes."""

    type: int
    robot_message_type: int | None
    data: bytes


def _text(data: bytes) -> str:
    return data.decode("utf-8", errors="replace")


def _decode_robot_message(body: bytes):
    if len(body) < 10:
        raise ProtocolError(f"a robot message has a 10-byte header; got {len(body)} bytes")
    timestamp, source, kind = struct.unpack_from(">QbB", body)
    data = body[10:]
    try:
        if kind == 0:
            return TextMessage(timestamp, source, _text(data))
        if kind == 1:
            (label,) = struct.unpack_from(">i", data)
            return LabelMessage(timestamp, source, label, _text(data[4:]))
        if kind == 2:
            request, popup_type, warning, error, blocking, title_size = struct.unpack_from(
                ">IB???B", data)
            title = _text(data[9:9 + title_size])
            return PopupMessage(timestamp, source, request, popup_type, warning, error,
                                blocking, title, _text(data[9 + title_size:]))
        if kind == 3:
            (name_size,) = struct.unpack_from(">b", data)
            project = _text(data[1:1 + name_size])
            major, minor, bugfix, build = struct.unpack_from(">BBii", data, 1 + name_size)
            return VersionMessage(timestamp, source, project, major, minor, bugfix, build,
                                  _text(data[11 + name_size:]))
        if kind == 5:
            code, argument, mode, report_type = struct.unpack_from(">iiBI", data)
            return SafetyModeMessage(timestamp, source, code, argument, mode, report_type,
                                     bytes(data[13:]))
        if kind == 6:
            code, argument, level, data_type, value = struct.unpack_from(">iiiII", data)
            return ErrorCodeMessage(timestamp, source, code, argument, level, data_type,
                                    value, _text(data[20:]))
        if kind == 7:
            code, argument, title_size = struct.unpack_from(">iiB", data)
            title = _text(data[9:9 + title_size])
            return KeyMessage(timestamp, source, code, argument, title,
                              _text(data[9 + title_size:]))
        if kind == 10:
            line, column = struct.unpack_from(">II", data)
            return RuntimeExceptionMessage(timestamp, source, line, column, _text(data[8:]))
    except struct.error:
        raise ProtocolError(f"robot message type {kind} is too short ({len(data)} bytes after "
                            "its header)") from None
    return RawMessage(ROBOT_MESSAGE, kind, bytes(body))


def decode_message(message: bytes):
    """Decode one whole message (header included)."""
    if len(message) < 5:
        raise ProtocolError(f"a primary message has a 5-byte header; got {len(message)} bytes")
    size, kind = struct.unpack_from(">iB", message)
    if size != len(message):
        raise ProtocolError(f"the size field says {size} bytes, the message has "
                            f"{len(message)}")
    body = message[5:]
    if kind == ROBOT_STATE:
        return _decode_state(body)
    if kind == ROBOT_MESSAGE:
        return _decode_robot_message(body)
    return RawMessage(kind, None, bytes(body))


class PrimaryDecoder:
    """Messages from a primary/secondary byte stream, however it is split."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list:
        self._buffer += data
        return [decode_message(bytes(m)) for m in self._messages()]

    def _messages(self) -> Iterator[bytearray]:
        buffer = self._buffer
        while len(buffer) >= 5:
            (size,) = struct.unpack_from(">i", buffer)
            if not 5 <= size <= MAX_MESSAGE:
                self._buffer = bytearray()
                raise ProtocolError(f"primary message size {size} is outside 5..{MAX_MESSAGE}"
                                    " bytes: the stream is not primary messages")
            if len(buffer) < size:
                return
            message = buffer[:size]
            del buffer[:size]
            yield message


# ---- encoders (what a controller sends) ------------------------------------------------------


def _frame(kind: int, body: bytes) -> bytes:
    return struct.pack(">iB", len(body) + 5, kind) + body


def _package(kind: int, data: bytes) -> bytes:
    return struct.pack(">IB", len(data) + 5, kind) + data


def _encode_package(package) -> bytes:
    if isinstance(package, RobotModeData):
        data = _ROBOT_MODE.pack(package.timestamp, package.real_robot_connected,
                                package.real_robot_enabled, package.robot_power_on,
                                package.emergency_stopped, package.protective_stopped,
                                package.program_running, package.program_paused,
                                package.robot_mode, package.control_mode,
                                package.target_speed_fraction, package.speed_scaling)
        if package.target_speed_fraction_limit is not None:
            data += struct.pack(">d", package.target_speed_fraction_limit)
        return _package(0, data + package.extra)
    if isinstance(package, JointData):
        rows = zip(package.q_actual, package.q_target, package.qd_actual, package.current,
                   package.voltage, package.motor_temperature, package.micro_temperature,
                   package.joint_mode, strict=True)
        return _package(1, b"".join(_JOINT.pack(*row) for row in rows) + package.extra)
    if isinstance(package, ToolData):
        return _package(2, _TOOL.pack(*package.analog_input_range, *package.analog_input,
                                      package.voltage_48v, package.output_voltage,
                                      package.current, package.temperature, package.mode)
                        + package.extra)
    if isinstance(package, MasterboardData):
        return _package(3, _MASTERBOARD.pack(
            package.digital_input_bits, package.digital_output_bits,
            *package.analog_input_range, *package.analog_input, *package.analog_output_domain,
            *package.analog_output, package.temperature, package.robot_voltage_48v,
            package.robot_current, package.io_current, package.safety_mode,
            package.in_reduced_mode) + package.extra)
    if isinstance(package, CartesianInfo):
        data = struct.pack(">6d", *package.tcp_pose)
        if package.tcp_offset is not None:
            data += struct.pack(">6d", *package.tcp_offset)
        return _package(4, data + package.extra)
    if isinstance(package, KinematicsInfo):
        return _package(5, _KINEMATICS.pack(*package.checksums, *package.dh_theta,
                                            *package.dh_a, *package.dh_d, *package.dh_alpha,
                                            package.calibration_status) + package.extra)
    if isinstance(package, ForceModeData):
        return _package(7, struct.pack(">7d", *package.wrench, package.dexterity)
                        + package.extra)
    if isinstance(package, RawPackage):
        return _package(package.type, package.data)
    raise ProtocolError(f"cannot encode a {type(package).__name__} as a sub-package")


def encode_robot_state(state: RobotState) -> bytes:
    """Message 16 with the sub-packages in type order."""
    return _frame(ROBOT_STATE, b"".join(_encode_package(state.packages[kind])
                                        for kind in sorted(state.packages)))


def encode_robot_message(message) -> bytes:
    """Message 20 for any of the robot message classes (or a :class:`RawMessage`)."""
    if isinstance(message, RawMessage):
        return _frame(message.type, message.data)
    head = struct.pack(">Qb", message.timestamp, message.source)

    def text(value: str) -> bytes:
        return value.encode("utf-8")

    if isinstance(message, TextMessage):
        kind, data = 0, text(message.text)
    elif isinstance(message, LabelMessage):
        kind, data = 1, struct.pack(">i", message.id) + text(message.text)
    elif isinstance(message, PopupMessage):
        title = text(message.title)
        kind, data = 2, struct.pack(">IB???B", message.request_id, message.popup_type,
                                    message.warning, message.error, message.blocking,
                                    len(title)) + title + text(message.text)
    elif isinstance(message, VersionMessage):
        project = text(message.project)
        kind, data = 3, (struct.pack(">b", len(project)) + project + struct.pack(
            ">BBii", message.major, message.minor, message.bugfix, message.build)
            + text(message.build_date))
    elif isinstance(message, SafetyModeMessage):
        kind, data = 5, struct.pack(">iiBI", message.code, message.argument,
                                    message.safety_mode, message.report_data_type
                                    ) + message.report_data
    elif isinstance(message, ErrorCodeMessage):
        kind, data = 6, struct.pack(">iiiII", message.code, message.argument,
                                    message.report_level, message.data_type,
                                    message.data) + text(message.text)
    elif isinstance(message, KeyMessage):
        title = text(message.title)
        kind, data = 7, struct.pack(">iiB", message.code, message.argument,
                                    len(title)) + title + text(message.text)
    elif isinstance(message, RuntimeExceptionMessage):
        kind, data = 10, struct.pack(">II", message.line, message.column) + text(message.text)
    else:
        raise ProtocolError(f"cannot encode a {type(message).__name__} as a robot message")
    return _frame(ROBOT_MESSAGE, head + struct.pack(">B", kind) + data)
