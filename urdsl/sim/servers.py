"""The virtual controller's network interfaces: one thread, one selector, every port.

==========  =======  ===============================================================
interface   port     what it does
==========  =======  ===============================================================
dashboard   29999    line commands (:mod:`urdsl.sim.dashboard`)
primary     30001    version message, robot state at 10 Hz, robot messages; takes scripts
secondary   30002    version message, robot state at 10 Hz; takes scripts
realtime    30003    realtime packet every controller step; takes scripts
primary_ro  30011    as primary, read-only (script text is ignored)
secondary_ro 30012   as secondary, read-only
realtime_ro 30013    as realtime, read-only
rtde        30004    RTDE (:mod:`urdsl.sim.rtde`)
==========  =======  ===============================================================

Every client has a bounded send buffer. The controller's clock thread writes a packet
straight to a client's non-blocking socket when nothing is queued for it, and queues the
rest; the network thread writes queued data out as the socket drains. A client that stops
reading until its buffer is full is dropped, so one stalled reader never delays the others.
A client that breaks a protocol's framing is dropped too; its neighbours do not notice.
"""

from __future__ import annotations

import errno
import logging
import selectors
import socket
import threading
import time
from dataclasses import dataclass
from typing import Any

from ..protocol.errors import ProtocolError
from ..protocol.primary import PrimaryServer
from ..protocol.script_framing import ScriptFramer
from .dashboard import WELCOME, DashboardSession
from .rtde import InputOwners, RtdeSession
from .state import ControllerMessage, Snapshot
from .wire import (
    encode_controller_message,
    encode_robot_state,
    encode_version_message,
    realtime_encoder,
)

__all__ = ["SimServers", "STANDARD_PORTS"]

_log = logging.getLogger(__name__.rpartition(".")[0])  # "urdsl.sim"

STANDARD_PORTS = {
    "dashboard": 29999, "primary": 30001, "secondary": 30002, "realtime": 30003,
    "rtde": 30004, "primary_ro": 30011, "secondary_ro": 30012, "realtime_ro": 30013,
}

SEND_LIMIT = 4 * 1024 * 1024
"""Bytes queued for one client before it counts as stalled and is dropped: about 3 s of
realtime packets at 500 Hz, or 10 s of RTDE with a 100-field recipe."""

MAX_CLIENTS = 64
"""Connections per port; more are refused (closed at once)."""

DROPS_KEPT = 1000
"""Reasons of the latest dropped connections kept in :attr:`SimServers.dropped`."""

_PRIMARY = frozenset(("primary", "secondary", "primary_ro", "secondary_ro"))
"""The interfaces served by :class:`urdsl.protocol.primary.PrimaryServer` (robot state at
10 Hz of wall time, robot messages on the primary ones)."""


@dataclass
class _Listener:
    kind: str
    sock: socket.socket
    port: int


class _Client:
    """One connection: its socket, its session and its bounded send buffer."""

    def __init__(self, servers: SimServers, sock: socket.socket, kind: str) -> None:
        self.servers = servers
        self.sock = sock
        self.kind = kind
        self.out = bytearray()
        self.lock = threading.Lock()
        self.session_lock = threading.Lock()
        self.closed = False
        self.dropped_for = ""
        self.session: Any = None
        self.framer: ScriptFramer | None = None  # cuts the script text of 30001-30003
        self.writing = False
        self.registered = False  # direct writes only once the connection's first
        # messages are out and the network thread knows it

    def send(self, data: bytes) -> None:
        """Queue ``data``; drop the client when its buffer would exceed the limit."""
        if self.closed:
            return
        with self.lock:
            if self.closed:  # checked under the lock: _drop closes the socket under it
                return
            if not self.out and self.registered:
                # nothing queued: write at once from this thread (the socket does not
                # block), sparing the hand-over to the network thread for every packet
                try:
                    sent = self.sock.send(data)
                except (BlockingIOError, InterruptedError):
                    sent = 0
                except OSError:
                    self.closed = True
                    sent = len(data)
                if sent == len(data):
                    if self.closed:
                        self.servers._poke(self)
                    return
                data = data[sent:]
            if len(self.out) + len(data) > self.servers.send_limit:
                self.dropped_for = "stalled: its send buffer is full"
                self.closed = True
            else:
                self.out += data
        self.servers._poke(self)


