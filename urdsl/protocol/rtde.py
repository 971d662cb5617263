"""RTDE (port 30004), protocol versions 1 and 2: packages, the field/type table, and the
client's state machine.

Every package is ``uint16 size`` (header included) · ``uint8 type`` · payload (UR_FACTS.md
§5). :class:`RtdeClient` is sans-I/O: its methods return the bytes to send, :meth:`feed`
turns received bytes into events. The handshake a recorder runs::

    client = RtdeClient()
    sock.sendall(client.request_protocol_version(2))   # → ProtocolVersion(accepted=True)
    sock.sendall(client.get_controller_version())      # → ControllerVersion(5, 15, ...)
    sock.sendall(client.setup_outputs(["timestamp", "actual_q"], frequency=125))
    sock.sendall(client.start())                       # → Started(accepted=True)
    ... client.feed(sock.recv(...)) → [DataPackage(recipe_id=1, values={...}), ...]
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

from .errors import ProtocolError

__all__ = [
    "TYPES", "OUTPUTS", "INPUTS", "RtdeClient", "ProtocolVersion", "ControllerVersion",
    "OutputSetup", "InputSetup", "Started", "Paused", "DataPackage", "Message",
    "encode_package", "PackageDecoder", "expand_names", "MAX_PACKAGE",
]

REQUEST_PROTOCOL_VERSION = 86  # 'V'
GET_URCONTROL_VERSION = 118  # 'v'
TEXT_MESSAGE = 77  # 'M'
DATA_PACKAGE = 85  # 'U'
SETUP_OUTPUTS = 79  # 'O'
SETUP_INPUTS = 73  # 'I'
START = 83  # 'S'
PAUSE = 80  # 'P'

MAX_PACKAGE = 65535
"""The size field is a uint16, so no package is longer."""

MAX_NAMES = 2048
"""Longest comma-separated name list a setup package may carry (bytes), per UR's guide."""

TYPES = {"BOOL": "?", "UINT8": "B", "UINT32": "I", "UINT64": "Q", "INT32": "i",
         "DOUBLE": "d", "VECTOR3D": "3d", "VECTOR6D": "6d", "VECTOR6INT32": "6i",
         "VECTOR6UINT32": "6I"}
"""RTDE type names and their big-endian struct codes (UR_FACTS.md §5.2)."""

_V6D = "VECTOR6D"
OUTPUTS: dict[str, str] = {
    "timestamp": "DOUBLE", "target_q": _V6D, "target_qd": _V6D, "target_qdd": _V6D,
    "target_current": _V6D, "target_moment": _V6D, "actual_q": _V6D, "actual_qd": _V6D,
    "actual_current": _V6D, "actual_current_window": _V6D, "actual_current_as_torque": _V6D,
    "joint_control_output": _V6D, "actual_TCP_pose": _V6D, "actual_TCP_speed": _V6D,
    "actual_TCP_force": _V6D, "target_TCP_pose": _V6D, "target_TCP_speed": _V6D,
    "tcp_offset": _V6D, "actual_TCP_acceleration": _V6D, "target_TCP_acceleration": _V6D,
    "actual_digital_input_bits": "UINT64", "actual_configurable_digital_input_bits": "UINT64",
    "joint_temperatures": _V6D, "actual_execution_time": "DOUBLE",
    "target_execution_time": "DOUBLE", "robot_mode": "INT32", "joint_mode": "VECTOR6INT32",
    "safety_mode": "INT32", "safety_status": "INT32", "actual_tool_accelerometer": "VECTOR3D",
    "speed_scaling": "DOUBLE", "target_speed_fraction": "DOUBLE", "actual_momentum": "DOUBLE",
    "actual_main_voltage": "DOUBLE", "actual_robot_voltage": "DOUBLE",
    "actual_robot_current": "DOUBLE", "actual_joint_voltage": _V6D,
    "actual_digital_output_bits": "UINT64",
    "actual_configurable_digital_output_bits": "UINT64", "runtime_state": "UINT32",
    "elbow_position": "VECTOR3D", "elbow_velocity": "VECTOR3D", "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32", "analog_io_types": "UINT32",
    "standard_analog_input0": "DOUBLE", "standard_analog_input1": "DOUBLE",
    "standard_analog_output0": "DOUBLE", "standard_analog_output1": "DOUBLE",
    "io_current": "DOUBLE", "euromap67_input_bits": "UINT32",
    "euromap67_output_bits": "UINT32", "euromap67_24V_voltage": "DOUBLE",
    "euromap67_24V_current": "DOUBLE", "tool_mode": "UINT32",
    "tool_analog_input_types": "UINT32", "tool_analog_input0": "DOUBLE",
    "tool_analog_input1": "DOUBLE", "tool_output_voltage": "INT32",
    "tool_output_current": "DOUBLE", "tool_temperature": "DOUBLE", "tool_output_mode": "UINT8",
    "tool_digital_output0_mode": "UINT8", "tool_digital_output1_mode": "UINT8",
    "tcp_force_scalar": "DOUBLE", "output_bit_registers0_to_31": "UINT32",
    "output_bit_registers32_to_63": "UINT32", "payload": "DOUBLE", "payload_cog": "VECTOR3D",
    "payload_inertia": _V6D, "script_control_line": "UINT32", "ft_raw_wrench": _V6D,
    "joint_position_deviation_ratio": "DOUBLE", "collision_detection_ratio": "DOUBLE",
    "encoder0_raw": "INT32", "encoder1_raw": "INT32",
    "actual_robot_energy_consumed": "DOUBLE",
    "actual_robot_braking_energy_dissipated": "DOUBLE", "wrench_calc_from_currents": _V6D,
    "time_scale_source": "INT32", "target_gravity": "VECTOR3D",
    "target_base_acceleration": _V6D, "control_step": "UINT64", "target_base_wrench": _V6D,
}
"""Output fields (robot → client) and their types (UR_FACTS.md §5.3)."""

