"""The robot clients against the virtual controller on loopback: send with feedback, state
with latest-sample semantics, RTDE recording to CSV and its plot, dashboard commands, and
clear errors when nothing listens. Only 127.0.0.1 is ever dialled."""

from __future__ import annotations

import csv
import json
import socket
import time

import pytest

from urdsl.cli import main
from urdsl.robot.connection import RobotConnectionError
from urdsl.robot.dashboard import DashboardClient
from urdsl.robot.recorder import plot_csv, record
from urdsl.robot.state import read_state
from urdsl.sim import VirtualController
from urdsl.sim.servers import STANDARD_PORTS

HOST = "127.0.0.1"


@pytest.fixture(scope="module")
def sim():
    with VirtualController(robot="ur5e", speed=4.0) as controller, \
            controller.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        yield servers.ports


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind((HOST, 0))
        return probe.getsockname()[1]


def send(sim, tmp_path, text: str, name: str = "prog.script", *extra: str) -> int:
    path = tmp_path / name
    path.write_text(text)
    return main(["send", str(path), "--host", HOST, "--port", str(sim["secondary"]),
                 "--primary-port", str(sim["primary"]), "--timeout", "30", *extra])


def test_send_checks_runs_and_reports_success(sim, tmp_path, capsys):
    status = send(sim, tmp_path, 'movej([0.2, -1.9, 1.9, -1.57, -1.57, 0])\ntextmsg("done")\n')
    out = capsys.readouterr().out
    assert status == 0, out
    assert "finished" in out and "controller: done" in out
    joints = read_state(HOST, "realtime", sim["realtime"]).joints
    assert joints[0] == pytest.approx(0.2, abs=1e-3)


def test_a_runtime_error_is_mapped_to_the_users_line(sim, tmp_path, capsys):
    text = "# a comment moves the lines\nx = 1\n\nmovej([0, -1.9, 1.9, -1.57, -1.57, 0])\n" \
           "y = missing + 1\n"
    status = send(sim, tmp_path, text, "bad.script", "--no-check")
    out = capsys.readouterr().out
    assert status == 1
    assert f"{tmp_path / 'bad.script'}:5:5" in out and "missing" in out
    assert "y = missing + 1" in out


def test_the_check_refuses_a_program_with_errors(sim, tmp_path, capsys):
    status = send(sim, tmp_path, "movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])\n", "far.script")
    captured = capsys.readouterr()
    assert status == 1 and "URS301" in captured.out and "not sent" in captured.err


def test_a_dsl_program_is_sent(sim, tmp_path, capsys):
    source = ("from urdsl.dsl import Program, Joints\nprogram = Program('dsl')\n"
              "program.movej(Joints(-0.2, -1.9, 1.9, -1.57, -1.57, 0))\n")
    assert send(sim, tmp_path, source, "dsl.py") == 0
    assert read_state(HOST, "primary", sim["primary"]).joints[0] == pytest.approx(-0.2,
                                                                                  abs=1e-3)


@pytest.mark.parametrize("interface", ["realtime", "primary", "rtde"])
def test_state_on_every_interface(sim, interface, capsys):
    port = {"realtime": sim["realtime"], "primary": sim["secondary"], "rtde": sim["rtde"]}
    assert main(["state", "--host", HOST, "--interface", interface, "--port",
                 str(port[interface]), "--json"]) == 0
    state = json.loads(capsys.readouterr().out)
    assert len(state["joints"]) == 6 and len(state["tcp_pose"]) == 6
    assert state["robot_mode_name"] == "RUNNING" and state["safety_mode_name"] == "NORMAL"


def test_state_is_the_newest_sample_even_for_a_slow_reader(sim):
    with socket.create_connection((HOST, sim["realtime"])) as slow:
        time.sleep(0.5)  # about 250 packets queue up at 500 Hz
        from urdsl.protocol.realtime import RealtimeDecoder

        decoder = RealtimeDecoder()
        slow.settimeout(1.0)
        data = b""
        while len(data) < 100_000:
            data += slow.recv(1 << 16)
        first = decoder.feed(data)[0]
    fresh = read_state(HOST, "realtime", sim["realtime"])
    assert fresh.time > first.time + 0.4  # the backlog's head is old; read_state skips it


