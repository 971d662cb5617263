"""The robot clients against the virtual controller on loopback (only 127.0.0.1 is dialled):
send with feedback and the error mapped to the user's line, state on every interface,
an RTDE recording and its plot, dashboard commands."""

from __future__ import annotations

import csv
import json

import pytest

from urdsl.cli import main
from urdsl.robot import read_state, record
from urdsl.robot.dashboard import Dashboard
from urdsl.robot.plot import plot_recording
from urdsl.sim import VirtualController
from urdsl.sim.servers import STANDARD_PORTS

HOST = "127.0.0.1"


@pytest.fixture(scope="module")
def sim():
    with VirtualController(robot="ur5e", speed=4.0) as controller, \
            controller.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        yield servers.ports


def send(sim, tmp_path, text: str, name: str = "prog.script", *extra: str) -> int:
    path = tmp_path / name
    path.write_text(text)
    return main(["send", str(path), "--host", HOST, "--port", str(sim["secondary"]),
                 "--monitor-port", str(sim["primary"]), "--timeout", "30", *extra])


def test_send_checks_runs_and_reports_success(sim, tmp_path, capsys):
    status = send(sim, tmp_path, 'movej([0.2, -1.9, 1.9, -1.57, -1.57, 0])\ntextmsg("done")\n')
    captured = capsys.readouterr()
    shown = captured.out + captured.err
    assert status == 0, shown
    assert "finished" in shown and "done" in shown
    assert read_state(HOST, "realtime", sim["realtime"]).joints[0] == pytest.approx(0.2,
                                                                                   abs=1e-3)


def test_a_runtime_error_is_mapped_to_the_users_line(sim, tmp_path, capsys):
    text = "# a comment moves the lines\nx = 1\n\nmovej([0, -1.9, 1.9, -1.57, -1.57, 0])\n" \
           "y = missing + 1\n"
    assert send(sim, tmp_path, text, "bad.script", "--no-check") == 1
    out = capsys.readouterr()
    shown = out.out + out.err
    assert f"{tmp_path / 'bad.script'}:5:" in shown and "missing" in shown


def test_the_check_refuses_a_program_with_errors(sim, tmp_path, capsys):
    assert send(sim, tmp_path, "movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])\n", "far.script") == 1
    out = capsys.readouterr()
    assert "URS301" in out.out + out.err


@pytest.mark.parametrize("interface", ["realtime", "primary", "rtde"])
def test_state_on_every_interface(sim, interface, capsys):
    port = {"realtime": sim["realtime"], "primary": sim["secondary"], "rtde": sim["rtde"]}
    assert main(["state", "--host", HOST, "--interface", interface, "--port",
                 str(port[interface]), "--json"]) == 0
    state = json.loads(capsys.readouterr().out.splitlines()[0])
    assert len(state["joints"]) == 6
    assert state["robot_mode_name"] == "RUNNING"


def test_record_and_plot(sim, tmp_path):
    output = tmp_path / "run.csv"
    result = record(HOST, output, ["actual_q", "actual_TCP_pose"], frequency=125.0,
                    duration=0.6, port=sim["rtde"])
    with open(output, newline="") as handle:
        table = list(csv.reader(handle, delimiter=" "))
    assert table[0][:3] == ["timestamp", "actual_q_0", "actual_q_1"]
    assert len(table) > 20 and len(table) == result.samples + 1
    png = tmp_path / "run.png"
    plot_recording(output, png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_dashboard(sim):
    with Dashboard(HOST, sim["dashboard"]) as dashboard:
        assert dashboard.run("robotmode").value == "RUNNING"
