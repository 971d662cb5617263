"""`urdsl send` / send_program against a fake controller speaking the primary interface."""

from __future__ import annotations

import textwrap
import time
from types import SimpleNamespace

import pytest
from _robot_fakes import LOOPBACK, FakeController, FakeServer, free_port, version_message

from urdsl.cli import main
from urdsl.robot.errors import CheckFailedError, ConnectError, ConnectionLost
from urdsl.robot.sender import run_program, send, send_program

BARE = """\
# wave hello
home = [0, -1.57, 0, -1.57, 0, 0]
movej(home, a=1.4)
if True:
  textmsg("x", 1 / 0)
end
"""


def runs(ticks: int = 5, *texts: str):
    """Behaviour: the program prints ``texts`` and runs for ``ticks`` state periods."""
    def behaviour(program: str):
        return [("text", t) for t in texts] + [("run", ticks)]
    return behaviour


def fails_at(needle: str, message: str):
    """Behaviour: the program runs briefly, then fails where ``needle`` is in the received
    text — line and column counted in that text, as a controller does."""
    def behaviour(program: str):
        for number, line in enumerate(program.splitlines(), start=1):
            if needle in line:
                return [("run", 2), ("exception", number, line.index(needle) + 1, message)]
        raise AssertionError(f"{needle!r} not in the program sent:\n{program}")
    return behaviour


def controller(behaviour, **kw):
    fake = FakeController(behaviour, **kw)
    return fake, FakeServer(fake.primary, connections=4)


def test_send_success_reports_started_and_finished():
    fake, server = controller(runs(5, "hello from the robot"))
    with server:
        result = run_program("def wave():\n  textmsg(\"hi\")\nend\n", LOOPBACK, server.port,
                             primary_port=server.port, timeout=5)
    assert result.status == "finished" and result.ok
    assert result.started and result.error is None
    assert result.duration is not None and result.duration > 0
    assert result.messages == ["hello from the robot"]
    assert result.controller_version == "3.15.7"
    assert fake.programs == ['def wave():\n  textmsg("hi")\nend\n']
    assert "finished after" in result.summary()


def test_runtime_exception_is_mapped_to_the_users_line_through_the_wrapper():
    fake, server = controller(fails_at("1 / 0", "division by zero"))
    with server:
        result = run_program(BARE, LOOPBACK, server.port, primary_port=server.port, timeout=5,
                             filename="wave.script")
    assert result.status == "failed" and not result.ok
    sent = fake.programs[0]
    assert sent.splitlines()[0] == "def urdsl_program():"
    error = result.error
    assert (error.line, error.column) == (6, 18)  # in the text the controller received
    location = error.location
    assert (location.filename, location.line, location.column) == ("wave.script", 5, 16)
    rendered = error.render()
    assert rendered.splitlines() == [
        "wave.script:5:16: error: division by zero (runtime exception on the controller)",
        '    textmsg("x", 1 / 0)',
        "                 ^",
    ]


def test_script_port_and_monitor_port_can_differ():
    fake = FakeController(runs(3))
    with FakeServer(fake.primary) as primary, FakeServer(fake.script_port) as secondary:
        result = run_program("movej([0, -1.57, 0, -1.57, 0, 0])\n", LOOPBACK, secondary.port,
                             timeout=5, primary_port=primary.port)
    assert result.status == "finished"
    assert fake.programs == ["def urdsl_program():\n  movej([0, -1.57, 0, -1.57, 0, 0])\nend\n"]


def test_check_refusal_sends_nothing():
    report = SimpleNamespace(has_errors=True, render_text=lambda **kw: "bad\n")
    calls = []

    def checker(tree, filename, robot):
        calls.append((filename, robot))
        return report

    # nothing listens on this port: a send attempt would raise ConnectError instead
    with pytest.raises(CheckFailedError) as caught:
        send_program(BARE, LOOPBACK, free_port(), filename="wave.script", robot="ur10e",
                     check=True, checker=checker)
    assert calls == [("wave.script", "ur10e")]
    assert caught.value.report is report
    assert "nothing was sent" in str(caught.value)


