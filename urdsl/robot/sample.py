"""One sample of the robot's state, the same whatever interface it was read from.

:class:`RobotState` is what :class:`urdsl.robot.state.StateReader` returns; the sources of
each interface (:mod:`.state` for realtime, :mod:`.primary_state`, :mod:`.rtde_state`) build
it, so it lives below all of them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["RobotState", "ROBOT_MODES", "SAFETY_MODES", "PROGRAM_STATES"]

ROBOT_MODES = {
    -1: "NO_CONTROLLER", 0: "DISCONNECTED", 1: "CONFIRM_SAFETY", 2: "BOOTING", 3: "POWER_OFF",
    4: "POWER_ON", 5: "IDLE", 6: "BACKDRIVE", 7: "RUNNING", 8: "UPDATING_FIRMWARE",
}
"""Robot modes of CB3 and e-Series (docs/controller-facts.md §5)."""

SAFETY_MODES = {
    1: "NORMAL", 2: "REDUCED", 3: "PROTECTIVE_STOP", 4: "RECOVERY", 5: "SAFEGUARD_STOP",
    6: "SYSTEM_EMERGENCY_STOP", 7: "ROBOT_EMERGENCY_STOP", 8: "VIOLATION", 9: "FAULT",
    10: "VALIDATE_JOINT_ID", 11: "UNDEFINED_SAFETY_MODE", 12: "AUTOMATIC_MODE_SAFEGUARD_STOP",
    13: "SYSTEM_THREE_POSITION_ENABLING_STOP",
}
"""Safety modes (docs/controller-facts.md §5)."""

PROGRAM_STATES = {0: "STOPPING", 1: "STOPPED", 2: "PLAYING", 3: "PAUSING", 4: "PAUSED",
                  5: "RESUMING"}
"""RTDE ``runtime_state`` / realtime ``program_state`` values."""

def _name(table: dict[int, str], value: int | None) -> str | None:
    if value is None:
        return None
    return table.get(value, f"UNKNOWN({value})")


@dataclass(frozen=True)
class RobotState:
    """The robot's state as one interface reported it, in SI units.

    ``joints`` (rad) and ``joint_speeds`` (rad/s) run base … wrist 3; ``tcp_pose`` is
    (x, y, z [m], rx, ry, rz [rad]) in the Base frame; ``time`` is the controller's clock
    (s since it started); ``skipped`` counts older samples dropped to hand out this one.
    Fields an interface (or controller version) does not send are ``None``.
    """

    interface: str
    host: str
    port: int
    time: float | None = None
    joints: tuple[float, ...] | None = None
    joint_speeds: tuple[float, ...] | None = None
    tcp_pose: tuple[float, ...] | None = None
    robot_mode: int | None = None
    safety_mode: int | None = None
    program_state: int | None = None
    program_running: bool | None = None
    speed_scaling: float | None = None
    version: str | None = None
    skipped: int = 0
    received_at: float = 0.0
    raw: Any = field(default=None, repr=False, compare=False)

    @property
    def robot_mode_name(self) -> str | None:
        return _name(ROBOT_MODES, self.robot_mode)

    @property
    def safety_mode_name(self) -> str | None:
        return _name(SAFETY_MODES, self.safety_mode)

    @property
    def program_state_name(self) -> str | None:
        return _name(PROGRAM_STATES, self.program_state)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: every field but ``raw``, plus the mode names."""
        return {
            "interface": self.interface, "host": self.host, "port": self.port,
            "time": self.time, "joints": _list(self.joints),
            "joint_speeds": _list(self.joint_speeds), "tcp_pose": _list(self.tcp_pose),
            "robot_mode": self.robot_mode, "robot_mode_name": self.robot_mode_name,
            "safety_mode": self.safety_mode, "safety_mode_name": self.safety_mode_name,
            "program_state": self.program_state, "program_state_name": self.program_state_name,
            "program_running": self.program_running, "speed_scaling": self.speed_scaling,
            "version": self.version, "skipped": self.skipped,
        }


def _list(values: tuple | None) -> list | None:
    return None if values is None else list(values)