INPUTS: dict[str, str] = {
    "speed_slider_mask": "UINT32", "speed_slider_fraction": "DOUBLE",
    "standard_digital_output_mask": "UINT8", "standard_digital_output": "UINT8",
    "configurable_digital_output_mask": "UINT8", "configurable_digital_output": "UINT8",
    "tool_digital_output_mask": "UINT8", "tool_digital_output": "UINT8",
    "standard_analog_output_mask": "UINT8", "standard_analog_output_type": "UINT8",
    "standard_analog_output_0": "DOUBLE", "standard_analog_output_1": "DOUBLE",
    "input_bit_registers0_to_31": "UINT32", "input_bit_registers32_to_63": "UINT32",
    "external_force_torque": _V6D,
}
"""Input fields (client → robot) (UR_FACTS.md §5.4); registers are added below."""

for _i in range(64, 128):
    OUTPUTS[f"output_bit_register_{_i}"] = "BOOL"
    INPUTS[f"input_bit_register_{_i}"] = "BOOL"
for _i in range(48):
    OUTPUTS[f"output_int_register_{_i}"] = "INT32"
    OUTPUTS[f"output_double_register_{_i}"] = "DOUBLE"
    INPUTS[f"input_int_register_{_i}"] = "INT32"
    INPUTS[f"input_double_register_{_i}"] = "DOUBLE"
for _name, _kind in list(INPUTS.items()):  # inputs can be read back as outputs
    OUTPUTS.setdefault(_name, _kind)


_WIDTHS = {"VECTOR3D": 3, "VECTOR6D": 6, "VECTOR6INT32": 6, "VECTOR6UINT32": 6}


def expand_names(names: list[str], types: list[str]) -> list[str]:
    """Column names with vectors expanded: ``actual_q`` → ``actual_q_0`` … ``actual_q_5``."""
    columns = []
    for name, kind in zip(names, types, strict=True):
        width = _WIDTHS.get(kind)
        columns += [name] if width is None else [f"{name}_{i}" for i in range(width)]
    return columns


# ---- events ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class ProtocolVersion:
    accepted: bool


@dataclass(frozen=True)
class ControllerVersion:
    major: int
    minor: int
    bugfix: int
    build: int


@dataclass(frozen=True)
class OutputSetup:
    """The reply to a setup of outputs: ``types`` per name (``NOT_FOUND`` for unknown names;
    then the recipe is invalid and nothing is streamed)."""

    recipe_id: int
    names: tuple[str, ...]
    types: tuple[str, ...]

    @property
    def valid(self) -> bool:
        return all(t in TYPES for t in self.types)

    @property
    def not_found(self) -> list[str]:
        return [n for n, t in zip(self.names, self.types, strict=True) if t == "NOT_FOUND"]


