"""The virtual controller's network interfaces, spoken to with raw sockets on loopback.

Byte layouts are decoded here from docs/controller-facts.md (offsets, sizes, type codes)
independently of the simulator's encoders. Every socket has a timeout, so no test can hang.
"""

from __future__ import annotations

import os
import socket
import struct
import time

import numpy as np
import pytest
from _sim_clients import Dashboard, connect, read_exactly, wait_until

from urdsl.sim.controller import VirtualController
from urdsl.sim.servers import STANDARD_PORTS
from urdsl.sim.state import ProgramState

TIMEOUT = 5.0
TARGET = [0.6, -1.4, 1.3, -1.5, -1.6, 0.2]


@pytest.fixture
def sim(tmp_path):
    (tmp_path / "wave.script").write_text(
        f"def wave():\n  movej({TARGET}, a=3, v=2)\nend\n")
    with VirtualController(speed=2.0, programs_dir=tmp_path) as controller:
        with controller.serve(ports={k: 0 for k in STANDARD_PORTS}, send_limit=256 * 1024) \
                as servers:
            controller.servers = servers
            yield controller


# ---- dashboard --------------------------------------------------------------------------------


def test_dashboard_answers_with_the_documented_replies(sim):
    dash = Dashboard(sim)
    assert dash.welcome == "Connected: Universal Robots Dashboard Server"
    assert dash.ask("robotmode") == "Robotmode: RUNNING"
    assert dash.ask("safetymode") == "Safetymode: NORMAL"
    assert dash.ask("is in remote control") == "true"
    assert dash.ask("running") == "Program running: false"
    assert dash.ask("get loaded program") == "No program loaded"
    assert dash.ask("load missing.script") == "File not found: missing.script"
    assert dash.ask("load wave.script") == "Loading program: wave.script"
    assert dash.ask("get loaded program") == "Loaded program: wave.script"
    assert dash.ask("programState") == "STOPPED wave.script"
    assert dash.ask("play") == "Starting program"
    assert wait_until(lambda: dash.ask("programState") == "PLAYING wave.script")
    assert dash.ask("running") == "Program running: true"
    assert dash.ask("stop") == "Stopped"
    assert wait_until(lambda: dash.ask("running") == "Program running: false")
    assert dash.ask("version") == "5.15.0.0"
    assert dash.ask("PolyscopeVersion").startswith("URSoftware 5.15")
    assert dash.ask("get robot model") == "UR5"
    assert dash.ask("fly to the moon") == "could not understand: 'fly to the moon'"
    assert dash.ask("power off") == "Powering off"
    assert dash.ask("robotmode") == "Robotmode: POWER_OFF"
    assert dash.ask("play") == "Failed to execute: play"
    assert dash.ask("power on") == "Powering on"
    assert wait_until(lambda: dash.ask("robotmode") == "Robotmode: IDLE")
    assert dash.ask("brake release") == "Brake releasing"
    assert wait_until(lambda: dash.ask("robotmode") == "Robotmode: RUNNING")
    assert dash.ask("quit") == "Disconnected"
    assert dash.file.read() == b""  # the server closed the connection
    dash.close()


# ---- RTDE -------------------------------------------------------------------------------------


class Rtde:
    def __init__(self, sim):
        self.sock = connect(sim, "rtde")

    def send(self, kind: str, payload: bytes = b"") -> None:
        self.sock.sendall(struct.pack(">HB", len(payload) + 3, ord(kind)) + payload)

    def receive(self) -> tuple[str, bytes]:
        size, kind = struct.unpack(">HB", read_exactly(self.sock, 3))
        return chr(kind), read_exactly(self.sock, size - 3)

    def ask(self, kind: str, payload: bytes = b"") -> bytes:
        self.send(kind, payload)
        while True:
            got, data = self.receive()
            if got == kind:
                return data

    def close(self):
        self.sock.close()


