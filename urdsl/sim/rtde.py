"""The controller's behaviour behind RTDE (port 30004): which value each output field has at a
controller step, what an input does, and when a data package is due.

The wire — framing, requests and replies, recipes, the field table, one input owner per field
— is :class:`urdsl.protocol.rtde.RtdeServer` and :mod:`urdsl.protocol.rtde_fields`
(docs/controller-facts.md §12). Output fields the simulation does not model (currents,
temperatures, voltages, forces) are sent as zeros of their type.

A client that breaks the framing (a size field below the 3-byte header) is dropped
(:class:`RtdeProtocolError`); a well-framed package that cannot be decoded is answered with an
error text message and the refusal its request expects, and the connection lives on.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..protocol.errors import ProtocolError
from ..protocol.rtde import DataPackage, InputOwnership, Recipe, RtdeServer, RtdeTextMessage
from ..protocol.rtde_fields import TYPES
from .state import ControllerVersion, Snapshot

__all__ = ["RtdeSession", "RtdeProtocolError", "InputOwners", "VALUES"]

InputOwners = InputOwnership
"""Which session owns each input field (the protocol's :class:`InputOwnership`)."""


class RtdeProtocolError(ProtocolError):
    """The client broke the framing; the connection is closed."""


Getter = Callable[[Snapshot], Any]


def _reg_bits(value: int, low: int) -> int:
    return (value >> low) & 0xFFFFFFFF


def robot_status_bits(snap: Snapshot) -> int:
    """RTDE ``robot_status_bits``: bit 0 power on, 1 program running, 2 teach button,
    3 power button."""
    return int(snap.power_on) | int(snap.program_running) << 1


def safety_status_bits(snap: Snapshot) -> int:
    """RTDE ``safety_status_bits``: bit 0 normal, 1 reduced, 2 protective stop, 3 recovery,
    4 safeguard stop, 5 system e-stop, 6 robot e-stop, 7 e-stop, 8 violation, 9 fault."""
    mode = int(snap.safety_mode)
    if mode == 1:
        return 1
    return 1 << (mode - 1) if 1 <= mode <= 10 else 0


VALUES: dict[str, Getter] = {
    "timestamp": lambda s: s.time,
    "target_q": lambda s: s.q,
    "target_qd": lambda s: s.qd,
    "target_qdd": lambda s: s.qdd,
    "actual_q": lambda s: s.q,
    "actual_qd": lambda s: s.qd,
    "actual_TCP_pose": lambda s: s.tcp,
    "actual_TCP_speed": lambda s: s.tcp_speed,
    "target_TCP_pose": lambda s: s.tcp,
    "target_TCP_speed": lambda s: s.tcp_speed,
    "tcp_offset": lambda s: s.tcp_offset,
    "actual_digital_input_bits": lambda s: s.digital_inputs,
    "actual_configurable_digital_input_bits": lambda s: (s.digital_inputs >> 8) & 0xFF,
    "robot_mode": lambda s: int(s.robot_mode),
    "joint_mode": lambda s: (int(s.joint_mode),) * 6,
    "safety_mode": lambda s: int(s.safety_mode),
    "safety_status": lambda s: int(s.safety_mode),
    "speed_scaling": lambda s: s.speed_scaling,
    "target_speed_fraction": lambda s: s.target_speed_fraction,
    "actual_digital_output_bits": lambda s: s.digital_outputs,
    "actual_configurable_digital_output_bits": lambda s: (s.digital_outputs >> 8) & 0xFF,
    "runtime_state": lambda s: int(s.program_state),
    "elbow_position": lambda s: s.elbow,
    "elbow_velocity": lambda s: s.elbow_speed,
    "robot_status_bits": robot_status_bits,
    "safety_status_bits": safety_status_bits,
    "standard_analog_input0": lambda s: s.analog_inputs[0],
    "standard_analog_input1": lambda s: s.analog_inputs[1],
    "standard_analog_output0": lambda s: s.analog_outputs[0],
    "standard_analog_output1": lambda s: s.analog_outputs[1],
    "tool_analog_input0": lambda s: s.tool_analog_inputs[0],
    "tool_analog_input1": lambda s: s.tool_analog_inputs[1],
    "output_bit_registers0_to_31": lambda s: _reg_bits(s.output_bool_registers, 0),
    "output_bit_registers32_to_63": lambda s: _reg_bits(s.output_bool_registers, 32),
    "input_bit_registers0_to_31": lambda s: _reg_bits(s.input_bool_registers, 0),
    "input_bit_registers32_to_63": lambda s: _reg_bits(s.input_bool_registers, 32),
    "payload": lambda s: s.payload_mass,
    "payload_cog": lambda s: s.payload_cog,
    "script_control_line": lambda s: s.script_line,
    "target_gravity": lambda s: (0.0, 0.0, -9.82),
}
"""Output fields the simulation models: name → its value at a snapshot. Every other output
of :data:`urdsl.protocol.rtde_fields.FIELDS` is sent as zeros of its type."""

for _i in range(48):
    VALUES[f"output_int_register_{_i}"] = lambda s, i=_i: s.output_int_registers[i]
    VALUES[f"output_double_register_{_i}"] = lambda s, i=_i: s.output_float_registers[i]
    VALUES[f"input_int_register_{_i}"] = lambda s, i=_i: s.input_int_registers[i]
    VALUES[f"input_double_register_{_i}"] = lambda s, i=_i: s.input_float_registers[i]


def _zero(type_name: str) -> Getter:
    code, count = TYPES[type_name]
    zero = 0.0 if code == "d" else (False if code == "?" else 0)
    value = zero if count == 1 else (zero,) * count
    return lambda s: value


def _getters(recipe: Recipe) -> list[tuple[Getter, bool]]:
    """(value at a snapshot, is a vector) for each field of an output recipe."""
    return [(VALUES.get(name) or _zero(type_name), TYPES[type_name][1] > 1)
            for name, type_name in zip(recipe.names, recipe.types, strict=True)]


class RtdeSession:
    """One RTDE connection, controller side: a :class:`RtdeServer` for the wire, plus what
    the controller does with it.

    ``environment``: the shared :class:`urdsl.runtime.Environment` the inputs are written
    into; ``owners``: the controller-wide :class:`InputOwners`; ``max_frequency``: 500 Hz
    e-Series, 125 Hz CB3.
    """

    def __init__(self, version: ControllerVersion, environment: Any, owners: InputOwnership,
                 max_frequency: float) -> None:
        self.version = version
        self.env = environment
        self.max_frequency = max_frequency
        self.server = RtdeServer((version.major, version.minor, version.bugfix, version.build),
                                 owners)
        self._recipe: Recipe | None = None
        self._getters: list[tuple[Getter, bool]] = []
        self._phase = 0.0
        self._every = 1
        self._count = 0
        self._was_running = False
        self.speed_slider: float = 1.0

    @property
    def protocol(self) -> int:
        return self.server.protocol

    @property
    def output(self) -> Recipe | None:
        """The output recipe (``valid`` false when a field was refused)."""
        return self.server.output_recipe

    @property
    def started(self) -> bool:
        return self.server.running

    @property
    def frequency(self) -> float:
        return self.server.frequency

    # ---- client → controller -------------------------------------------------------------

    def receive(self, data: bytes) -> bytes:
        """Handle the client's bytes; return the replies to send."""
        server = self.server
        try:
            packages = server.packages(data)
        except ProtocolError as error:
            raise RtdeProtocolError(error.message, interface="rtde", offset=error.offset) \
                from None
        for package in packages:
            try:
                event = server.receive_package(package)
            except ProtocolError as error:
                server.refuse(package, error.message)
                continue
            if isinstance(event, DataPackage):
                self._write(event.values)
            elif not isinstance(event, RtdeTextMessage):
                self._schedule()
        return server.data_to_send()

    def _schedule(self) -> None:
        """After a request: follow the output recipe and (re)start the package clock."""
        server = self.server
        if server.output_recipe is not self._recipe:
            self._recipe = server.output_recipe
            self._getters = _getters(self._recipe) if self._recipe and self._recipe.valid \
                else []
            if self.version.e_series:
                self._every = 1
            else:  # CB3 decimates: one package every floor(125 / f) steps (§12)
                self._every = server.decimation
        if server.running and not self._was_running:
            # the first package goes out at the next step, then one every max/f steps
            self._phase = 1.0 - server.frequency / self.max_frequency
            self._count = 0
        self._was_running = server.running

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
        if not self._getters or not self.server.running:
            return False
        if not self.version.e_series:
            self._count += 1
            if self._count >= self._every:
                self._count = 0
                return True
            return False
        self._phase += self.server.frequency / self.max_frequency
        if self._phase >= 1.0 - 1e-9:
            self._phase -= 1.0
            if self._phase > 1.0 or not math.isfinite(self._phase):
                self._phase = 0.0
            return True
        return False

    def encode(self, snap: Snapshot) -> bytes:
        """The output data package for ``snap`` (call when :meth:`output_due`)."""
        values: list[Any] = []
        append, extend = values.append, values.extend
        for getter, vector in self._getters:
            value = getter(snap)
            if vector:
                extend(value.tolist() if hasattr(value, "tolist") else value)
            else:
                append(value)
        return self.server.output_package(values)

    def close(self) -> None:
        self.server.close()
