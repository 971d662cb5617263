"""The RTDE field table: every documented input and output name with its type, as data.

Restated from UR's RTDE guide and cross-checked against the type table of UR's C++ client
library (docs/controller-facts.md §12). ``since`` gives the first CB3 and e-Series software
version that knows a field (``None``: that series does not have it). Where the guide's version
column could not be checked, ``confirmed`` is false and ``since`` is the RTDE baseline
(CB3 3.4, e-Series 5.0) or, for fields only newer e-Series releases have, 5.0 as well —
a simulated controller then offers the field earlier than a real one would.

A name may be usable as an input (the client writes it), as an output (the robot sends it),
or both: ``input_*`` registers can be read back in an output recipe.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from ..versions import ControllerVersion

__all__ = ["RtdeField", "FIELDS", "TYPES", "field_available", "output_fields", "input_fields"]

TYPES: MappingProxyType[str, tuple[str, int]] = MappingProxyType({
    "BOOL": ("?", 1),
    "UINT8": ("B", 1),
    "UINT32": ("I", 1),
    "UINT64": ("Q", 1),
    "INT32": ("i", 1),
    "DOUBLE": ("d", 1),
    "VECTOR3D": ("d", 3),
    "VECTOR6D": ("d", 6),
    "VECTOR6INT32": ("i", 6),
    "VECTOR6UINT32": ("I", 6),
})
"""RTDE type name → (struct format character, number of values). All big-endian."""


@dataclass(frozen=True)
class RtdeField:
    """One RTDE name: its ``type`` (a key of :data:`TYPES`), whether it can be an ``input``
    and/or an ``output``, a one-line ``description`` with units, and ``since`` =
    (first CB3 version, first e-Series version)."""

    name: str
    type: str
    input: bool
    output: bool
    description: str
    since: tuple[str | None, str | None] = ("3.4", "5.0")
    confirmed: bool = True


_BASE = ("3.4", "5.0")
_E_ONLY = (None, "5.0")


def _out(name: str, type_: str, description: str, since=_BASE, confirmed=True) -> RtdeField:
    return RtdeField(name, type_, False, True, description, since, confirmed)


def _in(name: str, type_: str, description: str, since=_BASE, confirmed=True) -> RtdeField:
    return RtdeField(name, type_, True, False, description, since, confirmed)


_FIELDS: list[RtdeField] = [
    # --- outputs: robot, joints, tool ---
    _out("timestamp", "DOUBLE", "time since the controller started [s]"),
    _out("target_q", "VECTOR6D", "target joint positions [rad]"),
    _out("target_qd", "VECTOR6D", "target joint velocities [rad/s]"),
    _out("target_qdd", "VECTOR6D", "target joint accelerations [rad/s²]"),
    _out("target_current", "VECTOR6D", "target joint currents [A]"),
    _out("target_moment", "VECTOR6D", "target joint moments (torques) [N·m]"),
    _out("actual_q", "VECTOR6D", "actual joint positions [rad]"),
    _out("actual_qd", "VECTOR6D", "actual joint velocities [rad/s]"),
    _out("actual_current", "VECTOR6D", "actual joint currents [A]"),
    _out("actual_current_window", "VECTOR6D", "allowed joint current band [A]", _E_ONLY, False),
    _out("actual_current_as_torque", "VECTOR6D",
         "actual joint currents converted to torques [N·m]", (None, "5.23")),
    _out("joint_control_output", "VECTOR6D", "joint control currents [A]"),
    _out("actual_TCP_pose", "VECTOR6D", "actual TCP pose (x, y, z, rx, ry, rz) [m, rad]"),
    _out("actual_TCP_speed", "VECTOR6D", "actual TCP speed [m/s, rad/s]"),
    _out("actual_TCP_force", "VECTOR6D", "generalised TCP force [N, N·m]"),
    _out("target_TCP_pose", "VECTOR6D", "target TCP pose [m, rad]"),
    _out("target_TCP_speed", "VECTOR6D", "target TCP speed [m/s, rad/s]"),
    _out("tcp_offset", "VECTOR6D", "active TCP offset from the flange [m, rad]", _BASE, False),
    _out("actual_TCP_acceleration", "VECTOR6D", "actual TCP acceleration [m/s², rad/s²]",
         _E_ONLY, False),
    _out("target_TCP_acceleration", "VECTOR6D", "target TCP acceleration [m/s², rad/s²]",
         _E_ONLY, False),
    _out("actual_digital_input_bits", "UINT64",
         "digital inputs: bits 0-7 standard, 8-15 configurable, 16-17 tool"),
    _out("actual_configurable_digital_input_bits", "UINT64", "configurable digital inputs",
         _BASE, False),
    _out("joint_temperatures", "VECTOR6D", "joint temperatures [°C]"),
    _out("actual_execution_time", "DOUBLE", "controller realtime thread execution time [ms]"),
    _out("target_execution_time", "DOUBLE", "target realtime thread execution time [ms]",
         _E_ONLY, False),
    _out("robot_mode", "INT32", "robot mode (-1 NO_CONTROLLER … 7 RUNNING, 8 UPDATING)"),
    _out("joint_mode", "VECTOR6INT32", "joint modes (253 RUNNING, 255 IDLE, …)"),
    _out("safety_mode", "INT32", "safety mode (1 NORMAL, 2 REDUCED, 3 PROTECTIVE_STOP, …)"),
    _out("safety_status", "INT32", "safety status (as safety mode, with more detail)",
         ("3.10", "5.4")),
    _out("actual_tool_accelerometer", "VECTOR3D", "tool accelerometer (x, y, z) [m/s²]"),
    _out("speed_scaling", "DOUBLE", "speed scaling of the trajectory limiter [0..1]"),
    _out("target_speed_fraction", "DOUBLE", "target speed fraction (speed slider) [0..1]"),
    _out("actual_momentum", "DOUBLE", "norm of the Cartesian linear momentum [kg·m/s]"),
    _out("actual_main_voltage", "DOUBLE", "safety board main voltage [V]"),
    _out("actual_robot_voltage", "DOUBLE", "safety board robot voltage (48 V) [V]"),
    _out("actual_robot_current", "DOUBLE", "safety board robot current [A]"),
    _out("actual_joint_voltage", "VECTOR6D", "actual joint voltages [V]"),
    _out("actual_digital_output_bits", "UINT64",
         "digital outputs: bits 0-7 standard, 8-15 configurable, 16-17 tool"),
    _out("actual_configurable_digital_output_bits", "UINT64", "configurable digital outputs",
         _BASE, False),
    _out("runtime_state", "UINT32",
         "program state (0 STOPPING, 1 STOPPED, 2 PLAYING, 3 PAUSING, 4 PAUSED, 5 RESUMING)"),
    _out("elbow_position", "VECTOR3D", "elbow position in the Base frame [m]", ("3.5", "5.0")),
    _out("elbow_velocity", "VECTOR3D", "elbow velocity in the Base frame [m/s]", ("3.5", "5.0")),
    _out("robot_status_bits", "UINT32",
         "bits 0-3: power on, program running, teach button pressed, power button pressed"),
    _out("safety_status_bits", "UINT32",
         "bits 0-10: normal, reduced, protective stop, recovery, safeguard stop, system "
         "e-stop, robot e-stop, e-stop, violation, fault, stopped due to safety"),
    _out("analog_io_types", "UINT32",
         "bits 0-3: standard analog input 0, 1, output 0, 1 (0 current, 1 voltage)"),
    _out("standard_analog_input0", "DOUBLE", "standard analog input 0 [A or V]"),
    _out("standard_analog_input1", "DOUBLE", "standard analog input 1 [A or V]"),
    _out("standard_analog_output0", "DOUBLE", "standard analog output 0 [A or V]"),
    _out("standard_analog_output1", "DOUBLE", "standard analog output 1 [A or V]"),
    _out("io_current", "DOUBLE", "I/O current [A]"),
    _out("euromap67_input_bits", "UINT32", "Euromap 67 input bits"),
    _out("euromap67_output_bits", "UINT32", "Euromap 67 output bits"),
    _out("euromap67_24V_voltage", "DOUBLE", "Euromap 24 V supply voltage [V]"),
    _out("euromap67_24V_current", "DOUBLE", "Euromap 24 V supply current [A]"),
    _out("tool_mode", "UINT32", "tool mode (as joint modes)"),
    _out("tool_analog_input_types", "UINT32",
         "bits 0-1: tool analog input 0, 1 (0 current, 1 voltage)"),
    _out("tool_analog_input0", "DOUBLE", "tool analog input 0 [A or V]"),
    _out("tool_analog_input1", "DOUBLE", "tool analog input 1 [A or V]"),
    _out("tool_output_voltage", "INT32", "tool output voltage setting [V]"),
    _out("tool_output_current", "DOUBLE", "tool current [A]"),
    _out("tool_temperature", "DOUBLE", "tool temperature [°C]"),
    _out("tool_output_mode", "UINT8", "tool output mode", _E_ONLY, False),
    _out("tool_digital_output0_mode", "UINT8", "tool digital output 0 mode", _E_ONLY, False),
    _out("tool_digital_output1_mode", "UINT8", "tool digital output 1 mode", _E_ONLY, False),
    _out("tcp_force_scalar", "DOUBLE", "TCP force scalar [N]"),
    _out("output_bit_registers0_to_31", "UINT32", "general purpose output bits 0-31"),
    _out("output_bit_registers32_to_63", "UINT32", "general purpose output bits 32-63"),
    _out("payload", "DOUBLE", "payload mass [kg]", ("3.11", "5.5.1")),
    _out("payload_cog", "VECTOR3D", "payload centre of gravity (x, y, z) [m]", ("3.11", "5.5.1")),
    _out("payload_inertia", "VECTOR6D",
         "payload inertia (Ixx, Iyy, Izz, Ixy, Ixz, Iyz) [kg·m²]", ("3.15", "5.11")),
    _out("script_control_line", "UINT32", "line of the script being executed",
         ("3.14", "5.9")),
    _out("ft_raw_wrench", "VECTOR6D", "raw force/torque sensor wrench [N, N·m]", (None, "5.9")),
    _out("joint_position_deviation_ratio", "DOUBLE",
         "joint position deviation over its limit [0..1]", _E_ONLY, False),
    _out("collision_detection_ratio", "DOUBLE", "collision detection over its limit [0..1]",
         _E_ONLY, False),
    _out("actual_robot_energy_consumed", "DOUBLE", "energy consumed by the robot [J]",
         _E_ONLY, False),
    _out("actual_robot_braking_energy_dissipated", "DOUBLE",
         "braking energy dissipated [J]", _E_ONLY, False),
    _out("encoder0_raw", "INT32", "raw count of encoder input 0", _E_ONLY, False),
    _out("encoder1_raw", "INT32", "raw count of encoder input 1", _E_ONLY, False),
    _out("wrench_calc_from_currents", "VECTOR6D", "TCP wrench estimated from joint currents",
         _E_ONLY, False),
    _out("time_scale_source", "INT32", "what limits the speed scaling", _E_ONLY, False),
    _out("target_gravity", "VECTOR3D", "gravity vector in the Base frame [m/s²]",
         _E_ONLY, False),
    _out("target_base_acceleration", "VECTOR6D", "acceleration of a moving base", _E_ONLY,
         False),
    _out("control_step", "UINT64", "control cycle counter", _E_ONLY, False),
    _out("target_base_wrench", "VECTOR6D", "wrench applied to a moving base", _E_ONLY, False),
    # --- inputs ---
    _in("speed_slider_mask", "UINT32", "1: apply speed_slider_fraction"),
    _in("speed_slider_fraction", "DOUBLE", "new speed slider value [0..1]"),
    _in("standard_digital_output_mask", "UINT8", "standard digital outputs to change"),
    _in("standard_digital_output", "UINT8", "standard digital output values"),
    _in("configurable_digital_output_mask", "UINT8", "configurable digital outputs to change"),
    _in("configurable_digital_output", "UINT8", "configurable digital output values"),
    _in("tool_digital_output_mask", "UINT8", "tool digital outputs to change (bits 0-1)",
        _BASE, False),
    _in("tool_digital_output", "UINT8", "tool digital output values (bits 0-1)", _BASE, False),
    _in("standard_analog_output_mask", "UINT8", "standard analog outputs to change (bits 0-1)"),
    _in("standard_analog_output_type", "UINT8",
        "analog output domain (bit 0/1: output 0/1; 0 current, 1 voltage)"),
    _in("standard_analog_output_0", "DOUBLE", "standard analog output 0 (ratio) [0..1]"),
    _in("standard_analog_output_1", "DOUBLE", "standard analog output 1 (ratio) [0..1]"),
    _in("external_force_torque", "VECTOR6D",
        "external F/T sensor wrench (with ft_rtde_input_enable) [N, N·m]", _BASE, False),
    RtdeField("input_bit_registers0_to_31", "UINT32", True, True,
              "general purpose input bits 0-31"),
    RtdeField("input_bit_registers32_to_63", "UINT32", True, True,
              "general purpose input bits 32-63"),
]

for _n in range(64, 128):
    _FIELDS.append(RtdeField(f"input_bit_register_{_n}", "BOOL", True, True,
                             f"general purpose input bit {_n}", ("3.9", "5.3")))
    _FIELDS.append(_out(f"output_bit_register_{_n}", "BOOL",
                        f"general purpose output bit {_n}", ("3.9", "5.3")))
for _n in range(48):
    _since = ("3.4", "5.0") if _n < 24 else ("3.9", "5.3")
    _use = "reserved for fieldbus/PLC adapters" if _n < 24 else "free for RTDE clients"
    _FIELDS.append(RtdeField(f"input_int_register_{_n}", "INT32", True, True,
                             f"general purpose input integer {_n} ({_use})", _since))
    _FIELDS.append(RtdeField(f"input_double_register_{_n}", "DOUBLE", True, True,
                             f"general purpose input double {_n} ({_use})", _since))
    _FIELDS.append(_out(f"output_int_register_{_n}", "INT32",
                        f"general purpose output integer {_n}", _since))
    _FIELDS.append(_out(f"output_double_register_{_n}", "DOUBLE",
                        f"general purpose output double {_n}", _since))

FIELDS: MappingProxyType[str, RtdeField] = MappingProxyType({f.name: f for f in _FIELDS})
"""Every RTDE name → its :class:`RtdeField`."""


def field_available(field: RtdeField, version: tuple[int, ...]) -> bool:
    """Does a controller of software ``version`` (``(5, 11, 1)``) know ``field``?"""
    cb3, eseries = field.since
    since = cb3 if version[0] < 5 else eseries
    if since is None:
        return False
    return ControllerVersion(*version[:4]) >= ControllerVersion.parse(since)


def output_fields(version: tuple[int, ...] | None = None) -> list[RtdeField]:
    """Fields an output recipe may name (on ``version``, if given)."""
    return [f for f in FIELDS.values()
            if f.output and (version is None or field_available(f, version))]


def input_fields(version: tuple[int, ...] | None = None) -> list[RtdeField]:
    """Fields an input recipe may name (on ``version``, if given)."""
    return [f for f in FIELDS.values()
            if f.input and (version is None or field_available(f, version))]
