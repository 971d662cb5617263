"""Node variants whose PolyScope output was learned from programs saved beside their
``.script`` in public repositories outside the benchmark pairs (other commits and projects
of the local mirrors): an Until that waits for an expression, a feature used as a constant
in an expression, a Switch's Default Case saved with a value, Switch variables, a MoveP that
ends a subprogram. Fixtures are written here; the expected forms are PolyScope's."""

from __future__ import annotations

import pytest
from test_polyscope_variants import WAYPOINT, compiled

from urdsl.polyscope.compile import CompileError, compile_program


def test_until_expression_stops_the_direction_when_it_holds():
    # o2ac/o2ac-ur cable_extend_red_v2 (PolyScope 5.10): the condition is kept in
    # <ExpressionBranch>; PolyScope writes kill, stopl(deceleration), marker, break
    lines = compiled("""
        <Move motionType="MoveL" speed="0.01" acceleration="0.25" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <gui.program.direction.MoveDirectionNode selectedDirection="XMinus">
              <children>
                <Until type="EXPRESSION" allowActions="false" deceleration="0.25">
                  <ExpressionBranch>
                    <ExpressionToken token="pose_dist"/>
                    <ExpressionChar character="("/>
                    <ExpressionToken token="p0, get_actual_tcp_pose()"/>
                    <ExpressionChar character=")"/>
                    <ExpressionChar character=" "/>
                    <ExpressionChar character="≥"/>
                    <ExpressionChar character=" "/>
                    <ExpressionToken token="pull_len"/>
                  </ExpressionBranch>
                </Until>
              </children>
            </gui.program.direction.MoveDirectionNode>
          </children>
        </Move>""")
    assert after(lines, "move_thread_han_3 = run move_thread_3()", 7) == [
        "while (True):",
        "if (pose_dist(p0, get_actual_tcp_pose()) >= pull_len):",
        "kill move_thread_han_3",
        "stopl(0.25)",
        '$ 4 "Until (expression)"',
        "break",
        "end",
    ]
    assert not any(line.startswith("join ") for line in lines)


def after(lines: list[str], start: str, count: int) -> list[str]:
    """The ``count`` lines after the last line ``start``."""
    at = len(lines) - 1 - lines[::-1].index(start)
    return lines[at + 1:at + 1 + count]


def test_a_feature_as_a_constant_is_its_installation_pose():
    # loukjeab/WS2223... (PolyScope 5.8): "Base_var:=Base_1_const" is written
    # ``global Base_var=p[...]``, the installation's pose of the plane Base_1
    lines = compiled("""
        <Assignment valueSource="Expression">
          <variable name="frame"/>
          <expression>
            <ExpressionGeomFeature><feature referencedName="Cube"/></ExpressionGeomFeature>
          </expression>
        </Assignment>""")
    assert "global frame = p[-0.65, -0.29, 0.15, 1.19, 1.2, 1.23]" in lines
    assert '$ 2 "frame≔Cube_const"' in lines


def test_switch_default_case_saved_with_a_value_is_the_else_branch():
    # loukjeab/WS2223... (5.8) and Pugens/ursim (5.15) save the Default Case as
    # <Case caseValue="2147483647"> (Java's Integer.MAX_VALUE); PolyScope writes `else:`
    lines = compiled("""
        <Switch>
          <expression><ExpressionToken token="mode"/></expression>
          <children>
            <Case caseValue="1"><children>
              <Wait type="Sleep"><waitTime>0.1</waitTime></Wait></children></Case>
            <Case caseValue="2147483647"><children>
              <Wait type="Sleep"><waitTime>0.2</waitTime></Wait></children></Case>
          </children>
        </Switch>""")
    assert not any("2147483647" in line for line in lines)
    assert after(lines, "sleep(0.1)", 3) == ["else:", '$ 5 "Default Case"', '$ 6 "Wait: 0.2"']


def test_switch_variables_one_after_another_and_nested():
    # loukjeab/WS2223... (5.8): four Switch nodes one after another in the Robot Program are
    # all ``switch_1``; one inside a case of another needs its own variable [U]
    switch = """<Switch>
          <expression><ExpressionToken token="{value}"/></expression>
          <children><Case caseValue="1"><children>{inner}</children></Case></children>
        </Switch>"""
    inner = switch.format(value="c", inner='<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>')
    lines = compiled(switch.format(value="a", inner=inner) +
                     switch.format(value="b", inner=""))
    assert [line for line in lines if line.startswith("switch_")] == [
        "switch_1 = a", "switch_2 = c", "switch_1 = b"]
    assert "if (1 == switch_2):" in lines