def test_rtde_v2_streams_the_recipe_at_the_requested_frequency(sim):
    rtde = Rtde(sim)
    assert rtde.ask("V", struct.pack(">H", 2)) == b"\x01"
    assert struct.unpack(">IIII", rtde.ask("v"))[:2] == (5, 15)
    reply = rtde.ask("O", struct.pack(">d", 125.0) +
                     b"timestamp,actual_q,runtime_state,output_int_register_5")
    recipe, types = reply[0], reply[1:].decode()
    assert recipe > 0 and types == "DOUBLE,VECTOR6D,UINT32,INT32"
    assert rtde.ask("S") == b"\x01"
    layout = struct.Struct(">B d 6d I i")
    stamps = []
    for _ in range(40):
        kind, data = rtde.receive()
        assert kind == "U" and data[0] == recipe
        values = layout.unpack(data)
        stamps.append(values[1])
        assert np.allclose(values[2:8], sim.snapshot().q, atol=0.5)
    steps = np.diff(stamps) / (4 * 0.002 * sim.speed)
    # 125 Hz out of 500 Hz: one package every 4 controller steps (speed 2: 16 ms of robot
    # time); a step the clock had to skip under load makes a gap of a whole multiple
    assert np.median(steps) == pytest.approx(1.0)
    assert np.allclose(steps, np.round(steps), atol=1e-6) and steps.min() > 0.99
    assert rtde.ask("P") == b"\x01"
    rtde.close()


def test_rtde_reports_unknown_outputs_and_refuses_to_start(sim):
    rtde = Rtde(sim)
    rtde.ask("V", struct.pack(">H", 2))
    reply = rtde.ask("O", struct.pack(">d", 500.0) + b"actual_q,warp_drive_status")
    assert reply[1:] == b"VECTOR6D,NOT_FOUND"
    assert rtde.ask("S") == b"\x00"
    rtde.close()


def test_rtde_v1_has_no_frequency_and_no_recipe_id(sim):
    rtde = Rtde(sim)
    assert rtde.ask("V", struct.pack(">H", 1)) == b"\x01"
    assert rtde.ask("O", b"timestamp,robot_mode") == b"DOUBLE,INT32"
    assert rtde.ask("S") == b"\x01"
    kind, data = rtde.receive()
    assert kind == "U" and len(data) == 8 + 4
    assert struct.unpack(">di", data)[1] == 7  # RUNNING
    rtde.close()


def test_rtde_inputs_reach_the_script_and_only_one_client_owns_an_input(sim):
    writer, other = Rtde(sim), Rtde(sim)
    for client in (writer, other):
        client.ask("V", struct.pack(">H", 2))
    reply = writer.ask("I", b"input_int_register_24,input_double_register_25")
    recipe = reply[0]
    assert recipe > 0 and reply[1:] == b"INT32,DOUBLE"
    assert other.ask("I", b"input_int_register_24")[1:] == b"IN_USE"
    assert writer.ask("S") == b"\x01"
    writer.send("U", struct.pack(">Bid", recipe, 21, 0.5))
    assert wait_until(lambda: sim.env.input_int_registers[24] == 21)
    sim.submit("def p():\n  write_output_float_register(0, read_input_integer_register(24) "
               "* read_input_float_register(25))\nend\n")
    assert wait_until(lambda: sim.snapshot().output_float_registers[0] == 10.5)
    writer.close()
    # the input is free again once its owner has gone
    assert wait_until(lambda: other.ask("I", b"input_int_register_24")[1:] == b"INT32")
    other.close()


# ---- realtime ---------------------------------------------------------------------------------


def realtime_packet(sock) -> bytes:
    (size,) = struct.unpack(">i", read_exactly(sock, 4))
    return struct.pack(">i", size) + read_exactly(sock, size - 4)


def test_realtime_packets_have_the_version_size_and_the_joints_at_offset_252(sim):
    sock = connect(sim, "realtime")
    sim.submit(f"def p():\n  movej({TARGET}, a=3, v=2)\nend\n")
    last = None
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        packet = realtime_packet(sock)
        assert len(packet) == 1220  # 5.10 and newer
        q = np.array(struct.unpack_from(">6d", packet, 252))
        tcp = np.array(struct.unpack_from(">6d", packet, 444))
        if np.allclose(q, TARGET, atol=1e-9):
            last = packet
            break
    assert last is not None, "the realtime joints never reached the target"
    from urdsl.kinematics import pose

    assert np.allclose(tcp[:3], pose.from_matrix(sim.kinematics.fk(np.array(TARGET)))[:3])
    assert struct.unpack_from(">d", last, 756)[0] == 7.0  # robot mode RUNNING
    assert struct.unpack_from(">d", last, 812)[0] == 1.0  # safety mode NORMAL
    sock.close()


def test_cb3_realtime_runs_at_125_hz_with_the_3_x_layout(tmp_path):
    with VirtualController(robot="ur5", version="3.3") as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        sock = socket.create_connection(("127.0.0.1", servers.ports["realtime"]), TIMEOUT)
        sock.settimeout(TIMEOUT)
        times = [struct.unpack_from(">d", realtime_packet(sock), 4)[0] for _ in range(5)]
        assert len(realtime_packet(sock)) == 1060
        assert np.median(np.diff(times)) == pytest.approx(0.008)
        sock.close()


