"""Node variants PolyScope writes that the census (bench/polyscope_census.py) found beyond the
tune pairs: a move with its own TCP, a Set node that selects a TCP, analog outputs, Modbus
signals as I/O, Event nodes, Direction in a variable feature, Until blends, tool contact
without retraction and PolyScope 3 variable waypoints. Fixtures are written here (plain
XML, as read_urp accepts it); the expected forms are those of real PolyScope scripts."""

from __future__ import annotations

import gzip

import pytest
from test_polyscope_programs import KINEMATICS  # the same UR5e arm

from urdsl.polyscope.compile import CompileError, compile_program
from urdsl.polyscope.installation import parse_installation
from urdsl.polyscope.urp import parse_urp
from urdsl.script import parse
from urdsl.script.printer import format as print_tree

INSTALLATION = """<Installation name="cell">
  <IOs>
    <analogOutputDomain value="1, 0"/>
    <GeneralPurposeBooleanRegisterOutputNames value="DONE, , "/>
    <GeneralPurposeIntRegisterInputNames value=", PRG_NO"/>
    <ModbusUnits>
      <Unit ipAddress="192.168.1.18" sequentialMode="false">
        <ModbusSignal name="RUN" type="DIGITAL_INPUT" signalAddress="3" slaveAddress="255"/>
        <ModbusSignal name="BRUSH" type="DIGITAL_OUTPUT" signalAddress="4" slaveAddress="255"/>
      </Unit>
    </ModbusUnits>
  </IOs>
  <TCPSettings activePose="Flange">
    <tcp name="Flange" offset="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
    <tcp name="Sander" offset="0.003, 0.11, 0.098, -0.785, 0.0, 0.0"/>
  </TCPSettings>
  <PayloadSettings>
    <Payload name="Gripper" mass="1.0" defaultPayload="true" centerOfGravity="0.0, 0.0, 0.05"
             inertiaParameters="0.001, 0.001, 0.001, 0.0, 0.0, 0.0"/>
    <Payload name="Part" mass="3.02" defaultPayload="false" centerOfGravity="0.012, 0.022, 0.058"
             inertiaParameters="0.009713, 0.009713, 0.009713, 0.0, 0.0, 0.0"/>
  </PayloadSettings>
  <Features>
    <wrapper>
      <GeomPoseNode name="Cube" isVariable="true">
        <toolPosition value="-0.65, -0.29, 0.15"/>
        <toolAxisAngle value="1.19, 1.2, 1.23"/>
      </GeomPoseNode>
    </wrapper>
  </Features>
</Installation>"""

WAYPOINT = """<Waypoint type="Fixed" name="{name}" kinematicsFlags="3">
              <motionParameters/>
              <position>
                <JointAngles angles="0.0, -1.5, 1.5, -1.5, -1.5, 0.0"/>
                <TCPOffset pose="0.0, 0.0, 0.2, 0.0, 0.0, 0.0"/>
              </position>
            </Waypoint>"""


def program(body: str, others: str = "", version: str = "5.11.5") -> str:
    return f"""<URProgram name="variants" installation="cell" createdIn="{version}"
    lastSavedIn="{version}">{KINEMATICS}
  <children>
    <MainProgram runOnlyOnce="true" InitVariablesNode="false">
      <children>
{body}
      </children>
    </MainProgram>
{others}
  </children>
</URProgram>"""


def compiled(body: str, others: str = "", version: str = "5.11.5",
             installation: bool = True) -> list[str]:
    prog = parse_urp(program(body, others, version).encode(), "variants.urp")
    inst = parse_installation(INSTALLATION.encode(), "cell.installation") \
        if installation else None
    text = compile_program(prog, inst).text
    assert print_tree(parse(text)) == text  # what is written is URScript
    return [line.strip() for line in text.splitlines()]


def after(lines: list[str], marker: str, count: int) -> list[str]:
    at = next(i for i, line in enumerate(lines) if line.startswith(marker))
    return lines[at + 1:at + 1 + count]


