"""The Python API: ``with connect(host) as robot: robot.send(...); robot.state(); ...``."""

from __future__ import annotations

import pytest
from _robot_fakes import LOOPBACK, FakeController, FakeRtde, FakeServer
from test_robot_dashboard import dashboard_handler
from test_robot_state import packet

from urdsl.dsl import Joints, Program
from urdsl.robot import connect
from urdsl.robot.csvfile import read_recording


def test_one_object_for_send_state_record_and_dashboard(tmp_path):
    controller = FakeController(lambda text: [("text", "hello"), ("run", 3)])
    rtde = FakeRtde()
    log: list[str] = []

    def realtime(sock, index):
        sock.sendall(packet(1) + packet(2))
        sock.recv(1)

    with FakeServer(controller.primary) as primary, FakeServer(realtime) as realtime_server, \
            FakeServer(rtde.handler) as rtde_server, \
            FakeServer(dashboard_handler({"modes": ["IDLE"]}, log)) as dashboard:
        ports = {"primary": primary.port, "secondary": primary.port,
                 "realtime": realtime_server.port, "rtde": rtde_server.port,
                 "dashboard": dashboard.port}
        with connect(LOOPBACK, ports=ports, timeout=5) as robot:
            program = Program("hello")
            program.movej(Joints(0, -1.5708, 1.5708, -1.5708, -1.5708, 0))
            program.textmsg("hello")
            result = robot.send(program, timeout=5, check=False)
            assert result.status == "finished" and result.messages == ["hello"]
            assert controller.programs[0].startswith("def hello():\n")

            state = robot.state()
            assert state.time == 2.0 and state.robot_mode_name == "RUNNING"

            recorded = robot.record(tmp_path / "r.csv", "actual_q", samples=20)
            assert recorded.samples == 20 and read_recording(tmp_path / "r.csv").rows == 20

            assert robot.dashboard("robotmode").value == "IDLE"
            assert robot.dashboard("load pick.urp").ok
            with pytest.raises(ValueError, match="unknown dashboard command"):
                robot.dashboard("fly away")
            with pytest.raises(ValueError, match="without an end"):
                robot.record(tmp_path / "x.csv")
    assert log == ["robotmode", "load pick.urp"]


def test_port_offset_moves_every_port():
    robot = connect(LOOPBACK, port_offset=1000)
    assert robot.ports["primary"] == 31001 and robot.ports["rtde"] == 31004
    assert robot.ports["dashboard"] == 30999
