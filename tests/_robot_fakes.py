"""Small fake controller servers for the robot client tests.

Each server listens on 127.0.0.1 on a free port (port 0) and runs a handler function in a
thread per accepted connection. Everything is bounded: the listener accepts at most
``connections`` clients, sockets time out, and closing the server joins its threads with a
timeout. Nothing here listens on or connects to any other address.
"""

from __future__ import annotations

import queue
import select
import socket
import threading
import time
from collections.abc import Callable

from urdsl.protocol import primary as p
from urdsl.protocol.script_framing import ScriptChunk

LOOPBACK = "127.0.0.1"
IO_TIMEOUT = 10.0  # s: no fake server socket blocks longer than this


class FakeServer:
    """``handler(sock, index)`` serves the ``index``-th connection (0-based). Use as a context
    manager; ``port`` is the port to connect to; ``errors`` collects handler exceptions."""

    def __init__(self, handler: Callable[[socket.socket, int], None], *,
                 connections: int = 1, port: int = 0) -> None:
        self.handler = handler
        self.connections = connections
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind((LOOPBACK, port))
        self.listener.listen(8)
        self.listener.settimeout(0.2)
        self.port = self.listener.getsockname()[1]
        self.errors: list[BaseException] = []
        self.stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._accept_thread = threading.Thread(target=self._accept, daemon=True)

    def _accept(self) -> None:
        accepted = 0
        while accepted < self.connections and not self.stop.is_set():
            try:
                sock, _ = self.listener.accept()
            except (TimeoutError, OSError):
                continue
            sock.settimeout(IO_TIMEOUT)
            thread = threading.Thread(target=self._serve, args=(sock, accepted), daemon=True)
            accepted += 1
            self._threads.append(thread)
            thread.start()

    def _serve(self, sock: socket.socket, index: int) -> None:
        try:
            self.handler(sock, index)
        except (ConnectionError, TimeoutError, BrokenPipeError):
            pass  # the client went away: that is what several tests do on purpose
        except BaseException as error:  # noqa: BLE001 - reported by the test
            self.errors.append(error)
        finally:
            try:
                sock.close()
            except OSError:
                pass

    def __enter__(self) -> FakeServer:
        self._accept_thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        self._accept_thread.join(timeout=IO_TIMEOUT)
        for thread in self._threads:
            thread.join(timeout=IO_TIMEOUT)
        self.listener.close()


