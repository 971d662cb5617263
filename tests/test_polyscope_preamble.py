"""The preamble PolyScope writes before a program's tree, from the installation: each kind
of block for PolyScope 3.x and 5.x, the order urdsl writes the blocks in, plane features,
and a missing or corrupt installation."""

from __future__ import annotations

import gzip
import json
import math

import pytest

from urdsl.cli import main
from urdsl.polyscope.compile import compile_program
from urdsl.polyscope.installation import InstallationError, parse_installation
from urdsl.polyscope.preamble import BLOCKS, preamble_blocks
from urdsl.polyscope.urp import parse_urp
from urdsl.script.printer import format as print_tree


def _urp(version: str = "5.11.9.1010452", installation: str = "cell") -> bytes:
    return (f'<URProgram name="pre" installation="{installation}" createdIn="{version}" '
            f'lastSavedIn="{version}"><children><MainProgram runOnlyOnce="true"><children>'
            '<Wait type="Sleep"><waitTime>0.1</waitTime></Wait></children></MainProgram>'
            '</children></URProgram>').encode()


_IOS = """<IOs>
  <DigitalOutputNames value="lamp, , , , , , , "/>
  <analogInputRange value="1, 0, 1, 1"/>
  <analogOutputDomain value="0, 1"/>
  <DigitalInputActions value="NONE, NONE, NONE, NONE, NONE, NONE, NONE, NONE"/>
  <ToolDigitalInputActions value="FREEDRIVE, NONE"/>
  <GeneralPurposeBooleanRegisterInputActions value="START, STOP, PAUSE, NONE, NONE, NONE, NONE,
    FREEDRIVE, NONE"/>
  <DigitalOutputActions value="LOW_WHEN_PROGRAM_STOPPED, NONE, NONE, LOW_WHEN_PROGRAM_STOPPED,
    NONE, NONE, NONE, NONE"/>
  <ConfigurableOutputActions value="NONE, NONE, LOW_WHEN_PROGRAM_STOPPED, NONE"/>
  <ModbusUnits>
    <Unit ipAddress="10.0.0.7" sequentialMode="false">
      <ModbusSignal name="ready" type="DIGITAL_INPUT" slaveAddress="255" updateFrequency="10"
        signalAddress="8195" modificationChoice="0"/>
      <ModbusSignal name="go" type="DIGITAL_OUTPUT" slaveAddress="1" updateFrequency="5"
        signalAddress="12" modificationChoice="2"/>
    </Unit>
  </ModbusUnits>
</IOs>"""

_PLANE_POINTS = ((0.1, 0.2, 0.0), (0.1, 0.5, 0.0), (-0.3, 0.2, 0.0))
"""A horizontal plane: origin (0.1, 0.2, 0), its y axis along +y, taught pointing down."""


def _point(tag: str, position, axis=(0.0, math.pi, 0.0)) -> str:
    return (f'<{tag}><GeomPoseNode name="hidden_{tag}" hiddenSubFeature="true" '
            f'isVariable="false"><toolPosition value="{", ".join(map(str, position))}"/>'
            f'<toolAxisAngle value="{", ".join(map(str, axis))}"/></GeomPoseNode></{tag}>')


def _features() -> str:
    plane = "".join(_point(tag, p) for tag, p in zip(
        ("firstPoint", "secondPoint", "thirdPoint"), _PLANE_POINTS, strict=True))
    return f"""<Features>
  <CameraView><worldTransform><WorldtoMarshal baseAngle="0.0" tiltAngle="0.0"/>
  </worldTransform></CameraView>
  <BaseView><BaseView isVariable="false"/></BaseView>
  <GeomPoseNode><GeomPoseNode name="pick" isVariable="true">
    <toolPosition value="0.4, -0.1, 0.25"/><toolAxisAngle value="0.0, 3.14, 0.0"/>
  </GeomPoseNode></GeomPoseNode>
  <GeomPoseNode><GeomPoseNode name="hidden" isVariable="false">
    <toolPosition value="0.0, 0.0, 0.0"/><toolAxisAngle value="0.0, 0.0, 0.0"/>
  </GeomPoseNode></GeomPoseNode>
  <GeomPlaneNode><GeomPlaneNode name="Table" isVariable="true">{plane}</GeomPlaneNode>
  </GeomPlaneNode>
</Features>"""