def test_record_and_plot(sim, tmp_path):
    output = tmp_path / "run.csv"
    rows = record(HOST, output, ["actual_q", "actual_TCP_pose", "runtime_state"], 125.0,
                  duration=0.6, port=sim["rtde"])
    assert rows > 20
    with open(output, newline="") as handle:
        table = list(csv.reader(handle, delimiter=" "))  # UR record.py's format
    assert table[0][:3] == ["timestamp", "actual_q_0", "actual_q_1"]
    assert len(table[0]) == 1 + 6 + 6 + 1 and len(table) == rows + 1
    times = [float(r[0]) for r in table[1:]]
    assert all(b > a for a, b in zip(times, times[1:], strict=False))
    png = tmp_path / "run.png"
    drawn = plot_csv(output, png, ["actual_q"])
    assert drawn == [f"actual_q_{i}" for i in range(6)]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_record_rejects_an_unknown_field(sim, tmp_path, capsys):
    assert main(["record", "--host", HOST, "--port", str(sim["rtde"]), "--fields",
                 "actual_q,warp_drive", "--duration", "0.2", "-o",
                 str(tmp_path / "x.csv")]) == 2
    assert "warp_drive" in capsys.readouterr().err


def test_dashboard(sim, capsys):
    with DashboardClient(HOST, sim["dashboard"]) as dashboard:
        assert dashboard.command("robotmode").value == "RUNNING"
        assert dashboard.command("safetymode").value == "NORMAL"
        assert not dashboard.command("frobnicate").ok
    assert main(["dashboard", "--host", HOST, "--port", str(sim["dashboard"]),
                 "running"]) == 0
    assert "Program running:" in capsys.readouterr().out


def test_nothing_listening_is_a_clear_error(capsys):
    port = free_port()
    with pytest.raises(RobotConnectionError, match=f"127.0.0.1:{port}: connection refused"):
        read_state(HOST, "realtime", port, timeout=1.0)
    assert main(["state", "--host", HOST, "--port", str(port), "--timeout", "1"]) == 2
    assert "connection refused" in capsys.readouterr().err


def test_a_server_that_hangs_up_is_a_clear_error():
    with socket.socket() as server:
        server.bind((HOST, 0))
        server.listen(1)
        port = server.getsockname()[1]
        import threading

        def hang_up():
            connection, _ = server.accept()
            connection.sendall(b"\x00\x00")  # half a size field, then goodbye
            connection.close()

        thread = threading.Thread(target=hang_up, daemon=True)
        thread.start()
        with pytest.raises(RobotConnectionError, match="closed the connection"):
            read_state(HOST, "realtime", port, timeout=2.0)
        thread.join(timeout=2)


def test_a_recording_cut_off_mid_stream_leaves_a_valid_file(tmp_path):
    """An RTDE server (written here with the codecs) that streams 50 samples and hangs up."""
    import struct
    import threading

    from urdsl.protocol import rtde

    server = socket.socket()
    server.bind((HOST, 0))
    server.listen(1)
    port = server.getsockname()[1]

    def serve():
        connection, _ = server.accept()
        connection.settimeout(5)
        decoder = rtde.PackageDecoder()
        replies = {86: b"\x01", 79: b"\x01DOUBLE,VECTOR6D", 83: b"\x01"}
        answered = 0
        while answered < 3:
            for kind, _payload in decoder.feed(connection.recv(4096)):
                connection.sendall(rtde.encode_package(kind, replies[kind]))
                answered += 1
        for i in range(50):
            connection.sendall(rtde.encode_package(85, struct.pack(">Bd6d", 1, i * 0.008,
                                                                   *[i] * 6)))
        whole = rtde.encode_package(85, struct.pack(">Bd6d", 1, 1.0, *[0] * 6))
        connection.sendall(whole[:20])  # half a package, then gone
        connection.close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    output = tmp_path / "cut.csv"
    with pytest.raises(RobotConnectionError, match="closed the connection"):
        record(HOST, output, ["actual_q"], 125.0, duration=5.0, port=port, timeout=3.0)
    thread.join(timeout=5)
    server.close()
    with open(output, newline="") as handle:
        table = list(csv.reader(handle, delimiter=" "))
    assert table[0] == ["timestamp"] + [f"actual_q_{i}" for i in range(6)]
    assert len(table) == 51 and float(table[-1][1]) == 49
