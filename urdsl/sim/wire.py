"""What the virtual controller sends on its realtime and primary/secondary ports (no sockets).

Realtime packets are laid out by the one layout table per controller version of
:mod:`urdsl.protocol.realtime` (docs/controller-facts.md §10); this module only says which
snapshot value each named field carries. Quantities the simulation does not model (motor
currents, temperatures, voltages, forces) are sent as 0.0 so that clients parse complete
packets.

The primary/secondary robot state and robot messages (docs/controller-facts.md §11) are
still packed here by hand; moving them onto :mod:`urdsl.protocol.primary`'s encoders is
the remaining part of issue 15's sim work.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

import numpy as np

from ..protocol.realtime import layout_for_version
from .state import ControllerVersion, SafetyMode, Snapshot

__all__ = [
    "realtime_size", "encode_realtime", "encode_robot_state", "encode_version_message",
    "encode_text_message", "encode_runtime_exception", "encode_safety_message",
    "ROBOT_STATE", "ROBOT_MESSAGE",
]

ROBOT_STATE = 16
ROBOT_MESSAGE = 20
SOURCE_CONTROLLER = -2  # [U] the int8 source the controller puts on its own messages


# ---- realtime (30003 / 30013) ---------------------------------------------------------------

_REALTIME: tuple[tuple[str, Callable[[Snapshot], Any]], ...] = (
    # the controller's behaviour: which snapshot value each named field of the protocol's
    # layout carries (the planner's path is the target); fields not named here are 0
    ("time", lambda s: s.time), ("controller_timer", lambda s: s.time),
    ("q_target", lambda s: s.q), ("qd_target", lambda s: s.qd),
    ("qdd_target", lambda s: s.qdd), ("q_actual", lambda s: s.q), ("qd_actual", lambda s: s.qd),
    ("tool_vector_actual", lambda s: s.tcp), ("tcp_speed_actual", lambda s: s.tcp_speed),
    ("tool_vector_target", lambda s: s.tcp), ("tcp_speed_target", lambda s: s.tcp_speed),
    ("digital_input_bits", lambda s: s.digital_inputs),
    ("robot_mode", lambda s: int(s.robot_mode)),
    ("joint_modes", lambda s: int(s.joint_mode)),
    ("safety_mode", lambda s: int(s.safety_mode)),
    ("speed_scaling", lambda s: s.speed_scaling),
    ("digital_outputs", lambda s: s.digital_outputs),
    ("program_state", lambda s: int(s.program_state)),
    ("elbow_position", lambda s: s.elbow), ("elbow_velocity", lambda s: s.elbow_speed),
    ("safety_status", lambda s: int(s.safety_mode)),
    ("payload_mass", lambda s: s.payload_mass), ("payload_cog", lambda s: s.payload_cog),
)

_PLANS: dict[ControllerVersion, tuple[bytes, int, tuple]] = {}


def _realtime_plan(version: ControllerVersion) -> tuple[bytes, int, tuple]:
    """(size field, doubles, (slot, value) pairs) of ``version``'s layout, from the one
    layout table of :mod:`urdsl.protocol.realtime`."""
    plan = _PLANS.get(version)
    if plan is None:
        layout = layout_for_version(f"{version.major}.{version.minor}")
        slots = tuple((layout.slot(name), value) for name, value in _REALTIME
                      if name in layout.names)
        plan = _PLANS[version] = (struct.pack(">i", layout.size), layout.doubles, slots)
    return plan


def realtime_size(version: ControllerVersion) -> int:
    """Total packet size (bytes, including the int32 size field) for a software version
    (docs/controller-facts.md §10)."""
    return layout_for_version(f"{version.major}.{version.minor}").size


def encode_realtime(snap: Snapshot, version: ControllerVersion) -> bytes:
    """One realtime packet of ``version``'s layout for ``snap``."""
    head, doubles, slots = _realtime_plan(version)
    values = np.zeros(doubles)
    for where, value in slots:
        values[where] = value(snap)
    return head + values.astype(">f8").tobytes()


# ---- primary / secondary (30001 / 30002, read-only 30011 / 30012) ----------------------------


def _package(kind: int, body: bytes) -> bytes:
    """A ROBOT_STATE sub-package: uint32 size (incl. the 5-byte header), uint8 type, body."""
    return struct.pack(">IB", len(body) + 5, kind) + body


def _robot_mode_data(snap: Snapshot, version: ControllerVersion) -> bytes:
    running = snap.program_running
    head = struct.pack(
        ">Q???????BBdd", int(snap.time * 1000), True, snap.power_on, snap.power_on,
        False, snap.safety_mode == SafetyMode.PROTECTIVE_STOP, running, snap.program_paused,
        max(int(snap.robot_mode), 0), 0, snap.target_speed_fraction, snap.speed_scaling)
    if version < ControllerVersion(3, 2):
        return _package(0, head)                                     # 38 bytes
    head += struct.pack(">d", 1.0)                                   # target speed limit
    if version < ControllerVersion(3, 5):
        return _package(0, head)                                     # 46 bytes
    return _package(0, head + b"\x00")                               # 47 bytes


def _joint_data(snap: Snapshot) -> bytes:
    body = b"".join(
        struct.pack(">dddffffB", snap.q[i], snap.q[i], snap.qd[i], 0.0, 0.0, 0.0, 0.0,
                    int(snap.joint_mode))
        for i in range(6))
    return _package(1, body)                                         # 251 bytes


