"""Reading the robot's state, always the newest sample.

Each interface pushes a stream (realtime 125/500 Hz, primary 10 Hz, RTDE at the requested
rate); a client that reads slowly finds old packets queued in its socket. These readers drain
what is queued and decode only the newest complete packet, so the state is never stale.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from ..protocol import primary, realtime, rtde
from .connection import Deadline, RobotConnectionError, connect, read_until

__all__ = ["RobotStateSample", "read_state", "DEFAULT_PORTS", "ROBOT_MODES", "SAFETY_MODES"]

DEFAULT_PORTS = {"realtime": 30003, "primary": 30002, "rtde": 30004}

ROBOT_MODES = {-1: "NO_CONTROLLER", 0: "DISCONNECTED", 1: "CONFIRM_SAFETY", 2: "BOOTING",
               3: "POWER_OFF", 4: "POWER_ON", 5: "IDLE", 6: "BACKDRIVE", 7: "RUNNING",
               8: "UPDATING_FIRMWARE"}
SAFETY_MODES = {1: "NORMAL", 2: "REDUCED", 3: "PROTECTIVE_STOP", 4: "RECOVERY",
                5: "SAFEGUARD_STOP", 6: "SYSTEM_EMERGENCY_STOP", 7: "ROBOT_EMERGENCY_STOP",
                8: "VIOLATION", 9: "FAULT", 10: "VALIDATE_JOINT_ID", 11: "UNDEFINED_SAFETY_MODE",
                12: "AUTOMATIC_MODE_SAFEGUARD_STOP", 13: "SYSTEM_THREE_POSITION_ENABLING_STOP"}


@dataclass(frozen=True)
class RobotStateSample:
    """Joints (rad), TCP pose (m, rotation vector rad), modes, and the interface it came
    from. ``time`` is the controller's clock (s) where the interface sends it."""

    interface: str
    joints: tuple[float, ...]
    tcp_pose: tuple[float, ...]
    robot_mode: int
    safety_mode: int
    time: float | None = None

    @property
    def robot_mode_name(self) -> str:
        return ROBOT_MODES.get(self.robot_mode, str(self.robot_mode))

    @property
    def safety_mode_name(self) -> str:
        return SAFETY_MODES.get(self.safety_mode, str(self.safety_mode))

    def to_dict(self) -> dict:
        result = asdict(self)
        result["robot_mode_name"] = self.robot_mode_name
        result["safety_mode_name"] = self.safety_mode_name
        return result


def read_state(host: str, interface: str = "realtime", port: int | None = None,
               timeout: float = 5.0, drain: float = 0.05) -> RobotStateSample:
    """The newest state from ``interface`` ("realtime", "primary" or "rtde"), after reading
    what arrives for ``drain`` s past the first packet (so that a backlog is skipped)."""
    if interface not in DEFAULT_PORTS:
        raise ValueError(f"unknown interface {interface!r}: realtime, primary or rtde")
    port = port or DEFAULT_PORTS[interface]
    sock = connect(host, port, timeout)
    try:
        if interface == "realtime":
            return _realtime(sock, host, port, timeout, drain)
        if interface == "primary":
            return _primary(sock, host, port, timeout, drain)
        return _rtde(sock, host, port, timeout)
    finally:
        sock.close()


def _realtime(sock, host, port, timeout, drain) -> RobotStateSample:
    decoder = realtime.RealtimeDecoder()
    deadline = Deadline(timeout)
    newest = None
    while newest is None:
        newest = decoder.latest(read_until(sock, deadline, "a realtime packet", host, port))
    settle = Deadline(drain)
    while not settle.passed:
        sock.settimeout(max(settle.left, 0.001))
        try:
            data = sock.recv(1 << 16)
        except TimeoutError:
            break
        if not data:
            break
        newest = decoder.latest(data) or newest
    fields = newest.fields
    return RobotStateSample("realtime", fields["q_actual"], fields["tool_vector_actual"],
                            int(fields.get("robot_mode", -1)),
                            int(fields.get("safety_mode", 0)), fields["time"])


def _primary(sock, host, port, timeout, drain) -> RobotStateSample:
    decoder = primary.PrimaryDecoder()
    deadline = Deadline(timeout)
    newest = None
    settle: Deadline | None = None
    while settle is None or not settle.passed:
        if settle is not None:
            sock.settimeout(max(settle.left, 0.001))
            try:
                data = sock.recv(1 << 16)
            except TimeoutError:
                break
            if not data:
                break
        else:
            data = read_until(sock, deadline, "the robot state", host, port)
        for message in decoder.feed(data):
            if isinstance(message, primary.RobotState) and message.get(primary.JointData):
                newest = message
        if newest is not None and settle is None:
            settle = Deadline(drain)
    joints = newest.get(primary.JointData)
    cartesian = newest.get(primary.CartesianInfo)
    mode = newest.get(primary.RobotModeData)
    board = newest.get(primary.MasterboardData)
    return RobotStateSample("primary", joints.q_actual,
                            cartesian.tcp_pose if cartesian else (float("nan"),) * 6,
                            mode.robot_mode if mode else -1,
                            board.safety_mode if board else 0,
                            mode.timestamp / 1000.0 if mode else None)


_RTDE_FIELDS = ["timestamp", "actual_q", "actual_TCP_pose", "robot_mode", "safety_mode"]


def _rtde(sock, host, port, timeout) -> RobotStateSample:
    client = rtde.RtdeClient()
    deadline = Deadline(timeout)

    pending: list = []

    def expect(kind):
        while True:
            if not pending:
                pending.extend(client.feed(read_until(sock, deadline, "an RTDE reply", host,
                                                      port)))
            event = pending.pop(0)
            if isinstance(event, kind):
                return event

    sock.sendall(client.request_protocol_version(2))
    if not expect(rtde.ProtocolVersion).accepted:
        sock.sendall(client.request_protocol_version(1))
        expect(rtde.ProtocolVersion)
    sock.sendall(client.setup_outputs(_RTDE_FIELDS, 125.0))
    setup = expect(rtde.OutputSetup)
    if not setup.valid:
        raise RobotConnectionError(f"{host}:{port}: the controller lacks "
                                   f"{', '.join(setup.not_found)}")
    sock.sendall(client.start())
    expect(rtde.Started)
    values = expect(rtde.DataPackage).values
    sock.sendall(client.pause())
    return RobotStateSample("rtde", values["actual_q"], values["actual_TCP_pose"],
                            values["robot_mode"], values["safety_mode"], values["timestamp"])