# ---- primary / secondary ------------------------------------------------------------------------


def primary_messages(sock, until, timeout=TIMEOUT):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        size, kind = struct.unpack(">iB", read_exactly(sock, 5))
        body = read_exactly(sock, size - 5)
        yield kind, body
        if until(kind, body):
            return


def test_primary_sends_version_then_state_and_reports_script_errors(sim):
    sock = connect(sim, "primary")
    size, kind = struct.unpack(">iB", read_exactly(sock, 5))
    body = read_exactly(sock, size - 5)
    assert kind == 20 and body[9] == 3  # ROBOT_MESSAGE, VERSION
    name_length = body[10]
    assert body[11:11 + name_length] == b"URControl"
    assert tuple(body[11 + name_length:13 + name_length]) == (5, 15)
    size, kind = struct.unpack(">iB", read_exactly(sock, 5))
    state = read_exactly(sock, size - 5)
    assert kind == 16
    sub_size, sub_type = struct.unpack_from(">IB", state)
    assert (sub_size, sub_type) == (47, 0)  # ROBOT_MODE_DATA, 3.5+/5.x size
    sock.sendall(b"def oops():\n  x = 1\n  y = x +* 2\nend\n")
    exception = None
    for kind, body in primary_messages(sock, lambda k, b: k == 20 and b[9] == 10):
        if kind == 20 and body[9] == 10:
            exception = body
    assert exception is not None, "no runtime exception message"
    line, column = struct.unpack_from(">II", exception, 10)
    assert (line, column) == (3, 10)
    assert b"3:10" in exception[18:]
    sock.close()


def test_secondary_state_carries_joints_and_tcp(sim):
    sock = connect(sim, "secondary")
    found = {}
    for kind, body in primary_messages(sock, lambda k, b: k == 16):
        if kind != 16:
            continue
        position = 0
        while position < len(body):
            sub_size, sub_type = struct.unpack_from(">IB", body, position)
            if sub_type == 1:
                found["q"] = [struct.unpack_from(">d", body, position + 5 + 41 * i)[0]
                              for i in range(6)]
            if sub_type == 4:
                found["tcp"] = struct.unpack_from(">6d", body, position + 5)
            position += sub_size
    assert np.allclose(found["q"], sim.snapshot().q)
    assert np.allclose(found["tcp"], sim.snapshot().tcp)
    sock.close()


def test_read_only_ports_ignore_scripts(sim):
    sock = connect(sim, "primary_ro")
    sock.sendall(f"def p():\n  movej({TARGET})\nend\n".encode())
    time.sleep(0.3)
    assert sim.snapshot().program_state == ProgramState.STOPPED
    assert sim.stats.programs == 0
    sock.close()


# ---- robustness ---------------------------------------------------------------------------------


def test_five_clients_garbage_a_dropped_rtde_stream_and_a_stalled_reader(sim):
    readers = [connect(sim, "realtime") for _ in range(2)]
    stalled = connect(sim, "realtime_ro")
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    rtde = Rtde(sim)
    rtde.ask("V", struct.pack(">H", 2))
    rtde.ask("O", struct.pack(">d", 500.0) + b"timestamp,actual_q")
    rtde.ask("S")
    rtde.receive()
    rtde.sock.close()  # gone mid-stream
    dash = Dashboard(sim)
    # random bytes to every port
    rng = np.random.default_rng(8)
    for interface in STANDARD_PORTS:
        junk = connect(sim, interface)
        junk.sendall(rng.integers(0, 256, 4000, dtype=np.uint8).tobytes())
        junk.sendall(b"\x00\x01\xff" * 50)
        junk.close()
    # the others keep being served: the program still runs, readers get fresh packets
    sim.submit(f"def p():\n  movej({TARGET}, a=3, v=2)\nend\n")
    assert wait_until(lambda: np.allclose(sim.snapshot().q, TARGET, atol=1e-9), 10)
    for reader in readers:
        deadline = time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            q = struct.unpack_from(">6d", realtime_packet(reader), 252)
            if np.allclose(q, TARGET, atol=1e-9):
                break
        else:
            pytest.fail("a realtime reader fell behind")
    assert dash.ask("robotmode") == "Robotmode: RUNNING"
    # the stalled reader was dropped once its buffer filled
    assert wait_until(lambda: any(r.startswith("stalled") for _, r in sim.servers.dropped),
                      15)
    errors = [m for m in sim.messages if m.kind == "runtime_exception"]
    assert errors, "the garbage sent to the script ports was reported"
    for sock in readers + [stalled]:
        sock.close()
    dash.close()


