"""What the virtual controller sends on its realtime and primary/secondary ports (no sockets).

The bytes are :mod:`urdsl.protocol`'s: realtime packets follow the one layout table per
controller version of :mod:`urdsl.protocol.realtime` (docs/controller-facts.md §10), the
robot state and robot messages the sub-package and message encoders of
:mod:`urdsl.protocol.primary` (§11), in the layout variant the version sends. This module
only says which snapshot value each field carries. Quantities the simulation does not model
(motor currents, temperatures, voltages, forces) are sent as 0 so that clients parse
complete packets.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np

from ..protocol.primary import (
    AdditionalInfo,
    CartesianInfo,
    ConfigurationData,
    ForceModeData,
    JointData,
    KinematicsInfo,
    MasterboardData,
    RobotModeData,
    RobotState,
    RuntimeExceptionMessage,
    SafetyModeMessage,
    TextMessage,
    ToolData,
    VersionMessage,
)
from ..protocol.realtime import layout_for_version
from .state import ControllerMessage, ControllerVersion, SafetyMode, Snapshot

__all__ = [
    "realtime_encoder", "encode_realtime", "encode_robot_state",
    "encode_version_message", "encode_text_message", "encode_runtime_exception",
    "encode_safety_message", "encode_controller_message",
]

_ZEROS = (0.0,) * 6
SOURCE_CONTROLLER = -2  # [U] the int8 source the controller puts on its own messages


# ---- realtime (30003 / 30013) ---------------------------------------------------------------

_REALTIME: dict[str, Callable[[Snapshot], Any]] = {
    # the controller's behaviour: which snapshot value each named field of the protocol's
    # layouts carries (the planner's path is the target); fields not named here are 0.
    # Arrays go as lists: a list spreads into the pack call ~5x faster than numpy's scalars.
    "time": lambda s: s.time, "controller_timer": lambda s: s.time,
    "q_target": lambda s: s.q.tolist(), "qd_target": lambda s: s.qd.tolist(),
    "qdd_target": lambda s: s.qdd.tolist(),
    "q_actual": lambda s: s.q.tolist(), "qd_actual": lambda s: s.qd.tolist(),
    "tool_vector_actual": lambda s: s.tcp.tolist(),
    "tcp_speed_actual": lambda s: s.tcp_speed.tolist(),
    "tool_vector_target": lambda s: s.tcp.tolist(),
    "tcp_speed_target": lambda s: s.tcp_speed.tolist(),
    "digital_input_bits": lambda s: s.digital_inputs,
    "robot_mode": lambda s: int(s.robot_mode),
    "joint_modes": lambda s: (int(s.joint_mode),) * 6,
    "safety_mode": lambda s: int(s.safety_mode),
    "speed_scaling": lambda s: s.speed_scaling,
    "digital_outputs": lambda s: s.digital_outputs,
    "program_state": lambda s: int(s.program_state),
    "elbow_position": lambda s: s.elbow.tolist(),
    "elbow_velocity": lambda s: s.elbow_speed.tolist(),
    "safety_status": lambda s: int(s.safety_mode),
    "payload_mass": lambda s: s.payload_mass, "payload_cog": lambda s: s.payload_cog.tolist(),
}


@cache
def realtime_encoder(version: ControllerVersion) -> Callable[[Snapshot], bytes]:
    """``version``'s realtime encoder (snapshot → packet), made once: the protocol's
    encoder of the layout (:meth:`urdsl.protocol.realtime.RealtimeLayout.packer`, one
    precompiled struct) with the values :data:`_REALTIME` names."""
    return layout_for_version(f"{version.major}.{version.minor}").packer(_REALTIME)


def encode_realtime(snap: Snapshot, version: ControllerVersion) -> bytes:
    """One realtime packet of ``version``'s layout for ``snap``."""
    return realtime_encoder(version)(snap)


# ---- primary / secondary (30001 / 30002, read-only 30011 / 30012) ----------------------------


def _variant(version: ControllerVersion, *labels: str) -> str:
    """The newest of a sub-package's layout ``labels`` (first versions that send them) that
    ``version`` sends."""
    chosen = labels[0]
    for label in labels:
        if version >= ControllerVersion.parse(label):
            chosen = label
    return chosen