class SimServers:
    """The network interfaces of one :class:`~urdsl.sim.controller.VirtualController`.

    ``port_offset`` shifts every standard port (``30004 + offset``); ``ports`` overrides
    single ports (0: a free port chosen by the system). After :meth:`start`, ``ports`` maps
    every interface to the port it listens on. A context manager: leaving it closes every
    connection and stops the controller's servers (not the controller).
    """

    def __init__(self, controller: Any, host: str = "127.0.0.1", port_offset: int = 0,
                 ports: dict[str, int] | None = None, send_limit: int = SEND_LIMIT) -> None:
        self.sim = controller
        self.send_limit = send_limit
        self.host = host
        self.requested = {k: v + port_offset for k, v in STANDARD_PORTS.items()}
        for name, port in (ports or {}).items():
            if name not in STANDARD_PORTS:
                raise ValueError(f"unknown interface {name!r}; known: "
                                 f"{', '.join(STANDARD_PORTS)}")
            self.requested[name] = port
        self.ports: dict[str, int] = {}
        self.owners = InputOwners()
        # (interface, reason) of the latest drops, for tests and logs; bounded, as a
        # controller runs for months and hostile clients may be dropped by the million
        # (a list, not a deque: readers in other threads may iterate while it grows)
        self.dropped: list[tuple[str, str]] = []
        self._selector = selectors.DefaultSelector()
        self._listeners: list[_Listener] = []
        self._clients: set[_Client] = set()
        self._pending: set[_Client] = set()
        self._pending_lock = threading.Lock()
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._woken = False
        self._closing = threading.Event()
        self._thread: threading.Thread | None = None
        self._encode_realtime = realtime_encoder(controller.version)
        self.owns_controller = False

    # ---- life cycle ----------------------------------------------------------------------

    def start(self) -> SimServers:
        try:
            for kind, port in self.requested.items():
                sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                try:
                    sock.bind((self.host, port))
                except OSError as error:
                    sock.close()
                    raise OSError(error.errno, f"cannot listen on {self.host}:{port} "
                                  f"({kind}): {error.strerror}") from None
                sock.listen(16)
                sock.setblocking(False)
                listener = _Listener(kind, sock, sock.getsockname()[1])
                self._listeners.append(listener)
                self.ports[kind] = listener.port
                self._selector.register(sock, selectors.EVENT_READ, listener)
        except BaseException:
            self._close_sockets()
            raise
        self._selector.register(self._wake_r, selectors.EVENT_READ, None)
        self.sim.subscribe(self._on_snapshot)
        self.sim.subscribe_messages(self._on_message)
        self._thread = threading.Thread(target=self._loop, name="urdsl-sim-net", daemon=True)
        self._thread.start()
        return self

    def close(self, timeout: float = 5.0) -> None:
        """Close every connection and listener; wait for the network thread (s)."""
        self.sim.unsubscribe(self._on_snapshot)
        self.sim.unsubscribe_messages(self._on_message)
        self._closing.set()
        self._poke(None)
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None
        self._close_sockets()
        if self.owns_controller:
            self.sim.close(timeout)

    def __getattr__(self, name: str):
        # the controller's API through the servers object (``sim.submit``, ``sim.snapshot``)
        if name.startswith("_") or name == "sim":
            raise AttributeError(name)
        return getattr(self.sim, name)

    def __enter__(self) -> SimServers:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def controller(self):
        return self.sim

    @property
    def client_count(self) -> int:
        return len(self._clients)

    def _close_sockets(self) -> None:
        if self._wake_r.fileno() < 0:
            return
        for client in list(self._clients):
            self._drop(client, "")
        for listener in self._listeners:
            try:
                self._selector.unregister(listener.sock)
            except (KeyError, ValueError):
                pass
            listener.sock.close()
        self._listeners.clear()
        try:
            self._selector.close()
        except (OSError, ValueError):
            pass
        self._wake_r.close()
        self._wake_w.close()

    # ---- from other threads --------------------------------------------------------------

    def _poke(self, client: _Client | None) -> None:
        if client is not None:
            with self._pending_lock:
                self._pending.add(client)
                if self._woken:
                    return
                self._woken = True
        try:
            self._wake_w.send(b"\x00")
        except (BlockingIOError, OSError):
            pass

    def _on_snapshot(self, snap: Snapshot) -> None:
        """Clock thread: queue realtime packets, due RTDE packages, and the 10 Hz state."""
        now = time.monotonic()
        realtime = None
        state = None
        for client in list(self._clients):
            if client.closed:
                continue
            kind = client.kind
            if kind in ("realtime", "realtime_ro"):
                if realtime is None:
                    realtime = self._encode_realtime(snap)
                client.send(realtime)
            elif kind == "rtde":
                session: RtdeSession = client.session
                try:
                    with client.session_lock:
                        data = session.encode(snap) if session.output_due() else None
                except Exception as error:  # noqa: BLE001 - this client's recipe: drop it
                    _log.error("virtual controller: RTDE client dropped: %s: %s",
                               type(error).__name__, error, exc_info=error)
                    client.dropped_for = f"internal error: {type(error).__name__}: {error}"
                    client.closed = True
                    self._poke(client)
                    continue
                if data is not None:
                    client.send(data)
            elif kind in _PRIMARY and client.session.state_due(now):
                if state is None:  # encoded once: the sessions share one 10 Hz grid
                    state = encode_robot_state(snap, self.sim.version)
                client.send(state)

    def _on_message(self, message: ControllerMessage) -> None:
        """Any thread: robot messages go to the primary interface (30001, 30011)."""
        data = encode_controller_message(message)
        for client in list(self._clients):
            if client.kind in _PRIMARY:
                out = client.session.robot_message(data)
                if out:
                    client.send(out)

    # ---- the network thread --------------------------------------------------------------

    def _loop(self) -> None:
        selector = self._selector
        while not self._closing.is_set():
            try:
                events = selector.select(timeout=0.05)
            except (OSError, ValueError):
                break
            for key, mask in events:
                data = key.data
                try:
                    if data is None:
                        self._drain_wake()
                    elif isinstance(data, _Listener):
                        self._accept(data)
                    else:
                        if mask & selectors.EVENT_READ:
                            self._read(data)
                        if mask & selectors.EVENT_WRITE and not data.closed:
                            self._flush(data)
                except Exception as error:  # noqa: BLE001 - see _failed
                    self._failed(data, error)
            with self._pending_lock:
                pending = list(self._pending)
                self._pending.clear()
                self._woken = False
            for client in pending:
                try:
                    if client in self._clients:
                        if client.closed:
                            self._drop(client, client.dropped_for)
                        else:
                            self._flush(client)
                except Exception as error:  # noqa: BLE001 - see _failed
                    self._failed(client, error)

    def _failed(self, data: Any, error: Exception) -> None:
        """An exception escaped a handler: a bug of urdsl that a client's input exposed.
        Log it with its traceback, drop that client (its session may be half updated) and
        keep serving everybody else. Never raises."""
        where = data.kind if isinstance(data, (_Client, _Listener)) else "wake-up"
        try:
            _log.error("virtual controller: %s client dropped after an internal error: "
                       "%s: %s", where, type(error).__name__, error, exc_info=error)
            if isinstance(data, _Client):
                self._drop(data, f"internal error: {type(error).__name__}: {error}")
            else:
                self._dropped((where, f"internal error: {type(error).__name__}"))
        except Exception:  # noqa: BLE001 - the loop must go on whatever happens
            pass

    def _drain_wake(self) -> None:
        try:
            while self._wake_r.recv(4096):
                pass
        except (BlockingIOError, OSError):
            pass

    def _accept(self, listener: _Listener) -> None:
        for _ in range(16):  # bounded: at most 16 connections per readiness event
            try:
                sock, _address = listener.sock.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:
                return
            if sum(1 for c in self._clients if c.kind == listener.kind) >= MAX_CLIENTS:
                sock.close()
                self._dropped((listener.kind, "too many clients"))
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            client = _Client(self, sock, listener.kind)
            try:
                self._open(client)
            except Exception as error:  # noqa: BLE001 - see _failed
                self._failed(client, error)
                sock.close()

    def _open(self, client: _Client) -> None:
        kind = client.kind
        sim = self.sim
        if kind == "dashboard":
            client.session = DashboardSession(sim)
            client.send((WELCOME + "\n").encode())
        elif kind == "rtde":
            client.session = RtdeSession(sim.version, sim.env, self.owners, sim.frequency)
        elif kind in _PRIMARY:
            snap = sim.snapshot()
            client.session = PrimaryServer(encode_version_message(sim.version, snap.time),
                                           interface=kind.removesuffix("_ro"),
                                           read_only=kind.endswith("_ro"))
            client.send(client.session.greeting(encode_robot_state(
                snap, sim.version, sim.spec, (sim.kinematics.qd_max, sim.q_min, sim.q_max)
                if hasattr(sim.kinematics, "qd_max") else None, configuration=True),
                now=time.monotonic()))
            client.framer = client.session.framer
        elif kind == "realtime":
            client.framer = ScriptFramer(interface="realtime")
        # only now may the clock and the message publisher add to its stream: the version
        # message must come first
        self._clients.add(client)
        self._selector.register(client.sock, selectors.EVENT_READ, client)
        self._flush(client)
        client.registered = True

    def _read(self, client: _Client) -> None:
        try:
            data = client.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            self._drop(client, "connection error")
            return
        if not data:
            self._drop(client, "")
            return
        kind = client.kind
        try:
            if kind == "dashboard":
                session: DashboardSession = client.session
                for reply in session.receive(data):
                    client.send((reply + "\n").encode("utf-8"))
                if session.closed:
                    self._flush(client)
                    self._drop(client, "")
            elif kind == "rtde":
                with client.session_lock:
                    reply = client.session.receive(data)
                if reply:
                    client.send(reply)
            elif client.framer is not None:  # script text; read-only ports ignore it
                origin = f"<{kind} {self.ports.get(kind, 0)}>"
                for chunk in client.framer.feed(data):
                    self.sim.submit_chunk(chunk.kind, chunk.text, origin)
        except ProtocolError as error:  # a broken RTDE framing, a program over the limit
            self._drop(client, f"protocol error: {error}")
        except ValueError as error:
            self._drop(client, f"bad input: {error}")

    def _flush(self, client: _Client) -> None:
        if client.closed:
            self._drop(client, client.dropped_for)
            return
        with client.lock:
            if not client.out:
                data = b""
            else:
                data = bytes(client.out)
        sent = 0
        if data:
            try:
                sent = client.sock.send(data)
            except (BlockingIOError, InterruptedError):
                sent = 0
            except OSError as error:
                if error.errno not in (errno.EAGAIN, errno.EWOULDBLOCK):
                    self._drop(client, "")
                    return
        with client.lock:
            del client.out[:sent]
            left = bool(client.out)
        want = selectors.EVENT_READ | (selectors.EVENT_WRITE if left else 0)
        if want != (selectors.EVENT_READ | (selectors.EVENT_WRITE if client.writing else 0)):
            client.writing = left
            try:
                self._selector.modify(client.sock, want, client)
            except (KeyError, ValueError, OSError):
                pass

    def _dropped(self, entry: tuple[str, str]) -> None:
        self.dropped.append(entry)
        if len(self.dropped) > DROPS_KEPT:
            del self.dropped[:len(self.dropped) - DROPS_KEPT // 2]

    def _drop(self, client: _Client, reason: str) -> None:
        client.closed = True
        if client not in self._clients:
            return
        self._clients.discard(client)
        if reason:
            self._dropped((client.kind, reason))
        if client.framer is not None and client.framer.pending and \
                not self._closing.is_set():
            # a program cut off (the client closed or reset the connection before its
            # 'end' line, or was dropped): say so, rather than nothing ever happening
            how = "was reset" if reason == "connection error" else "ended"
            self.sim.refuse(f"<{client.kind} {self.ports.get(client.kind, 0)}>",
                            f"the connection {how} before the program's 'end' line "
                            "arrived; it was not run")
        if client.kind == "rtde" and client.session is not None:
            try:
                client.session.close()
            except Exception as error:  # noqa: BLE001 - the socket must still be closed
                _log.error("virtual controller: closing an RTDE session failed: %s", error)
        try:
            self._selector.unregister(client.sock)
        except (KeyError, ValueError, OSError):
            pass
        with client.lock:  # no direct write from the clock thread is under way
            try:
                client.sock.close()
            except OSError:
                pass