def test_a_movep_that_ends_a_subprogram_keeps_its_blend():
    # loukjeab/WS2223... (5.8): three MoveP followed by a MoveL end with r=0, the MoveP that
    # is the last node of a subprogram keeps r=0.025
    movep = f"""<Move motionType="MoveP" speed="0.25" acceleration="1.2" blendRadius="0.025"
              useActiveTCP="true" positionType="CartesianPose">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>{WAYPOINT.format(name="{name}")}</children>
        </Move>"""
    movel = f"""<Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>{WAYPOINT.format(name="Down")}</children>
        </Move>"""
    body = f"""<CallSubProgram>
          <subprogram name="Place" keepHidden="false" keepSynchronizedWithDisk="false">
            <children>{movep.format(name="Above")}{movel}{movep.format(name="Away")}</children>
          </subprogram>
        </CallSubProgram>"""
    lines = compiled(body, others='<SubProgram reference="../MainProgram/children/'
                                  'CallSubProgram/subprogram"/>')
    assert "movep(Above_p, a=1.2, v=0.25, r=0.0)" in lines
    assert "movep(Away_p, a=1.2, v=0.25, r=0.025)" in lines


def test_polyscope3_conveyor_tracking_runs_its_children_while_tracking():
    # Usaakm/UR10-Conveyor-Belt (PolyScope 3.15): a Contributed node of Universal Robots
    # that PolyScope compiles itself, without a URCap block
    lines = compiled("""
        <Contributed strategyClass="ConveyorTracking" strategyProgramNodeType="Conveyor Tracking"
            strategyURCapDeveloper="Universal Robots" strategyURCapName="Conveyor Tracking">
          <dataModel/>
          <children>
            <Assignment valueSource="Expression">
              <variable name="here"/>
              <expression><ExpressionToken token="get_actual_tcp_pose()"/></expression>
            </Assignment>
          </children>
        </Contributed>""", version="3.15.4.106291")
    assert after(lines, '$ 1 "Robot Program"', 5) == [
        '$ 2 "Tracking Conveyor 1"',
        "start_conveyor_tracking0()",
        '$ 3 "here≔get_actual_tcp_pose()" "noBreak"',
        "global here = get_actual_tcp_pose()",
        "stop_conveyor_tracking()",
    ]
    assert not any("URCap" in line for line in lines)


RELATIVE = """
        <Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true">
          <children>
            <Waypoint type="Relative" name="Slide" kinematicsFlags="4">
              <motionParameters/>
              {start}
              {end}
            </Waypoint>
          </children>
        </Move>"""
POSITION = """<{tag}><JointAngles angles="{q}"/>
              <TCPOffset pose="0.0, 0.0, 0.2, 0.0, 0.0, 0.0"/></{tag}>"""


def test_relative_waypoint_moves_by_the_taught_difference():
    # CA-Giken MAIN (5.13): globals Slide_from_p and Slide_to_p, the motion from where the
    # arm is by their difference
    lines = compiled(RELATIVE.format(
        start=POSITION.format(tag="relativeFromPosition", q="0.0, -1.5, 1.5, -1.5, -1.5, 0.0"),
        end=POSITION.format(tag="position", q="0.1, -1.5, 1.5, -1.5, -1.5, 0.0")))
    assert any(line.startswith("global Slide_from_p = p[") for line in lines)
    assert any(line.startswith("global Slide_to_p = p[") for line in lines)
    assert "movel(pose_add(get_target_tcp_pose(), pose_sub(Slide_to_p, Slide_from_p)), " \
           "a=1.2, v=0.25)" in lines


def test_polyscope3_relative_waypoint_writes_its_poses_in_place():
    # PolyScope 3 writes no waypoint globals; a relative waypoint's two poses stand in the
    # motion as a fixed waypoint's pose does, from the forward kinematics (seen: 3.15.6
    # ati-ia/ft-urcap, 3.15.8 ic-sw1821/UR_RTDE_2)
    lines = compiled(RELATIVE.format(
        start='<relativeFromPosition joints="0, -1.5, 1.5, -1.5, -1.5, 0" '
              'pose="0.1, 0.2, 0.3, 0.0, 3.14, 0.0"/>',
        end='<position joints="0, -1.4, 1.5, -1.5, -1.5, 0" '
            'pose="0.1, 0.25, 0.3, 0.0, 3.14, 0.0"/>'),
        version="3.15.4.106291")
    assert not any("Slide_" in line for line in lines)
    assert "movel(pose_add(get_forward_kin(), pose_sub(p[0.1, 0.25, 0.3, 0.0, 3.14, 0.0], " \
           "p[0.1, 0.2, 0.3, 0.0, 3.14, 0.0])), a=1.2, v=0.25)" in lines


def test_a_wait_not_yet_set_writes_its_marker_only():
    # MuhammadUmarAnjum/PakBot (3.15): <Wait type="NoWait"/> is '$ 53 "Wait: 0"' alone
    lines = compiled('<Wait type="NoWait"/>', version="3.15.3.106223")
    assert after(lines, '$ 1 "Robot Program"', 2) == ['$ 2 "Wait: 0"', "end"]


def test_operator_assignment_as_polyscope_labels_and_writes_it():
    # Snupai/SZ (5.9): '$ 3 "Artikel≔'Artikelnummer eingeben'"', then
    # global Artikel=request_string_from_primary_client("Artikelnummer eingeben")
    lines = compiled("""<Assignment valueSource="Operator" message="Startlage eingeben"
          valueType="Integer"><variable name="Lage"/></Assignment>""")
    assert after(lines, '$ 1 "Robot Program"', 2) == [
        '$ 2 "Lage≔\'Startlage eingeben\'"',
        'global Lage = request_integer_from_primary_client("Startlage eingeben")']