MOVE_WITH_TCP = f"""
        <Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="false"
              positionType="CartesianPose">
          <tcp referencedName="Sander"/>
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            {WAYPOINT.format(name="Start")}
            <Waypoint type="Variable" name="Here" kinematicsFlags="-1">
              <motionParameters/>
              <variable name="here_pose"/>
            </Waypoint>
          </children>
        </Move>
        <Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="false"
              positionType="JointAngles">
          <tcp referencedName="Sander"/>
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            {WAYPOINT.format(name="Home")}
          </children>
        </Move>"""


def test_a_move_with_its_own_tcp_sets_it_before_each_motion():
    lines = compiled(MOVE_WITH_TCP)
    sander = "set_tcp(p[0.003, 0.11, 0.098, -0.785, 0.0, 0.0])"
    assert after(lines, '$ 3 "Start"', 2) == [sander, "movel(Start_p, a=1.2, v=0.25)"]
    assert after(lines, '$ 4 "here_pose"', 2) == [sander, "movel(here_pose, a=1.2, v=0.25)"]
    # a move to joint angles does not need the TCP: nothing is set
    assert after(lines, '$ 6 "Home"', 1) == ["movej(Home_q, a=1.4, v=1.05)"]


def test_without_the_installation_the_taught_tcp_is_set():
    lines = compiled(MOVE_WITH_TCP, installation=False)
    assert after(lines, '$ 3 "Start"', 1) == ["set_tcp(p[0.0, 0.0, 0.2, 0.0, 0.0, 0.0])"]


def test_set_node_selecting_a_tcp_and_an_output_with_a_tcp():
    lines = compiled("""
        <Set type="NoAction"><tcp referencedName="Sander"/></Set>
        <Set type="DigitalOutput">
          <tcp referencedName="Flange"/>
          <pin referencedName="digital_out[1]"/>
          <digitalValue>1</digitalValue>
        </Set>""")
    assert after(lines, '$ 2 "Set"', 1) == ["set_tcp(p[0.003, 0.11, 0.098, -0.785, 0.0, 0.0])"]
    assert after(lines, '$ 3 "Set digital_out[1]=On"', 2) == [
        "set_standard_digital_out(1, True)", "set_tcp(p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0])"]


def test_analog_output_is_a_ratio_of_its_domain():
    lines = compiled("""
        <Set type="AnalogOutput"><pin referencedName="analog_out[0]"/>
          <analogValue>4.0</analogValue></Set>
        <Set type="AnalogOutput"><pin referencedName="analog_out[1]"/>
          <analogValue>10.0</analogValue></Set>""")
    assert "set_standard_analog_out(0, 0.4)" in lines  # 4 V of 10 V (voltage domain)
    assert "set_standard_analog_out(1, 0.5)" in lines  # 10 mA of 20 mA (current domain)


def test_modbus_signals_as_io():
    lines = compiled("""
        <Set type="ExpressionOutput">
          <pin referencedName="BRUSH"/>
          <expression><ExpressionToken token=" False "/></expression>
        </Set>
        <Wait type="DigitalInput">
          <pin referencedName="RUN"/>
          <digitalValue>1</digitalValue>
        </Wait>""")
    assert after(lines, '$ 2 "Set BRUSH= False "', 1) == [
        'modbus_set_output_signal("BRUSH", False)']
    assert after(lines, '$ 3 "Wait RUN=HI"', 1) == [
        'while (modbus_get_signal_status("RUN") == False):']


