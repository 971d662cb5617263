"""The robot's state over RTDE (port 30004), for :class:`urdsl.robot.state.StateReader`.

Sets up an output recipe of the fields every RTDE controller has (CB3 3.4+, e-Series):
timestamp, joints, joint speeds, TCP pose, robot and safety mode, runtime state and speed
scaling, at :data:`STATE_FREQUENCY`; each read drains the stream and keeps the newest sample.
"""

from __future__ import annotations

import time
from typing import Any

from ..protocol import rtde as r
from .connection import Connection
from .rtde_session import RtdeSession
from .sample import RobotState

__all__ = ["RtdeStateSource", "STATE_FIELDS", "STATE_FREQUENCY"]

STATE_FIELDS = ("timestamp", "actual_q", "actual_qd", "actual_TCP_pose", "robot_mode",
                "safety_mode", "runtime_state", "speed_scaling")

STATE_FREQUENCY = 125.0
"""Hz: every CB3 and e-Series controller offers it; a reader that shows ten samples a second
drains the rest, so a higher rate would only cost bandwidth."""


class RtdeStateSource:
    """RTDE samples → :class:`urdsl.robot.state.RobotState`."""

    def __init__(self, connection: Connection) -> None:
        self.connection = connection
        self.session: RtdeSession | None = None

    def start(self, timeout: float) -> None:
        self.session = RtdeSession(self.connection.host, self.connection.port,
                                   timeout=timeout, connection=self.connection)
        self.session.setup_outputs(STATE_FIELDS, STATE_FREQUENCY)
        self.session.start()

    def latest(self, data: bytes) -> tuple[Any, int] | None:
        assert self.session is not None
        events = self.session.take_queued() + self.session.feed(data)
        samples = [e for e in events if isinstance(e, r.DataPackage)]
        if not samples:
            return None
        return samples[-1], len(samples) - 1

    def state(self, sample: r.DataPackage, skipped: int):
        values = sample.values
        runtime = int(values["runtime_state"])  # type: ignore[call-overload]
        assert self.session is not None
        return RobotState(
            "rtde", self.connection.host, self.connection.port,
            time=float(values["timestamp"]),  # type: ignore[arg-type]
            joints=tuple(values["actual_q"]),  # type: ignore[arg-type]
            joint_speeds=tuple(values["actual_qd"]),  # type: ignore[arg-type]
            tcp_pose=tuple(values["actual_TCP_pose"]),  # type: ignore[arg-type]
            robot_mode=int(values["robot_mode"]),  # type: ignore[call-overload]
            safety_mode=int(values["safety_mode"]),  # type: ignore[call-overload]
            program_state=runtime, program_running=runtime in (2, 3, 5),
            speed_scaling=float(values["speed_scaling"]),  # type: ignore[arg-type]
            version=self.session.controller_version, skipped=skipped,
            received_at=time.monotonic(), raw=sample)

    def stop(self) -> None:
        if self.session is not None:
            self.session.close(timeout=1.0)