def _installation5(extra: str = "") -> bytes:
    return f"""<Installation>
  {_IOS}
  <Version major="5" minor="24" bugfix="0"/>
  <ToolCommSettings enabled="true" baudRate="BAUD_1000000" parity="EVEN" stopBits="ONE"
    rxIdleChars="1.5" txIdleChars="3.5" toolOutputMode="OUTPUT" toolDigitalOutput0="SINKING"
    toolDigitalOutput1="PUSH_PULL" toolOutputVoltage="TWENTY_FOUR"/>
  {_features()}
  <PayloadSettings><Payload name="box" mass="1.5" centerOfGravity="0.0, 0.0, 0.05"
    defaultPayload="true"/></PayloadSettings>
  <TCPSettings activePose="gripper"><availablePoses>
    <tcp name="flange" offset="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
    <tcp name="gripper" offset="0.0, 0.0, 0.15, 0.0, 0.0, 0.0"/>
  </availablePoses></TCPSettings>
  <SmoothTransitionSettings transitionHardness="HARD"/>
  <ToolWrenchConfiguration forceLimitEnabled="false" momentLimitEnabled="false"/>
  <MotionSettingsConfiguration motionVersion="JERK_LIMITED"/>
  <Contributions><URCaps>
    <Contributed id="ConveyorTracking" name="Conveyor Tracking" vendor="Universal Robots"
      installationContributionTitle="Conveyor Tracking"/>
    <Contributed id="com.acme.GripperService" name="Acme Gripper" vendor="Acme Inc."
      installationContributionTitle="Gripper"/>
  </URCaps></Contributions>
  {extra}
</Installation>""".encode()


_INSTALLATION3 = b"""<Installation>
  <IOs><analogInputRange value="1, 1, 1, 1"/><analogOutputDomain value="0, 0"/>
    <DigitalInputActions value="NONE"/></IOs>
  <Version major="3" minor="15" bugfix="8"/>
  <ToolCommSettings toolOutputVoltage="TWELVE"/>
  <Features><CameraView><worldTransform>
    <WorldtoMarshal baseAngle="0.0" tiltAngle="3.141592653589793"/></worldTransform>
  </CameraView></Features>
  <TCPSettings activePose="TCP" toolPayload="1.2">
    <availablePoses><tcp name="TCP" offset="0.0, 0.0, 0.1, 0.0, 0.0, 0.0"/></availablePoses>
  </TCPSettings>
  <SmoothTransitionSettings transitionHardness="SOFT"/>
</Installation>"""


def _blocks(urp: bytes, installation: bytes | None, variables=()):
    program = parse_urp(urp, "pre.urp")
    parsed = parse_installation(installation, "cell.installation") if installation else None
    return {kind: [print_tree(item).strip() for item in items]
            for kind, items in preamble_blocks(program, parsed, list(variables))}


@pytest.fixture(scope="module")
def five():
    return _blocks(_urp("5.24.0"), _installation5(), [("count", "3"), ("home", "p[0,0,0,0,0,0]")])


def test_polyscope_5_safety_tool_gravity_payload_and_tcp(five):
    assert five["safety"] == ["set_safety_mode_transition_hardness(0)"]
    assert five["wrench"] == ["tool_wrench_limit_disable()"]
    assert five["motion"] == ["motion_version_set(2)"]
    assert five["tool"] == ["set_tool_communication(True, 1000000, 2, 1, 1.5, 3.5)",
                            "set_tool_output_mode(0)", "set_tool_digital_output_mode(0, 1)",
                            "set_tool_digital_output_mode(1, 3)", "set_tool_voltage(24)"]
    assert five["gravity"] == ["set_gravity([0.0, 0.0, 9.82])"]
    assert five["payload"] == ["set_payload(1.5, [0.0, 0.0, 0.05])"]
    assert five["tcp"] == ["set_tcp(p[0.0, 0.0, 0.15, 0.0, 0.0, 0.0])"]  # the active one


