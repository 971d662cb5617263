"""One object for one controller: send, state, record, dashboard.

>>> from urdsl.robot import connect
>>> with connect("127.0.0.1") as robot:                       # doctest: +SKIP
...     result = robot.send(program)          # checked, sent, followed to the end
...     print(robot.state().joints)           # the newest sample, never a queued one
...     robot.record("run.csv", ["actual_q"], duration=5.0)
...     robot.dashboard("robotmode").value

Connections are opened when first needed and kept: ``state()`` reuses its reader (each call
still drains the socket and hands out the newest sample), the dashboard keeps its line
open. ``close()`` (or leaving the ``with``) closes them all.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..kinematics.models import model_spec
from ..protocol.dashboard import DashboardReply
from .connection import DEFAULT_PORTS
from .dashboard import Dashboard, parse_command_words
from .errors import ConnectionLost
from .recorder import RecordProgress, RecordResult, record
from .sender import Checker, SendResult, send
from .state import RobotState, StateReader

__all__ = ["Robot", "connect"]


class Robot:
    """A controller at ``host`` (a real robot or ``urdsl sim``).

    ``port_offset`` shifts every standard port (as ``urdsl sim --port-offset``); ``ports``
    overrides single ones by interface name (``{"rtde": 30004, "primary": 30001}``).
    ``robot`` is the model the offline check of :meth:`send` uses (any name
    :func:`urdsl.kinematics.model_spec` knows, e.g. ``"UR5e"``; KinematicsError for another);
    ``timeout`` (s) bounds each connect and each wait for a reply or sample.
    """

    def __init__(self, host: str, *, robot: str = "ur5e", timeout: float = 5.0,
                 port_offset: int = 0, ports: dict[str, int] | None = None) -> None:
        self.host = host
        self.robot = model_spec(robot).name
        self.timeout = timeout
        self.ports = {name: port + port_offset for name, port in DEFAULT_PORTS.items()}
        self.ports.update(ports or {})
        self._readers: dict[str, StateReader] = {}
        self._dashboard: Dashboard | None = None
        self._lock = threading.Lock()

    def send(self, program: Any, *, port: int | None = None, timeout: float = 60.0,
             check: bool = True, checker: Checker | None = None, follow: bool = True,
             filename: str | None = None) -> SendResult:
        """Check, send and follow ``program`` (text, syntax tree or DSL ``Program``) on the
        secondary port (or ``port``), following it on the primary port; see
        :func:`urdsl.robot.sender.send`. ``timeout`` (s) bounds the wait for its end."""
        return send(program, self.host, self.ports["secondary"] if port is None else port,
                    timeout=timeout, filename=filename, check=check, robot=self.robot,
                    checker=checker, follow=follow, monitor_port=self.ports["primary"],
                    connect_timeout=self.timeout)

    def state(self, interface: str = "realtime") -> RobotState:
        """The newest state from ``interface`` (``"realtime"``, ``"primary"``, ``"rtde"``).
        A reader whose connection dropped is reopened once."""
        port = self.ports["secondary" if interface == "primary" else interface]
        with self._lock:
            reader = self._readers.get(interface)
            if reader is None:
                reader = StateReader(self.host, interface, port, timeout=self.timeout)
                self._readers[interface] = reader
        try:
            return reader.read()
        except ConnectionLost:
            reader.reconnect()
            return reader.read()

    def record(self, path: str | Path, fields: str | Sequence[str] | None = None, *,
               frequency: float = 125.0, duration: float | None = None,
               samples: int | None = None, stop: threading.Event | None = None,
               progress: Callable[[RecordProgress], None] | None = None) -> RecordResult:
        """Record RTDE ``fields`` into the CSV file ``path`` until ``duration`` s,
        ``samples`` samples or ``stop``; see :func:`urdsl.robot.recorder.record`."""
        if duration is None and samples is None and stop is None:
            raise ValueError("give duration, samples or a stop event: a recording without "
                             "an end would never return")
        return record(self.host, path, fields, frequency=frequency, duration=duration,
                      samples=samples, port=self.ports["rtde"], timeout=self.timeout,
                      stop=stop, progress=progress)

    def dashboard(self, command: str) -> DashboardReply:
        """Send a dashboard command (``"robotmode"``, ``"load pick.urp"``, ``"power on"``)
        and return the reply; ``reply.ok`` says whether it is the documented success."""
        parse_command_words(command)  # unknown commands fail before connecting
        with self._lock:
            if self._dashboard is None:
                self._dashboard = Dashboard(self.host, self.ports["dashboard"],
                                            timeout=self.timeout)
            try:
                return self._dashboard.run(command)
            except ConnectionLost:
                self._dashboard.close()
                self._dashboard = Dashboard(self.host, self.ports["dashboard"],
                                            timeout=self.timeout)
                return self._dashboard.run(command)

    def close(self) -> None:
        """Close every connection this object opened."""
        with self._lock:
            for reader in self._readers.values():
                reader.close()
            self._readers.clear()
            if self._dashboard is not None:
                self._dashboard.close()
                self._dashboard = None

    def __enter__(self) -> Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"Robot({self.host!r}, robot={self.robot!r})"


def connect(host: str, **options: Any) -> Robot:
    """A :class:`Robot` for the controller at ``host`` (connections open when needed)."""
    return Robot(host, **options)
