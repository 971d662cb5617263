"""PolyScope behaviour learned from real program/script pairs, on small programs written
here: script files read as PolyScope reads them, waypoints in a variable feature, an empty
Force node, the installation a program names by relative path."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from urdsl.cli import main
from urdsl.polyscope.compile import compile_program, script_file_candidates
from urdsl.polyscope.installation import parse_installation
from urdsl.polyscope.urp import parse_urp
from urdsl.script import parse
from urdsl.script.printer import format as print_tree

KINEMATICS = """
  <kinematics status="LINEARIZED" validChecksum="true">
    <deltaTheta value="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
    <a value="0.0, -0.425, -0.3922, 0.0, 0.0, 0.0"/>
    <d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>
    <alpha value="1.5707963267948966, 0.0, 0.0, 1.5707963267948966, -1.5707963267948966, 0.0"/>
  </kinematics>"""


def program(body: str, *, name: str = "prog", directory: str = "/programs/cell",
            installation: str = "default", relative: str | None = None) -> bytes:
    """A PolyScope 5 program whose Robot Program holds ``body`` (XML)."""
    relative_attr = f' installationRelativePath="{relative}"' if relative else ""
    return (f'<URProgram name="{name}" installation="{installation}"{relative_attr} '
            f'directory="{directory}" createdIn="5.11.0" lastSavedIn="5.11.0">{KINEMATICS}'
            f'<children><MainProgram runOnlyOnce="true"><children>{body}</children>'
            f'</MainProgram></children></URProgram>').encode()


def lines_of(data: bytes, **options) -> list[str]:
    text = compile_program(parse_urp(data, "prog.urp"), **options).text
    assert print_tree(parse(text)) == text
    return [line.strip() for line in text.splitlines()]


SCRIPT_FILE = """<Script type="File">
  <cachedContents>def helper():
  return 1
end
</cachedContents>
  <file>/programs/cell/scripts/helper.script</file>
</Script>"""


def test_a_script_file_is_compiled_from_the_file_as_it_is_now():
    files = {"scripts/helper.script": b"def helper():\r\n  sync()\r\n  return 2\r\nend\r\n"}
    lines = lines_of(program(SCRIPT_FILE), files=files.get)
    assert lines[lines.index('$ 2 "Script: helper.script"') + 1:][:4] == [
        "def helper():", "sync()", "return 2", "end"]


def test_a_script_file_not_found_falls_back_to_the_copy_in_the_program():
    lines = lines_of(program(SCRIPT_FILE), files=lambda _path: None)
    assert "return 1" in lines and "return 2" not in lines
    assert "return 1" in lines_of(program(SCRIPT_FILE))  # no file reader at all


def test_script_files_are_looked_for_relative_to_the_saved_folder_then_by_their_tail():
    prog = parse_urp(program(SCRIPT_FILE, directory="/programs/cell/v2"), "p.urp")
    assert script_file_candidates(prog, "/programs/cell/scripts/helper.script") == [
        "../scripts/helper.script", "programs/cell/scripts/helper.script",
        "cell/scripts/helper.script", "scripts/helper.script", "helper.script"]
    # a copy laid out differently: the file beside the program
    lines = lines_of(program(SCRIPT_FILE, directory="/programs/cell/v2"),
                     files={"helper.script": b"def helper():\n  return 3\nend\n"}.get)
    assert "return 3" in lines


def test_the_compile_command_reads_script_files_beside_the_program(tmp_path, capsys):
    (tmp_path / "scripts").mkdir()
    (tmp_path / "scripts" / "helper.script").write_text("def helper():\n  return 7\nend\n")
    (tmp_path / "prog.urp").write_bytes(program(SCRIPT_FILE))
    assert main(["compile", str(tmp_path / "prog.urp")]) == 0
    assert "return 7" in capsys.readouterr().out


FEATURE_MOVE = """<Move motionType="{motion}" speed="1.0" acceleration="1.4" useActiveTCP="true"
      positionType="CartesianPose">
  <feature class="GeomFeatureReference" referencedName="{feature}"/>
  <children>
    <Waypoint type="Fixed" name="corner" kinematicsFlags="3">
      <motionParameters/>
      <position>
        <JointAngles angles="0.0, -1.5, 1.5, -1.5, -1.5, 0.0"/>
        <TCPOffset pose="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
      </position>
      <BaseToFeature pose="-0.5, -0.1, 0.07, 2.221441469079183, 2.221441469079183, 0.0"/>
    </Waypoint>
  </children>
