"""Socket plumbing: bounded connect with retries, reads with deadlines, drain, clear errors."""

from __future__ import annotations

import threading

import pytest
from _robot_fakes import LOOPBACK, FakeServer, free_port

from urdsl.robot.connection import Connection, where
from urdsl.robot.errors import ConnectError, ConnectionLost, RobotTimeout


def test_refused_connection_names_host_port_and_interface():
    port = free_port()
    with pytest.raises(ConnectError) as caught:
        Connection.open(LOOPBACK, port, interface="secondary", timeout=1.0)
    message = str(caught.value)
    assert f"{LOOPBACK}:{port} (secondary)" in message
    assert "refused" in message
    assert caught.value.port == port


def test_retries_back_off_and_stop_at_the_cap():
    port = free_port()
    waits: list[float] = []
    with pytest.raises(ConnectError) as caught:
        Connection.open(LOOPBACK, port, timeout=1.0, attempts=6, backoff=0.1, backoff_cap=0.5,
                        sleep=waits.append)
    assert waits == [0.1, 0.2, 0.4, 0.5, 0.5]
    assert "tried 6 times" in str(caught.value)


def test_retry_finds_a_server_that_starts_late():
    port = free_port()
    started: list[FakeServer] = []

    def start_server(delay: float) -> None:
        # the first wait of the backoff starts the server on the port that was refused
        if not started:
            started.append(FakeServer(lambda sock, i: sock.sendall(b"hello"), port=port))
            started[0].__enter__()

    try:
        with Connection.open(LOOPBACK, port, timeout=2.0, attempts=3, backoff=0.01,
                             sleep=start_server) as connection:
            assert connection.recv(5.0) == b"hello"
    finally:
        for server in started:
            server.__exit__(None, None, None)


def test_recv_timeout_and_lost_connection_are_distinct():
    release = threading.Event()

    def handler(sock, index):
        sock.sendall(b"abc")
        release.wait(10)

    with FakeServer(handler) as server:
        with Connection.open(LOOPBACK, server.port, timeout=2.0) as connection:
            assert connection.recv(5.0) == b"abc"
            with pytest.raises(RobotTimeout, match="sent nothing for 0.1 s"):
                connection.recv(0.1)
            release.set()
            with pytest.raises(ConnectionLost) as caught:
                connection.recv(5.0)
    assert "closed the connection (after 3 bytes received)" in str(caught.value)
    assert f"{LOOPBACK}:{server.port}" in str(caught.value)


def test_drain_takes_everything_buffered_without_waiting():
    sent = threading.Event()
    release = threading.Event()
    payload = bytes(range(256)) * 200  # 51 kB

    def handler(sock, index):
        sock.sendall(payload)
        sent.set()
        release.wait(10)

    with FakeServer(handler) as server:
        with Connection.open(LOOPBACK, server.port, timeout=2.0) as connection:
            assert sent.wait(5)
            received = b""
            for _ in range(100):  # bounded: the loopback delivers within a few reads
                assert connection.readable(5.0)
                received += connection.drain()
                if len(received) == len(payload):
                    break
            assert received == payload
            assert connection.drain() == b""  # nothing more, and no waiting
            release.set()
            assert connection.readable(5.0)
            with pytest.raises(ConnectionLost):
                connection.drain()


def test_where_names_standard_interfaces():
    assert where("10.0.0.2", 30004) == "10.0.0.2:30004 (RTDE)"
    assert where("h", 1234) == "h:1234"
    assert where("h", 1234, "realtime") == "h:1234 (realtime)"