def test_check_runs_a_conveyor_program_whose_functions_urdsl_cannot_write(tmp_path, capsys):
    # PolyScope 3's Conveyor Tracking calls start_conveyor_tracking0(), which the
    # installation's preamble defines; urdsl does not write it: the check takes it as a
    # device instead of stopping at a name it cannot find
    import json

    from test_polyscope_variants import program

    from urdsl.cli import main
    from urdsl.runtime.unknown import DEVICE_REPLY_TIME

    path = tmp_path / "conveyor.urp"
    path.write_text(program("""
        <Contributed strategyClass="ConveyorTracking" strategyProgramNodeType="Conveyor Tracking"
            strategyURCapDeveloper="Universal Robots" strategyURCapName="Conveyor Tracking">
          <dataModel/>
          <children><Wait type="Sleep"><waitTime>0.5</waitTime></Wait></children>
        </Contributed>""", version="3.15.4.106291"))
    assert main(["check", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not any(f["severity"] == "error" for f in report["findings"])
    assert "start_conveyor_tracking0" in report["context"]
    # the node and the stand-in each answer as a device, then the wait
    assert report["cycle_time"] == pytest.approx(2 * DEVICE_REPLY_TIME + 0.5, abs=0.01)


def test_assignment_of_two_calls_typed_together_is_written_as_polyscope_writes_it():
    # o2ac/o2ac-ur (5.9): "currentpose≔get_actual_tcp_pose()get_actual_joint_positions()" is
    # written ``global currentpose= get_actual_tcp_pose () get_actual_joint_positions ()``
    lines = compiled("""<Assignment valueSource="Expression"><variable name="here"/>
          <expression><ExpressionToken token="get_actual_tcp_pose"/>
          <ExpressionChar character="("/><ExpressionChar character=")"/>
          <ExpressionToken token="get_actual_joint_positions"/>
          <ExpressionChar character="("/><ExpressionChar character=")"/></expression>
        </Assignment>""")
    assert after(lines, '$ 1 "Robot Program"', 3) == [
        '$ 2 "here≔get_actual_tcp_pose()get_actual_joint_positions()"',
        "global here = get_actual_tcp_pose()", "get_actual_joint_positions()"]
    # what is not URScript at all is still one message naming the node
    with pytest.raises(CompileError, match="Robot Program > here"):
        compiled("""<Assignment valueSource="Expression"><variable name="here"/>
          <expression><ExpressionToken token="1 +"/></expression></Assignment>""")


def test_a_relative_start_on_kinematics_never_filled_in_uses_the_waypoints_own():
    # underautomation/UniversalRobots.NET "all instructions" (UR16e): the program's top-level
    # <kinematics> is status NOT_INITIALIZED with every value 0, and the relative waypoint's
    # start refers to it; its end carries the arm's kinematics. Both poses come from the
    # arm's: a start and end that differ in wrist 3 alone are at the same place.
    from test_polyscope_programs import KINEMATICS

    from urdsl.polyscope.urp import parse_urp

    zeros = ('<kinematics status="NOT_INITIALIZED" validChecksum="false">'
             + "".join(f'<{key} value="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>'
                       for key in ("deltaTheta", "a", "d", "alpha")) + "</kinematics>")
    arm = KINEMATICS.replace("<kinematics", "<Kinematics").replace("</kinematics>",
                                                                   "</Kinematics>")
    waypoint = RELATIVE.format(
        start='<relativeFromPosition><JointAngles angles="0.3, -1.5, 1.5, -1.5, -1.5, 0.0"/>'
              '<TCPOffset pose="0, 0, 0, 0, 0, 0"/>'
              '<Kinematics reference="../../../../../../../../kinematics"/>'
              '</relativeFromPosition>',
        end='<position><JointAngles angles="0.3, -1.5, 1.5, -1.5, -1.5, 0.3"/>'
            f'<TCPOffset pose="0, 0, 0, 0, 0, 0"/>{arm}</position>')
    text = (f'<URProgram name="t" installation="t" createdIn="5.11.1" lastSavedIn="5.11.1">'
            f'{zeros}<children><MainProgram runOnlyOnce="true"><children>{waypoint}'
            '</children></MainProgram></children></URProgram>')
    lines = compile_program(parse_urp(text.encode(), "t.urp")).text.splitlines()
    poses = {}
    for line in lines:
        for name in ("Slide_from_p", "Slide_to_p"):
            if line.strip().startswith(f"global {name} = p["):
                poses[name] = [float(v) for v in line.split("p[", 1)[1].rstrip("]").split(",")]
    assert set(poses) == {"Slide_from_p", "Slide_to_p"}
    assert max(abs(a - b) for a, b in zip(poses["Slide_from_p"][:3], poses["Slide_to_p"][:3],
                                          strict=True)) < 1e-9
    assert max(abs(v) for v in poses["Slide_from_p"][:3]) > 0.1  # a place of the arm