def test_polyscope_5_io_block(five):
    assert five["io"] == [
        "set_standard_analog_input_domain(0, 1)", "set_standard_analog_input_domain(1, 0)",
        "set_tool_analog_input_domain(0, 1)", "set_tool_analog_input_domain(1, 1)",
        "set_analog_outputdomain(0, 0)", "set_analog_outputdomain(1, 1)",
        "set_input_actions_to_default()", 'set_tool_digital_input_action(0, "freedrive")',
        # a general purpose register's freedrive; start, stop and pause write nothing
        'set_gp_boolean_input_action(7, "freedrive")',
        "set_runstate_standard_digital_outputs([0, 3])",
        "set_runstate_configurable_digital_outputs([2])",
        "set_runstate_standard_digital_output_to_value(0, 1)",
        "set_runstate_standard_digital_output_to_value(3, 1)",
        "set_runstate_configurable_digital_output_to_value(2, 1)"]


def test_modbus_signals(five):
    assert five["modbus"] == [
        'modbus_add_signal("10.0.0.7", 255, 8195, 0, "ready", False)',
        'modbus_set_signal_update_frequency("ready", 10)',
        'modbus_add_signal("10.0.0.7", 1, 12, 1, "go", False)',
        'modbus_set_signal_update_frequency("go", 5)',
        'modbus_set_runstate_dependent_choice("go", 2)']  # outputs only


def test_the_step_counter_and_the_verification_global_of_recent_versions(five):
    assert five["verification"] == ["global _hidden_verificationVariable = 0"]  # 5.12 on
    assert "verification" in _blocks(_urp("5.12.4.1101661"), _installation5())
    assert five["steps"][0].startswith("step_count_")
    older = _blocks(_urp("5.11.9.1010452"), _installation5())
    assert "verification" not in older and "steps" in older
    # seen from 5.7.0 (o2ac/o2ac-ur) and 3.12.1 (kg398/kg_ursim); not in 3.8 and 3.5
    assert "steps" in _blocks(_urp("5.7.0.90932"), _installation5())
    assert "steps" in _blocks(_urp("3.12.1.90940"), _INSTALLATION3)
    assert "steps" not in _blocks(_urp("3.8.0.61336"), _INSTALLATION3)
    assert "steps" not in _blocks(_urp("5.6.0.90886"), _installation5())  # not seen [U]


def test_polyscope_5_7_payload_without_centre_of_gravity_is_the_mass_alone():
    """5.x before named payloads keeps the payload as ``toolPayload`` on the TCP settings,
    without a centre of gravity: PolyScope 5.7.0 writes ``set_payload(0.0)``
    (o2ac/o2ac-ur b_bot's center_object, seven programs)."""
    installation = b"""<Installation><Version major="5" minor="7" bugfix="0"/>
  <TCPSettings activePose="tip" toolPayload="0.8">
    <availablePoses><tcp name="tip" offset="0.0, 0.0, 0.165, 0.0, 0.0, 0.0"/></availablePoses>
  </TCPSettings></Installation>"""
    blocks = _blocks(_urp("5.7.0.90932"), installation)
    assert blocks["payload"] == ["set_payload(0.8)"]
    assert blocks["tcp"] == ["set_tcp(p[0.0, 0.0, 0.165, 0.0, 0.0, 0.0])"]


def test_a_5_7_installation_reaches_the_check(tmp_path, capsys):
    """The TCP, the payload without centre of gravity and a ceiling mounting of a 5.7
    installation are what the check runs with; PolyScope's step counter thread is not
    reported as left running."""
    (tmp_path / "cell.installation").write_bytes(b"""<Installation>
  <Version major="5" minor="7" bugfix="0"/>
  <Features><CameraView><worldTransform>
    <WorldtoMarshal baseAngle="0.0" tiltAngle="3.141592653589793"/></worldTransform>
  </CameraView></Features>
  <TCPSettings activePose="tip" toolPayload="0.8">
    <availablePoses><tcp name="tip" offset="0.0, 0.0, 0.165, 0.0, 0.0, 0.0"/></availablePoses>
  </TCPSettings></Installation>""")
    program = tmp_path / "pre.urp"
    program.write_bytes(_urp("5.7.0.90932"))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    inferred = report["inferred"]
    assert inferred["tcp"]["pose"] == pytest.approx([0, 0, 0.165, 0, 0, 0])
    assert inferred["payload"]["mass"] == pytest.approx(0.8)
    assert inferred["payload"]["cog"] is None  # the installation gives none
    assert inferred["gravity"] == pytest.approx([0, 0, -9.82])  # the ceiling
    assert not report["findings"]