def test_passing_check_then_send(monkeypatch):
    fake, server = controller(runs(2))
    report = SimpleNamespace(has_errors=False)
    with server:
        result = run_program(BARE.replace("1 / 0", "1"), LOOPBACK, server.port,
                             primary_port=server.port, timeout=5, check=True,
                             checker=lambda tree, name, robot: report)
    assert result.report is report and result.status == "finished"


def test_protective_stop_fails_the_program():
    def behaviour(program):
        return [("run", 2), ("safety", 3)]
    fake, server = controller(behaviour)
    with server:
        result = run_program("def p():\n  movej([0,0,0,0,0,0])\nend\n", LOOPBACK,
                             server.port, primary_port=server.port, timeout=5)
    assert result.status == "failed"
    assert result.error.kind == "protective stop"
    assert "PROTECTIVE_STOP" in result.error.render()


def test_still_running_when_the_wait_ends_is_not_a_failure():
    fake, server = controller(runs(10_000))
    with server:
        result = run_program("def p():\n  sleep(100)\nend\n", LOOPBACK, server.port,
                             primary_port=server.port, timeout=0.5)
    assert result.status == "timeout" and result.ok
    assert "still running" in result.summary()


def test_no_sign_of_a_start():
    fake, server = controller(lambda program: [])
    with server:
        result = run_program("def p():\n  x = 1\nend\n", LOOPBACK, server.port,
                             primary_port=server.port, timeout=5, start_timeout=0.3)
    assert result.status == "not observed" and not result.started and result.ok


def test_send_program_sends_and_returns_at_once():
    fake, server = controller(runs(1000))
    with server:
        result = send_program("textmsg(\"x\")", LOOPBACK, server.port)
        assert result.status == "sent" and not result.started
        assert result.bytes_sent == len('def urdsl_program():\n  textmsg("x")\nend\n')
        deadline = time.monotonic() + 5
        while not fake.programs and time.monotonic() < deadline:
            time.sleep(0.01)
    assert fake.programs == ['def urdsl_program():\n  textmsg("x")\nend\n']


def test_disconnect_while_following_is_a_clear_error():
    def handler(sock, index):
        sock.sendall(version_message())
        from _robot_fakes import robot_state

        sock.sendall(robot_state(False))
        data = b""
        while not data.endswith(b"end\n"):
            data += sock.recv(4096)
        sock.close()  # the controller goes away right after taking the program

    with FakeServer(handler) as server:
        with pytest.raises(ConnectionLost) as caught:
            run_program("def p():\n  x = 1\nend\n", LOOPBACK, server.port,
                        primary_port=server.port, timeout=5)
    assert "the program was sent, but" in str(caught.value)
    assert f"{LOOPBACK}:{server.port}" in str(caught.value)


def test_connect_refused_is_a_connect_error():
    port = free_port()
    with pytest.raises(ConnectError, match=f"connection refused by {LOOPBACK}:{port}"):
        send_program("def p():\nend\n", LOOPBACK, port, check=False)


def test_send_accepts_a_dsl_program_and_maps_to_its_python_line():
    from urdsl.dsl import Joints, Program

    program = Program("wave")
    program.movej(Joints(0, -1.57, 0, -1.57, 0, 0))
    program.textmsg("boom")  # the fake controller fails here
    fake, server = controller(fails_at("textmsg", "something went wrong"))
    with server:
        result = send(program, LOOPBACK, server.port, timeout=5, check=False)
    assert result.error.location.filename == __file__
    assert "program.textmsg" in result.error.location.source_line


# ---- the command -----------------------------------------------------------------------------


def test_cli_send_success_with_the_real_check(tmp_path, capsys):
    path = tmp_path / "home.script"
    path.write_text("movej([0, -1.5708, 1.5708, -1.5708, -1.5708, 0])\ntextmsg(\"home\")\n")
    fake, server = controller(runs(3, "home"))
    with server:
        status = main(["send", str(path), "--host", LOOPBACK, "--port", str(server.port),
                       "--timeout", "5"])
    err = capsys.readouterr().err
    assert status == 0, err
    assert f"checked {path} on ur5e: no errors" in err
    assert "controller: home" in err
    assert "urdsl_program: finished after" in err
    assert len(fake.programs) == 1