def test_serve_as_the_only_context_manager_runs_and_stops_the_controller():
    with VirtualController(speed=4.0).serve(ports={k: 0 for k in STANDARD_PORTS}) as sim:
        sock = socket.create_connection(("127.0.0.1", sim.ports["secondary"]), TIMEOUT)
        sock.sendall(f"def p():\n  movej({TARGET}, a=3, v=2)\nend\n".encode())
        sim.wait_snapshot(lambda s: np.allclose(s.q, TARGET, atol=1e-9), 10)
        sock.close()
        threads = list(sim.controller._threads)
    assert threads and not any(thread.is_alive() for thread in threads)


def test_a_100000_line_program_sent_on_a_socket_runs_while_others_are_served(sim):
    body = "".join(f"  x{i % 50} = {i} + 1\n" for i in range(100_000))
    reader = connect(sim, "realtime")
    sender = connect(sim, "primary")
    sender.sendall(("def big():\n" + body + "  write_output_integer_register(0, x49)\nend\n")
                   .encode())
    stamps = []
    deadline = time.monotonic() + 60
    while sim.snapshot().output_int_registers[0] != 100_000:
        assert time.monotonic() < deadline, "the big program did not finish"
        stamps.append(struct.unpack_from(">d", realtime_packet(reader), 4)[0])
    assert len(stamps) > 100 and np.all(np.diff(stamps) > 0)  # realtime kept streaming
    assert not [m for m in sim.messages if m.kind == "runtime_exception"]
    sender.close()
    reader.close()


def test_a_program_that_never_ends_its_def_is_kept_until_the_connection_sends_end(sim):
    sock = connect(sim, "secondary")
    sock.sendall(b"def p():\n  write_output_integer_register(1, 5)\n")
    time.sleep(0.2)
    assert sim.snapshot().output_int_registers[1] == 0
    sock.sendall(b"end\n")
    assert wait_until(lambda: sim.snapshot().output_int_registers[1] == 5)
    sock.close()


@pytest.mark.skipif(os.name != "posix", reason="signals")
def test_servers_close_every_connection_on_shutdown(tmp_path):
    with VirtualController() as sim:
        servers = sim.serve(ports={k: 0 for k in STANDARD_PORTS})
        sock = socket.create_connection(("127.0.0.1", servers.ports["realtime"]), TIMEOUT)
        sock.settimeout(TIMEOUT)
        realtime_packet(sock)
        servers.close()
        with pytest.raises((ConnectionError, OSError)):
            for _ in range(10_000):
                if not sock.recv(65536):
                    raise ConnectionError("closed")
        sock.close()


# ---- the project's own decoders read what the simulator sends -----------------------------------


def test_urdsl_protocol_decoders_read_the_simulators_realtime_and_primary_streams(sim):
    realtime = pytest.importorskip("urdsl.protocol.realtime")
    primary = pytest.importorskip("urdsl.protocol.primary")
    sock = connect(sim, "realtime")
    state = realtime.decode_realtime(realtime_packet(sock), "5.15")
    sock.close()
    assert state.size == 1220 and state.robot_mode == 7 and state.safety_mode == 1
    assert np.allclose(state.q_actual, sim.snapshot().q)
    assert np.allclose(state.tool_vector_actual, sim.snapshot().tcp)

    sock = connect(sim, "primary")
    decoder = primary.PrimaryDecoder()
    sock.sendall(b"def oops():\n  x = 1 +* 2\nend\n")
    decoded = []
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline and not any(
            isinstance(m, primary.RuntimeExceptionMessage) for m in decoded):
        decoded += decoder.feed(sock.recv(65536))
    sock.close()
    version = decoded[0]
    assert isinstance(version, primary.VersionMessage)
    assert (version.project_name, version.major, version.minor) == ("URControl", 5, 15)
    robot_state = next(m for m in decoded if isinstance(m, primary.RobotState))
    assert robot_state.get(primary.RobotModeData).robot_mode == 7
    assert np.allclose(robot_state.get(primary.JointData).q_actual, sim.snapshot().q)
    assert np.allclose(robot_state.get(primary.CartesianInfo).tcp_pose, sim.snapshot().tcp)
    error = next(m for m in decoded if isinstance(m, primary.RuntimeExceptionMessage))
    assert (error.line, error.column) == (2, 10) and "2:10" in error.text
