"""Reading the robot's state with latest-sample semantics.

The controller pushes its state: the realtime interface every control cycle (125 Hz CB3,
500 Hz e-Series), the primary/secondary interfaces at 10 Hz, RTDE at the frequency asked
for. A client that reads more slowly than that finds old packets queued in its socket — the
course's `recv(1108)` loop shows the arm where it was seconds ago. :class:`StateReader`
never does that: each :meth:`StateReader.read` first drains everything the kernel holds and
keeps only the newest complete sample (``skipped`` counts the others); only when nothing
is buffered does it wait, bounded, for the next one.

The result is a :class:`RobotState` with the same fields whatever the interface: joints,
joint speeds, TCP pose, robot and safety mode (as numbers and names), program state.
"""

from __future__ import annotations

import time
from typing import Any

from ..protocol.errors import ProtocolError
from ..protocol.realtime import RealtimeDecoder, RealtimeState
from .connection import DEFAULT_PORTS, Connection
from .errors import ConnectionLost, ControllerProtocolError, RobotTimeout
from .sample import PROGRAM_STATES, ROBOT_MODES, SAFETY_MODES, RobotState

__all__ = [
    "RobotState", "StateReader", "read_state", "INTERFACES", "ROBOT_MODES", "SAFETY_MODES",
    "PROGRAM_STATES", "default_port",
]

INTERFACES = ("realtime", "primary", "rtde")

_DEFAULT_PORTS = {"realtime": DEFAULT_PORTS["realtime"], "primary": DEFAULT_PORTS["secondary"],
                  "rtde": DEFAULT_PORTS["rtde"]}

MAX_DRAINS = 64
"""Drains per read at most (each up to :data:`urdsl.robot.connection.MAX_DRAIN` bytes): a
peer that sends faster than we decode cannot keep a read going forever."""


def default_port(interface: str) -> int:
    """The port a state reader uses for ``interface``: realtime 30003, primary 30002 (the
    secondary interface: the same robot state, and no robot messages to skip), RTDE 30004."""
    return _DEFAULT_PORTS[interface]


def _from_realtime(sample: RealtimeState, host: str, port: int, skipped: int) -> RobotState:
    program_state = sample.program_state
    return RobotState(
        "realtime", host, port, time=sample.time, joints=sample.q_actual,
        joint_speeds=sample.qd_actual, tcp_pose=sample.tcp_pose, robot_mode=sample.robot_mode,
        safety_mode=sample.safety_mode, program_state=program_state,
        program_running=None if program_state is None else program_state in (2, 3, 5),
        speed_scaling=sample.speed_scaling, version=sample.version, skipped=skipped,
        received_at=time.monotonic(), raw=sample)


class _RealtimeSource:
    """Realtime packets (30003/30013) → :class:`RobotState`."""

    def __init__(self, connection: Connection) -> None:
        self.connection = connection
        self.decoder = RealtimeDecoder()

    def start(self, timeout: float) -> None:
        pass

    def latest(self, data: bytes) -> tuple[Any, int] | None:
        before = self.decoder.skipped
        sample = self.decoder.latest(data)
        if sample is None:
            return None
        return sample, self.decoder.skipped - before

    def state(self, sample: Any, skipped: int) -> RobotState:
        return _from_realtime(sample, self.connection.host, self.connection.port, skipped)

    def stop(self) -> None:
        pass


class StateReader:
    """A connection that hands out the newest state (see the module docstring).

    ``interface`` is ``"realtime"``, ``"primary"`` or ``"rtde"``; ``port`` defaults per
    interface (:func:`default_port`). ``timeout`` (s) bounds the connect and each wait for
    a sample. A context manager.
    """

    def __init__(self, host: str, interface: str = "realtime", port: int | None = None, *,
                 timeout: float = 5.0, attempts: int = 1) -> None:
        if interface not in INTERFACES:
            raise ValueError(f"unknown interface {interface!r}; use one of "
                             f"{', '.join(INTERFACES)}")
        self.host = host
        self.interface = interface
        self.port = default_port(interface) if port is None else port
        self.timeout = timeout
        self.attempts = attempts
        self._source: Any = None
        self._lost: ConnectionLost | None = None
        self.connection: Connection | None = None
        self._connect()

    def _connect(self) -> None:
        self._lost = None
        self.connection = Connection.open(self.host, self.port, interface=self.interface,
                                          timeout=self.timeout, attempts=self.attempts)
        try:
            self._source = self._make_source(self.connection)
            self._source.start(self.timeout)
        except BaseException:
            self.connection.close()
            raise

    def _make_source(self, connection: Connection) -> Any:
        if self.interface == "realtime":
            return _RealtimeSource(connection)
        if self.interface == "primary":
            from .primary_state import PrimarySource

            return PrimarySource(connection)
        from .rtde_state import RtdeStateSource

        return RtdeStateSource(connection)

    def reconnect(self, attempts: int = 5) -> None:
        """Open the connection again (after :class:`ConnectionLost`), retrying with backoff."""
        self.close()
        self.attempts = max(self.attempts, attempts)
        self._connect()

    def read(self, timeout: float | None = None) -> RobotState:
        """The newest complete sample: drains the socket, decodes only the last packet, and
        waits (at most ``timeout`` s) only if nothing was buffered."""
        assert self.connection is not None and self._source is not None
        timeout = self.timeout if timeout is None else timeout
        connection = self.connection
        try:
            found = None
            skipped = 0
            if self._lost is not None:
                raise self._lost
            for _ in range(MAX_DRAINS):
                try:
                    data = connection.drain()
                except ConnectionLost as error:
                    if found is None:
                        raise
                    self._lost = error  # hand out the last sample; the next read raises
                    break
                if not data:
                    break
                got = self._source.latest(data)
                if got is not None:
                    skipped += got[1] + (found is not None)
                    found = got
            deadline = time.monotonic() + timeout
            while found is None:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RobotTimeout(f"{connection.where} sent no complete {self.interface} "
                                       f"sample within {timeout:g} s", host=self.host,
                                       port=self.port, interface=self.interface)
                try:
                    data = connection.recv(left)
                except RobotTimeout:
                    continue
                found = self._source.latest(data)
                if found is not None:
                    skipped += found[1]
        except ProtocolError as error:
            raise ControllerProtocolError(f"{connection.where} sent bytes that are not the "
                                          f"{self.interface} protocol: {error}",
                                          host=self.host, port=self.port,
                                          interface=self.interface) from None
        return self._source.state(found[0], skipped)

    def close(self) -> None:
        if self.connection is not None:
            try:
                if self._source is not None and not self.connection.closed:
                    self._source.stop()
            except (ConnectionLost, RobotTimeout, ProtocolError, OSError):
                pass
            self.connection.close()

    def __enter__(self) -> StateReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_state(host: str, interface: str = "realtime", port: int | None = None, *,
               timeout: float = 5.0) -> RobotState:
    """One fresh sample from ``host`` (connect, read, close)."""
    with StateReader(host, interface, port, timeout=timeout) as reader:
        return reader.read()
