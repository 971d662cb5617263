"""`urdsl state` and StateReader against fake controllers: fresh samples, never stale ones."""

from __future__ import annotations

import fcntl
import json
import math
import struct
import termios
import threading
import time

import pytest
from _robot_fakes import LOOPBACK, FakeServer, free_port

from urdsl.cli import main
from urdsl.protocol.realtime import encode_realtime, realtime_state
from urdsl.robot.errors import ConnectionLost, ControllerProtocolError
from urdsl.robot.state import StateReader, read_state

HOME = (0.0, -math.pi / 2, 0.0, -math.pi / 2, 0.0, 0.0)
POSE = (0.1, -0.4, 0.3, 0.0, 3.1, 0.0)


def packet(i: int, version: str = "5.10") -> bytes:
    """Realtime packet number ``i``: time = i s, base joint = i mrad."""
    q = (i / 1000.0,) + HOME[1:]
    values = {"time": float(i), "q_actual": q, "tool_vector_actual": POSE, "robot_mode": 7,
              "safety_mode": 1, "qd_actual": (0.1,) * 6, "speed_scaling": 1.0}
    if version in ("3.2", "3.5", "3.10", "5.10"):
        values["program_state"] = 2
    return encode_realtime(realtime_state(version, **values))


def _available(sock) -> int:
    """Bytes waiting in a socket's receive queue (FIONREAD)."""
    return struct.unpack("i", fcntl.ioctl(sock.fileno(), termios.FIONREAD, b"\0\0\0\0"))[0]


def test_one_sample_decoded_by_name():
    def handler(sock, index):
        sock.sendall(packet(7))
        sock.recv(1)  # waits until the client closes

    with FakeServer(handler) as server:
        state = read_state(LOOPBACK, "realtime", server.port, timeout=5)
    assert state.time == 7.0
    assert state.joints == pytest.approx((0.007,) + HOME[1:])
    assert state.tcp_pose == POSE
    assert (state.robot_mode_name, state.safety_mode_name) == ("RUNNING", "NORMAL")
    assert state.program_state_name == "PLAYING" and state.program_running
    assert state.interface == "realtime" and state.port == server.port


@pytest.mark.parametrize("version", ["3.0", "3.10", "5.10"])
def test_slow_reader_gets_the_latest_packet_not_the_oldest(version):
    count = 40  # 40 packets of <= 1220 bytes: all fit in the loopback receive queue
    sent = threading.Event()
    done = threading.Event()

    def handler(sock, index):
        sock.sendall(b"".join(packet(i, version) for i in range(count)))
        sent.set()
        done.wait(10)

    with FakeServer(handler) as server:
        with StateReader(LOOPBACK, "realtime", server.port, timeout=5) as reader:
            assert sent.wait(5)
            total = len(packet(0, version)) * count
            deadline = time.monotonic() + 5
            while _available(reader.connection.sock) < total and time.monotonic() < deadline:
                time.sleep(0.005)
            state = reader.read()
            # a FIFO reader (the course's recv loop) would show packet 0 here
            assert state.time == count - 1
            assert state.skipped == count - 1
            assert state.joints[0] == pytest.approx((count - 1) / 1000)
            done.set()


def test_continuous_stream_reads_are_not_consecutive_packets():
    stop = threading.Event()

    def handler(sock, index):
        i = 0
        while not stop.is_set() and i < 200_000:  # bounded
            sock.sendall(packet(i))
            i += 1
            if i % 50 == 0:
                time.sleep(0.001)

    with FakeServer(handler) as server:
        with StateReader(LOOPBACK, "realtime", server.port, timeout=5) as reader:
            first = reader.read()
            time.sleep(0.3)  # a slow reader: hundreds of packets queue up meanwhile
            second = reader.read()
            stop.set()
    assert second.time - first.time > 10  # FIFO would give first.time + 1
    assert second.skipped > 10