def test_general_purpose_registers_as_io():
    # CA-Giken/docker-noetic-capc: named RTDE registers (GPBO_..., GPII_...) and unnamed
    # ones (GP_int_in[23]) in Set, Wait and expressions
    lines = compiled("""
        <Set type="DigitalOutput">
          <pin referencedName="DONE"/>
          <digitalValue>1</digitalValue>
        </Set>
        <Set type="ExpressionOutput">
          <pin referencedName="GP_int_out[3]"/>
          <expression><ExpressionToken token="7"/></expression>
        </Set>
        <Wait type="Condition">
          <expression>
            <ExpressionIO><pin referencedName="PRG_NO"/></ExpressionIO>
            <ExpressionChar character="="/><ExpressionChar character="="/>
            <ExpressionIO><pin referencedName="GP_int_in[23]"/></ExpressionIO>
          </expression>
        </Wait>""")
    assert after(lines, '$ 2 "Set DONE=On"', 1) == ["write_output_boolean_register(0, True)"]
    assert after(lines, '$ 3 "Set GP_int_out[3]=7"', 1) == [
        "write_output_integer_register(3, 7)"]
    assert "while (not (read_input_integer_register(1) == read_input_integer_register(23))):" \
        in lines


def test_timers_in_polyscopes_order():
    # the order of a Java HashSet of their names (eight timers of CA-Giken MAIN and two of
    # mswaidan modbustest are written so), not the order of the nodes
    timer = """<Timer action="Start"><variable name="{}"/></Timer>"""
    lines = compiled(timer.format("timer_brush") + timer.format("timer_dry"))
    counting = [line for line in lines if line.endswith("_is_counting = False")]
    assert counting == ["global timer_dry_is_counting = False",
                        "global timer_brush_is_counting = False"]
    # each timer's global, by name, comes before (mswaidan modbustest, CA-Giken MAIN)
    globals_ = [line for line in lines if line.startswith("global timer_")]
    assert globals_[:2] == ["global timer_brush = 0", "global timer_dry = 0"]


@pytest.mark.parametrize(("before", "feature", "after", "written"), [
    # "UF:=Base" is written ``global UF=p[0.0,0.0,0.0,0.0,0.0,0.0]``
    ("", "Joint_0_name", "", "p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]"),
    # taunoe/UR-scripts XMLRPC_loop: "camera.get_next_pose(Tool)"; "Joint_6_name" is
    # PolyScope's name of the Tool feature, never a variable of the program
    ("camera.get_next_pose(", "Joint_6_name", ")",
     "camera.get_next_pose(get_actual_tcp_pose())"),
])
def test_built_in_features_in_an_expression(before, feature, after, written):
    token = '<ExpressionToken token="{}"/>'
    lines = compiled(f"""
        <Assignment valueSource="Expression">
          <variable name="value"/>
          <expression>{token.format(before) if before else ""}
            <ExpressionGeomFeature><feature referencedName="{feature}"/></ExpressionGeomFeature>
            {token.format(after) if after else ""}</expression>
        </Assignment>""")
    assert f"global value = {written}" in lines


def test_names_beyond_ascii_in_an_expression():
    # CA-Giken TEST_SPEED: "pose_sub(CurrPos_p, ウェイポイント_1_p)" in an assignment
    lines = compiled("""
        <Assignment valueSource="Expression">
          <variable name="PoseSub"/>
          <expression><ExpressionToken token="pose_sub(p0, 点_1_p)"/>
          <ExpressionToken token=" # 点"/></expression>
        </Assignment>""")
    assert "global PoseSub = pose_sub(p0, u28857_1_p)" in lines


def test_an_unknown_io_is_still_one_message():
    with pytest.raises(CompileError, match="NOPE"):
        compiled("""<Set type="ExpressionOutput"><pin referencedName="NOPE"/>
          <expression><ExpressionToken token=" True "/></expression></Set>""")