def _tool_data(snap: Snapshot) -> bytes:
    body = struct.pack(">BBddfBffB", 0, 0, snap.tool_analog_inputs[0],
                       snap.tool_analog_inputs[1], 0.0, 0, 0.0, 0.0, 0)
    return _package(2, body)                                         # 37 bytes


def _masterboard_data(snap: Snapshot) -> bytes:
    body = struct.pack(
        ">IIBBddBBddffffBBBIBBB",
        snap.digital_inputs & 0xFFFFFFFF, snap.digital_outputs & 0xFFFFFFFF, 0, 0,
        snap.analog_inputs[0], snap.analog_inputs[1], 0, 0,
        snap.analog_outputs[0], snap.analog_outputs[1], 0.0, 0.0, 0.0, 0.0,
        int(snap.safety_mode), snap.safety_mode == SafetyMode.REDUCED, False, 0, 0, False, 0)
    return _package(3, body)


def _cartesian_info(snap: Snapshot, version: ControllerVersion) -> bytes:
    body = struct.pack(">6d", *snap.tcp)
    if version >= ControllerVersion(3, 2):
        body += struct.pack(">6d", *snap.tcp_offset)
    return _package(4, body)                                         # 101 bytes (53 < 3.2)


def _kinematics_info(spec) -> bytes:
    body = struct.pack(">6I", *([0] * 6))
    body += struct.pack(">24d", *([0.0] * 6), *spec.dh_a, *spec.dh_d, *spec.dh_alpha)
    return _package(5, body + struct.pack(">I", 0))                  # 225 bytes


def _configuration_data(spec, qd_max, q_min, q_max) -> bytes:
    limits = [v for i in range(6) for v in (q_min[i], q_max[i])]
    limits = [v if np.isfinite(v) else np.sign(v) * 1e9 for v in limits]
    speeds = [v for i in range(6) for v in (qd_max[i], 0.0)]  # max accel: not published
    defaults = (1.05, 1.4, 0.25, 1.2, 0.0)  # movej v, a; movel v, a (script defaults); eq radius
    body = struct.pack(">12d12d5d", *limits, *speeds, *defaults)
    body += struct.pack(">24d", *spec.dh_a, *spec.dh_d, *spec.dh_alpha, *([0.0] * 6))
    body += struct.pack(">4i", 0, 0, int(getattr(spec, "robot_type", 0)), 0)
    return _package(6, body)                                         # 445 bytes


def _force_mode_data() -> bytes:
    return _package(7, struct.pack(">7d", *([0.0] * 7)))             # 61 bytes


def _additional_info(version: ControllerVersion) -> bytes:
    if version.e_series:  # freedrive button pressed / enabled, IO-enabled freedrive [U]
        return _package(8, struct.pack(">???", False, False, False))
    return _package(8, struct.pack(">??", False, False))             # teach button


def encode_robot_state(snap: Snapshot, version: ControllerVersion, spec=None,
                       limits: tuple | None = None, configuration: bool = False) -> bytes:
    """A ROBOT_STATE message (type 16): robot mode, joint, tool, masterboard, cartesian,
    (kinematics and configuration when ``configuration`` and a model ``spec`` are given),
    force mode and additional info sub-packages. ``limits`` = (qd_max, q_min, q_max)."""
    parts = [_robot_mode_data(snap, version), _joint_data(snap), _tool_data(snap),
             _masterboard_data(snap), _cartesian_info(snap, version)]
    if configuration and spec is not None:
        parts.append(_kinematics_info(spec))
        if limits is not None:
            parts.append(_configuration_data(spec, *limits))
    if version >= ControllerVersion(3, 2):
        parts += [_force_mode_data(), _additional_info(version)]
    body = b"".join(parts)
    return struct.pack(">iB", len(body) + 5, ROBOT_STATE) + body


def _robot_message(time: float, kind: int, body: bytes) -> bytes:
    head = struct.pack(">QbB", int(time * 1000), SOURCE_CONTROLLER, kind)
    payload = head + body
    return struct.pack(">iB", len(payload) + 5, ROBOT_MESSAGE) + payload


def encode_version_message(version: ControllerVersion, time: float = 0.0,
                           build_date: str = "urdsl virtual controller") -> bytes:
    """ROBOT_MESSAGE VERSION (type 3), the first message on 30001/30002 (layout of 3.12+/5.x)."""
    name = b"URControl"
    body = struct.pack(">b", len(name)) + name
    body += struct.pack(">BBii", version.major, version.minor, version.bugfix, version.build)
    return _robot_message(time, 3, body + build_date.encode("utf-8"))


def encode_text_message(text: str, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE TEXT (type 0): what ``textmsg`` shows."""
    return _robot_message(time, 0, text.encode("utf-8", errors="replace"))


def encode_runtime_exception(line: int, column: int, text: str, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE RUNTIME_EXCEPTION (type 10): uint32 line, uint32 column, text."""
    body = struct.pack(">II", max(line, 0), max(column, 0))
    return _robot_message(time, 10, body + text.encode("utf-8", errors="replace"))


def encode_safety_message(code: int, argument: int, mode: SafetyMode, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE SAFETY_MODE (type 5): int32 code, int32 argument, uint8 safety mode,
    uint32 report data type (0: none), uint32 report data."""
    body = struct.pack(">iiBII", code, argument, int(mode), 0, 0)
    return _robot_message(time, 5, body)
