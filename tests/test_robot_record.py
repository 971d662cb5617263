"""`urdsl record` (RTDE → CSV) and `urdsl plot` against a fake RTDE controller."""

from __future__ import annotations

import json
import signal
import threading

import numpy as np
import pytest
from _robot_fakes import LOOPBACK, FakeRtde, FakeServer, free_port

from urdsl.cli import main
from urdsl.robot.csvfile import read_recording
from urdsl.robot.recorder import record
from urdsl.robot.rtde_session import RtdeSetupError
from urdsl.robot.state import read_state

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
HEADER = ["timestamp", *[f"actual_q_{i}" for i in range(6)],
          *[f"actual_TCP_pose_{i}" for i in range(6)]]


def test_record_to_csv_then_plot_to_png(tmp_path, capsys):
    fake = FakeRtde()
    out = tmp_path / "run.csv"
    with FakeServer(fake.handler) as server:
        status = main(["record", "--host", LOOPBACK, "--port", str(server.port), "--fields",
                       "actual_q,actual_TCP_pose", "--frequency", "500", "--samples", "200",
                       "-o", str(out), "-q"])
    err = capsys.readouterr().err
    assert status == 0, err
    lines = out.read_text().splitlines()
    assert lines[0].split(" ") == HEADER
    assert len(lines) == 201
    recording = read_recording(out)
    # the very values the controller sent, in order, none lost or repeated
    sent = fake.sent_values[:200]
    np.testing.assert_array_equal(recording.field("timestamp"), [v["timestamp"] for v in sent])
    np.testing.assert_array_equal(recording.field("actual_q"), [v["actual_q"] for v in sent])
    assert np.all(np.diff(recording.field("timestamp")) == pytest.approx(0.002))
    assert "recorded 200 samples" in err and "RTDE v2" in err and "0 missed" in err

    png = tmp_path / "run.png"
    assert main(["plot", str(out), "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == PNG_MAGIC
    assert png.stat().st_size > 10_000


def test_frequency_decimates_and_protocol_1_fallback(tmp_path):
    fake = FakeRtde(refuse_v2=True)
    out = tmp_path / "v1.csv"
    with FakeServer(fake.handler) as server:
        result = record(LOOPBACK, out, "actual_q", samples=50, port=server.port)
    assert fake.requests[0] == "V2 refused"
    assert result.protocol == 1 and result.samples == 50
    # protocol 1 has no frequency: the controller streams at its rate (500 Hz)
    stamps = read_recording(out).field("timestamp")
    assert np.diff(stamps) == pytest.approx(np.full(49, 0.002))

    fake = FakeRtde()
    with FakeServer(fake.handler) as server:
        result = record(LOOPBACK, out, "actual_q", samples=30, frequency=125, port=server.port)
    assert result.protocol == 2
    assert np.diff(read_recording(out).field("timestamp")) == pytest.approx(np.full(29, 0.008))
    assert result.missed == 0


def test_text_messages_do_not_stop_the_recording(tmp_path):
    fake = FakeRtde(texts={20: "Real-time priority lost", 40: "second message"})
    out = tmp_path / "t.csv"
    with FakeServer(fake.handler) as server:
        result = record(LOOPBACK, out, "actual_q", samples=100, port=server.port,
                        frequency=500)
    assert result.ok and result.samples == 100
    assert result.messages == ["warning: Controller: Real-time priority lost",
                               "warning: Controller: second message"]
    assert read_recording(out).rows == 100


def test_connection_dropped_mid_recording_keeps_a_valid_file(tmp_path, capsys):
    fake = FakeRtde(stop_after=73)
    out = tmp_path / "drop.csv"
    with FakeServer(fake.handler) as server:
        status = main(["record", "--host", LOOPBACK, "--port", str(server.port), "-o", str(out),
                       "--frequency", "500", "-q"])
    err = capsys.readouterr().err
    assert status == 1
    assert f"{LOOPBACK}:{server.port} (RTDE) closed the connection" in err
    assert "recording stopped" in err and "recorded 73 samples" in err
    recording = read_recording(out)  # every line complete, every sample there
    assert recording.rows == 73
    np.testing.assert_array_equal(recording.field("timestamp"),
                                  [v["timestamp"] for v in fake.sent_values])


def test_unknown_field_is_refused_with_a_suggestion(tmp_path, capsys):
    fake = FakeRtde()
    out = tmp_path / "x.csv"
    with FakeServer(fake.handler, connections=2) as server:
        with pytest.raises(RtdeSetupError) as caught:
            record(LOOPBACK, out, "actual_q,actual_tcp_pose", samples=5, port=server.port)
        status = main(["record", "--host", LOOPBACK, "--port", str(server.port), "--fields",
                       "actul_q", "-o", str(out), "-q"])
    assert "does not know the output field(s): actual_tcp_pose (did you mean " \
           "actual_TCP_pose" in str(caught.value)
    assert status == 1
    assert "actul_q (did you mean actual_q" in capsys.readouterr().err
    assert not out.exists()  # nothing recorded, no empty file left behind


def test_cb3_frequency_limit(tmp_path):
    fake = FakeRtde(version=(3, 15, 7, 0))
    with FakeServer(fake.handler) as server:
        with pytest.raises(RtdeSetupError, match=r"CB3 controller \(3.15.7.0\) streams at 1 to "
                                                 r"125 Hz, not 500 Hz"):
            record(LOOPBACK, tmp_path / "c.csv", "actual_q", frequency=500, samples=5,
                   port=server.port)


def test_stalled_stream_ends_with_a_clear_error(tmp_path):
    fake = FakeRtde(silent=True)
    out = tmp_path / "s.csv"
    with FakeServer(fake.handler) as server:
        result = record(LOOPBACK, out, "actual_q", port=server.port, stall_timeout=0.3)
    assert result.stopped_by == "stall" and not result.ok
    assert "sent no data for 0.3 s" in result.error
    assert read_recording(out).rows == 0


def test_stop_event_ends_cleanly_with_every_sample(tmp_path):
    stop = threading.Event()
    fake = FakeRtde(on_sample=lambda count: stop.set() if count >= 120 else None)
    out = tmp_path / "c.csv"
    with FakeServer(fake.handler) as server:
        result = record(LOOPBACK, out, "actual_q", port=server.port, frequency=500, stop=stop)
    assert result.stopped_by == "stop" and result.ok
    recording = read_recording(out)
    assert recording.rows == result.samples >= 120
    # samples that arrived until the pause took effect are kept too, in order
    np.testing.assert_array_equal(recording.field("timestamp"),
                                  [v["timestamp"] for v in fake.sent_values[:recording.rows]])


def test_ctrl_c_on_the_command_line(tmp_path, capsys):
    main_thread = threading.main_thread().ident
    fired = []

    def interrupt(count):
        if count >= 100 and not fired:
            fired.append(count)
            signal.pthread_kill(main_thread, signal.SIGINT)

    fake = FakeRtde(on_sample=interrupt)
    out = tmp_path / "ctrl_c.csv"
    before = signal.getsignal(signal.SIGINT)  # SIG_IGN when a shell ran the suite in background
    with FakeServer(fake.handler) as server:
        status = main(["record", "--host", LOOPBACK, "--port", str(server.port), "-o", str(out),
                       "--frequency", "500"])
    err = capsys.readouterr().err
    assert status == 0, err
    assert fired
    rows = read_recording(out).rows
    assert rows >= 100
    assert f"recorded {rows} samples" in err
    assert signal.getsignal(signal.SIGINT) is before  # the handler it found is back


def test_connection_refused_exit_1(tmp_path, capsys):
    port = free_port()
    assert main(["record", "--host", LOOPBACK, "--port", str(port), "-o",
                 str(tmp_path / "r.csv"), "-q"]) == 1
    err = capsys.readouterr().err
    assert f"connection refused by {LOOPBACK}:{port} (RTDE)" in err
    assert "Traceback" not in err


def test_state_over_rtde(capsys):
    fake = FakeRtde()
    with FakeServer(fake.handler, connections=2) as server:
        state = read_state(LOOPBACK, "rtde", server.port, timeout=5)
        assert main(["state", "--host", LOOPBACK, "--interface", "rtde", "--port",
                     str(server.port), "--json"]) == 0
    assert state.interface == "rtde"
    assert state.joints == pytest.approx(tuple(i + state.time * 500 / 1000 for i in range(6)))
    assert state.robot_mode_name == "RUNNING" and state.program_state_name == "PLAYING"
    assert state.version == "5.11.1.0"
    document = json.loads(capsys.readouterr().out)
    assert document["interface"] == "rtde" and len(document["tcp_pose"]) == 6