def test_server_that_disconnects_mid_stream():
    def handler(sock, index):
        data = packet(1) + packet(2) + packet(3)
        sock.sendall(data + packet(4)[:500])  # half a packet, then hang up
        sock.shutdown(2)

    with FakeServer(handler) as server:
        with StateReader(LOOPBACK, "realtime", server.port, timeout=5) as reader:
            time.sleep(0.1)
            assert reader.read().time == 3.0
            with pytest.raises(ConnectionLost) as caught:
                reader.read()
    assert f"{LOOPBACK}:{server.port} (realtime) closed the connection" in str(caught.value)


def test_garbage_is_a_protocol_error_naming_the_place():
    def handler(sock, index):
        sock.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")
        sock.recv(1)

    with FakeServer(handler) as server:
        with pytest.raises(ControllerProtocolError) as caught:
            read_state(LOOPBACK, "realtime", server.port, timeout=5)
    assert f"{LOOPBACK}:{server.port}" in str(caught.value)
    assert "realtime" in str(caught.value)


def test_cli_state_json_and_text(capsys):
    def handler(sock, index):
        sock.sendall(packet(5))
        sock.recv(1)

    with FakeServer(handler, connections=2) as server:
        assert main(["state", "--host", LOOPBACK, "--port", str(server.port), "--json"]) == 0
        document = json.loads(capsys.readouterr().out)
        assert document["joints"] == pytest.approx([0.005, *HOME[1:]])
        assert document["robot_mode_name"] == "RUNNING"
        assert document["tcp_pose"] == list(POSE)
        assert main(["state", "--host", LOOPBACK, "--port", str(server.port)]) == 0
        out = capsys.readouterr().out
        assert "robot mode    RUNNING (7)" in out
        assert "safety mode   NORMAL (1)" in out
        assert "-90.00" in out  # the shoulder in degrees


def test_cli_watch_json_lines_for_a_duration(capsys):
    stop = threading.Event()

    def handler(sock, index):
        i = 0
        while not stop.is_set() and i < 100_000:
            sock.sendall(packet(i))
            i += 1
            time.sleep(0.002)

    with FakeServer(handler) as server:
        status = main(["state", "--host", LOOPBACK, "--port", str(server.port), "--watch",
                       "--json", "--rate", "20", "--duration", "0.5"])
        stop.set()
    assert status == 0
    lines = capsys.readouterr().out.splitlines()
    assert 2 <= len(lines) <= 12
    times = [json.loads(line)["time"] for line in lines]
    assert times == sorted(times) and len(set(times)) == len(times)


def test_cli_connection_refused_exits_1(capsys):
    port = free_port()
    assert main(["state", "--host", LOOPBACK, "--port", str(port)]) == 1
    err = capsys.readouterr().err
    assert f"connection refused by {LOOPBACK}:{port} (realtime)" in err
    assert "Traceback" not in err


def test_primary_interface_state_merges_sub_packages_and_skips_old_states():
    from _robot_fakes import robot_state, version_message

    sent = threading.Event()
    done = threading.Event()
    count = 30

    data = version_message()
    for i in range(count):
        data += robot_state(i % 2 == 1, q=(i / 100,) + HOME[1:], timestamp=i * 100)

    def handler(sock, index):
        sock.sendall(data)
        sent.set()
        done.wait(10)

    with FakeServer(handler) as server:
        with StateReader(LOOPBACK, "primary", server.port, timeout=5) as reader:
            assert sent.wait(5)
            deadline = time.monotonic() + 5
            while _available(reader.connection.sock) < len(data) and \
                    time.monotonic() < deadline:
                time.sleep(0.005)
            state = reader.read()
            done.set()
    assert state.interface == "primary"
    assert state.joints[0] == pytest.approx((count - 1) / 100)
    assert state.time == pytest.approx((count - 1) / 10)
    assert state.program_running is True
    assert state.tcp_pose == pytest.approx((0.1, -0.4, 0.3, 0.0, 3.1, 0.0))
    assert state.robot_mode_name == "RUNNING" and state.safety_mode_name == "NORMAL"
    assert state.version == "3.15.7"
    assert state.skipped == count - 1
