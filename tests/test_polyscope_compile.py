"""Compiling PolyScope programs to URScript as PolyScope does: markers and their numbering,
waypoint globals, each node's statements, URCap blocks, the compile and show commands."""

from __future__ import annotations

import gzip
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.cli import main
from urdsl.polyscope.compile import (
    CompileError,
    _matrix_to_rotvec,
    _rotvec_to_matrix,
    compile_program,
    waypoint_pose,
)
from urdsl.polyscope.installation import read_installation
from urdsl.polyscope.urp import Kinematics, read_urp
from urdsl.script import parse
from urdsl.script.printer import format as print_tree

DATA = Path(__file__).parent / "data" / "polyscope"
CELL = DATA / "cell.urp"
UR5E = Kinematics((0.0,) * 6, (0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
                  (0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996),
                  (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0))


@pytest.fixture(scope="module")
def compiled():
    program = read_urp(CELL)
    return compile_program(program, read_installation(DATA / "cell.installation"))


@pytest.fixture(scope="module")
def lines(compiled):
    return [line.strip() for line in compiled.text.splitlines()]


def test_the_text_is_the_printers_and_reads_back(compiled):
    text = compiled.text
    assert text.startswith("def celltest1():\n")  # the name without . and space
    assert print_tree(parse(text)) == text
    assert compile_program(read_urp(CELL), read_installation(DATA / "cell.installation")
                           ).text == text  # generated ids are the same every time


def test_the_step_counter_thread_of_polyscope_5(lines):
    assert lines[1].startswith("step_count_") and lines[1].endswith(" = 0.0")
    assert lines[2].startswith("thread Step_Counter_Thread_")
    assert lines[8].startswith("run Step_Counter_Thread_")


def test_markers_are_numbered_in_program_order_with_flags(lines):
    markers = [line for line in lines if line.startswith("$ ")]
    assert markers[:4] == ['$ 33 "Home" "noBreak"', '$ 34 "count≔count+1"',
                           '$ 2 "BeforeStart"', '$ 3 "count≔0"']
    assert '$ 5 "Robot Program"' in markers  # 1 is the variables setup: no marker
    assert '$ 7 "Waypoint_1" "breakAfter"' in markers
    assert '$ 17 "Halt"' in markers
    assert '$ 18 "Else" "noBreak"' in markers
    assert '$ 31 "Thread_1"' in markers
    # the suppressed Wait (23) writes nothing but keeps its number
    assert not any(m.startswith("$ 23 ") for m in markers)
    assert '$ 24 "Call Home"' in markers


def test_waypoint_globals_are_calibrated_forward_kinematics(lines):
    tree = parse("\n".join(line for line in lines if line.startswith("global Waypoint_")))
    names = [item.name for item in tree.body]
    assert names == ["Waypoint_1_p", "Waypoint_1_q", "Waypoint_2_p", "Waypoint_2_q"]
    pose = [float(print_tree(v)) for v in tree.body[0].value.items]
    # UR5e at zero joints: x = a2 + a3, y = -(d4 + d6), z = d1 - d5, flange turned about x
    assert pose == pytest.approx([-0.8172, -0.2329, 0.0628, math.pi / 2, 0, 0], abs=1e-12)


def test_the_tcp_offset_is_applied_to_the_pose():
    q = (0.1, -1.2, 1.1, -1.4, -1.6, 0.2)
    flange = waypoint_pose(q, (0,) * 6, UR5E)
    tool = waypoint_pose(q, (0, 0, 0.1, 0, 0, 0), UR5E)
    z_axis = _rotvec_to_matrix(flange[3:])[:, 2]
    assert np.allclose(np.subtract(tool[:3], flange[:3]), 0.1 * z_axis, atol=1e-12)
    assert np.allclose(tool[3:], flange[3:], atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
       st.floats(0.0, math.pi))
def test_rotation_vectors_round_trip(axis, angle):
    axis = np.array(axis)
    if np.linalg.norm(axis) < 1e-3:
        axis = np.array([0.0, 0.0, 1.0])
    rv = axis / np.linalg.norm(axis) * angle
    back = _matrix_to_rotvec(_rotvec_to_matrix(rv))
    # near a half turn the angle comes from the acos of the trace, as PolyScope computes it,
    # which keeps about 8 digits (axis [0, 1, 0.5] at exactly pi: 2e-8 off)
    tolerance = 1e-7 if math.pi - angle < 1e-6 else 1e-9
    assert np.allclose(_rotvec_to_matrix(back), _rotvec_to_matrix(rv), atol=tolerance)
    assert np.linalg.norm(back) <= math.pi + 1e-12


def test_moves_use_shared_and_per_waypoint_parameters(lines):
    assert "movej(get_inverse_kin(Waypoint_1_p, qnear=Waypoint_1_q), " \
           "a=1.3962634015954636, v=1.0471975511965976)" in lines
    assert "movej(get_inverse_kin(Waypoint_2_p, qnear=Waypoint_2_q), t=2.5)" in lines
    assert "movel(count, a=1.2, v=0.25, r=0.01)" in lines  # a variable waypoint


def test_loops_ifs_waits_and_sets(lines):
    at = lines.index('$ 11 "Loop 3 times"')
    assert lines[at + 1:at + 3] == ["Loop_1 = 0", "while (Loop_1 < 3):"]
    assert "Loop_1 = Loop_1 + 1" in lines
    assert "set_standard_digital_out(2, True)" in lines  # 'gripper' named in the installation
    assert "sleep(0.5)" in lines
    assert "if (count == 1):" in lines
    at = lines.index('$ 16 "ElseIf part_present"')
    assert lines[at - 1] == "else:" and lines[at + 1] == "if (get_standard_digital_in(3)):"
    at = lines.index('$ 20 "Wait part_present=HI"')
    assert lines[at + 1:at + 3] == ["while (get_standard_digital_in(3) == False):", "sync()"]


def test_assignment_script_popup_halt_call(lines):
    assert "global count = 0" in lines
    assert 'textmsg("hi")' in lines
    assert 'popup("one", "Warning", True, False, blocking=True)' in lines
    assert "halt" in lines
    assert "Home()" in lines and "def Home():" in lines


def test_switch_timer_thread(lines):
    assert "switch_1 = count" in lines
    assert "if (1 == switch_1):" in lines and "elif (2 == switch_1):" in lines
    assert "global cycle_is_counting = False" in lines
    assert "cycle_is_counting = True" in lines and "cycle = 0" in lines
    assert "run Timer_Thread()" in lines
    assert "threadId_Thread_1 = run Thread_1()" in lines


def test_urcap_and_unknown_nodes_are_marked_not_dropped(lines):
    at = lines.index("# begin: URCap Program Node")
    assert lines[at + 1:at + 5] == ["#   Source: Example_Gripper, Example Inc.",
                                    "#   Type: Grip", '$ 4 "Grip"',
                                    "# end: URCap Program Node"]
    assert "# urdsl: PolyScope node <FancyNewNode> is not compiled" in lines


def test_an_unnamed_io_is_an_error_naming_the_node():
    import dataclasses

    from urdsl.polyscope.installation import read_installation

    # an installation that does not name 'gripper'
    installation = dataclasses.replace(read_installation(DATA / "cell.installation"),
                                       io_names=())
    with pytest.raises(CompileError) as error:
        compile_program(read_urp(CELL), installation)
    assert "Robot Program > Loop > Set" in str(error.value)
    assert "'gripper' is not named in the installation" in str(error.value)
    # without the installation that would name it, the name is what it is
    assert compile_program(read_urp(CELL)).unknown == {"gripper": "an I/O",
                                                       "part_present": "an I/O"}


# ---- the commands --------------------------------------------------------------------------


def test_compile_command_writes_the_script(tmp_path, capsys, compiled):
    for name in ("cell.urp", "cell.installation"):
        shutil.copy(DATA / name, tmp_path / name)
    out = tmp_path / "cell.script"
    assert main(["compile", str(tmp_path / "cell.urp"), "-o", str(out)]) == 0
    assert out.read_text() == compiled.text
    (tmp_path / "cell.urp").write_bytes(gzip.compress((DATA / "cell.urp").read_bytes()))
    assert main(["compile", str(tmp_path / "cell.urp")]) == 0
    assert capsys.readouterr().out == compiled.text


def test_compile_command_on_a_broken_program(tmp_path, capsys):
    bad = tmp_path / "bad.urp"
    bad.write_bytes(gzip.compress(b"<URProgram><children>")[:-4])
    assert main(["compile", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"{bad}: error: ") and "Traceback" not in err


def test_compile_command_names_what_it_accepts(tmp_path, capsys):
    other = tmp_path / "notes.txt"
    other.write_text("hello")
    assert main(["compile", str(other)]) == 2
    err = capsys.readouterr().err
    assert ".py" in err and ".urp" in err


def test_show_command_prints_the_tree_with_numbers(tmp_path, capsys):
    for name in ("cell.urp", "cell.installation"):
        shutil.copy(DATA / name, tmp_path / name)
    assert main(["show", str(tmp_path / "cell.urp")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("Program cell test.1")
    assert "  11   Loop 3 times" in out
    assert "  23     Wait  (suppressed)" in out or any(
        line.startswith("  23") and "(suppressed)" in line for line in out)
    assert any("Grip  [URCap Example_Gripper]" in line for line in out)


def test_the_preamble_from_the_installation(lines):
    start = lines.index("set_safety_mode_transition_hardness(1)")
    end = lines.index("set_tcp(p[0.0, 0.0, 0.1, 0.0, 0.0, 0.0])")
    assert lines[start + 1:end] == [
        "set_tool_communication(True, 115200, 0, 1, 1.5, 3.5)",
        "set_tool_output_mode(0)",
        "set_tool_digital_output_mode(0, 1)",
        "set_tool_digital_output_mode(1, 2)",
        "set_tool_voltage(24)",
        "set_gravity([0.0, 0.0, 9.82])",
        "set_standard_analog_input_domain(0, 1)",
        "set_standard_analog_input_domain(1, 0)",
        "set_tool_analog_input_domain(0, 1)",
        "set_tool_analog_input_domain(1, 1)",
        "set_analog_outputdomain(0, 0)",
        "set_analog_outputdomain(1, 1)",
        "set_input_actions_to_default()",
        'set_tool_digital_input_action(0, "freedrive")',
        "set_target_payload(1.25, [0.002, 0.001, 0.051], "
        "[0.002233, 0.002233, 0.002233, 0.0, 0.0, 0.0])",
    ]
    assert end < lines.index("global Waypoint_1_p = p[-0.8171999999999999, -0.2329, "
                             "0.06280000000000001, 1.5707963267948966, 0.0, 0.0]")


def test_installation_variables_and_point_features_follow_the_settings():
    from urdsl.polyscope.compile import parse_variables
    from urdsl.polyscope.installation import parse_installation

    installation = parse_installation(
        b'<Installation><Features><GeomPoseNode><GeomPoseNode name="Pick" isVariable="true">'
        b'<toolPosition value="0.1, 0.2, 0.3"/><toolAxisAngle value="0.0, 3.14, 0.0"/>'
        b'</GeomPoseNode></GeomPoseNode><GeomPoseNode><GeomPoseNode name="Above">'
        b'<toolPosition value="0.1, 0.2, 0.5"/><toolAxisAngle value="0.0, 3.14, 0.0"/>'
        b'</GeomPoseNode></GeomPoseNode></Features></Installation>', "cell.installation")
    variables = parse_variables(gzip.compress(b"#saved\ncount=3\nhome=p[0, 0, 0.1, 0, 0, 0]\n"))
    assert variables == [("count", "3"), ("home", "p[0, 0, 0.1, 0, 0, 0]")]
    assert parse_variables(b'<InstallationVariables><variable name="n" value="2"/>'
                           b'</InstallationVariables>') == [("n", "2")]
    text = compile_program(read_urp(DATA / "moves.urp"), installation, variables).text
    lines = [line.strip() for line in text.splitlines()]
    at = lines.index("global count = 3")
    assert lines[at + 1:at + 4] == ["global home = p[0, 0, 0.1, 0, 0, 0]",
                                    "global Above = p[0.1, 0.2, 0.5, 0.0, 3.14, 0.0]",
                                    "global Pick = p[0.1, 0.2, 0.3, 0.0, 3.14, 0.0]"]


def test_show_lines_puts_each_nodes_script_under_it(tmp_path, capsys):
    for name in ("cell.urp", "cell.installation"):
        shutil.copy(DATA / name, tmp_path / name)
    assert main(["show", "--lines", str(tmp_path / "cell.urp")]) == 0
    out = capsys.readouterr().out.splitlines()
    at = out.index("  13     Set gripper=On")
    assert out[at + 1].strip() == "| set_standard_digital_out(2, True)"


def test_operator_assignment_and_an_undefined_expression():
    from urdsl.polyscope.urp import parse_urp

    def program(assignment: str) -> bytes:
        return (b'<URProgram name="p" lastSavedIn="5.9.1"><children><MainProgram '
                b'runOnlyOnce="true"><children>' + assignment.encode() +
                b'</children></MainProgram></children></URProgram>')

    text = compile_program(parse_urp(program(
        '<Assignment valueSource="Operator" message="Part number?" valueType="String">'
        '<variable name="part"/></Assignment>'), "p.urp")).text
    assert 'global part = request_string_from_primary_client("Part number?")' in text
    with pytest.raises(CompileError) as error:
        compile_program(parse_urp(program(
            '<Assignment valueSource="Expression"><variable name="x"/><expression/>'
            '</Assignment>'), "p.urp"))
    assert str(error.value).startswith("p.urp: error: node Robot Program > x: the node has "
                                       "no expression")


def test_safe_home_with_a_stand_in_installation_is_unknown():
    # the program names cell.installation; another one found beside it stands in and has no
    # safe home: the position is the missing one's (unknown), not an error of the program
    from urdsl.polyscope.compile import SAFE_HOME
    from urdsl.polyscope.installation import parse_installation
    from urdsl.polyscope.urp import parse_urp

    program = parse_urp(
        b'<URProgram name="p" lastSavedIn="5.11.1" installation="cell"><children>'
        b'<MainProgram runOnlyOnce="true"><children><Move motionType="MoveJ" speed="1.0" '
        b'acceleration="1.4"><children><SafeHome positionOptionType="SPEED_AND_ACCELERATION" '
        b'speed="1.05" acceleration="1.4"/></children></Move></children></MainProgram>'
        b'</children></URProgram>', "p.urp")
    stand_in = parse_installation(b"<Installation/>", "default.installation")
    assert compile_program(program, stand_in).unknown == {SAFE_HOME: "the safe home position"}
    with pytest.raises(CompileError, match="safe home position is unknown"):
        compile_program(program, parse_installation(b"<Installation/>", "cell.installation"))


def test_safe_home_moves_to_the_installations_position():
    from urdsl.polyscope.installation import parse_installation
    from urdsl.polyscope.urp import parse_urp

    program = parse_urp(
        b'<URProgram name="p" lastSavedIn="5.11.1"><children><MainProgram runOnlyOnce="true">'
        b'<children><Move motionType="MoveJ" speed="1.0" acceleration="1.4"><children>'
        b'<SafeHome positionOptionType="SPEED_AND_ACCELERATION" speed="1.05" '
        b'acceleration="1.4" nextMotionTime="2.0"/></children></Move></children>'
        b'</MainProgram></children></URProgram>', "p.urp")
    installation = parse_installation(
        b'<Installation><SafeHomeSettings enabled="true" position="0.1, -1.5, 1.5, -1.5, '
        b'-1.5, 0.0"/></Installation>', "i")
    text = compile_program(program, installation).text
    assert "movej([0.1, -1.5, 1.5, -1.5, -1.5, 0.0], a=1.4, v=1.05)" in text
    with pytest.raises(CompileError, match="safe home position is unknown"):
        compile_program(program, parse_installation(b"<Installation/>", "i"))