def test_events_share_one_thread_started_before_the_robot_program():
    events = """
    <Event>
      <expression><ExpressionIO><pin referencedName="digital_in[1]"/></ExpressionIO>
        <ExpressionChar character="≠"/><ExpressionToken token=" True "/></expression>
      <children><Halt/></children>
    </Event>
    <Event>
      <expression><ExpressionIO><pin referencedName="digital_in[2]"/></ExpressionIO>
        <ExpressionChar character="≟"/><ExpressionToken token=" True "/></expression>
      <children><Set type="DigitalOutput"><pin referencedName="digital_out[0]"/>
        <digitalValue>0</digitalValue></Set></children>
    </Event>"""
    lines = compiled('<Wait type="Sleep"><waitTime>1.0</waitTime></Wait>', events)
    start = lines.index("thread EventThread():")
    assert lines[start:start + 9] == [
        "thread EventThread():", "while (True):",
        "if (get_standard_digital_in(1) != True):", '$ 4 "Halt"', "halt",
        "elif (get_standard_digital_in(2) == True):", '$ 6 "Set digital_out[0]=Off"',
        "set_standard_digital_out(0, False)", "end"]
    assert lines.index("eventThread = run EventThread()") < lines.index('$ 1 "Robot Program"')


WAYPOINT_MOVE = f"""
        <Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            {WAYPOINT.format(name="Start")}
          </children>
        </Move>"""


DIRECTION = """
        <Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <gui.program.direction.MoveDirectionNode selectedDirection="ZPlus">
              <feature class="GeomFeatureVariable" featureName="Cube"/>
              <children>
                <Until type="DISTANCE" allowActions="false" deceleration="3.0"
                       distanceNodeType="{kind}">
                  <Distance>0.1</Distance>
                  <motionParameters blendRadius="0.025"/>
                </Until>
              </children>
            </gui.program.direction.MoveDirectionNode>
            <gui.program.direction.MoveDirectionNode selectedDirection="ZMinus">
              <feature class="GeomFeatureReference" referencedName="Joint_6_name"/>
              <children>
                <Until type="TOOL_CONTACT_DETECTION" allowActions="false" retraction="NONE"
                       decelerationAcceleration="3.0"/>
              </children>
            </gui.program.direction.MoveDirectionNode>
          </children>
        </Move>"""


def test_direction_in_a_variable_feature_and_until_blend():
    lines = compiled(DIRECTION.format(kind="BLEND"))
    assert "local towardsPos = calculate_point_to_move_towards(" \
           "p[-0.65, -0.29, 0.15, 1.19, 1.2, 1.23], [0.0, 0.0, 1.0], 0.1)" in lines
    assert "movel(towardsPos, a=1.2, v=0.25, r=0.025)" in lines
    # a STOP distance does not blend, whatever radius it keeps
    assert "movel(towardsPos, a=1.2, v=0.25)" in compiled(DIRECTION.format(kind="STOP"))


def test_direction_without_a_feature_moves_in_its_moves_feature():
    # CubeFinishApril2022 (mswaidan/finishing-line): a Direction with no <feature> under a
    # MoveL in the plane feature CubeFront; PolyScope labels it "Direction: CubeFront Z+"
    # and writes CubeFront's pose, not the base's p[0, ...]
    lines = compiled("""
        <Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Cube"/>
          <children>
            <gui.program.direction.MoveDirectionNode selectedDirection="ZPlus"
                toolParams="0.2, 1.2">
              <children>
                <Until type="DISTANCE" allowActions="false" deceleration="3.0"
                       distanceNodeType="STOP">
                  <Distance>0.1</Distance>
                  <motionParameters blendRadius="0.0"/>
                </Until>
              </children>
            </gui.program.direction.MoveDirectionNode>
          </children>
        </Move>""")
    assert '$ 3 "Direction: Cube Z+"' in lines
    assert "local towardsPos = calculate_point_to_move_towards(" \
           "p[-0.65, -0.29, 0.15, 1.19, 1.2, 1.23], [0.0, 0.0, 1.0], 0.1)" in lines
    assert "movel(towardsPos, a=1.2, v=0.2)" in lines


