"""Third-party clients against ``urdsl sim`` on loopback: ur_rtde (RTDE receive, dashboard)
and python-urx (secondary + realtime), as a user would run them.

ur_rtde takes only a host name and uses the controller's fixed ports (30004, 29999), so these
tests start one ``urdsl sim`` process on the standard ports of 127.0.0.1 for the module; they
are skipped, saying why, when one of those ports is taken. ur_rtde's calls block without
releasing Python's GIL, which is why the simulator runs in its own process here. Every wait
is bounded.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from urdsl.sim.controller import DEFAULT_START
from urdsl.sim.servers import STANDARD_PORTS

TARGET = [0.5, -1.3, 1.4, -1.7, -1.5, 0.3]
WAVE = f"def wave():\n  movej({TARGET}, a=1.2, v=0.8)\n  sleep(60)\nend\n"


def _sim_command(*args: str) -> list[str]:
    script = Path(sys.executable).with_name("urdsl")
    if script.exists():
        return [str(script), "sim", *args]
    found = shutil.which("urdsl")
    return [found, "sim", *args] if found else [sys.executable, "-m", "urdsl.cli", "sim", *args]


def _ports_free(offset: int = 0) -> str | None:
    """None if every controller port + offset is free on 127.0.0.1, else the reason."""
    for name, port in STANDARD_PORTS.items():
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            # as the simulator binds: a port in TIME_WAIT after a restart counts as free
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                probe.bind(("127.0.0.1", port + offset))
            except OSError:
                return f"port {port + offset} ({name}) is taken on 127.0.0.1"
    return None


def _start(args: list[str], offset: int = 0) -> subprocess.Popen:
    process = subprocess.Popen(_sim_command(*args), stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", 29999 + offset), timeout=1) as probe:
                probe.settimeout(5)
                if probe.recv(100).startswith(b"Connected"):
                    return process
        except OSError:
            if process.poll() is not None:
                raise RuntimeError(f"urdsl sim exited: {process.stdout.read()}") from None
            time.sleep(0.2)
    process.kill()
    raise RuntimeError("urdsl sim did not start within 60 s")


def _stop(process: subprocess.Popen, sig=signal.SIGINT) -> tuple[int, str]:
    process.send_signal(sig)
    try:
        out, _ = process.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        process.kill()
        out, _ = process.communicate(timeout=20)
        return -1, out
    return process.returncode, out


@pytest.fixture(scope="module")
def standard_sim(tmp_path_factory):
    reason = _ports_free()
    if reason:
        pytest.skip(f"the interop tests need the controller's standard ports: {reason}")
    folder = tmp_path_factory.mktemp("programs")
    (folder / "wave.script").write_text(WAVE)
    process = _start(["--programs", str(folder), "--quiet"])
    yield process
    code, out = _stop(process)
    assert code == 0, out


def _send_script(text: str) -> None:
    """Send a program with urdsl's sender (``urdsl send`` uses the same function); do not
    follow it: the test watches the arm itself."""
    from urdsl.robot.sender import send_program

    send_program(text, "127.0.0.1", follow=False)


def _eventually(condition, timeout: float = 2.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, "the condition did not become true in time"
        time.sleep(0.01)


def _rest(timeout: float = 20.0) -> None:
    """Stop whatever runs and bring the arm back to the start joints."""
    _send_script(f"def home():\n  movej({list(DEFAULT_START)}, a=4, v=3)\nend\n")


def test_ur_rtde_receive_follows_a_program_sent_by_urdsl(standard_sim):
    rtde_receive = pytest.importorskip("rtde_receive")
    receiver = rtde_receive.RTDEReceiveInterface("127.0.0.1")
    try:
        assert receiver.isConnected()
        start = np.array(receiver.getActualQ())
        _send_script(f"def follow():\n  movej({TARGET}, a=1.2, v=0.8)\nend\n")
        samples, states = [], set()
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            q = np.array(receiver.getActualQ())
            samples.append(q)
            states.add(receiver.getRuntimeState())
            if np.allclose(q, TARGET, atol=1e-6) and len(samples) > 5:
                break
            time.sleep(0.01)
        else:
            pytest.fail(f"actual_q never reached the target; last {samples[-1]}")
        travel = np.linalg.norm(np.array(samples) - start, axis=1)
        total = np.linalg.norm(np.array(TARGET) - start)
        between = travel[(travel > 0.05 * total) & (travel < 0.95 * total)]
        assert len(between) >= 3, "actual_q jumped instead of following the move"
        assert np.all(np.diff(travel) >= -1e-9), "actual_q went backwards"
        assert 2 in states  # runtime_state PLAYING while it moved
        assert receiver.getRobotMode() == 7 and receiver.getSafetyMode() == 1
        timestamp = receiver.getTimestamp()
        time.sleep(0.1)
        assert receiver.getTimestamp() > timestamp
    finally:
        receiver.disconnect()
        _rest()


def test_ur_rtde_dashboard_powers_on_plays_and_stops(standard_sim):
    dashboard_client = pytest.importorskip("dashboard_client")
    dashboard = dashboard_client.DashboardClient("127.0.0.1")
    dashboard.connect()
    try:
        assert dashboard.isConnected()
        assert dashboard.isInRemoteControl()
        dashboard.powerOff()
        assert "POWER_OFF" in dashboard.robotmode()
        dashboard.powerOn()
        dashboard.brakeRelease()
        deadline = time.monotonic() + 10
        while "RUNNING" not in dashboard.robotmode():
            assert time.monotonic() < deadline, dashboard.robotmode()
            time.sleep(0.05)
        dashboard.loadURP("wave.script")
        assert dashboard.getLoadedProgram() == "Loaded program: wave.script"
        dashboard.play()
        deadline = time.monotonic() + 10
        while not dashboard.running():
            assert time.monotonic() < deadline
            time.sleep(0.05)
        assert "PLAYING" in dashboard.programState()
        dashboard.stop()
        deadline = time.monotonic() + 10
        while dashboard.running():
            assert time.monotonic() < deadline
            time.sleep(0.05)
        assert "STOPPED" in dashboard.programState()
        assert dashboard.safetymode().endswith("NORMAL")
    finally:
        dashboard.disconnect()
        _rest()


def test_python_urx_reads_joints_and_pose_and_movej_moves_the_arm(standard_sim):
    urx = pytest.importorskip("urx")
    from urdsl.kinematics import Robot, pose

    _rest()
    time.sleep(3)
    robot = urx.Robot("127.0.0.1")
    try:
        joints = np.array(robot.getj())
        model = Robot.model("ur5e")
        # python-urx 0.11 with math3d 4: Robot.getl() calls a method math3d 4 removed; the
        # pose itself is read fine through get_pose()
        tcp = np.array(robot.get_pose().pose_vector.array)
        assert np.allclose(tcp[:3], pose.from_matrix(model.fk(joints))[:3], atol=1e-9)
        target = [0.2, -1.4, 1.2, -1.4, -1.6, 0.4]
        # urx's own wait (wait=True) needs 3.0-3.4 robot mode data; on 5.x controllers it
        # reports "Robot stopped" against real robots too, so poll the joints instead
        robot.movej(target, acc=1.5, vel=1.0, wait=False)
        deadline = time.monotonic() + 15
        while not np.allclose(robot.getj(), target, atol=1e-6):
            assert time.monotonic() < deadline, f"urx movej did not arrive: {robot.getj()}"
            time.sleep(0.05)
        moved = np.array(robot.get_pose().pose_vector.array)
        assert np.allclose(moved[:3], pose.from_matrix(model.fk(np.array(target)))[:3],
                           atol=1e-9)
    finally:
        robot.close()
        _rest()


def test_ur_rtde_control_uploads_its_script_and_moves_j_and_l(standard_sim):
    """Stretch goal: RTDEControlInterface sends its own control script (hundreds of lines
    of URScript with threads and register handshakes), which our interpreter runs."""
    rtde_control = pytest.importorskip("rtde_control")
    rtde_receive = pytest.importorskip("rtde_receive")
    control = rtde_control.RTDEControlInterface("127.0.0.1")
    receiver = rtde_receive.RTDEReceiveInterface("127.0.0.1")
    try:
        assert control.isConnected() and control.isProgramRunning()
        assert control.moveJ(TARGET, 1.4, 1.05)
        # moveJ returns when the script reports the move done; the receiver's newest sample
        # may be a few controller steps older
        _eventually(lambda: np.allclose(receiver.getActualQ(), TARGET, atol=1e-6))
        goal = np.array(receiver.getActualTCPPose())
        goal[:3] += (0.03, 0.0, -0.05)
        assert control.moveL(goal.tolist(), 0.5, 0.25)
        _eventually(lambda: np.allclose(receiver.getActualTCPPose()[:3], goal[:3], atol=1e-6))
    finally:
        control.stopScript()
        control.disconnect()
        receiver.disconnect()
        _rest()


@pytest.mark.skipif(os.name != "posix", reason="POSIX signals")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_urdsl_sim_shuts_down_cleanly_on_signals(sig):
    offset = 2000 + (os.getpid() % 500) * 10 + (1 if sig == signal.SIGTERM else 0)
    reason = _ports_free(offset)
    if reason:
        pytest.skip(reason)
    process = _start(["--port-offset", str(offset)], offset)
    with socket.create_connection(("127.0.0.1", 30003 + offset), timeout=5) as client:
        client.settimeout(5)
        assert len(client.recv(4096)) > 0
        code, out = _stop(process, sig)
    assert code == 0, out
    assert "urdsl sim: stopped" in out
    assert _ports_free(offset) is None  # every port released


def test_urdsl_sim_refuses_a_model_that_does_not_run_that_software():
    result = subprocess.run(_sim_command("--robot", "ur5", "--version", "5.15"),
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert "CB3" in result.stderr and "Traceback" not in result.stderr