def free_port() -> int:
    """A port on 127.0.0.1 where nothing listens (bound, then released)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))
        return sock.getsockname()[1]


def recv_exactly(sock: socket.socket, count: int) -> bytes:
    data = bytearray()
    while len(data) < count:
        chunk = sock.recv(count - len(data))
        if not chunk:
            raise ConnectionError("client closed")
        data += chunk
    return bytes(data)


def recv_until_closed(sock: socket.socket, limit: int = 1 << 20) -> bytes:
    """Everything the client sends until it closes (bounded by ``limit`` bytes)."""
    data = bytearray()
    while len(data) < limit:
        chunk = sock.recv(65536)
        if not chunk:
            break
        data += chunk
    return bytes(data)


# ---- a fake controller speaking the primary interface ------------------------------------

HOME = (0.0, -1.5707963267948966, 0.0, -1.5707963267948966, 0.0, 0.0)


def robot_state(running: bool, q=HOME, safety_mode: int = 1, timestamp: int = 0) -> bytes:
    """A CB3.5-style ROBOT_STATE message with robot mode, joints, TCP pose and safety mode."""
    return p.RobotState((
        p.RobotModeData(variant="3.5", timestamp=timestamp, is_real_robot_connected=True,
                        is_robot_power_on=True, is_program_running=running, robot_mode=7,
                        target_speed_fraction=1.0, speed_scaling=1.0,
                        target_speed_fraction_limit=1.0, reserved=0),
        p.JointData(variant="3.0", q_actual=q, q_target=q, qd_actual=(0.0,) * 6,
                    i_actual=(0.0,) * 6, v_actual=(48.0,) * 6, t_motor=(30.0,) * 6,
                    t_micro=(30.0,) * 6, joint_mode=(253,) * 6),
        p.CartesianInfo(variant="3.2", tcp_pose=(0.1, -0.4, 0.3, 0.0, 3.1, 0.0),
                        tcp_offset=(0.0,) * 6),
        p.MasterboardData(variant="3.2", safety_mode=safety_mode,
                          operational_mode_selector_input=0,
                          three_position_enabling_device_input=False),
    )).encode()


def version_message() -> bytes:
    return p.VersionMessage(major=3, minor=15, bugfix=7, build_number=106331,
                            build_date="11-01-2021, 13:18:33").encode()


class FakeController:
    """A controller model shared by fake primary and script servers, on the protocol's
    server side of the primary interface (:class:`urdsl.protocol.primary.PrimaryServer`).

    ``behaviour(program_text)`` returns the events that running the program causes, each one
    of ``("run", ticks)`` (program running for that many state ticks), ``("text", s)``,
    ``("exception", line, column, text)``, ``("safety", mode)``. ``programs`` collects the
    programs received, cut from the stream as the controller cuts them
    (:class:`~urdsl.protocol.script_framing.ScriptFramer`). States go out every ``period``
    s (the real controller: 0.1 s). Each connection is served for ``lifetime`` s at most.
    """

    def __init__(self, behaviour, period: float = 0.02, lifetime: float = 10.0) -> None:
        self.behaviour = behaviour
        self.period = period
        self.lifetime = lifetime
        self.programs: list[str] = []
        self.inbox: queue.Queue[str] = queue.Queue()

    def _take_programs(self, chunks: list[ScriptChunk]) -> None:
        """Programs cut from the stream (a ``def``/``sec`` block up to its ``end``; bare
        lines run as they come)."""
        for chunk in chunks:
            self.programs.append(chunk.text)
            self.inbox.put(chunk.text)

    def _events(self, events: list, server: p.PrimaryServer) -> tuple[bytes, int | None, int]:
        """The robot messages of the events due now, up to the next ``("run", ticks)``: (their
        bytes, a new safety mode or None, the ticks the program runs from now; 0 when no
        run of at least one tick came)."""
        out = b""
        safety_mode = None
        while events:
            event = events.pop(0)
            if event[0] == "run" and event[1] > 0:
                return out, safety_mode, event[1]
            if event[0] == "text":
                out += server.robot_message(p.TextMessage(text=event[1]))
            elif event[0] == "exception":
                out += server.robot_message(p.RuntimeExceptionMessage(
                    line=event[1], column=event[2], text=event[3]))
            elif event[0] == "safety":
                safety_mode = event[1]
                out += server.robot_message(p.SafetyModeMessage(
                    code=209, argument=0, safety_mode_type=event[1]))
        return out, safety_mode, 0

    def primary(self, sock, index) -> None:
        """Serve the primary interface (also takes scripts, as 30001 does)."""
        server = p.PrimaryServer(version_message(), period=self.period)
        sock.sendall(server.greeting())
        events: list = []
        running_ticks = 0
        safety_mode = 1
        tick = 0
        end = time.monotonic() + self.lifetime
        while (now := time.monotonic()) < end:
            ready, _, _ = select.select([sock], [], [], min(server.until_state(now), end - now))
            if ready:
                data = sock.recv(65536)
                if not data:
                    return
                self._take_programs(server.receive_data(data))
            if not server.state_due(time.monotonic()):
                continue
            tick += 1
            while not self.inbox.empty():
                events = list(self.behaviour(self.inbox.get()))
                running_ticks = 0
            out = b""
            if running_ticks == 0:
                out, new_mode, running_ticks = self._events(events, server)
                safety_mode = new_mode if new_mode is not None else safety_mode
            running = running_ticks > 0
            if running_ticks:
                running_ticks -= 1
            out += robot_state(running, safety_mode=safety_mode, timestamp=tick * 100)
            sock.sendall(out)

    def script_port(self, sock, index) -> None:
        """Serve a secondary-like port: one state at first, takes scripts, no messages."""
        server = p.PrimaryServer(version_message(), interface="secondary", period=self.period)
        sock.sendall(server.greeting(robot_state(False)))
        end = time.monotonic() + self.lifetime
        while time.monotonic() < end:
            ready, _, _ = select.select([sock], [], [], 0.05)
            if ready:
                data = sock.recv(65536)
                if not data:
                    return
                self._take_programs(server.receive_data(data))


# ---- a fake RTDE server ------------------------------------------------------------------


def rtde_values(names, cycle: int, rate: float = 500.0) -> dict:
    """Deterministic values for every name of a recipe at control cycle ``cycle``:
    timestamp = cycle / rate; joint i = i + cycle / 1000; poses, modes fixed."""
    from urdsl.protocol.rtde_fields import FIELDS, TYPES

    values: dict = {}
    for name in names:
        kind = FIELDS[name].type
        code, count = TYPES[kind]
        if name == "timestamp":
            values[name] = cycle / rate
        elif name in ("robot_mode",):
            values[name] = 7
        elif name in ("safety_mode",):
            values[name] = 1
        elif name == "runtime_state":
            values[name] = 2
        elif code == "d" and count == 6:
            values[name] = tuple(i + cycle / 1000 for i in range(6))
        elif code == "d" and count == 3:
            values[name] = (0.0, 0.1, 0.2)
        elif code == "d":
            values[name] = 1.0
        elif code == "?":
            values[name] = True
        elif count == 1:
            values[name] = 1
        else:
            values[name] = tuple(range(count))
    return values


class FakeRtde:
    """An RTDE controller on the protocol's server side (:class:`RtdeServer`).

    Streams the output recipe in bursts of ``burst`` control cycles every ``period`` s (so
    500 Hz is reached without a 2 ms sleep). Knobs for the tests: ``refuse_v2`` answers the
    protocol-2 request with "not accepted"; ``stop_after`` closes the connection after that
    many samples; ``texts`` maps a sample count to a text message sent after it; ``silent``
    starts but never sends data; ``on_sample(count)`` is called after each sample.
    """

    def __init__(self, version=(5, 11, 1, 0), *, refuse_v2: bool = False,
                 stop_after: int | None = None, texts: dict | None = None,
                 silent: bool = False, burst: int = 10, period: float = 0.02,
                 lifetime: float = 20.0, on_sample=None) -> None:
        self.version = version
        self.refuse_v2 = refuse_v2
        self.stop_after = stop_after
        self.texts = texts or {}
        self.silent = silent
        self.burst = burst
        self.period = period
        self.lifetime = lifetime
        self.on_sample = on_sample
        self.sent = 0
        self.sent_values: list[dict] = []
        self.requests: list = []

    def handler(self, sock, index) -> None:
        from urdsl.protocol import rtde as r

        server = r.RtdeServer(self.version)
        cycle = 0
        end = time.monotonic() + self.lifetime
        next_burst = time.monotonic()
        while time.monotonic() < end:
            wait = max(min(next_burst - time.monotonic(), 0.05), 0.0) if server.running \
                else 0.05
            ready, _, _ = select.select([sock], [], [], wait)
            if ready:
                data = sock.recv(65536)
                if not data:
                    return
                if self.refuse_v2 and data[2:3] == b"V" and data[3:5] == b"\x00\x02":
                    self.requests.append("V2 refused")
                    sock.sendall(r.encode_rtde(r.ProtocolVersionReply(False), 1))
                    data = data[5:]
                    if not data:
                        continue
                for event in server.receive_data(data):
                    self.requests.append(type(event).__name__)
                sock.sendall(server.data_to_send())
            if not server.running or self.silent or time.monotonic() < next_burst:
                continue
            next_burst += self.period
            out = b""
            recipe = server.output_recipe
            for _ in range(self.burst):
                package = server.outputs(rtde_values(recipe.names, cycle, server.rate), cycle)
                cycle += 1
                if package is None:
                    continue
                out += package
                self.sent += 1
                self.sent_values.append(rtde_values(recipe.names, cycle - 1, server.rate))
                if self.sent in self.texts:
                    out += r.encode_rtde(r.RtdeTextMessage(self.texts[self.sent], "Controller",
                                                           r.WARNING), server.protocol)
                if self.stop_after is not None and self.sent >= self.stop_after:
                    sock.sendall(out)
                    return
            sock.sendall(out)
            if self.on_sample is not None:
                self.on_sample(self.sent)
