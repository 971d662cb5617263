"""The controller side of RTDE (port 30004) as a state machine without sockets.

Feed the client's bytes to :meth:`RtdeSession.receive`; it returns the reply bytes. Call
:meth:`RtdeSession.output` at every controller step with the snapshot; it returns a data
package when one is due at the negotiated frequency. Layouts: docs/controller-facts.md §12.

Limits, with their reason: a package may be 65535 bytes (the size field is a uint16); a
variable-name list may be 2048 bytes (the RTDE guide's limit); a client that sends a package
shorter than its own header is dropped (:class:`RtdeProtocolError`), as the framing is lost.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .state import ControllerVersion, Snapshot
from .wire import robot_status_bits, safety_status_bits

__all__ = ["RtdeSession", "RtdeProtocolError", "InputOwners", "OUTPUTS", "INPUTS"]

REQUEST_PROTOCOL_VERSION = 86  # 'V'
GET_URCONTROL_VERSION = 118    # 'v'
TEXT_MESSAGE = 77              # 'M'
DATA_PACKAGE = 85              # 'U'
SETUP_OUTPUTS = 79             # 'O'
SETUP_INPUTS = 73              # 'I'
START = 83                     # 'S'
PAUSE = 80                     # 'P'

MAX_NAMES = 2048

MAX_INPUT_RECIPES = 255
"""Input recipes one connection may set up: the recipe id is one byte and 0 means refused.
Further SETUP_INPUTS requests are answered with id 0 (refused), and the connection lives on.
"""

_CODES = {"BOOL": "?", "UINT8": "B", "UINT32": "I", "UINT64": "Q", "INT32": "i",
          "DOUBLE": "d", "VECTOR3D": "3d", "VECTOR6D": "6d", "VECTOR6INT32": "6i",
          "VECTOR6UINT32": "6I"}
_WIDTH = {"VECTOR3D": 3, "VECTOR6D": 6, "VECTOR6INT32": 6, "VECTOR6UINT32": 6}


class RtdeProtocolError(Exception):
    """The client broke the framing; the connection is closed."""


Getter = Callable[[Snapshot], Any]
_Z3, _Z6 = (0.0,) * 3, (0.0,) * 6


def _reg_bits(value: int, low: int) -> int:
    return (value >> low) & 0xFFFFFFFF


OUTPUTS: dict[str, tuple[str, Getter]] = {
    "timestamp": ("DOUBLE", lambda s: s.time),
    "target_q": ("VECTOR6D", lambda s: s.q),
    "target_qd": ("VECTOR6D", lambda s: s.qd),
    "target_qdd": ("VECTOR6D", lambda s: s.qdd),
    "target_current": ("VECTOR6D", lambda s: _Z6),
    "target_moment": ("VECTOR6D", lambda s: _Z6),
    "actual_q": ("VECTOR6D", lambda s: s.q),
    "actual_qd": ("VECTOR6D", lambda s: s.qd),
    "actual_current": ("VECTOR6D", lambda s: _Z6),
    "actual_current_window": ("VECTOR6D", lambda s: _Z6),
    "actual_current_as_torque": ("VECTOR6D", lambda s: _Z6),
    "joint_control_output": ("VECTOR6D", lambda s: _Z6),
    "actual_TCP_pose": ("VECTOR6D", lambda s: s.tcp),
    "actual_TCP_speed": ("VECTOR6D", lambda s: s.tcp_speed),
    "actual_TCP_force": ("VECTOR6D", lambda s: _Z6),
    "target_TCP_pose": ("VECTOR6D", lambda s: s.tcp),
    "target_TCP_speed": ("VECTOR6D", lambda s: s.tcp_speed),
    "actual_TCP_acceleration": ("VECTOR6D", lambda s: _Z6),
    "target_TCP_acceleration": ("VECTOR6D", lambda s: _Z6),
    "tcp_offset": ("VECTOR6D", lambda s: s.tcp_offset),
    "actual_digital_input_bits": ("UINT64", lambda s: s.digital_inputs),
    "actual_configurable_digital_input_bits": ("UINT64", lambda s: (s.digital_inputs >> 8)
                                               & 0xFF),
    "joint_temperatures": ("VECTOR6D", lambda s: _Z6),
    "actual_execution_time": ("DOUBLE", lambda s: 0.0),
    "target_execution_time": ("DOUBLE", lambda s: 0.0),
    "robot_mode": ("INT32", lambda s: int(s.robot_mode)),
    "joint_mode": ("VECTOR6INT32", lambda s: (int(s.joint_mode),) * 6),
    "safety_mode": ("INT32", lambda s: int(s.safety_mode)),
    "safety_status": ("INT32", lambda s: int(s.safety_mode)),
    "actual_tool_accelerometer": ("VECTOR3D", lambda s: _Z3),
    "speed_scaling": ("DOUBLE", lambda s: s.speed_scaling),
    "target_speed_fraction": ("DOUBLE", lambda s: s.target_speed_fraction),
    "actual_momentum": ("DOUBLE", lambda s: 0.0),
    "actual_main_voltage": ("DOUBLE", lambda s: 0.0),
    "actual_robot_voltage": ("DOUBLE", lambda s: 0.0),
    "actual_robot_current": ("DOUBLE", lambda s: 0.0),
    "actual_joint_voltage": ("VECTOR6D", lambda s: _Z6),
    "actual_digital_output_bits": ("UINT64", lambda s: s.digital_outputs),
    "actual_configurable_digital_output_bits": ("UINT64", lambda s: (s.digital_outputs >> 8)
                                                & 0xFF),
    "runtime_state": ("UINT32", lambda s: int(s.program_state)),
    "elbow_position": ("VECTOR3D", lambda s: s.elbow),
    "elbow_velocity": ("VECTOR3D", lambda s: s.elbow_speed),
    "robot_status_bits": ("UINT32", robot_status_bits),
    "safety_status_bits": ("UINT32", safety_status_bits),
    "analog_io_types": ("UINT32", lambda s: 0),
    "standard_analog_input0": ("DOUBLE", lambda s: s.analog_inputs[0]),
    "standard_analog_input1": ("DOUBLE", lambda s: s.analog_inputs[1]),
    "standard_analog_output0": ("DOUBLE", lambda s: s.analog_outputs[0]),
    "standard_analog_output1": ("DOUBLE", lambda s: s.analog_outputs[1]),
    "io_current": ("DOUBLE", lambda s: 0.0),
    "euromap67_input_bits": ("UINT32", lambda s: 0),
    "euromap67_output_bits": ("UINT32", lambda s: 0),
    "euromap67_24V_voltage": ("DOUBLE", lambda s: 0.0),
    "euromap67_24V_current": ("DOUBLE", lambda s: 0.0),
    "tool_mode": ("UINT32", lambda s: 0),
    "tool_analog_input_types": ("UINT32", lambda s: 0),
    "tool_analog_input0": ("DOUBLE", lambda s: s.tool_analog_inputs[0]),
    "tool_analog_input1": ("DOUBLE", lambda s: s.tool_analog_inputs[1]),
    "tool_output_voltage": ("INT32", lambda s: 0),
    "tool_output_current": ("DOUBLE", lambda s: 0.0),
    "tool_temperature": ("DOUBLE", lambda s: 0.0),
    "tool_output_mode": ("UINT8", lambda s: 0),
    "tool_digital_output0_mode": ("UINT8", lambda s: 0),
    "tool_digital_output1_mode": ("UINT8", lambda s: 0),
    "tcp_force_scalar": ("DOUBLE", lambda s: 0.0),
    "output_bit_registers0_to_31": ("UINT32", lambda s: _reg_bits(s.output_bool_registers, 0)),
    "output_bit_registers32_to_63": ("UINT32", lambda s: _reg_bits(s.output_bool_registers,
                                                                    32)),
    "input_bit_registers0_to_31": ("UINT32", lambda s: _reg_bits(s.input_bool_registers, 0)),
    "input_bit_registers32_to_63": ("UINT32", lambda s: _reg_bits(s.input_bool_registers, 32)),
    "payload": ("DOUBLE", lambda s: s.payload_mass),
    "payload_cog": ("VECTOR3D", lambda s: s.payload_cog),
    "payload_inertia": ("VECTOR6D", lambda s: _Z6),
    "script_control_line": ("UINT32", lambda s: s.script_line),
    "ft_raw_wrench": ("VECTOR6D", lambda s: _Z6),
    "joint_position_deviation_ratio": ("DOUBLE", lambda s: 0.0),
    "collision_detection_ratio": ("DOUBLE", lambda s: 0.0),
    "encoder0_raw": ("INT32", lambda s: 0),
    "encoder1_raw": ("INT32", lambda s: 0),
    "actual_robot_energy_consumed": ("DOUBLE", lambda s: 0.0),
    "actual_robot_braking_energy_dissipated": ("DOUBLE", lambda s: 0.0),
    "wrench_calc_from_currents": ("VECTOR6D", lambda s: _Z6),
    "time_scale_source": ("INT32", lambda s: 0),
    "target_gravity": ("VECTOR3D", lambda s: (0.0, 0.0, -9.82)),
    "target_base_acceleration": ("VECTOR6D", lambda s: _Z6),
    "target_base_wrench": ("VECTOR6D", lambda s: _Z6),
}
"""Output fields: name → (RTDE type, value at a snapshot). Fields the simulation does not
model (currents, temperatures, voltages, forces) are 0."""

for _i in range(48):
    OUTPUTS[f"output_int_register_{_i}"] = ("INT32", lambda s, i=_i: s.output_int_registers[i])
    OUTPUTS[f"output_double_register_{_i}"] = ("DOUBLE",
                                               lambda s, i=_i: s.output_float_registers[i])
    OUTPUTS[f"input_int_register_{_i}"] = ("INT32", lambda s, i=_i: s.input_int_registers[i])
    OUTPUTS[f"input_double_register_{_i}"] = ("DOUBLE",
                                              lambda s, i=_i: s.input_float_registers[i])

INPUTS: dict[str, str] = {
    "speed_slider_mask": "UINT32", "speed_slider_fraction": "DOUBLE",
    "standard_digital_output_mask": "UINT8", "standard_digital_output": "UINT8",
    "configurable_digital_output_mask": "UINT8", "configurable_digital_output": "UINT8",
    "tool_digital_output_mask": "UINT8", "tool_digital_output": "UINT8",
    "standard_analog_output_mask": "UINT8", "standard_analog_output_type": "UINT8",
    "standard_analog_output_0": "DOUBLE", "standard_analog_output_1": "DOUBLE",
    "input_bit_registers0_to_31": "UINT32", "input_bit_registers32_to_63": "UINT32",
    "external_force_torque": "VECTOR6D",
}
"""Input fields: name → RTDE type (bool registers 64-127 are not simulated)."""
for _i in range(48):
    INPUTS[f"input_int_register_{_i}"] = "INT32"
    INPUTS[f"input_double_register_{_i}"] = "DOUBLE"


class InputOwners:
    """Which session owns each input field: only one RTDE client may write an input."""

    def __init__(self) -> None:
        self._owners: dict[str, object] = {}

    def claim(self, names: list[str], owner: object) -> list[bool]:
        """For each name, whether ``owner`` may have it (claims the free ones only if all
        are free or already its own)."""
        free = [self._owners.get(n, owner) is owner for n in names]
        if all(free):
            for name in names:
                self._owners[name] = owner
        return free

    def release(self, owner: object) -> None:
        for name in [n for n, o in self._owners.items() if o is owner]:
            del self._owners[name]


@dataclass
class _Recipe:
    names: list[str]
    types: list[str]
    layout: struct.Struct | None
    getters: list[Getter] = field(default_factory=list)
    valid: bool = True


def _layout(types: list[str]) -> struct.Struct:
    return struct.Struct(">B" + "".join(_CODES[t] for t in types))


def package(kind: int, payload: bytes = b"") -> bytes:
    """An RTDE package: uint16 size (incl. the 3-byte header), uint8 type, payload."""
    return struct.pack(">HB", len(payload) + 3, kind) + payload


class RtdeSession:
    """One RTDE connection, controller side.

    ``environment``: the shared :class:`urdsl.runtime.Environment` the inputs are written
    into; ``owners``: the controller-wide :class:`InputOwners`; ``max_frequency``: 500 Hz
    e-Series, 125 Hz CB3.
    """

    def __init__(self, version: ControllerVersion, environment: Any, owners: InputOwners,
                 max_frequency: float) -> None:
        self.version = version
        self.env = environment
        self.owners = owners
        self.max_frequency = max_frequency
        self.protocol = 1
        self.output: _Recipe | None = None
        self.output_id = 0
        self.inputs: dict[int, _Recipe] = {}
        self.frequency = max_frequency
        self.started = False
        self._buffer = b""
        self._next_id = 1  # input recipes count from 1 (ur_rtde relies on it)
        self._phase = 0.0
        self._every = 1
        self._count = 0
        self.speed_slider: float = 1.0

    # ---- client → controller -------------------------------------------------------------

    def receive(self, data: bytes) -> bytes:
        """Handle the client's bytes; return the replies to send."""
        self._buffer += data
        replies = []
        while len(self._buffer) >= 3:
            size, kind = struct.unpack_from(">HB", self._buffer)
            if size < 3:
                raise RtdeProtocolError(f"package size {size} is smaller than its header")
            if len(self._buffer) < size:
                break
            payload = self._buffer[3:size]
            self._buffer = self._buffer[size:]
            reply = self._handle(kind, payload)
            if reply:
                replies.append(reply)
        return b"".join(replies)

    def _handle(self, kind: int, payload: bytes) -> bytes:
        if kind == REQUEST_PROTOCOL_VERSION:
            if len(payload) < 2:
                return package(kind, b"\x00")
            (version,) = struct.unpack_from(">H", payload)
            accepted = version in (1, 2)
            if accepted:
                self.protocol = version
            return package(kind, struct.pack(">B", accepted))
        if kind == GET_URCONTROL_VERSION:
            v = self.version
            return package(kind, struct.pack(">IIII", v.major, v.minor, v.bugfix, v.build))
        if kind == SETUP_OUTPUTS:
            return self._setup_outputs(payload)
        if kind == SETUP_INPUTS:
            return self._setup_inputs(payload)
        if kind == START:
            ok = self.output is not None and self.output.valid or (
                self.output is None and bool(self.inputs))
            self.started = bool(ok)
            # the first package goes out at the next step, then one every max/f steps
            self._phase = 1.0 - self.frequency / self.max_frequency
            self._count = 0
            return package(kind, struct.pack(">B", self.started))
        if kind == PAUSE:
            self.started = False
            return package(kind, b"\x01")
        if kind == DATA_PACKAGE:
            self._apply_inputs(payload)
            return b""
        return b""  # TEXT_MESSAGE from the client and unknown types: nothing to answer

    def _names(self, raw: bytes) -> list[str]:
        if len(raw) > MAX_NAMES:
            return []
        text = raw.decode("ascii", errors="replace").strip().strip("\x00")
        return [name.strip() for name in text.split(",") if name.strip()]

    def _setup_outputs(self, payload: bytes) -> bytes:
        frequency = self.max_frequency
        if self.protocol >= 2:
            if len(payload) < 8:
                return package(SETUP_OUTPUTS, b"\x00")
            (frequency,) = struct.unpack_from(">d", payload)
            payload = payload[8:]
        names = self._names(payload)
        types = [OUTPUTS[n][0] if n in OUTPUTS else "NOT_FOUND" for n in names]
        valid = bool(names) and "NOT_FOUND" not in types and \
            0 < frequency <= self.max_frequency
        recipe = _Recipe(names, types, _layout(types) if valid else None,
                         [OUTPUTS[n][1] for n in names] if valid else [], valid)
        self.output = recipe
        self.output_id = 1 if valid else 0  # one output recipe per connection
        if valid:
            self.frequency = frequency
            if self.version.e_series:
                self._every = 1
            else:  # CB3 decimates: one package every floor(125 / f) steps (controller-facts.md §12)
                self._every = max(int(self.max_frequency // frequency), 1)
        text = ",".join(types).encode("ascii")
        if self.protocol >= 2:
            return package(SETUP_OUTPUTS, struct.pack(">B", self.output_id) + text)
        return package(SETUP_OUTPUTS, text)

    def _setup_inputs(self, payload: bytes) -> bytes:
        names = self._names(payload)
        types = [INPUTS.get(n, "NOT_FOUND") for n in names]
        known = [n for n, t in zip(names, types, strict=True) if t != "NOT_FOUND"]
        if self._next_id > MAX_INPUT_RECIPES:
            # no id left: refused (id 0), as a recipe with an unknown field is; the
            # connection and its earlier recipes live on
            return package(SETUP_INPUTS, b"\x00" + ",".join(types).encode("ascii"))
        if known and len(known) == len(names):
            free = self.owners.claim(names, self)
            types = [t if ok else "IN_USE" for t, ok in zip(types, free, strict=True)]
        valid = bool(names) and all(t in _CODES for t in types)
        recipe_id = 0
        if valid:
            recipe_id = self._next_id
            self._next_id += 1
            self.inputs[recipe_id] = _Recipe(names, types, _layout(types))
        return package(SETUP_INPUTS, struct.pack(">B", recipe_id) +
                       ",".join(types).encode("ascii"))

    def _apply_inputs(self, payload: bytes) -> None:
        if not payload:
            return
        recipe = self.inputs.get(payload[0])
        if recipe is None or recipe.layout is None or len(payload) != recipe.layout.size:
            return  # unknown recipe or wrong length: the controller ignores the package
        values = recipe.layout.unpack(payload)[1:]
        fields: dict[str, Any] = {}
        position = 0
        for name, kind in zip(recipe.names, recipe.types, strict=True):
            width = _WIDTH.get(kind, 1)
            fields[name] = values[position] if width == 1 else values[position:position + width]
            position += width
        self._write(fields)

    def _write(self, fields: dict[str, Any]) -> None:
        env = self.env
        for name, value in fields.items():
            if name.startswith("input_int_register_"):
                env.input_int_registers[int(name.rsplit("_", 1)[1])] = int(value)
            elif name.startswith("input_double_register_"):
                env.input_float_registers[int(name.rsplit("_", 1)[1])] = float(value)
            elif name in ("input_bit_registers0_to_31", "input_bit_registers32_to_63"):
                low = 0 if name.endswith("0_to_31") else 32
                for bit in range(32):
                    env.input_bool_registers[low + bit] = bool(value >> bit & 1)
        for prefix, bank in (("standard_digital_output", env.standard_digital_out),
                             ("configurable_digital_output", env.configurable_digital_out),
                             ("tool_digital_output", env.tool_digital_out)):
            if prefix + "_mask" in fields and prefix in fields:
                mask, bits = fields[prefix + "_mask"], fields[prefix]
                for index in range(len(bank)):
                    if mask >> index & 1:
                        bank[index] = bool(bits >> index & 1)
        mask = fields.get("standard_analog_output_mask", 0)
        for index in range(2):
            key = f"standard_analog_output_{index}"
            if mask >> index & 1 and key in fields:
                env.standard_analog_out[index] = float(fields[key])
        if fields.get("speed_slider_mask", 0) & 1 and "speed_slider_fraction" in fields:
            self.speed_slider = float(fields["speed_slider_fraction"])

    # ---- controller → client -------------------------------------------------------------

    def output_due(self) -> bool:
        """Advance one controller step; True when a data package is due at this step."""
        if not self.started or self.output is None or not self.output.valid:
            return False
        if not self.version.e_series:
            self._count += 1
            if self._count >= self._every:
                self._count = 0
                return True
            return False
        self._phase += self.frequency / self.max_frequency
        if self._phase >= 1.0 - 1e-9:
            self._phase -= 1.0
            if self._phase > 1.0:
                self._phase = 0.0
            return True
        return False

    def encode(self, snap: Snapshot) -> bytes:
        """The output data package for ``snap`` (call when :meth:`output_due`)."""
        recipe = self.output
        values: list[Any] = []
        for getter, kind in zip(recipe.getters, recipe.types, strict=True):
            value = getter(snap)
            if kind in _WIDTH:
                values.extend(value.tolist() if isinstance(value, np.ndarray) else value)
            else:
                values.append(value)
        body = recipe.layout.pack(self.output_id, *values)
        if self.protocol < 2:
            body = body[1:]
        return package(DATA_PACKAGE, body)

    def close(self) -> None:
        self.owners.release(self)

    def text_message(self, text: str, level: int = 1, source: str = "urdsl") -> bytes:
        """A TEXT_MESSAGE to the client (level 0 exception, 1 error, 2 warning, 3 info)."""
        message = text.encode("utf-8", errors="replace")[:255]
        if self.protocol >= 2:
            src = source.encode("ascii")[:255]
            return package(TEXT_MESSAGE, struct.pack(">B", len(message)) + message +
                           struct.pack(">B", len(src)) + src + struct.pack(">B", level))
        return package(TEXT_MESSAGE, struct.pack(">B", level) + message)
