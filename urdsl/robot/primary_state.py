"""The primary/secondary interfaces (30001/30002) as a stream of states and robot messages.

:class:`PrimaryStream` wraps a :class:`urdsl.protocol.primary.PrimaryDecoder`: it merges the
sub-packages of ROBOT_STATE messages (a message need not carry every sub-package, so the
newest of each kind is kept) and hands out robot messages (text, runtime exceptions, key
events, safety events) in order. A message that is malformed inside correct framing is
skipped and counted (``malformed``), as the decoder allows; broken framing raises.

:class:`PrimarySource` adapts it to :class:`urdsl.robot.state.StateReader`.
"""

from __future__ import annotations

import time
from collections import deque
from typing import Any

from ..protocol import primary as p
from ..protocol.errors import ProtocolError
from .connection import Connection
from .sample import RobotState

__all__ = ["PrimaryStream", "PrimarySource", "state_from_packages"]

MAX_MESSAGES = 1024
"""Robot messages kept for a reader that does not take them (oldest dropped first)."""


class PrimaryStream:
    """Bytes of the primary/secondary interface in; merged state and robot messages out."""

    def __init__(self) -> None:
        self.decoder = p.PrimaryDecoder()
        self.packages: dict[type, Any] = {}
        self.states = 0
        self.malformed = 0
        self.last_error: ProtocolError | None = None

    def feed(self, data: bytes) -> tuple[int, list[p.RobotMessage]]:
        """Add bytes; return (ROBOT_STATE messages completed, robot messages completed)."""
        self.decoder.receive_data(data)
        states = 0
        messages: list[p.RobotMessage] = []
        for _ in range(1 << 20):  # bounded: each turn consumes a message or stops
            try:
                message = self.decoder.next_message()
            except ProtocolError as error:
                self.decoder.receive_data(b"")  # raises when the framing is lost
                self.malformed += 1
                self.last_error = error
                continue
            if message is None:
                break
            if isinstance(message, p.RobotState):
                for package in message.packages:
                    self.packages[type(package)] = package
                states += 1
            elif isinstance(message, p.RobotMessage):
                messages.append(message)
        self.states += states
        return states, messages

    @property
    def version(self) -> str | None:
        version = self.decoder.version
        return None if version is None else ".".join(str(v) for v in version)

    def get(self, kind: type) -> Any:
        return self.packages.get(kind)

    @property
    def program_running(self) -> bool | None:
        mode = self.get(p.RobotModeData)
        return None if mode is None else bool(mode.is_program_running)


def state_from_packages(stream: PrimaryStream, host: str, port: int, skipped: int):
    """A :class:`urdsl.robot.state.RobotState` of the newest sub-packages."""
    mode = stream.get(p.RobotModeData)
    joints = stream.get(p.JointData)
    cartesian = stream.get(p.CartesianInfo)
    board = stream.get(p.MasterboardData)
    running = None if mode is None else bool(mode.is_program_running)
    paused = None if mode is None else bool(mode.is_program_paused)
    program_state = None
    if running is not None:
        program_state = 4 if paused else 2 if running else 1
    return RobotState(
        "primary", host, port,
        # ROBOT_MODE_DATA's timestamp counts milliseconds [U: UR documents only "uint64";
        # ur_client_library and urdsl sim treat it as ms]
        time=None if mode is None else mode.timestamp / 1000.0,
        joints=None if joints is None else tuple(joints.q_actual),
        joint_speeds=None if joints is None else tuple(joints.qd_actual),
        tcp_pose=None if cartesian is None else tuple(cartesian.tcp_pose),
        robot_mode=None if mode is None else mode.robot_mode,
        safety_mode=None if board is None else board.safety_mode,
        program_state=program_state, program_running=running,
        speed_scaling=None if mode is None else mode.speed_scaling,
        version=stream.version, skipped=skipped, received_at=time.monotonic(),
        raw=dict(stream.packages))


class PrimarySource:
    """Primary/secondary robot state for :class:`urdsl.robot.state.StateReader`; robot
    messages that arrive meanwhile are kept in ``messages`` (at most :data:`MAX_MESSAGES`)."""

    def __init__(self, connection: Connection) -> None:
        self.connection = connection
        self.stream = PrimaryStream()
        self.messages: deque[p.RobotMessage] = deque(maxlen=MAX_MESSAGES)

    def start(self, timeout: float) -> None:
        pass

    def latest(self, data: bytes) -> tuple[Any, int] | None:
        states, messages = self.stream.feed(data)
        self.messages.extend(messages)
        if not states:
            return None
        return self.stream, states - 1

    def state(self, sample: PrimaryStream, skipped: int):
        return state_from_packages(sample, self.connection.host, self.connection.port, skipped)

    def stop(self) -> None:
        pass