def test_variables_then_features_by_name_without_hidden_ones(five):
    assert five["variables"] == ["global count = 3", "global home = p[0, 0, 0, 0, 0, 0]"]
    names = [line.split("=")[0].split()[1] for line in five["features"]]
    assert names == ["Table", "pick"]  # sorted as PolyScope does: capitals first


def test_a_plane_feature_is_placed_as_polyscope_places_it(five):
    installation = parse_installation(_installation5(), "cell.installation")
    pose = dict(installation.features)["Table"]
    assert pose[:3] == pytest.approx(_PLANE_POINTS[0])
    # y along the first point to the second (+y), z along the normal on the side of the
    # taught tool's z (down), x = y × z (-x): a half turn about y
    assert pose[3:] == pytest.approx((0.0, math.pi, 0.0), abs=1e-9)


def test_urcap_installation_nodes_are_marked_empty_blocks(five):
    """Their code only the URCap can generate; UR's built-in contributions write none."""
    assert five["urcaps"] == ["# begin: URCap Installation Node",
                              "#   Source: Acme Gripper, Acme Inc.", "#   Type: Gripper",
                              "# end: URCap Installation Node"]


def test_polyscope_3_preamble():
    blocks = _blocks(_urp("3.15.8.106339"), _INSTALLATION3)
    assert blocks["tool"] == ["set_tool_voltage(12)"]  # no tool communication on CB3
    gravity = blocks["gravity"][0].removeprefix("set_gravity([").removesuffix("])")
    assert [float(v) for v in gravity.split(",")] == pytest.approx([0, 0, -9.82])  # ceiling
    assert blocks["payload"] == ["set_payload(1.2)"]  # no centre of gravity: mass only
    assert blocks["safety"] == ["set_safety_mode_transition_hardness(1)"]
    assert blocks["io"][-1] == "set_input_actions_to_default()"
    assert "steps" in blocks and "verification" not in blocks


def test_the_blocks_come_in_one_fixed_order():
    """PolyScope's order of these blocks changes from save to save; urdsl's does not."""
    program = parse_urp(_urp("5.24.0"), "pre.urp")
    installation = parse_installation(_installation5(), "cell.installation")
    kinds = [kind for kind, _ in preamble_blocks(program, installation, [("n", "1")])]
    movable = [kind for kind in kinds if kind in BLOCKS]
    assert kinds[0] == "verification" and kinds[-3:] == ["variables", "features", "urcaps"]
    assert movable == [kind for kind in BLOCKS if kind in movable]
    first = compile_program(program, installation).text
    assert compile_program(program, installation).text == first
    assert first.index("set_tcp(") < first.index("global Table")


def test_no_installation_gives_only_what_the_version_writes():
    assert list(_blocks(_urp("5.24.0"), None)) == ["verification", "steps"]


def test_an_enabled_tool_wrench_limit_is_said_not_written():
    extra = _installation5().replace(b'forceLimitEnabled="false"', b'forceLimitEnabled="true"')
    assert _blocks(_urp("5.24.0"), extra)["wrench"] == [
        "# urdsl: the tool wrench limit is not written"]


@pytest.mark.parametrize("data, reason", [
    (gzip.compress(_installation5())[:40], "truncated"),
    (b"<Installation><IOs>", "not well-formed XML"),
    (b"<Installation><IOs><ModbusUnits><Unit><ModbusSignal name='x' signalAddress='lots'/>"
     b"</Unit></ModbusUnits></IOs></Installation>", "Modbus signal 'x' address"),
])
def test_a_corrupt_installation_is_named(data, reason):
    with pytest.raises(InstallationError) as error:
        parse_installation(data, "cell.installation")
    assert str(error.value).startswith("cell.installation: ") and reason in str(error.value)