def test_cli_refuses_a_program_the_check_rejects(tmp_path, capsys):
    path = tmp_path / "course.script"
    path.write_text("movej([0, -1.57, 0, -1.57, 0])\n")  # the course's five-joint movej
    fake, server = controller(runs(1))
    with server:
        status = main(["send", str(path), "--host", LOOPBACK, "--port", str(server.port)])
    err = capsys.readouterr().err
    assert status == 1
    assert f"{path}:1:" in err
    assert "nothing was sent" in err
    assert fake.programs == []


def test_cli_runtime_exception_exit_1_with_the_users_line(tmp_path, capsys):
    path = tmp_path / "wave.script"
    path.write_text(BARE)
    fake, server = controller(fails_at("1 / 0", "division by zero"))
    with server:
        status = main(["send", str(path), "--host", LOOPBACK, "--port", str(server.port),
                       "--no-check", "--timeout", "5"])
    err = capsys.readouterr().err
    assert status == 1
    assert f"{path}:5:16: error: division by zero" in err
    assert '  textmsg("x", 1 / 0)' in err
    assert "urdsl_program: failed" in err


def test_cli_send_dsl_program_file(tmp_path, capsys):
    path = tmp_path / "wave.py"
    path.write_text(textwrap.dedent("""\
        from urdsl.dsl import Joints, Program

        program = Program("wave")
        program.movej(Joints(0, -1.5708, 1.5708, -1.5708, -1.5708, 0))
        program.textmsg("boom")
        """))
    fake, server = controller(fails_at("textmsg", "boom failed"))
    with server:
        status = main(["send", str(path), "--host", LOOPBACK, "--port", str(server.port),
                       "--timeout", "5"])
    err = capsys.readouterr().err
    assert status == 1
    assert f"{path}:5:1: error: boom failed" in err
    assert 'program.textmsg("boom")' in err


def test_cli_dry_run_prints_the_text_and_sends_nothing(tmp_path, capsys):
    path = tmp_path / "w.script"
    path.write_text("textmsg(\"a\")\n")
    assert main(["send", str(path), "--host", LOOPBACK, "--port", str(free_port()),
                 "--dry-run", "--no-check"]) == 0
    assert capsys.readouterr().out == 'def urdsl_program():\n  textmsg("a")\nend\n'


def test_cli_connect_refused_exit_1(tmp_path, capsys):
    path = tmp_path / "w.script"
    path.write_text("textmsg(\"a\")\n")
    port = free_port()
    assert main(["send", str(path), "--host", LOOPBACK, "--port", str(port), "--no-check",
                 "--monitor-port", str(port)]) == 1
    err = capsys.readouterr().err
    assert f"connection refused by {LOOPBACK}:{port}" in err and "Traceback" not in err


def test_cli_syntax_error_is_shown_with_the_line(tmp_path, capsys):
    path = tmp_path / "bad.script"
    path.write_text("p1 = p[0.2, -0.3, 0.3, 0.5, 0.0, -0.3])\n")
    assert main(["send", str(path), "--host", LOOPBACK, "--no-check"]) == 1
    err = capsys.readouterr().err
    assert f"{path}:1:" in err and "^" in err


def test_a_100000_line_program_sent_to_the_sim_runs():
    """The sending connection used to close with the controller's states unread: the kernel
    reset it, threw away what was still queued, and the sim never saw the program's end
    ("no start was seen"; 20,000 and 50,000 lines happened to fit the socket buffers)."""
    from urdsl.sim.controller import VirtualController
    from urdsl.sim.servers import STANDARD_PORTS

    lines = ["def big():", "  x = 0"] + ["  x = x + 1"] * 99_996 + \
        ['  textmsg("big done ", x)', "end"]
    text = "\n".join(lines) + "\n"
    assert text.count("\n") == 100_000
    with VirtualController(speed=10) as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        result = send(text, LOOPBACK, servers.ports["secondary"], check=False, timeout=300,
                      monitor_port=servers.ports["primary"])
        assert result.status == "finished", result.summary()
        assert "big done 99996" in result.messages
        assert list(servers.dropped) == []
