"""Dashboard client against a fake dashboard server built on the protocol's server side."""

from __future__ import annotations

import json

import pytest
from _robot_fakes import LOOPBACK, FakeServer, free_port

from urdsl.cli import main
from urdsl.protocol.dashboard import DashboardServer
from urdsl.robot.dashboard import Dashboard, parse_command_words
from urdsl.robot.errors import ConnectionLost, RobotTimeout


def dashboard_handler(state: dict, log: list):
    """A dashboard server: robot mode advances on power on / brake release, like a robot."""

    def handler(sock, index):
        server = DashboardServer()
        sock.sendall(server.greeting())
        while not server.closed:
            data = sock.recv(4096)
            if not data:
                return
            for command in server.receive_data(data):
                log.append(command.line)
                name = command.name
                if name == "robotmode":
                    mode = state["modes"].pop(0) if len(state["modes"]) > 1 else \
                        state["modes"][0]
                    sock.sendall(server.reply(command, mode=mode))
                elif name == "load" and command.argument != "pick.urp":
                    sock.sendall(server.reply(command, ok=False))
                elif name == "play" and not state.get("remote", True):
                    sock.sendall(b"Command is not allowed due to safety reasons. The robot is "
                                 b"not in remote control\n")
                elif name == "programState":
                    sock.sendall(server.reply(command, state="PLAYING", name="pick.urp"))
                elif name == "running":
                    sock.sendall(server.reply(command, bool=True))
                elif command.known:
                    sock.sendall(server.reply(command))
                else:
                    sock.sendall(server.reply(command))

    return handler


@pytest.fixture
def fake_dashboard():
    state = {"modes": ["RUNNING"]}
    log: list[str] = []
    with FakeServer(dashboard_handler(state, log), connections=4) as server:
        yield server, state, log


def test_documented_replies(fake_dashboard):
    server, state, log = fake_dashboard
    with Dashboard(LOOPBACK, server.port, timeout=5) as dashboard:
        assert dashboard.welcome == "Connected: Universal Robots Dashboard Server"
        reply = dashboard.command("robotmode")
        assert reply.ok and reply.value == "RUNNING"
        reply = dashboard.run("load pick.urp")
        assert reply.ok and reply.text == "Loading program: pick.urp"
        reply = dashboard.run("load missing.urp")
        assert not reply.ok and reply.text == "File not found: missing.urp"
        reply = dashboard.command("programState")
        assert reply.value == "PLAYING" and reply.field("name") == "pick.urp"
        assert dashboard.command("running").value is True
    assert log == ["robotmode", "load pick.urp", "load missing.urp", "programState", "running"]


def test_command_words():
    assert parse_command_words(["power", "on"]) == ("power on", None)
    assert parse_command_words(["load", "/programs/a b.urp"]) == ("load", "/programs/a b.urp")
    with pytest.raises(ValueError, match="did you mean 'robotmode'"):
        parse_command_words(["RobotMode"])
    with pytest.raises(ValueError, match="needs an argument"):
        parse_command_words(["load"])


def test_cli_prints_reply_and_exit_status(fake_dashboard, capsys):
    server, state, log = fake_dashboard
    assert main(["dashboard", "--host", LOOPBACK, "--port", str(server.port), "play"]) == 0
    assert capsys.readouterr().out == "Starting program\n"
    state["remote"] = False
    assert main(["dashboard", "--host", LOOPBACK, "--port", str(server.port), "play"]) == 1
    captured = capsys.readouterr()
    assert "not in remote control" in captured.out
    assert "did not do 'play'" in captured.err and "Remote Control" in captured.err
    assert main(["dashboard", "--host", LOOPBACK, "--port", str(server.port), "--json",
                 "programState"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document == {"command": "programState", "reply": "PLAYING pick.urp", "ok": True,
                        "value": "PLAYING", "fields": {"name": "pick.urp",
                                                       "state": "PLAYING"}}


def test_power_on_waits_for_idle(fake_dashboard, capsys):
    server, state, log = fake_dashboard
    state["modes"] = ["POWER_OFF", "BOOTING", "IDLE"]
    assert main(["dashboard", "--host", LOOPBACK, "--port", str(server.port), "power", "on",
                 "--wait", "--wait-timeout", "10"]) == 0
    assert capsys.readouterr().out == "Powering on\nRobotmode: IDLE\n"
    assert log == ["power on", "robotmode", "robotmode", "robotmode"]


def test_unknown_command_is_a_usage_error(capsys):
    assert main(["dashboard", "--host", LOOPBACK, "--port", "1", "fly"]) == 2
    assert "unknown dashboard command 'fly'" in capsys.readouterr().err


def test_connection_refused_exits_1(capsys):
    port = free_port()
    assert main(["dashboard", "--host", LOOPBACK, "--port", str(port), "robotmode"]) == 1
    err = capsys.readouterr().err
    assert f"connection refused by {LOOPBACK}:{port} (dashboard)" in err
    assert "Traceback" not in err


def test_server_that_hangs_up_or_stays_silent():
    with FakeServer(lambda sock, i: None) as server:  # closes at once, no welcome
        with pytest.raises(ConnectionLost, match="closed the connection"):
            Dashboard(LOOPBACK, server.port, timeout=5)

    def silent(sock, index):
        sock.sendall(b"Connected: Universal Robots Dashboard Server\n")
        sock.recv(100)  # takes the command, never answers, then waits for the client
        sock.recv(100)

    with FakeServer(silent) as server:
        with Dashboard(LOOPBACK, server.port, timeout=5) as dashboard:
            with pytest.raises(RobotTimeout, match="no reply to 'stop' within 0.2 s"):
                dashboard.command("stop", timeout=0.2)