def test_compile_names_a_missing_or_corrupt_installation(tmp_path, capsys):
    program = tmp_path / "pre.urp"
    program.write_bytes(_urp("5.11.9.1010452"))
    out = tmp_path / "pre.script"
    assert main(["compile", str(program), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"{program}: the installation it names, {tmp_path / 'cell.installation'}, is not " \
           "there" in err and "Traceback" not in err
    assert "set_tcp" not in out.read_text()
    (tmp_path / "cell.installation").write_bytes(gzip.compress(_installation5())[:60])
    assert main(["compile", str(program), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert f"{tmp_path / 'cell.installation'}: the gzip data is" in err
    assert "Traceback" not in err
    (tmp_path / "cell.installation").write_bytes(gzip.compress(_installation5()))
    assert main(["compile", str(program), "-o", str(out)]) == 0
    text = out.read_text()
    assert "modbus_add_signal(" in text and "global Table = p[" in text
    assert "warning" not in capsys.readouterr().err


def test_initial_values_of_the_variables_setup_and_of_urcap_variables():
    urp = (b'<URProgram name="pre" installation="cell" createdIn="5.11.9" lastSavedIn="5.11.9">'
           b'<children><InitVariablesNode><variables>'
           b'<variable name="ready"><expression><ExpressionToken token=" False "/>'
           b'</expression></variable>'
           b'<variable name="count"><expression><ExpressionChar character="1"/>'
           b'<ExpressionChar character="2"/></expression></variable>'
           b'<variable name="twice"><expression><ExpressionVariable><variable name="count"/>'
           b'</ExpressionVariable><ExpressionChar character="*"/><ExpressionChar character="2"/>'
           b'</expression></variable>'
           b'<variable name="bad"><expression><ExpressionVariable/></expression></variable>'
           b'</variables></InitVariablesNode>'
           b'<MainProgram runOnlyOnce="true"><children>'
           b'<Contributed strategyURCapName="Gripper"><dataModel><Variable key="v">'
           b'<variable name="part"><initializeExpression><ExpressionToken token="True"/>'
           b'</initializeExpression></variable></Variable></dataModel></Contributed>'
           b'<Contributed strategyURCapName="Gripper"><dataModel><Variable key="v">'
           b'<variable name="part"><initializeExpression><ExpressionToken token="True"/>'
           b'</initializeExpression></variable></Variable></dataModel></Contributed>'
           b'</children></MainProgram></children></URProgram>')
    blocks = _blocks(urp, None)
    assert blocks["initial"] == ["global ready = False", "global count = 12",
                                 "global twice = count * 2",
                                 "# urdsl: the initial value of bad is not compiled",
                                 "global part = True"]  # each name once
    assert list(blocks)[-1] == "initial"  # after the installation's blocks


def test_ethernet_ip_watchdog_and_general_purpose_register_state():
    # CA-Giken/docker-noetic-capc (5.13): EtherNet/IP enabled with the watchdog action
    # IGNORE, and register 0's action PROGRAM_RUNNING
    installation = b"""<Installation>
  <IOs><GeneralPurposeBooleanRegisterOutputActions value="PROGRAM_RUNNING, NONE, NONE"/></IOs>
  <Contributions><URCaps>
    <Contributed ownerId="com.ur.urcap.ethernetip" id="EthernetIP" name="Ethernet/IP">
      <data key="watchdogAction" value="IGNORE"/><data key="enabled" value="true"/>
    </Contributed>
  </URCaps></Contributions>
</Installation>"""
    blocks = _blocks(_urp("5.13.0"), installation)
    assert blocks["io"] == ["set_runstate_gp_boolean_output_to_value(0, 3)"]
    assert blocks["watchdog"] == ['rtde_set_watchdog("speed_slider_mask", 10.0, "ignore")']
    # the adapter disabled (creativity-software/ur10-robot-draw-circle): no watchdog
    disabled = installation.replace(b'value="true"', b'value="false"')
    assert "watchdog" not in _blocks(_urp("5.13.0"), disabled)


def test_modbus_output_choices_come_after_all_signals():
    # mswaidan/finishing-line modbustest: every modbus_set_runstate_dependent_choice after
    # the last signal's modbus_add_signal and update frequency
    installation = b"""<Installation><IOs><ModbusUnits>
  <Unit ipAddress="10.0.0.7" sequentialMode="false">
    <ModbusSignal name="out" type="REGISTER_OUTPUT" slaveAddress="255" updateFrequency="50"
      signalAddress="101" modificationChoice="0"/>
    <ModbusSignal name="in" type="DIGITAL_INPUT" slaveAddress="255" updateFrequency="10"
      signalAddress="3" modificationChoice="0"/>
  </Unit></ModbusUnits></IOs></Installation>"""
    assert _blocks(_urp(), installation)["modbus"] == [
        'modbus_add_signal("10.0.0.7", 255, 101, 3, "out", False)',
        'modbus_set_signal_update_frequency("out", 50)',
        'modbus_add_signal("10.0.0.7", 255, 3, 0, "in", False)',
        'modbus_set_signal_update_frequency("in", 10)',
        'modbus_set_runstate_dependent_choice("out", 0)']


def test_polyscope_3_5_tcp_settings_and_tool_voltage():
    # Sander-ONeil/robotics-project-2023 (3.5): the TCP settings under their class name,
    # the tool voltage (V) on the root
    installation = b"""<Installation toolOutputVoltage="0">
  <com.ur.view.tcp.domain.TCPSettingsImpl activePose="TCP" toolPayload="1.6">
    <availablePoses><tcp name="TCP" offset="0.0, 0.0, 0.0, 0.0, 2.2217, -2.218"/></availablePoses>
  </com.ur.view.tcp.domain.TCPSettingsImpl>
</Installation>"""
    blocks = _blocks(_urp("3.5.0.10584"), installation)
    assert blocks["tcp"] == ["set_tcp(p[0.0, 0.0, 0.0, 0.0, 2.2217, -2.218])"]
    assert blocks["payload"] == ["set_payload(1.6)"]
    assert blocks["tool"] == ["set_tool_voltage(0)"]


def _line_installation(first, second, axis) -> bytes:
    points = (_point("firstPoint", first, axis) + _point("secondPoint", second, axis))
    return f"""<Installation><Version major="5" minor="11" bugfix="0"/><Features>
  <GeomLineNode><GeomLineNode name="Edge" isVariable="true">{points}</GeomLineNode>
  </GeomLineNode>
  <GeomLineNode><GeomLineNode name="Untaught" isVariable="true">
    {_point("firstPoint", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))}
    {_point("secondPoint", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))}</GeomLineNode>
  </GeomLineNode></Features></Installation>""".encode()


def test_a_line_feature_is_placed_as_polyscope_places_it():
    """Origin at the first point, y along the line, z the taught tool's z made
    perpendicular to the line: a line along +x taught with the tool pointing down (and a
    little along the line) has y = +x, z = -z, x = y × z = +y."""
    tilt = 0.2  # the tool tilted about y: its z has a component along the line
    installation = parse_installation(
        _line_installation((0.3, -0.1, 0.05), (0.7, -0.1, 0.05), (0.0, math.pi - tilt, 0.0)),
        "cell.installation")
    features = dict(installation.features)
    pose = features["Edge"]
    assert pose[:3] == pytest.approx((0.3, -0.1, 0.05))
    # the rotation with columns x = (0, 1, 0), y = (1, 0, 0), z = (0, 0, -1): a half
    # turn about (1, 1, 0)/√2
    half = math.pi / math.sqrt(2)
    assert [abs(v) for v in pose[3:]] == pytest.approx([half, half, 0.0], abs=1e-9)
    assert pose[3] * pose[4] > 0
    # a line never taught (both points zero) is the zero pose, as PolyScope writes it
    assert features["Untaught"] == pytest.approx((0.0,) * 6)
    blocks = _blocks(_urp("5.11.0"), _line_installation(
        (0.3, -0.1, 0.05), (0.7, -0.1, 0.05), (0.0, math.pi, 0.0)))
    assert [line.split(" =")[0] for line in blocks["features"]] == [
        "global Edge", "global Untaught"]


def test_a_plane_a_hair_off_a_half_turn_is_written_as_polyscope_writes_it():
    """Near a half turn PolyScope takes the angle from the acos of the trace and the axis
    from the symmetric part of the rotation (reproduced to the last digit on a real plane:
    eggsu/comp4320_ass2 assignment.installation, ``letter_start``). A plane whose second
    point is 1 nm higher, taught pointing down: the rotation's columns are x = (0, 1, 0),
    y = (1, 0, 1e-9), z = (1e-9, 0, -1); its trace is -1 (angle π) and the symmetric
    part's axis (1, 1, 1e-9/2)/√2 gives z = π·1e-9/(2√2) (the column alone gives 0)."""
    points = ((0.0, 0.0, 0.0), (1.0, 0.0, 1e-9), (0.0, 1.0, 0.0))
    plane = "".join(_point(tag, p) for tag, p in zip(
        ("firstPoint", "secondPoint", "thirdPoint"), points, strict=True))
    data = f"""<Installation><Version major="5" minor="10" bugfix="0"/><Features>
  <GeomPlaneNode><GeomPlaneNode name="Sheet" isVariable="true">{plane}</GeomPlaneNode>
  </GeomPlaneNode></Features></Installation>""".encode()
    pose = dict(parse_installation(data, "cell.installation").features)["Sheet"]
    half = math.pi / math.sqrt(2)
    assert pose[3:5] == pytest.approx((half, half), abs=1e-12)
    assert pose[5] == pytest.approx(math.pi * 1e-9 / (2 * math.sqrt(2)), abs=1e-15)


def _conveyor_installation(switch: str = "true", encoder: str = "1", kind: str = "1",
                           major: str = "3") -> bytes:
    """Usaakm/UR10-Conveyor-Belt's conveyor (3.15): conveyor 0, linear, an incremental
    encoder on digital inputs 0 and 1, 13333 ticks a metre, its direction a line feature
    taught by two points; output 7 high when the program stops; EtherNet/IP on."""
    line = (_point("firstPoint", (0.8, -0.45, -0.17), (-3.1, -0.2, 0.0))
            + _point("secondPoint", (-0.85, -0.46, -0.16), (-3.1, -0.2, 0.0)))
    return f"""<Installation><Version major="{major}" minor="15" bugfix="4"/>
  <IOs><DigitalOutputActions value="NONE, NONE, NONE, NONE, NONE, NONE, NONE,
    HIGH_WHEN_PROGRAM_STOPPED"/></IOs>
  <Features>
    <GeomLineNode><GeomLineNode name="belt" isVariable="false">{line}</GeomLineNode>
    </GeomLineNode>
    <GeomPoseNode><GeomPoseNode name="pick" isVariable="true">
      <toolPosition value="0.4, -0.1, 0.25"/><toolAxisAngle value="0.0, 3.14, 0.0"/>
    </GeomPoseNode></GeomPoseNode>
  </Features>
  <Contributions><URCaps>
    <Contributed ownerId="com.ur.urcap.conveyortracking" id="ConveyorTracking"
        name="Conveyor Tracking" vendor="Universal Robots">
      <data key="major.version" value="3"/><data key="enabled_0" value="true"/>
      <data key="apin_0" value="0"/><data key="bpin_0" value="1"/>
      <data key="tpr_0" value="0"/><data key="rotateTool_0" value="false"/>
      <data key="encoderType_0" value="{encoder}"/><data key="incrementalMode_0" value="1"/>
      <data key="conveyorType_0" value="{kind}"/><data key="direction_0" value="belt"/>
      <data key="tpm_0" value="13333"/><data key="switchDirection_0" value="{switch}"/>
      <data key="enabled_1" value="false"/><data key="apin_1" value="2"/>
    </Contributed>
    <Contributed ownerId="com.ur.urcap.ethernetip" id="EthernetIP" name="Ethernet/IP">
      <data key="enabled" value="true"/><data key="watchdogAction" value="IGNORE"/>
    </Contributed>
  </URCaps></Contributions>
</Installation>""".encode()


_FIRST = "p[0.8, -0.45, -0.17, -3.1, -0.2, 0.0]"
_SECOND = "p[-0.85, -0.46, -0.16, -3.1, -0.2, 0.0]"


@pytest.mark.parametrize("switch, direction", [
    ("true", f"pose_sub({_FIRST}, {_SECOND})"),  # U.urp (Testings/UR10_Code_V2)
    ("false", f"pose_sub({_SECOND}, {_FIRST})"),  # Lower_Z.urp (UR10_Code_V1)
])
def test_conveyor_tracking_writes_its_encoder_and_its_start_function(switch, direction):
    """After the features: the encoder's pulse decoding, then the function the program's
    conveyor tracking node calls; the direction is the line's second point minus its first,
    or the first minus the second when switched; a disabled conveyor writes nothing."""
    program = parse_urp(_urp("3.15.4.106291"), "pre.urp")
    installation = parse_installation(_conveyor_installation(switch), "cell.installation")
    blocks = dict(preamble_blocks(program, installation, []))
    lines = [print_tree(item).strip() for item in blocks["conveyor"]]
    assert lines == ["encoder_enable_pulse_decode(0, 1, 0, 1)",
                     "def start_conveyor_tracking0():\n"
                     f"  track_conveyor_linear({direction}, 13333, 0)\nend"]
    kinds = list(blocks)
    assert kinds.index("features") < kinds.index("conveyor") < kinds.index("watchdog")
    text = compile_program(program, installation).text
    assert text.index("global pick") < text.index("encoder_enable_pulse_decode(0, 1, 0, 1)") \
        < text.index("def start_conveyor_tracking0():") < text.index("rtde_set_watchdog(")
    assert "tracking1" not in text and "global belt" not in text  # the line is not variable


def test_a_conveyor_urdsl_cannot_write_is_said():
    """An encoder other than the incremental one and a conveyor that is not linear: no
    script seen, a comment each, nothing guessed."""
    blocks = _blocks(_urp("3.15.4.106291"), _conveyor_installation(encoder="2", kind="2"))
    assert blocks["conveyor"] == ["# urdsl: conveyor 0's encoder (type 2) is not written",
                                  "# urdsl: conveyor 0 (type 2) is not written"]


def test_polyscope_3_sets_each_outputs_stop_state_only():
    """PolyScope 3.15 writes only ``set_runstate_standard_digital_output_to_value(7, 2)``
    (output 7 high when the program stops: state 2); PolyScope 5 first names the outputs
    that have a state (mswaidan/finishing-line, 5.11)."""
    three = _blocks(_urp("3.15.4.106291"), _conveyor_installation())
    assert three["io"] == ["set_runstate_standard_digital_output_to_value(7, 2)"]
    five = _blocks(_urp("5.11.5.1010327"), _conveyor_installation(major="5"))
    assert five["io"] == ["set_runstate_standard_digital_outputs([7])",
                          "set_runstate_standard_digital_output_to_value(7, 2)"]


def test_a_plane_never_taught_is_the_zero_pose():
    """A variable plane whose three points were never taught (all at zero) is written as
    ``p[0, 0, 0, 0, 0, 0]`` (srs827/Robot-Cello-ResidualRL, 5.17: ``Plane_4``)."""
    points = "".join(_point(tag, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
                     for tag in ("firstPoint", "secondPoint", "thirdPoint"))
    installation = f"""<Installation><Version major="5" minor="17" bugfix="3"/><Features>
  <GeomPlaneNode><GeomPlaneNode name="Plane_4" userHasPoints="false" isVariable="true">
  {points}</GeomPlaneNode></GeomPlaneNode></Features></Installation>""".encode()
    blocks = _blocks(_urp("5.17.3"), installation)
    assert blocks["features"] == ["global Plane_4 = p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]"]