def test_set_payload_selects_a_payload_of_the_installation():
    # CubeFinishApril2022 (mswaidan/finishing-line): <SetPayload workpieceName="SandSpray"/>
    # is written '$ 6 "Set Payload: SandSpray"' and the payload's set_target_payload
    body = """<SetPayload workpieceName="Part"/>"""
    lines = compiled(body)
    assert after(lines, '$ 2 "Set Payload: Part"', 1) == [
        "set_target_payload(3.02, [0.012, 0.022, 0.058], "
        "[0.009713, 0.009713, 0.009713, 0.0, 0.0, 0.0])"]
    # the installation's default payload is the preamble's, not the one the node selects
    assert lines.count("set_target_payload(1.0, [0.0, 0.0, 0.05], "
                       "[0.001, 0.001, 0.001, 0.0, 0.0, 0.0])") == 1
    # without the installation the payload is unknown: the node is kept and named
    unknown = compiled(body, installation=False)
    assert "# urdsl: PolyScope node <SetPayload> is not compiled" in unknown
    assert not any(line.startswith("set_target_payload") for line in unknown)


def test_single_digital_pulse_is_a_thread_started_in_place():
    # CA-Giken/docker-noetic-capc MAIN: '$ 586 "... =HI:Pulse 1.0"', thread SinglePulse660
    # (PolyScope's number is a counter across programs; urdsl counts from 1 in the program)
    pulse = """<Set type="SingleDigitalPulseActionState">
          <SingleDigitalPulseActionState hiPulseInSeconds="{t}">
            <pin referencedName="digital_out[{n}]"/>
          </SingleDigitalPulseActionState>
        </Set>"""
    lines = compiled(pulse.format(t="0.1", n=0) + pulse.format(t="1.5", n=2))
    assert after(lines, '$ 2 "Set digital_out[0]=HI:Pulse 0.1"', 6) == [
        "thread SinglePulse1():", "set_standard_digital_out(0, True)", "sleep(0.1)",
        "set_standard_digital_out(0, False)", "end", "singlePulse1 = run SinglePulse1()"]
    assert after(lines, '$ 3 "Set digital_out[2]=HI:Pulse 1.5"', 6)[2] == "sleep(1.5)"
    assert "singlePulse2 = run SinglePulse2()" in lines


def test_names_beyond_ascii_are_written_as_polyscope_does():
    # CA-Giken/docker-noetic-capc: a thread "スレッド_2" is u12473u12524u12483u12489_2
    lines = compiled(WAYPOINT_MOVE.replace('name="Start"', 'name="点_1"'),
                     others="""<Thread><children>
          <Wait type="Sleep"><waitTime>0.5</waitTime></Wait></children></Thread>""")
    assert "global u28857_1_p = p[" in " ".join(lines)
    assert any(line.startswith("movej(get_inverse_kin(u28857_1_p") or
               line.startswith("movej(u28857_1_q") for line in lines), lines


def test_tool_contact_without_retraction_stops_where_it_touched():
    lines = compiled(DIRECTION.format(kind="STOP"))
    found = lines.index("if (stepsToRetract > 0):")
    assert lines[found + 1:found + 6] == [
        "kill move_thread_han_5", "stopl(3.0)", '$ 6 "Until (tool_contact_detection)"',
        "break", "end"]
    assert not any(line.startswith("local backTrackMovement") for line in lines)


def test_polyscope3_variable_waypoint_in_the_base():
    lines = compiled("""
        <Move motionType="MoveL" speed="2.0" acceleration="0.1" useActiveTCP="false">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <Waypoint type="Variable" name="Waypoint" kinematicsFlags="-1">
              <motionParameters/>
              <variable name="setp"/>
            </Waypoint>
          </children>
        </Move>""", version="3.15.8")
    assert "movel(pose_trans(p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], setp), a=0.1, v=2.0)" in lines


def test_urscript_saved_as_urp_is_named_as_such():
    from urdsl.polyscope.urp import UrpError

    with pytest.raises(UrpError, match="not a PolyScope program but URScript text"):
        parse_urp(b"textmsg(get_actual_joint_positions())\nsleep(0.5)\n", "main_cycle.urp")
    with pytest.raises(UrpError, match="not well-formed XML"):
        parse_urp(b"textmsg(1\n", "broken.urp")
    # an empty file parses as an empty script, but is nothing: a program the controller
    # cannot load (seen: a 31-byte gzip of nothing among a project's sample programs)
    with pytest.raises(UrpError, match=r"empty once decompressed: not a PolyScope program"):
        parse_urp(gzip.compress(b""), "program.urp")
    with pytest.raises(UrpError, match=r"error: empty: not a PolyScope program"):
        parse_urp(b" \n", "program.urp")