def _robot_mode_data(snap: Snapshot, version: ControllerVersion) -> RobotModeData:
    variant = _variant(version, "3.0", "3.2", "3.5")
    return RobotModeData(
        variant=variant, timestamp=int(snap.time * 1000), is_real_robot_connected=True,
        is_real_robot_enabled=snap.power_on, is_robot_power_on=snap.power_on,
        is_emergency_stopped=False,
        is_protective_stopped=snap.safety_mode == SafetyMode.PROTECTIVE_STOP,
        is_program_running=snap.program_running, is_program_paused=snap.program_paused,
        robot_mode=max(int(snap.robot_mode), 0), control_mode=0,
        target_speed_fraction=snap.target_speed_fraction, speed_scaling=snap.speed_scaling,
        target_speed_fraction_limit=None if variant == "3.0" else 1.0,
        reserved=0 if variant == "3.5" else None)


def _joint_data(snap: Snapshot) -> JointData:
    q, qd = tuple(snap.q.tolist()), tuple(snap.qd.tolist())
    return JointData(variant="3.0", q_actual=q, q_target=q, qd_actual=qd, i_actual=_ZEROS,
                     v_actual=_ZEROS, t_motor=_ZEROS, t_micro=_ZEROS,
                     joint_mode=(int(snap.joint_mode),) * 6)


def _tool_data(snap: Snapshot) -> ToolData:
    return ToolData(variant="3.0", analog_input_2=snap.tool_analog_inputs[0],
                    analog_input_3=snap.tool_analog_inputs[1])


def _masterboard_data(snap: Snapshot, version: ControllerVersion) -> MasterboardData:
    variant = _variant(version, "3.0", "3.2", "5.0")
    return MasterboardData(
        variant=variant, digital_input_bits=snap.digital_inputs & 0xFFFFFFFF,
        digital_output_bits=snap.digital_outputs & 0xFFFFFFFF,
        analog_input_0=snap.analog_inputs[0], analog_input_1=snap.analog_inputs[1],
        analog_output_0=snap.analog_outputs[0], analog_output_1=snap.analog_outputs[1],
        safety_mode=int(snap.safety_mode),
        in_reduced_mode=snap.safety_mode == SafetyMode.REDUCED,
        operational_mode_selector_input=None if variant == "3.0" else 0,
        three_position_enabling_device_input=None if variant == "3.0" else False,
        reserved_2=0 if variant == "5.0" else None)


def _cartesian_info(snap: Snapshot, version: ControllerVersion) -> CartesianInfo:
    variant = _variant(version, "3.0", "3.2")
    return CartesianInfo(variant=variant, tcp_pose=tuple(snap.tcp.tolist()),
                         tcp_offset=tuple(snap.tcp_offset.tolist()) if variant == "3.2"
                         else None)


def _kinematics_info(spec: Any) -> KinematicsInfo:
    return KinematicsInfo(variant="3.0", checksum=(0,) * 6, dh_theta=_ZEROS,
                          dh_a=tuple(spec.dh_a), dh_d=tuple(spec.dh_d),
                          dh_alpha=tuple(spec.dh_alpha), calibration_status=0)


def _configuration_data(spec: Any, version: ControllerVersion, qd_max, q_min,
                        q_max) -> ConfigurationData:
    def finite(values) -> tuple[float, ...]:
        return tuple(float(v) if np.isfinite(v) else float(np.sign(v)) * 1e9 for v in values)

    e_series = _variant(version, "3.0", "5.0") == "5.0"
    return ConfigurationData(
        variant="5.0" if e_series else "3.0", joint_min_limit=finite(q_min),
        joint_max_limit=finite(q_max), joint_max_speed=tuple(float(v) for v in qd_max),
        joint_max_acceleration=_ZEROS,  # not published by the models
        # movej v, a; movel v, a (the script defaults); equivalent radius
        v_joint_default=1.05, a_joint_default=1.4, v_tool_default=0.25, a_tool_default=1.2,
        eq_radius=0.0, dh_a=tuple(spec.dh_a), dh_d=tuple(spec.dh_d),
        dh_alpha=tuple(spec.dh_alpha), dh_theta=_ZEROS,
        robot_type=int(getattr(spec, "robot_type", 0)),
        reserved_1=0 if e_series else None, reserved_2=0 if e_series else None)


