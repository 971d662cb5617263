"""The virtual controller's core, without sockets: programs run in (scaled) real time, replace
each other as on a real controller, report their errors, and the arm stops for a protective
stop at a joint limit or the floor."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.script_framing import ScriptFramer
from urdsl.sim.controller import DEFAULT_START, SimError, VirtualController, link_points
from urdsl.sim.state import ControllerVersion, ProgramState, RobotMode, SafetyMode

TARGET = [0.6, -1.4, 1.3, -1.5, -1.6, 0.2]


@pytest.fixture
def sim():
    with VirtualController(speed=4.0) as controller:
        yield controller


def move(q, a=3.0, v=2.0, name="p"):
    return f"def {name}():\n  movej({list(q)}, a={a}, v={v})\nend\n"


def near(q, target, tol=1e-6):
    return np.allclose(q, target, atol=tol)


def messages(sim, kind, timeout=5.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = [m for m in sim.messages if m.kind == kind]
        if found:
            return found
        time.sleep(0.02)
    return []


def test_a_program_moves_the_arm_through_intermediate_positions_to_its_target(sim):
    sim.submit(move(TARGET))
    seen = sim.wait_snapshot(lambda s: s.program_state == ProgramState.PLAYING
                             and 0.1 < s.q[0] < 0.5, 5)
    assert seen.qd[0] > 0  # moving towards the target
    done = sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED
                             and near(s.q, TARGET), 10)
    # between programs the arm rests where the last one left it
    later = sim.wait_snapshot(lambda s: s.time > done.time + 0.1, 5)
    assert near(later.q, TARGET) and np.allclose(later.qd, 0, atol=1e-12)


def test_snapshot_tcp_is_the_forward_kinematics_of_the_joints(sim):
    from urdsl.kinematics import pose

    snap = sim.snapshot()
    expected = pose.from_matrix(sim.kinematics.fk(np.array(snap.q)))
    assert np.allclose(snap.tcp[:3], expected[:3], atol=1e-12)
    assert snap.robot_mode == RobotMode.RUNNING and snap.safety_mode == SafetyMode.NORMAL


def test_a_new_def_program_replaces_the_running_one(sim):
    sim.submit(move([2.5, -1.57, 1.57, -1.57, -1.57, 0], a=0.5, v=0.3, name="slow"))
    sim.wait_snapshot(lambda s: s.q[0] > 0.05, 5)
    sim.submit(move(TARGET, name="fast"))
    done = sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED
                             and near(s.q, TARGET), 10)
    assert done.q[0] == pytest.approx(TARGET[0])
    assert sim.program_name == "fast"


def test_a_syntax_error_is_reported_with_line_and_column_and_leaves_the_program_running(sim):
    sim.submit("def p():\n  sleep(30)\nend\n")
    sim.wait_snapshot(lambda s: s.program_state == ProgramState.PLAYING, 5)
    sim.submit("def broken():\n  x = 1\n  movej([0, 0, 0, 0, 0, 0]))\nend\n")
    found = messages(sim, "runtime_exception")
    assert found and found[0].line == 3 and found[0].column == 28
    assert "<script>:3:28" in found[0].text
    assert sim.snapshot().program_state == ProgramState.PLAYING
    assert sim.program_name == "p"


def test_a_runtime_error_stops_the_program_and_names_its_line(sim):
    sim.submit("def p():\n  x = 1\n  y = x + undefined_name\nend\n")
    found = messages(sim, "runtime_exception")
    assert found[0].line == 3 and found[0].column == 11
    assert "undefined_name" in found[0].text
    sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED, 5)


def test_textmsg_becomes_a_text_message(sim):
    sim.submit('def p():\n  textmsg("value: ", 42)\nend\n')
    found = messages(sim, "text")
    assert found[0].text == "value: 42"


def test_bare_lines_run_as_a_one_off_program(sim):
    sim.submit(f"movej({TARGET}, a=3, v=2)\n")
    sim.wait_snapshot(lambda s: near(s.q, TARGET), 10)


def test_a_sec_program_runs_beside_the_main_program(sim):
    sim.submit("def main():\n  sleep(20)\nend\n")
    sim.wait_snapshot(lambda s: s.program_state == ProgramState.PLAYING, 5)
    sim.submit("sec helper():\n  write_output_integer_register(7, 1234)\nend\n")
    snap = sim.wait_snapshot(lambda s: s.output_int_registers[7] == 1234, 5)
    assert snap.program_state == ProgramState.PLAYING and sim.program_name == "main"


def test_a_sec_program_cannot_move_the_arm(sim):
    sim.submit(f"sec mover():\n  movej({TARGET})\nend\n")
    found = messages(sim, "runtime_exception")
    assert "sec program cannot move" in found[0].text
    assert near(sim.snapshot().q, DEFAULT_START)


def test_scripts_read_input_registers_and_write_outputs(sim):
    sim.env.input_int_registers[24] = 20
    sim.env.input_float_registers[25] = 0.5
    sim.submit("def p():\n  n = read_input_integer_register(24)\n"
               "  f = read_input_float_register(25)\n"
               "  write_output_float_register(3, n * f)\n  set_standard_digital_out(2, True)\n"
               "end\n")
    snap = sim.wait_snapshot(lambda s: s.output_float_registers[3] == 10.0, 5)
    assert snap.digital_outputs & 0b100


def test_stop_freezes_the_arm_where_it_is(sim):
    sim.submit(move([2.0, -1.57, 1.57, -1.57, -1.57, 0], a=1.0, v=0.5))
    sim.wait_snapshot(lambda s: s.q[0] > 0.2, 5)
    assert sim.stop_program()
    stopped = sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED, 5)
    time.sleep(0.1)
    assert 0.2 < sim.snapshot().q[0] < 2.0
    assert sim.snapshot().q[0] == pytest.approx(stopped.q[0], abs=1e-9)


def test_pause_holds_the_arm_and_play_resumes(sim):
    sim.submit(move([1.5, -1.57, 1.57, -1.57, -1.57, 0], a=1.0, v=0.5))
    sim.wait_snapshot(lambda s: s.q[0] > 0.2, 5)
    assert sim.pause_program()
    held = sim.wait_snapshot(lambda s: s.program_state == ProgramState.PAUSED, 2)
    time.sleep(0.2)
    assert sim.snapshot().q[0] == pytest.approx(held.q[0], abs=0.02)
    assert sim.snapshot().speed_scaling == 0.0
    assert sim.play()
    sim.wait_snapshot(lambda s: near(s.q, [1.5, -1.57, 1.57, -1.57, -1.57, 0]), 10)


def test_the_floor_causes_a_protective_stop():
    below = [0.0, 0.3, 0.0, -1.57, -1.57, 0.0]  # upper arm pointing down: the wrist at z < 0
    with VirtualController(speed=4.0) as sim:
        assert (link_points(sim.spec, np.array(below), None)[:, 2] < 0).any()
        sim.submit(move(below, a=2, v=1))
        snap = sim.wait_snapshot(lambda s: s.safety_mode == SafetyMode.PROTECTIVE_STOP, 10)
        assert snap.program_state == ProgramState.STOPPED or \
            sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED, 5)
        assert (link_points(sim.spec, np.array(snap.q), None)[:, 2] >= 0).all()
        assert "below the floor" in messages(sim, "safety")[0].text
        # no program runs during a protective stop
        sim.submit(move(TARGET))
        assert "not started" in messages(sim, "error")[0].text


def test_a_joint_limit_causes_a_protective_stop_and_unlock_waits_five_seconds():
    beyond = list(DEFAULT_START[:5]) + [6.6]  # wrist 3 beyond 2 pi
    with VirtualController(speed=20.0) as sim:
        sim.submit(move(beyond, a=40, v=30))
        snap = sim.wait_snapshot(lambda s: s.safety_mode == SafetyMode.PROTECTIVE_STOP, 10)
        assert snap.q[5] <= 2 * np.pi
        assert "wrist 3" in messages(sim, "safety")[0].text
        assert not sim.unlock_protective_stop()  # within 5 s of the stop
        # 5.5 s of controller time later (in wall time that depends on the machine's load:
        # the controller runs at most 20x as fast)
        sim.wait_snapshot(lambda s: s.time >= snap.time + 5.5, 10)
        assert sim.unlock_protective_stop()
        sim.submit(move(TARGET))
        sim.wait_snapshot(lambda s: near(s.q, TARGET), 10)


def test_power_off_refuses_programs_until_power_on_and_brake_release():
    with VirtualController(speed=10.0, powered=False) as sim:
        assert sim.snapshot().robot_mode == RobotMode.POWER_OFF
        sim.submit(move(TARGET))
        assert "POWER_OFF" in messages(sim, "error")[0].text
        sim.power_on()
        sim.wait_snapshot(lambda s: s.robot_mode == RobotMode.IDLE, 5)
        sim.brake_release()
        sim.wait_snapshot(lambda s: s.robot_mode == RobotMode.RUNNING, 5)
        sim.submit(move(TARGET))
        sim.wait_snapshot(lambda s: near(s.q, TARGET), 10)


def test_model_and_version_must_agree():
    with pytest.raises(SimError, match="CB3"):
        VirtualController(robot="ur5", version="5.15")
    with pytest.raises(SimError, match="unknown robot model"):
        VirtualController(robot="ur6")
    cb3 = VirtualController(robot="ur10")
    assert cb3.version == ControllerVersion(3, 15) and cb3.frequency == 125


def test_load_reads_only_urscript_inside_the_programs_folder(tmp_path):
    (tmp_path / "good.script").write_text(move(TARGET, name="good"))
    (tmp_path / "bad.script").write_text("def bad():\n  x = \nend\n")
    with VirtualController(speed=4.0, programs_dir=tmp_path) as sim:
        with pytest.raises(FileNotFoundError):
            sim.load_program("../etc/passwd")
        with pytest.raises(SimError, match="bad.script:3:1"):
            sim.load_program("bad.script")
        assert sim.load_program("good.script") == "good.script"
        assert sim.play()
        sim.wait_snapshot(lambda s: near(s.q, TARGET), 10)


# ---- framing ---------------------------------------------------------------------------------


def test_framer_cuts_def_sec_and_bare_lines():
    framer = ScriptFramer()
    chunks = framer.feed(b"textmsg(1)\ndef a():\n  x = 1\nend\nsec b():\n  y = 2\nend\n")
    assert [(c.kind, c.text.splitlines()[0]) for c in chunks] == [
        ("bare", "textmsg(1)"), ("def", "def a():"), ("sec", "sec b():")]
    assert not framer.pending


def test_framer_keeps_an_unfinished_block():
    framer = ScriptFramer()
    assert framer.feed(b"def a():\n  x = 1\n") == []
    assert framer.pending
    assert framer.feed(b"en")[:1] == []
    assert [c.kind for c in framer.feed(b"d\n")] == ["def"]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=40), min_size=1, max_size=20))
def test_framer_result_does_not_depend_on_how_tcp_splits_the_stream(cuts):
    stream = (b"def a():\n  movej([0,0,0,0,0,0])\nend\n"
              b"sec s():\n  x = 1\nend\ndef b():\n  if True:\n    y = 2\n  end\nend\n")
    framer = ScriptFramer()
    got, position = [], 0
    for cut in cuts:
        got += framer.feed(stream[position:position + cut])
        position += cut
    got += framer.feed(stream[position:])
    assert [(c.kind, c.text) for c in got] == [
        (c.kind, c.text) for c in ScriptFramer().feed(stream)]
    assert [c.kind for c in got] == ["def", "sec", "def"]


@settings(max_examples=60, deadline=None)
@given(st.binary(max_size=400))
def test_framer_never_crashes_on_random_bytes(data):
    framer = ScriptFramer(limit=300)
    try:
        for chunk in framer.feed(data):
            assert chunk.kind in ("def", "sec", "bare")
    except ProtocolError:
        pass


def test_models_resolve_as_every_command_resolves_them_and_versions_are_3_or_5():
    long = VirtualController(robot="UR8 Long")  # the one model resolver: any case, spaces
    assert long.robot_name == "ur8long" and long.version == ControllerVersion(5, 15)
    with pytest.raises(SimError, match="imitates CB3 software 3.x and e-Series software 5.x"):
        VirtualController(robot="ur5e", version="10.7")