def test_polyscope_before_3_15_writes_markers_without_flags():
    # josepquintana/UR5-Motion-Planning scripts/test (3.8.0): '$ 2 "MoveJ"',
    # '$ 3 "Waypoint_1"' and no marker for the Robot Program; 3.15 on write both
    old = [line for line in compiled(WAYPOINT_MOVE, version="3.8.0.61336")
           if line.startswith("$")]
    assert old == ['$ 2 "MoveJ"', '$ 3 "Start"']
    new = [line for line in compiled(WAYPOINT_MOVE, version="3.15.3.106223")
           if line.startswith("$")]
    assert new == ['$ 1 "Robot Program"', '$ 2 "MoveJ"', '$ 3 "Start" "breakAfter"']
    # 3.5.0 (Sander-ONeil/robotics-project-2023): the Robot Program marker, no flags
    oldest = [line for line in compiled(WAYPOINT_MOVE, version="3.5.0.10584")
              if line.startswith("$")]
    assert oldest == ['$ 1 "Robot Program"', '$ 2 "MoveJ"', '$ 3 "Start"']


def test_polyscope_3_move_without_a_tcp_goes_to_the_joint_angles():
    # Sander-ONeil/robotics-project-2023 (3.5): useActiveTCP="false", no <tcp>, no
    # positionType: movej([q]) and movel([q]); a move with the active TCP (3.8) goes to
    # get_inverse_kin(pose, qnear=q)
    move = """<Move motionType="{motion}" speed="0.25" acceleration="1.2" useActiveTCP="{active}">
          <children>
            <Waypoint type="Fixed" name="W" kinematicsFlags="3">
              <motionParameters/>
              <position joints="0.1, -1.5, 1.5, -1.5, -1.5, 0.0"
                        pose="0.4, -0.1, 0.3, 0.0, 3.1, 0.0"/>
              <poseInFeatureCoordinates pose="0.4, -0.1, 0.3, 0.0, 3.1, 0.0"/>
            </Waypoint>
          </children>
        </Move>"""
    for motion, function in (("MoveJ", "movej"), ("MoveL", "movel")):
        lines = compiled(move.format(motion=motion, active="false"), version="3.5.0.10584")
        assert f"{function}([0.1, -1.5, 1.5, -1.5, -1.5, 0.0], a=1.2, v=0.25)" in lines
    lines = compiled(move.format(motion="MoveJ", active="true"), version="3.8.0.61336")
    assert "movej(get_inverse_kin(p[0.4, -0.1, 0.3, 0.0, 3.1, 0.0], " \
           "qnear=[0.1, -1.5, 1.5, -1.5, -1.5, 0.0]), a=1.2, v=0.25)" in lines


def test_switch_variables_count_per_function():
    # CA-Giken MAIN: Switch nodes in two subprograms and the Robot Program are each switch_1
    switch = """<Switch>
          <expression><ExpressionToken token="{}"/></expression>
          <children><Case caseValue="1"><children>
            <Wait type="Sleep"><waitTime>0.1</waitTime></Wait>
          </children></Case></children>
        </Switch>"""
    body = f"""<CallSubProgram>
          <subprogram name="Sub" keepHidden="false" keepSynchronizedWithDisk="false">
            <children>{switch.format("a")}</children>
          </subprogram>
        </CallSubProgram>
        {switch.format("b")}"""
    lines = compiled(body, others='<SubProgram reference="../MainProgram/children/'
                                  'CallSubProgram/subprogram"/>')
    assert "switch_1 = a" in lines and "switch_1 = b" in lines
    assert not any(line.startswith("switch_2") for line in lines)