def encode_robot_state(snap: Snapshot, version: ControllerVersion, spec=None,
                       limits: tuple | None = None, configuration: bool = False) -> bytes:
    """A ROBOT_STATE message (type 16) in ``version``'s sub-package layouts
    (:mod:`urdsl.protocol.primary`): robot mode, joint, tool, masterboard, cartesian,
    (kinematics and configuration when ``configuration`` and a model ``spec`` are given),
    force mode and additional info. ``limits`` = (qd_max, q_min, q_max)."""
    parts: list[Any] = [_robot_mode_data(snap, version), _joint_data(snap), _tool_data(snap),
                        _masterboard_data(snap, version), _cartesian_info(snap, version)]
    if configuration and spec is not None:
        parts.append(_kinematics_info(spec))
        if limits is not None:
            parts.append(_configuration_data(spec, version, *limits))
    if version >= ControllerVersion(3, 2):
        e_series = version.e_series
        parts += [ForceModeData(variant="3.0", wrench=_ZEROS, robot_dexterity=0.0),
                  AdditionalInfo(variant="5.0" if e_series else "3.2",
                                 io_enabled_freedrive=False if e_series else None,
                                 reserved=0 if e_series else None)]
    return RobotState(tuple(parts)).encode()


def _text(text: str) -> str:
    """``text`` as it survives UTF-8 (lone surrogates replaced)."""
    return text.encode("utf-8", errors="replace").decode("utf-8")


def _ms(time: float) -> int:
    return int(time * 1000)


def encode_version_message(version: ControllerVersion, time: float = 0.0,
                           build_date: str = "urdsl virtual controller") -> bytes:
    """ROBOT_MESSAGE VERSION (type 3), the first message on 30001/30002 (layout of 3.12+/5.x)."""
    return VersionMessage(timestamp=_ms(time), source=SOURCE_CONTROLLER,
                          project_name="URControl", major=version.major, minor=version.minor,
                          bugfix=version.bugfix, build_number=version.build,
                          build_date=build_date).encode()


def encode_text_message(text: str, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE TEXT (type 0): what ``textmsg`` shows."""
    return TextMessage(timestamp=_ms(time), source=SOURCE_CONTROLLER, text=_text(text)).encode()


def encode_runtime_exception(line: int, column: int, text: str, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE RUNTIME_EXCEPTION (type 10): line, column (1-based), text."""
    return RuntimeExceptionMessage(timestamp=_ms(time), source=SOURCE_CONTROLLER,
                                   line=max(line, 0), column=max(column, 0),
                                   text=_text(text)).encode()


def encode_safety_message(code: int, argument: int, mode: SafetyMode, time: float = 0.0) -> bytes:
    """ROBOT_MESSAGE SAFETY_MODE (type 5): code, argument, safety mode, no report data."""
    return SafetyModeMessage(timestamp=_ms(time), source=SOURCE_CONTROLLER, code=code,
                             argument=argument, safety_mode_type=int(mode),
                             report_data_type=0, report_data=0).encode()


def encode_controller_message(message: ControllerMessage) -> bytes:
    """The robot message(s) of one :class:`ControllerMessage` for the primary interface: a
    runtime exception with line and column; a protective stop as a SAFETY_MODE message
    (code and argument from its ``C<code>A<argument>`` text) followed by its text; any other
    kind as a TEXT message."""
    if message.kind == "runtime_exception":
        return encode_runtime_exception(message.line, message.column, message.text,
                                        message.time)
    if message.kind == "safety":
        match = re.match(r"C(\d+)A(\d+)", message.text)
        code, argument = (int(match.group(1)), int(match.group(2))) if match else (0, 0)
        return (encode_safety_message(code, argument, SafetyMode.PROTECTIVE_STOP, message.time)
                + encode_text_message(message.text, message.time))
    return encode_text_message(message.text, message.time)