</Move>"""


def _pose_numbers(text: str) -> list[float]:
    return [float(v) for v in text.split("p[", 1)[1].split("]", 1)[0].split(",")]


def test_a_waypoint_in_a_variable_feature_follows_the_feature():
    lines = lines_of(program(FEATURE_MOVE.format(motion="MoveJ", feature="table")))
    move = next(line for line in lines if line.startswith("movej("))
    assert move.startswith("movej(get_inverse_kin(pose_trans(table, pose_trans(p[")
    assert move.endswith(", corner_p)), qnear=corner_q), a=1.4, v=1.0)")
    # the literal is the inverse of the feature's pose when the waypoint was taught: a half
    # turn about (1, 1, 0) maps x to y, y to x and z to -z
    inverse = _pose_numbers(move)
    assert np.allclose(inverse[:3], [0.1, 0.5, 0.07], atol=1e-9)
    assert math.isclose(np.linalg.norm(inverse[3:]), math.pi, abs_tol=1e-9)
    linear = lines_of(program(FEATURE_MOVE.format(motion="MoveL", feature="table")))
    assert any(line.startswith("movel(pose_trans(table, pose_trans(p[") and
               line.endswith(", corner_p)), a=1.4, v=1.0)") for line in linear)


INSTALLATION = """<Installation name="default"><Features>
  <GeomPlaneNode name="table" isVariable="{variable}"/>
</Features></Installation>"""


def test_a_waypoint_in_a_fixed_feature_or_the_base_is_written_as_taught():
    fixed = parse_installation(INSTALLATION.format(variable="false").encode(), "d")
    lines = lines_of(program(FEATURE_MOVE.format(motion="MoveL", feature="table")),
                     installation=fixed)
    assert "movel(corner_p, a=1.4, v=1.0)" in lines
    base = lines_of(program(FEATURE_MOVE.format(motion="MoveL", feature="Joint_0_name")))
    assert "movel(corner_p, a=1.4, v=1.0)" in base
    variable = parse_installation(INSTALLATION.format(variable="true").encode(), "d")
    lines = lines_of(program(FEATURE_MOVE.format(motion="MoveL", feature="table")),
                     installation=variable)
    assert any(line.startswith("movel(pose_trans(table, ") for line in lines)


def test_a_force_node_with_an_empty_body_writes_nothing():
    force = """<Force type="Frame">
      <feature referencedName="Joint_6_name"/>
      <selection value="0, 0, 1, 0, 0, 0"/>
      <wrench value="0.0, 0.0, 3.0, 0.0, 0.0, 0.0"/>
      <limitsForce value="0.1, 0.1, 0.1, 1.0, 1.0, 1.0"/>
      <limitsMotion value="0.1, 0.1, 0.1, 0.3, 0.3, 0.3"/>
      <children><Placeholder/></children>
    </Force>"""
    lines = lines_of(program(force))
    assert not any("force_mode" in line or "zero_ftsensor" in line for line in lines)
    assert lines_of(program(force.replace("<Placeholder/>", '<Wait type="Sleep">'
                                          "<waitTime>1.0</waitTime></Wait>")))[-5:-1] == [
        '$ 3 "Wait: 1.0" "noBreak"', "sleep(1.0)", "end_force_mode()", "stopl(5.0)"]


def test_the_installation_named_by_relative_path_is_read(tmp_path: Path, capsys):
    (tmp_path / "sub").mkdir()
    (tmp_path / "shared.installation").write_text(
        '<Installation name="shared"><IOs><DigitalOutputNames value="lamp,,,,,,,"/></IOs>'
        "</Installation>")
    (tmp_path / "sub" / "prog.urp").write_bytes(program(
        '<Set type="DigitalOutput"><pin referencedName="lamp"/><digitalValue>1</digitalValue>'
        "</Set>", installation="shared", relative="../shared"))
    assert main(["compile", str(tmp_path / "sub" / "prog.urp")]) == 0
    assert "set_standard_digital_out(0, True)" in capsys.readouterr().out


def _folder_with_programs(tmp_path: Path) -> Path:
    cell = tmp_path / "cell"
    cell.mkdir()
    (cell / "pick.urp").write_bytes(program('<Wait type="Sleep"><waitTime>0.1</waitTime>'
                                            "</Wait>", name="pick"))
    (cell / "pick.script").write_text("def pick():\n  sleep(0.1)\nend\n")  # PolyScope's
    (cell / "tool.script").write_text("def tool():\n  sleep(0.2)\nend\n")
    return cell


def test_lint_of_a_folder_takes_polyscopes_script_for_a_urp_beside_it(tmp_path, capsys):
    cell = _folder_with_programs(tmp_path)
    assert main(["lint", "--format", "json", str(cell)]) == 0
    captured = capsys.readouterr()
    assert "Found" not in captured.out
    # the .script PolyScope generated holds what the URCaps add: it is what the robot ran
    assert f"note: {cell / 'pick.urp'} skipped: pick.script beside it is what PolyScope " \
           "generated from it" in captured.err
    assert "name pick.urp to lint its program tree" in captured.err
    assert "tool.script" not in captured.err
    # a .urp without its .script is linted: a program PolyScope could not run is an error
    # (an I/O its installation does not name); an empty .script beside it is no export
    (cell / "pick.script").write_text("")
    (cell / "default.installation").write_bytes(
        (Path(__file__).parent / "data" / "polyscope" / "cell.installation").read_bytes())
    (cell / "pick.urp").write_bytes(program('<Set type="DigitalOutput"><pin '
                                            'referencedName="nowhere"/></Set>', name="pick"))
    assert main(["lint", str(cell)]) == 1
    out = capsys.readouterr().out
    assert "pick.urp:1:1: URS001" in out and "'nowhere' is not named" in out


def test_check_of_a_folder_checks_each_program_once(tmp_path, capsys):
    cell = _folder_with_programs(tmp_path)
    main(["check", "--json", str(cell)])
    captured = capsys.readouterr()
    assert "pick.urp skipped" in captured.err
    import json
    names = [Path(document["file"]).name for document in json.loads(captured.out)]
    assert sorted(names) == ["pick.script", "tool.script"]
    # named on the command line, the .urp is checked itself
    main(["check", "--json", str(cell / "pick.urp")])
    assert Path(json.loads(capsys.readouterr().out)["file"]).name == "pick.urp (compiled)"


WAYPOINT_UNTIL = """<Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true"
      positionType="CartesianPose">
  <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
  <children>
    <Waypoint type="Fixed" name="Press" kinematicsFlags="3">
      <motionParameters/>
      <position>
        <JointAngles angles="0.0, -1.5, 1.5, -1.5, -1.5, 0.0"/>
        <TCPOffset pose="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
      </position>
      <children>
        {untils}
      </children>
    </Waypoint>
  </children>
