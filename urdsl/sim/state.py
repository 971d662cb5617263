"""What the virtual controller publishes: the modes of a UR controller and one snapshot of the
simulated robot per controller step.

The numeric codes are the controller's (docs/controller-facts.md §5): they appear unchanged on the
realtime, primary and RTDE interfaces, and the dashboard prints their names.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from ..versions import ControllerVersion

__all__ = [
    "RobotMode", "SafetyMode", "ProgramState", "JointMode", "ControllerVersion", "Snapshot",
    "SimError", "ControllerMessage",
]


class RobotMode(enum.IntEnum):
    """Robot mode (3.x/5.x numbering)."""

    NO_CONTROLLER = -1
    DISCONNECTED = 0
    CONFIRM_SAFETY = 1
    BOOTING = 2
    POWER_OFF = 3
    POWER_ON = 4
    IDLE = 5
    BACKDRIVE = 6
    RUNNING = 7
    UPDATING_FIRMWARE = 8


class SafetyMode(enum.IntEnum):
    """Safety mode (the subset a virtual controller can be in, with the controller's codes)."""

    NORMAL = 1
    REDUCED = 2
    PROTECTIVE_STOP = 3
    RECOVERY = 4
    SAFEGUARD_STOP = 5
    SYSTEM_EMERGENCY_STOP = 6
    ROBOT_EMERGENCY_STOP = 7
    VIOLATION = 8
    FAULT = 9


class ProgramState(enum.IntEnum):
    """RTDE ``runtime_state`` and the realtime interface's program state."""

    STOPPING = 0
    STOPPED = 1
    PLAYING = 2
    PAUSING = 3
    PAUSED = 4
    RESUMING = 5


class JointMode(enum.IntEnum):
    """Joint mode (3.x/5.x); the simulated joints are powered off, idle or running."""

    BACKDRIVE = 238
    POWER_OFF = 239
    BOOTING = 247
    RUNNING = 253
    IDLE = 255


class SimError(Exception):
    """A request the virtual controller refuses (bad configuration, unknown program file)."""


@dataclass(frozen=True)
class ControllerMessage:
    """Something the controller tells its primary clients.

    ``kind``: ``"runtime_exception"`` (syntax and runtime errors; ``line``/``column`` 1-based
    in the program), ``"text"`` (``textmsg``), ``"popup"``, ``"safety"`` (a protective stop),
    ``"error"`` (a program refused). ``time`` is controller time in s.
    """

    time: float
    kind: str
    text: str
    line: int = 0
    column: int = 0
    title: str = ""


@dataclass(frozen=True, eq=False)
class Snapshot:
    """The simulated robot at one controller step. Arrays are read-only.

    ``time``: s since the controller started (robot time, runs ``speed`` times wall time);
    ``q``, ``qd``, ``qdd``: joints (rad, rad/s, rad/s²); ``tcp``: TCP pose (m, rotation
    vector in rad) in Base; ``tcp_speed``: (m/s, rad/s); ``tcp_offset``: the active TCP in the
    flange frame; the digital bit masks count as the controller's (standard 0-7,
    configurable 8-15, tool 16-17); registers are copies taken at this step.
    """

    time: float
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tcp: np.ndarray
    tcp_speed: np.ndarray
    tcp_offset: np.ndarray
    robot_mode: RobotMode
    safety_mode: SafetyMode
    program_state: ProgramState
    joint_mode: JointMode
    power_on: bool
    speed_scaling: float
    target_speed_fraction: float
    digital_inputs: int
    digital_outputs: int
    analog_inputs: tuple[float, float]
    analog_outputs: tuple[float, float]
    tool_analog_inputs: tuple[float, float]
    input_int_registers: tuple[int, ...]
    output_int_registers: tuple[int, ...]
    input_float_registers: tuple[float, ...]
    output_float_registers: tuple[float, ...]
    input_bool_registers: int
    output_bool_registers: int
    payload_mass: float
    payload_cog: np.ndarray
    elbow: np.ndarray
    elbow_speed: np.ndarray
    script_line: int

    @property
    def program_running(self) -> bool:
        return self.program_state in (ProgramState.PLAYING, ProgramState.PAUSING,
                                      ProgramState.RESUMING, ProgramState.PAUSED)

    @property
    def program_paused(self) -> bool:
        return self.program_state == ProgramState.PAUSED

    @property
    def protective_stopped(self) -> bool:
        return self.safety_mode == SafetyMode.PROTECTIVE_STOP
