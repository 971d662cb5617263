"""Node variants learned from programs saved beside their ``.script`` that the benchmark
pairs do not hold (nedlecky/UR programs outside the 30 pairs, PolyScope 5.9). Fixtures are
written here; the expected forms are PolyScope's."""

from __future__ import annotations

from test_polyscope_nodes2 import after
from test_polyscope_variants import WAYPOINT, compiled


def ignore_tcp_move(motion: str) -> str:
    return f"""
        <Move motionType="{motion}" speed="1.05" acceleration="1.4" useActiveTCP="false"
              positionType="CartesianPose">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            {WAYPOINT.format(name="Home")}
          </children>
        </Move>"""


def test_a_move_that_ignores_the_active_tcp_moves_the_flange_to_the_waypoint():
    # Safe_Home_BeforeStart, VisionCognex (5.9): "Ignore Active TCP" (useActiveTCP false,
    # no <tcp>): the waypoint is the flange's pose, the active TCP goes beyond it
    lines = compiled(ignore_tcp_move("MoveJ"))
    assert after(lines, '$ 3 "Home" "breakAfter"', 1) == [
        "movej(get_inverse_kin(pose_trans(Home_p, get_tcp_offset()), qnear=Home_q), "
        "a=1.4, v=1.05)"]
    assert not any(line.startswith("set_tcp") for line in lines[lines.index(
        '$ 3 "Home" "breakAfter"'):])


def test_a_linear_move_that_ignores_the_active_tcp_moves_the_flange_too():
    lines = compiled(ignore_tcp_move("MoveL"))
    assert after(lines, '$ 3 "Home" "breakAfter"', 1) == [
        "movel(pose_trans(Home_p, get_tcp_offset()), a=1.4, v=1.05)"]


def test_a_move_using_the_active_tcp_goes_to_the_waypoint_as_taught():
    lines = compiled(ignore_tcp_move("MoveJ").replace('useActiveTCP="false"',
                                                       'useActiveTCP="true"'))
    assert after(lines, '$ 3 "Home" "breakAfter"', 1) == [
        "movej(get_inverse_kin(Home_p, qnear=Home_q), a=1.4, v=1.05)"]


TOOL_CONTACT = """
        <Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <gui.program.direction.MoveDirectionNode selectedDirection="ZMinus"
                toolParams="0.01, 0.8">
              <children>
                <Until type="TOOL_CONTACT_DETECTION" allowActions="false"
                       retraction="0.0"{decel}/>
              </children>
            </gui.program.direction.MoveDirectionNode>
          </children>
        </Move>"""


def test_tool_contact_without_its_deceleration_stops_at_the_moves_acceleration():
    # L03_Touchoff (5.9): the Direction moves at toolParams' 0.8 m/s², the tool contact
    # (no decelerationAcceleration) stops and retracts at the MoveL's 1.2
    lines = compiled(TOOL_CONTACT.format(decel=""))
    assert "movel(towardsPos, a=0.8, v=0.01)" in lines
    assert after(lines, "kill move_thread_han_3", 1) == ["stopl(1.2)"]
    assert "movel(retractTo, a=1.2, v=0.1)" in lines


def test_tool_contact_with_its_deceleration_uses_it():
    # L06_extract_force, partmover03_touch (5.9): decelerationAcceleration is written
    lines = compiled(TOOL_CONTACT.format(decel=' decelerationAcceleration="1.0"'))
    assert after(lines, "kill move_thread_han_3", 1) == ["stopl(1.0)"]
    assert "movel(retractTo, a=1.0, v=0.1)" in lines


def test_polyscope3_movep_without_a_tcp_writes_the_pose_as_it_is():
    # Sander-ONeil Group21Lab1Task3 (3.5): no positionType, no <tcp>: the pose in place
    move = ignore_tcp_move("MoveP").replace(' positionType="CartesianPose"', "")
    lines = compiled(move, version="3.5.4.10845")
    moves = [line for line in lines if line.startswith("movep(")]
    assert len(moves) == 1 and "get_tcp_offset" not in moves[0]


OLD_NODES = """
        <Script type="File">
          <cachedContents>def hello():
  textmsg("hi")
end
</cachedContents>
          <file>/programs/hello.script</file>
        </Script>
        <Popup type="Error" haltProgram="false" message="Lost"/>"""


def test_polyscope_3_2_writes_no_marker_for_a_script_file_and_titles_popups_message():
    # KeyenceRobotVisionSample (3.2.20175): the file's code without its marker; an Error
    # popup titled "Message" with its error flag
    lines = compiled(OLD_NODES, version="3.2.20175")
    assert not any(line.startswith("$") and "Script" in line for line in lines)
    assert "def hello():" in lines
    assert 'popup("Lost", "Message", False, True, blocking=True)' in lines


def test_later_polyscope_marks_a_script_file_and_titles_an_error_popup_error():
    for version in ("3.15.4.106291", "5.11.5"):
        lines = compiled(OLD_NODES, version=version)
        assert any(line.startswith("$") and "Script: hello.script" in line for line in lines)
        assert 'popup("Lost", "Error", False, True, blocking=True)' in lines


TAUGHT_THEN_NAMED = """
        <Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            {waypoint}
          </children>
        </Move>
        <Assignment valueSource="Expression">
          <variable name="first_p_wp" prefersPersistentValue="false"/>
          <expression>
            <ExpressionWaypoint>
              <Waypoint referenceName="first_p" reference="../../../../Move/children/Waypoint"/>
            </ExpressionWaypoint>
          </expression>
        </Assignment>""".format(waypoint=WAYPOINT.format(name="first_p"))


def test_polyscope_3_writes_a_waypoint_in_an_expression_as_its_pose():
    # samho_main_Fillet (3.15.8): PolyScope 3 has no waypoint globals, so "first_p_wp≔first_p"
    # is written ``global first_p_wp=p[.431245807847, ...]``, not first_p_p (not defined)
    lines = compiled(TAUGHT_THEN_NAMED, version="3.15.8.106339")
    [assignment] = [line for line in lines if line.startswith("global first_p_wp")]
    assert assignment.startswith("global first_p_wp = p[")
    assert not any("first_p_p" in line for line in lines)
    # PolyScope 5 names the waypoint's global
    lines = compiled(TAUGHT_THEN_NAMED)
    assert "global first_p_wp = first_p_p" in lines