</Move>"""

REACHED = '<Until type="REACHED_WAYPOINT"/>'
EXPRESSION = """<Until type="EXPRESSION" deceleration="2.5">
  <expression><ExpressionToken token="get_standard_digital_in"/>
    <ExpressionChar character="("/><ExpressionChar character="2"/>
    <ExpressionChar character=")"/></expression>
  <children><Popup type="Message" haltProgram="false" message="pressed"
    inputType="Text"/></children>
</Until>"""


def test_a_waypoint_with_until_moves_in_a_thread_until_it_is_reached():
    # as PolyScope 5 writes a waypoint with "Until (reached_waypoint)"
    lines = lines_of(program(WAYPOINT_UNTIL.format(untils=REACHED)))
    at = lines.index('$ 3 "Press" "breakAfter"')
    assert lines[at + 1:at + 21] == [
        "global move_thread_flag_3 = 0", "thread move_thread_3():", "enter_critical",
        "move_thread_flag_3 = 1", "movel(Press_p, a=1.2, v=0.25)", "move_thread_flag_3 = 2",
        "exit_critical", "end", "move_thread_flag_3 = 0",
        "move_thread_han_3 = run move_thread_3()", "while (True):", "sleep(1e-10)",
        "if (move_thread_flag_3 > 1):", "join move_thread_han_3",
        '$ 4 "Until (reached_waypoint)"', "break", "end", "sync()", "end", "end"]


def test_an_until_condition_stops_the_move_when_it_holds():
    lines = lines_of(program(WAYPOINT_UNTIL.format(untils=EXPRESSION + REACHED)))
    loop = lines.index("move_thread_han_3 = run move_thread_3()") + 1
    assert lines[loop + 1:loop + 8] == [
        "if (get_standard_digital_in(2)):", "kill move_thread_han_3", "stopl(2.5)",
        '$ 4 "Until (expression)"', '$ 5 "Popup: pressed"',
        'popup("pressed", "Message", False, False, blocking=True)', "break"]
    # then the end of the move, then the next cycle
    assert '$ 6 "Until (reached_waypoint)"' in lines
    assert not any("not compiled" in line for line in lines)


def test_a_direction_until_a_condition():
    direction = f"""<gui.program.direction.MoveDirectionNode selectedDirection="ZMinus"
        toolParams="0.05, 1.0">
      <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
      <children>{EXPRESSION}</children>
    </gui.program.direction.MoveDirectionNode>"""
    move = WAYPOINT_UNTIL.format(untils="").replace(
        "</Waypoint>", f"</Waypoint>{direction}")
    lines = lines_of(program(move))
    # no distance: the move heads 1000 m away and the condition ends it
    assert "local towardsPos = calculate_point_to_move_towards(p[0.0, 0.0, 0.0, 0.0, 0.0, " \
           "0.0], [0.0, 0.0, -1.0], 1000.0)" in lines
    assert "movel(towardsPos, a=1.0, v=0.05)" in lines
    at = lines.index("if (get_standard_digital_in(2)):")
    assert lines[at + 1:at + 4] == ["kill move_thread_han_4", "stopl(2.5)",
                                    '$ 5 "Until (expression)"']


def test_a_process_move_blends_into_itself_when_the_program_loops():
    move = """<Move motionType="MoveP" speed="0.25" acceleration="1.2" blendRadius="0.025"
        useActiveTCP="true" positionType="CartesianPose">
      <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
      <children>
        <Waypoint type="Variable" name="Waypoint" kinematicsFlags="-1">
          <variable name="a"/></Waypoint>
        <Waypoint type="Variable" name="Waypoint" kinematicsFlags="-1">
          <variable name="b"/></Waypoint>
      </children>
    </Move>"""
    once = lines_of(program(move))
    # nothing follows the end of a program run once: PolyScope keeps the blend (o2ac/o2ac-ur
    # taskboard_pick_hook, 5.7: a MoveP ending a Force that ends the program; see
    # test_polyscope_nodes6.py)
    assert "movep(b, a=1.2, v=0.25, r=0.025)" in once
    looping = lines_of(program(move).replace(b'runOnlyOnce="true"', b'runOnlyOnce="false"'))
    assert "movep(b, a=1.2, v=0.25, r=0.025)" in looping  # the next motion is its first


def test_a_variable_waypoint_is_the_variable_in_the_moves_feature():
    move = """<Move motionType="MoveL" speed="0.64" acceleration="0.32" useActiveTCP="true"
        positionType="CartesianPose">
      <feature class="GeomFeatureReference" referencedName="{feature}"/>
      <children><Waypoint type="Variable" name="Waypoint" kinematicsFlags="-1">
        <variable name="pick_pose"/></Waypoint></children>
    </Move>"""
    lines = lines_of(program(move.format(feature="pallet")))
    assert lines[-3:-1] == ['$ 3 "pick_pose" "breakAfter"',
                            "movel(pose_trans(pallet, pick_pose), a=0.32, v=0.64)"]
    assert "movel(pick_pose, a=0.32, v=0.64)" in lines_of(program(move.format(
        feature="Joint_0_name")))


def test_inside_force_mode_every_marker_is_no_break():
    # as a PolyScope 5 script shows a Force around a MoveL whose waypoint has an Until
    force = f"""<Force type="Frame">
      <feature referencedName="Joint_6_name"/>
      <selection value="1, 0, 0, 0, 0, 0"/>
      <wrench value="-50.0, 50.0, 0.0, 0.0, 0.0, 0.0"/>
      <limitsForce value="0.15, 0.1, 0.1, 0.35, 0.35, 0.35"/>
      <limitsMotion value="0.1, 0.1, 0.1, 0.35, 0.35, 0.35"/>
      <children>{WAYPOINT_UNTIL.format(untils=REACHED)}</children>
    </Force>"""
    lines = lines_of(program(force))
    markers = [line for line in lines if line.startswith("$ ") and int(line.split()[1]) > 2]
    assert markers == ['$ 3 "MoveL" "noBreak"', '$ 4 "Press" "noBreak"',
                       '$ 5 "Until (reached_waypoint)" "noBreak"']
    assert lines[-4:-1] == ["end", "end_force_mode()", "stopl(5.0)"]