@dataclass(frozen=True)
class InputSetup:
    """The reply to a setup of inputs; ``IN_USE`` marks inputs another client owns."""

    recipe_id: int
    names: tuple[str, ...]
    types: tuple[str, ...]

    @property
    def valid(self) -> bool:
        return all(t in TYPES for t in self.types)

    @property
    def problems(self) -> list[str]:
        return [f"{n} ({t})" for n, t in zip(self.names, self.types, strict=True)
                if t not in TYPES]


@dataclass(frozen=True)
class Started:
    accepted: bool


@dataclass(frozen=True)
class Paused:
    accepted: bool


@dataclass(frozen=True)
class DataPackage:
    recipe_id: int
    values: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Message:
    """A text message: ``level`` 0 exception, 1 error, 2 warning, 3 info."""

    level: int
    text: str
    source: str = ""


# ---- framing --------------------------------------------------------------------------------


def encode_package(kind: int, payload: bytes = b"") -> bytes:
    size = len(payload) + 3
    if size > MAX_PACKAGE:
        raise ProtocolError(f"an RTDE package holds at most {MAX_PACKAGE} bytes, not {size}")
    return struct.pack(">HB", size, kind) + payload


class PackageDecoder:
    """``(type, payload)`` pairs from a byte stream, however it is split."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[tuple[int, bytes]]:
        self._buffer += data
        packages = []
        buffer = self._buffer
        while len(buffer) >= 3:
            size, kind = struct.unpack_from(">HB", buffer)
            if size < 3:
                self._buffer = bytearray()
                raise ProtocolError(f"RTDE package size {size} is below its 3-byte header")
            if len(buffer) < size:
                break
            packages.append((kind, bytes(buffer[3:size])))
            del buffer[:size]
        return packages


def _layout(types: tuple[str, ...]) -> struct.Struct:
    return struct.Struct(">" + "".join(TYPES[t] for t in types))


def _unpack(layout: struct.Struct, names, types, data: bytes, offset: int) -> dict:
    try:
        flat = layout.unpack_from(data, offset)
    except struct.error:
        raise ProtocolError(f"data package of {len(data)} bytes is shorter than its recipe's "
                            f"{layout.size + offset}") from None
    if len(data) != layout.size + offset:
        raise ProtocolError(f"data package of {len(data)} bytes does not match its recipe's "
                            f"{layout.size + offset}")
    values, position = {}, 0
    for name, kind in zip(names, types, strict=True):
        width = _WIDTHS.get(kind, 1)
        chunk = flat[position:position + width]
        values[name] = chunk[0] if width == 1 else tuple(chunk)
        position += width
    return values


class RtdeClient:
    """The client side of RTDE, sans-I/O: requests as bytes, replies as events.

    The client remembers what it asked, so that the replies (which carry no names) can be
    decoded: the output recipe's names and types, the input recipes, the protocol version.
    """

    def __init__(self) -> None:
        self.protocol = 1
        self._requested: list[int] = []  # versions asked for, in order
        self._pending_outputs: list[tuple[str, ...]] = []
        self._pending_inputs: list[tuple[str, ...]] = []
        self.outputs: OutputSetup | None = None
        self.inputs: dict[int, InputSetup] = {}
        self._output_layout: struct.Struct | None = None
        self._decoder = PackageDecoder()

    # -- requests ---------------------------------------------------------------------------

    def request_protocol_version(self, version: int = 2) -> bytes:
        if version not in (1, 2):
            raise ProtocolError(f"RTDE protocol versions are 1 and 2, not {version}")
        self._requested.append(version)
        return encode_package(REQUEST_PROTOCOL_VERSION, struct.pack(">H", version))

    def get_controller_version(self) -> bytes:
        return encode_package(GET_URCONTROL_VERSION)

    def setup_outputs(self, names: list[str], frequency: float = 125.0) -> bytes:
        """Subscribe to output ``names`` at ``frequency`` Hz (v2; v1 has no frequency)."""
        text = ",".join(names).encode("ascii")
        if len(text) > MAX_NAMES:
            raise ProtocolError(f"the output names take {len(text)} bytes; RTDE allows "
                                f"{MAX_NAMES}")
        self._pending_outputs.append(tuple(names))
        if self.protocol >= 2:
            return encode_package(SETUP_OUTPUTS, struct.pack(">d", frequency) + text)
        return encode_package(SETUP_OUTPUTS, text)

    def setup_inputs(self, names: list[str]) -> bytes:
        text = ",".join(names).encode("ascii")
        if len(text) > MAX_NAMES:
            raise ProtocolError(f"the input names take {len(text)} bytes; RTDE allows "
                                f"{MAX_NAMES}")
        self._pending_inputs.append(tuple(names))
        return encode_package(SETUP_INPUTS, text)

    def start(self) -> bytes:
        return encode_package(START)

    def pause(self) -> bytes:
        return encode_package(PAUSE)

    def send_inputs(self, recipe_id: int, values: dict) -> bytes:
        """A data package for input recipe ``recipe_id`` with a value for each of its names."""
        recipe = self.inputs.get(recipe_id)
        if recipe is None or not recipe.valid:
            raise ProtocolError(f"input recipe {recipe_id} is not set up")
        missing = [n for n in recipe.names if n not in values]
        if missing:
            raise ProtocolError(f"input recipe {recipe_id} needs {missing[0]!r}")
        flat: list = []
        for name in recipe.names:
            value = values[name]
            flat.extend(value if isinstance(value, (list, tuple)) else [value])
        layout = _layout(recipe.types)
        return encode_package(DATA_PACKAGE, struct.pack(">B", recipe_id) + layout.pack(*flat))

    # -- replies ----------------------------------------------------------------------------

    def feed(self, data: bytes) -> list:
        """Events for the bytes received."""
        return [self._event(kind, payload) for kind, payload in self._decoder.feed(data)]

    def _event(self, kind: int, payload: bytes):
        try:
            if kind == REQUEST_PROTOCOL_VERSION:
                (accepted,) = struct.unpack(">B", payload[:1])
                version = self._requested.pop(0) if self._requested else 1
                if accepted:
                    self.protocol = version
                return ProtocolVersion(bool(accepted))
            if kind == GET_URCONTROL_VERSION:
                return ControllerVersion(*struct.unpack(">IIII", payload[:16]))
            if kind == SETUP_OUTPUTS:
                names = self._pending_outputs.pop(0) if self._pending_outputs else ()
                if self.protocol >= 2:
                    recipe_id, text = payload[0], payload[1:]
                else:
                    recipe_id, text = 0, payload
                types = tuple(text.decode("ascii").split(",")) if text else ()
                setup = OutputSetup(recipe_id, names, types)
                self.outputs = setup
                self._output_layout = _layout(types) if setup.valid else None
                return setup
            if kind == SETUP_INPUTS:
                names = self._pending_inputs.pop(0) if self._pending_inputs else ()
                recipe_id, text = payload[0], payload[1:]
                setup = InputSetup(recipe_id, names, tuple(text.decode("ascii").split(",")))
                self.inputs[recipe_id] = setup
                return setup
            if kind == START:
                return Started(bool(payload[0]))
            if kind == PAUSE:
                return Paused(bool(payload[0]))
            if kind == DATA_PACKAGE:
                return self._data(payload)
            if kind == TEXT_MESSAGE:
                return self._message(payload)
        except (IndexError, UnicodeDecodeError, struct.error):
            raise ProtocolError(f"RTDE reply type {kind} ({chr(kind)!r}) is malformed: "
                                f"{payload[:32]!r}") from None
        raise ProtocolError(f"unknown RTDE package type {kind}")

    def _data(self, payload: bytes) -> DataPackage:
        if self.outputs is None or self._output_layout is None:
            raise ProtocolError("a data package arrived before a valid output setup")
        offset = 1 if self.protocol >= 2 else 0
        recipe_id = payload[0] if offset else self.outputs.recipe_id
        values = _unpack(self._output_layout, self.outputs.names, self.outputs.types, payload,
                         offset)
        return DataPackage(recipe_id, values)

    def _message(self, payload: bytes) -> Message:
        if self.protocol >= 2:
            size = payload[0]
            text = payload[1:1 + size].decode("utf-8", errors="replace")
            source_size = payload[1 + size]
            source = payload[2 + size:2 + size + source_size].decode("utf-8", errors="replace")
            level = payload[2 + size + source_size]
            return Message(level, text, source)
        return Message(payload[0], payload[1:].decode("utf-8", errors="replace"))
