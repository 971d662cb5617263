"""``urdsl check X.urp`` and ``urdsl lint X.urp``: the compiled program checked and linted,
findings naming the program node (path and XML position), URCap nodes as devices, the arm's
calibration from ``<kinematics>``, errors without tracebacks."""

from __future__ import annotations

import gzip
import json
import math
import shutil
from pathlib import Path

import pytest
from _urp import chars as _chars
from _urp import program as _program

from urdsl.cli import main
from urdsl.polyscope.check import calibration_of, generate
from urdsl.polyscope.urp import read_urp
from urdsl.runtime.unknown import DEVICE_REPLY_TIME

DATA = Path(__file__).parent / "data" / "polyscope"


URCAP = ('<Contributed strategyClass="com.example.Grip" strategyProgramNodeType="Grip" '
         'strategyURCapDeveloper="Example Inc." strategyURCapName="Example_Gripper"/>\n')


@pytest.fixture
def cell(tmp_path):
    for name in ("cell.urp", "cell.installation"):
        shutil.copy(DATA / name, tmp_path / name)
    return tmp_path / "cell.urp"


def test_nodes_know_their_place_in_the_xml():
    program = read_urp(DATA / "cell.urp")
    lines = (DATA / "cell.urp").read_text(encoding="utf-8").splitlines()
    for node in program.main.walk():
        line, column = node.position
        assert lines[line - 1][column - 1:].startswith(f"<{node.element.tag}")


def test_check_names_the_node_beside_the_generated_line(cell, capsys):
    assert main(["check", str(cell), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["file"] == f"{cell} (compiled)"
    error = next(f for f in report["findings"] if f["severity"] == "error")
    assert "node Robot Program > MoveL > Variable" in error["message"]
    assert f"{cell}:53:13" in error["message"]  # the Waypoint element in the XML
    generated = generate(cell)
    assert generated.text.splitlines()[error["line"] - 1].strip().startswith("movel(count")
    assert report["cycle_time"] > 0


def test_urcap_nodes_are_an_info_finding_and_a_device(tmp_path, capsys):
    program = tmp_path / "urcap.urp"
    program.write_text(_program(URCAP + '<If type="If" checkContinuously="false"><expression>'
                                + _chars("grip_ok") + '</expression><children><Wait '
                                'type="Sleep"><waitTime>0.5</waitTime></Wait></children></If>'))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    codes = [f["code"] for f in report["findings"]]
    assert "URS214" in codes and "URS311" not in codes  # PolyScope's step counter is fine
    assert not any(c.startswith("URS2") and c not in ("URS210", "URS214") for c in codes)
    urcap = next(f for f in report["findings"] if f["code"] == "URS214")
    assert "only the URCap can generate" in urcap["message"]
    assert "Robot Program > Grip" in urcap["message"]
    depends = next(f for f in report["findings"] if f["code"] == "URS210")
    assert "URCap" in depends["message"] and "Robot Program > If" in depends["message"]
    # the URCap node answers as a device does, then the branch of a working one runs
    assert report["cycle_time"] == pytest.approx(DEVICE_REPLY_TIME + 0.5, abs=0.01)


def test_lint_of_a_urp_with_urcap_code_warns_for_names_only_that_code_can_define(tmp_path,
                                                                                capsys):
    program = tmp_path / "urcap.urp"
    body = ('<If type="If" checkContinuously="false"><expression>' + _chars("grip_ok")
            + '</expression><children><Wait type="Sleep"><waitTime>0.5</waitTime></Wait>'
            '</children></If>')
    program.write_text(_program(URCAP + body))
    assert main(["lint", str(program)]) == 0
    out = capsys.readouterr().out
    assert "URS101 name 'grip_ok' is not defined; it may come from code only a URCap " \
           "generates (Example_Gripper)" in out and "Found 1 warning" in out
    # a function only the URCap defines, too
    program.write_text(_program(URCAP + '<Script type="Line"><expression>' + _chars("p_rel(1)")
                                + "</expression></Script>"))
    assert main(["lint", str(program)]) == 0
    assert "URS102 unknown function 'p_rel'" in capsys.readouterr().out
    # without URCap code nothing can define it: still an error
    program.write_text(_program(body))
    assert main(["lint", str(program)]) == 1
    out = capsys.readouterr().out
    assert "URS101 name 'grip_ok' is not defined [node" in out and "Found 1 error" in out


def test_lint_names_the_node(cell, capsys):
    main(["lint", str(cell), "--format", "json"])
    found = json.loads(capsys.readouterr().out)
    assert any(d["code"] == "URS214" and "BeforeStart > Grip" in d["message"] for d in found)
    assert all(d["file"] == f"{cell} (compiled)" for d in found)
    assert any("node Robot Program > MoveL" in d["message"] for d in found)


@pytest.mark.parametrize("data", [b"\x89garbage\xff\x00",
                                  gzip.compress(b"<URProgram><children>")[:-6],
                                  b"<URProgram name='x'><children></children></URProgram>"])
def test_a_broken_program_is_one_message(tmp_path, capsys, data):
    program = tmp_path / "broken.urp"
    program.write_bytes(data)
    assert main(["check", str(program)]) == 1
    captured = capsys.readouterr()
    assert f"{program}:1:1: error:" in captured.out and "URS001" in captured.out
    assert f"{program}: not checked" in captured.out and "Traceback" not in captured.err
    assert main(["check", "--json", str(program)]) == 1  # the same, for a machine
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] is False and report["checked"] is False
    assert [f["code"] for f in report["findings"]] == ["URS001"]
    assert main(["lint", str(program)]) == 1
    assert str(program) in capsys.readouterr().out


def test_calibration_from_kinematics_of_the_matching_model():
    program = read_urp(DATA / "cell.urp")
    calibration, model = calibration_of(program)
    assert model == "ur5e" and calibration.is_zero
    assert calibration_of(program, "ur10e") == (None, None)


def test_the_arm_calibration_moves_the_check(tmp_path, capsys):
    kinematics = ('<kinematics><deltaTheta value="0, 0, 0, 0, 0, 0"/>'
                  '<a value="0.0, -0.4265, -0.3922, 0.0, 0.0, 0.0"/>'
                  '<d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>'
                  '<alpha value="1.5707963267948966, 0, 0, 1.5707963267948966, '
                  '-1.5707963267948966, 0"/></kinematics>')
    program = tmp_path / "arm.urp"
    program.write_text(_program('<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>',
                                kinematics))
    calibration, model = calibration_of(read_urp(program))
    assert model == "ur5e" and calibration.delta_a[1] == pytest.approx(-0.0015)
    main(["check", str(program), "--json"])
    assert "very arm" in json.loads(capsys.readouterr().out)["context"]
    main(["check", str(program), "--json", "--nominal"])
    assert "--nominal" in json.loads(capsys.readouterr().out)["context"]


def _safety(tcp_speed: float = 1.5, shoulder_max: float = 0.0524, plane: str = "") -> str:
    """A ``<SafetySettings>`` block as PolyScope writes it (INI text)."""
    return f"""<SafetySettings>
[SafetyLimits BoundaryPlane0]
name = Ceiling
displacement = 0.0
mode = {'BOTH' if plane else 'DISABLED'}
planeNormal = {plane or '[0.0, 0.0, 0.0]'}
distanceToOrigin = 0.3
elbowRestricted = true

[SafetyLimits BoundaryPlane1]
name = Wall
mode = TRIGGER
planeNormal = [1.0, 0.0, 0.0]
distanceToOrigin = 0.1

[SafetySetup]
withPositionLimits = [true, true, true, true, true, false]

[SafetyLimits Normal Values]
maxTcpSpeed = {tcp_speed}
maxForce = 150.0

[SafetyLimits Normal Joints]
maxJointSpeed = [3.14, 3.14, 3.14, 6.28, 6.28, 6.28]
minJointPosition = [6.2308, 6.2308, 6.2308, 6.2308, 6.2308, 0.0]
maxJointPosition = [0.0524, {shoulder_max}, 0.0524, 0.0524, 0.0524, 0.0]
minJointRevolutions = [-2, -2, -2, -2, -2, -2147483648]
maxJointRevolutions = [1, {1 if shoulder_max == 0.0524 else -1}, 1, 1, 1, 2147483647]
</SafetySettings>"""


def _with_safety(cell: Path, block: str) -> None:
    installation = cell.with_suffix(".installation")
    text = installation.read_text(encoding="utf-8")
    installation.write_text(text.replace("</Installation>", block + "\n</Installation>"),
                            encoding="utf-8")


def test_safety_limits_are_read_from_the_installation():
    from urdsl.polyscope.installation import parse_safety

    safety = parse_safety(_safety(0.25).split(">", 1)[1].rsplit("<", 1)[0])
    assert safety.tcp_speed == 0.25 and safety.force == 150.0
    assert safety.q_max[0] == pytest.approx(2 * math.pi + 0.0524)  # angle + whole turns
    assert safety.q_min[0] == pytest.approx(-4 * math.pi + 6.2308)
    assert safety.q_min[5] is None and safety.q_max[5] is None  # not limited
    assert safety.joint_speed[3] == 6.28
    assert [p.name for p in safety.planes] == ["Wall"] and safety.planes[0].mode == "TRIGGER"


def test_installation_tcp_speed_limit_reaches_the_check(cell, capsys):
    _with_safety(cell, _safety(tcp_speed=0.05))
    main(["check", str(cell), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert "TCP speed limit 0.05 m/s" in report["context"]
    speed = [f for f in report["findings"] if f["code"] == "URS306"]
    assert speed and "node Robot Program > MoveJ > Waypoint_" in speed[0]["message"]
    main(["check", str(cell), "--json", "--tcp-speed-limit", "50"])  # the flag wins
    assert "URS306" not in [f["code"] for f in json.loads(capsys.readouterr().out)["findings"]]


def test_installation_joint_limits_reach_the_check(cell, capsys):
    _with_safety(cell, _safety(shoulder_max=6.1))  # shoulder at most −2π + 6.1 = −0.18 rad
    main(["check", str(cell), "--json"])
    report = json.loads(capsys.readouterr().out)
    assert "joint position limits" in report["context"]
    assert any(f["code"] == "URS303" and "shoulder" in f["message"]
               for f in report["findings"])


def test_installation_safety_planes_reach_the_check(cell, capsys):
    _with_safety(cell, _safety(plane="[0.0, 0.0, -1.0]"))  # stay below z = 0.3 m
    main(["check", str(cell), "--json"])
    report = json.loads(capsys.readouterr().out)
    # not the trigger plane, which restricts nothing
    assert "1 safety plane(s) for the TCP and elbow (Ceiling)" in report["context"]
    assert any(f["code"] == "URS308" and "safety plane Ceiling" in f["message"]
               for f in report["findings"])


@pytest.mark.parametrize(("height", "elbow", "found"), [
    (0.5, False, None),        # only the forearm reaches over it: allowed
    (0.5, True, "elbow"),      # the plane restricts the elbow too (at 0.565 m)
    (0.4, False, "TCP"),       # the TCP (the flange, 0.465 m) is beyond
])
def test_a_safety_plane_restricts_the_tcp_and_elbow_not_the_links(height, elbow, found):
    # UR's safety system watches the TCP (and tool) and, where a plane says so, the elbow:
    # a forearm over a plane is no violation (an arm taught there was reported colliding)
    from urdsl.polyscope.installation import SafetyPlane
    from urdsl.verify.run import CheckOptions, check_text

    plane = SafetyPlane("Head", (0.0, 0.0, -1.0), height, "BOTH", elbow)
    report = check_text("movej([0, -1.9, 1.9, -1.57, -1.57, 0])\n"
                        "movej([0.2, -1.9, 1.9, -1.57, -1.57, 0])\n", "p.script",
                        options=CheckOptions(safety_planes=(plane,)))
    hits = [f.message for f in report.findings if f.code == "URS308"]
    if found is None:
        assert hits == []
    else:
        assert hits and all(f"the {found} passes the safety plane Head" in hit for hit in hits)


def test_the_demo_program_is_checked_by_node(capsys):
    program = Path(__file__).parents[1] / "programs" / "polyscope" / "pick.urp"
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # the installation's 0.25 m/s: the controller slows the moves over it (warnings)
    speed = [f for f in report["findings"] if f["code"] == "URS306"]
    assert any("node Robot Program > Loop > MoveL > LiftPick" in f["message"] for f in speed)
    assert {f["severity"] for f in speed} == {"warning"}
    assert "TCP speed limit 0.25 m/s" in report["context"]
    assert len(report["moves"]) == 13 and report["cycle_time"] > 10
    assert report["slowed"]["moves"] == 6 and report["slowed"]["up_to"] > 1


def test_a_missing_installation_is_named(tmp_path, capsys):
    program = tmp_path / "alone.urp"
    program.write_text(_program('<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>'))
    assert main(["check", str(program), "--json"]) == 0
    assert "no installation default.installation beside the program" in json.loads(
        capsys.readouterr().out)["context"]


def test_a_urcap_function_of_a_missing_installation_is_a_device(tmp_path, capsys):
    # proprioception_expt_program (5.11.7, project 159): a Script node calls Robotiq's
    # rq_activate_and_wait(), which the URCap's code in the preamble of the missing
    # installation defines; a function no URCap is known for stays an error
    from _urp import script_line

    program = tmp_path / "grip.urp"
    program.write_text(_program(script_line("rq_activate_and_wait()")))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "URCap functions, defined by the URCaps' code of the missing installation, taken " \
        "as devices: rq_activate_and_wait" in report["context"]
    # lint: a warning naming the URCap and the missing installation
    assert main(["lint", "--format", "json", str(program)]) == 0
    [found] = json.loads(capsys.readouterr().out)
    assert (found["code"], found["severity"]) == ("URS102", "warning")
    assert "a function of the URCap" in found["message"] and "Robotiq_Grippers" in \
        found["message"] and "default.installation" in found["message"]
    program.write_text(_program(script_line("rq_activate_and_wait()") +
                                script_line("grab_part()")))
    assert main(["check", str(program), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert [f["message"].split(" [node")[0] for f in report["findings"]
            if f["severity"] == "error"] == ["name 'grab_part' is not defined"]


def test_a_feature_constant_of_a_missing_installation_is_unknown(tmp_path, capsys):
    # Main.urp of project 126 (3.12.1): "pose1≔pose_add(Point_1_const, p[...])", the feature
    # written as <feature referencedName="Point_1"/> (no class); the installation is not in
    # the repository, so its pose is unknown, not an undefined name
    assignment = ('<Assignment valueSource="Expression"><variable name="pose1"/><expression>'
                  + _chars("pose_add(") + '<ExpressionGeomFeature><feature referencedName='
                  '"Point_1"/></ExpressionGeomFeature>' + _chars(", p[0.01, 0, 0.03, 0, 0, 0])")
                  + "</expression></Assignment>")
    program = tmp_path / "Main.urp"
    program.write_text(_program(assignment, version="3.12.1.90940"))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "Point_1" in report["context"]


def test_a_socket_a_urcaps_code_opens_answers(tmp_path, capsys):
    # Floor Corner Extended.urp (project 6): Vention's URCap opens socket MachineMotion1 in
    # the installation's preamble, which urdsl does not generate for a .urp; the program's
    # reads of it are a device's replies, not "nothing read" ([0], whose item 1 is missing)
    from _urp import script_line

    program = tmp_path / "lift.urp"
    program.write_text(_program(
        script_line('temp_drive = socket_read_ascii_float(1, "MachineMotion1", timeout=15)')
        + script_line("height = temp_drive[1]")))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    # a script that never opens the socket reads nothing: item 1 is missing
    script = tmp_path / "lift.script"
    script.write_text('temp_drive = socket_read_ascii_float(1, "MachineMotion1", timeout=15)\n'
                      "height = temp_drive[1]\n")
    program.unlink()
    assert main(["check", str(script), "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["findings"][0]["code"] == "URS202"


def test_a_variable_a_urcap_node_is_set_up_with_is_its_result(tmp_path, capsys):
    # UR5e_Program.urp (project 82): an OPC UA URCap node reads into the program variable
    # "service" (<data key="selectedProgramVariable" value="service"/>) before the program
    # assigns it itself; the node's code, which urdsl does not generate, sets it
    from _urp import script_line

    read = ('<Contributed strategyClass="com.example.OpcuaRead" strategyProgramNodeType='
            '"Read" strategyURCapDeveloper="Example Inc." strategyURCapName="Example_OPCUA">'
            '<dataModel><data key="selectedProgramVariable" value="service"/></dataModel>'
            "</Contributed>")
    body = ('<CallSubProgram><subprogram name="Service" keepHidden="false" '
            'keepSynchronizedWithDisk="false"><children>' + read
            + script_line("switch_1 = service") + script_line("global service = 0")
            + "</children></subprogram></CallSubProgram>")
    program = tmp_path / "opc.urp"
    program.write_text(_program(body).replace(
        "</MainProgram>", '</MainProgram><SubProgram reference="../MainProgram/children/'
        'CallSubProgram/subprogram"/>'))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]


def test_io_named_only_in_a_missing_installation(tmp_path, capsys):
    # a user's name for an input or output (a renamed pin, a Modbus signal) is resolved by
    # the installation: without it the program still compiles; a read is a value the check
    # does not know (its condition a warning that says so), a Set of it keeps its marker
    program = tmp_path / "alone.urp"
    program.write_text(_program(
        '<Set type="DigitalOutput"><pin referencedName="gripper"/>'
        '<digitalValue>1</digitalValue></Set>'
        '<Wait type="DigitalInput"><pin referencedName="part_ready"/>'
        '<digitalValue>1</digitalValue></Wait>'))
    assert main(["compile", str(program)]) == 0
    out, err = capsys.readouterr()
    assert "values only the missing installation gives (gripper (an I/O), part_ready " \
           "(an I/O))" in err
    assert '$ 2 "Set gripper=On"' in out and "while (part_ready == False):" in out
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    (waits,) = [f for f in report["findings"] if f["code"] == "URS210"]
    assert "an I/O of the installation default.installation (not beside the program)" \
        in waits["message"]
    assert main(["lint", str(program), "--format", "json"]) == 0
    (found,) = json.loads(capsys.readouterr().out)
    assert found["severity"] == "warning" and "'part_ready'" in found["message"]


def test_a_feature_of_a_missing_installation_is_not_a_mistake_of_the_program(tmp_path,
                                                                              capsys):
    # a feature made a variable in the installation is defined by the installation's
    # preamble: with the installation not beside the program, reading it is a warning that
    # says so (lint) and an unknown value (check); the same name typed is still an error
    feature = ('<ExpressionVariable><GeomFeatureVariable featureName="Plane_3"/>'
               '</ExpressionVariable>')
    program = tmp_path / "pallet.urp"
    program.write_text(_program('<Script type="Line"><expression>' + _chars("textmsg(")
                                + feature + _chars(")") + "</expression></Script>"))
    assert main(["lint", str(program), "--format", "json"]) == 0
    (found,) = json.loads(capsys.readouterr().out)
    assert found["severity"] == "warning" and "'Plane_3'" in found["message"]
    assert "a feature of the installation default.installation (not beside the program)" \
        in found["message"]
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    program.write_text(_program('<Script type="Line"><expression>'
                                + _chars("textmsg(Plane_3)") + "</expression></Script>"))
    assert main(["lint", str(program)]) == 1
    assert "URS101 name 'Plane_3' is not defined [node" in capsys.readouterr().out


def test_a_variable_waypoint_at_a_feature_of_a_missing_installation(tmp_path, capsys):
    # ylkhayat/universal-robots-mixing (5.9.5): MoveJ to a Variable waypoint whose variable
    # is a point feature of the installation, <variable featureName="Control_Standby"/>; the
    # installation is not in the repository. The name is the installation's (a warning that
    # says so, an unknown target the check does not move to), not the program's mistake
    program = tmp_path / "standby.urp"
    program.write_text(_program(
        '<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true" '
        'positionType="CartesianPose"><feature class="GeomFeatureReference" '
        'referencedName="Joint_0_name"/><children><Waypoint type="Variable" name="Waypoint" '
        'kinematicsFlags="7"><motionParameters/><variable featureName="Control_Standby"/>'
        '</Waypoint></children></Move>'))
    assert main(["lint", str(program), "--format", "json"]) == 0
    (found,) = json.loads(capsys.readouterr().out)
    assert found["severity"] == "warning" and "'Control_Standby'" in found["message"]
    assert "a feature of the installation default.installation" in found["message"]
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]


def test_installation_variables_and_move_features_of_a_missing_installation(tmp_path, capsys):
    # an IncrementVariable Set of an installation variable and a MoveL in a feature both take
    # names from the installation; without it beside the program they are unknown values
    # (check) and warnings that say so (lint), not "not defined" errors
    increment = ('<Set type="IncrementVariable"><installationVariable name="i_count"/></Set>')
    test = ('<If type="If"><expression>' + _chars("i_count == 3") + '</expression>'
            '<children><Wait type="Sleep"><waitTime>0.1</waitTime></Wait></children></If>')
    program = tmp_path / "counter.urp"
    program.write_text(_program(increment + test))
    assert main(["check", str(program), "--json"]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "names of a missing installation): i_count" in report["context"]
    assert f"{program}: the installation it names, " in captured.err
    move = ('<Move motionType="MoveL" speed="0.25" acceleration="1.2" useActiveTCP="true" '
            'positionType="CartesianPose">'
            '<feature class="GeomFeatureReference" referencedName="Joint_6_name"/>'
            '<children><Waypoint type="Variable" name="Variable">'
            '<variable name="offset"/></Waypoint></children></Move>')
    offset = ('<Script type="Line"><expression>' + _chars("global offset = p[0, 0, 0.01, 0, 0, 0]")
              + "</expression></Script>")
    program.write_text(_program(offset + move))
    assert main(["lint", str(program), "--format", "json"]) == 0
    found = [f for f in json.loads(capsys.readouterr().out) if "Joint_6_name" in f["message"]]
    assert found and found[0]["severity"] == "warning"
    assert "a name of the installation default.installation (not beside the program)" in \
        found[0]["message"]


def test_an_export_is_checked_on_the_arm_of_the_program_beside_it(tmp_path, capsys):
    # PolyScope saves X.script beside X.urp, whose <kinematics> is the arm's calibration: a
    # pose taught with the arm stretched up lies beyond the nominal model's reach (here its
    # upper arm is 1.5 mm longer) and is reached by the very arm
    import numpy as np

    from urdsl.kinematics import Robot
    from urdsl.kinematics.pose import matrix_to_rotvec

    kinematics = ('<kinematics><deltaTheta value="0, 0, 0, 0, 0, 0"/>'
                  '<a value="0.0, -0.4265, -0.3922, 0.0, 0.0, 0.0"/>'
                  '<d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>'
                  '<alpha value="1.5707963267948966, 0, 0, 1.5707963267948966, '
                  '-1.5707963267948966, 0"/></kinematics>')
    (tmp_path / "arm.urp").write_text(_program(
        '<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>', kinematics))
    calibration, _ = calibration_of(read_urp(tmp_path / "arm.urp"))
    up = [0.0, -1.5707963267948966, 0.0, -1.5707963267948966, 0.0, 0.0]
    pose = Robot.model("ur5e", calibration=calibration).fk(np.array(up))
    target = [float(v) for v in (*pose[:3, 3], *matrix_to_rotvec(pose[:3, :3]))]
    export = tmp_path / "arm.script"
    export.write_text("def arm():\n  movej(get_inverse_kin(p[" + ", ".join(map(repr, target))
                      + "]))\nend\n")
    assert main(["check", str(export), "--robot", "ur5e", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert "calibration of arm.urp's <kinematics>" in report["context"]
    # on the nominal model it is 1.5 mm out of reach: within a calibration's millimetres, so
    # a warning that the arm's calibration decides, not an error
    assert main(["check", str(export), "--robot", "ur5e", "--json", "--nominal"]) == 0
    (reach,) = [f for f in json.loads(capsys.readouterr().out)["findings"]
                if f["code"] == "URS301"]
    assert reach["severity"] == "warning" and "calibration decides" in reach["message"]


def test_an_export_without_waypoints_is_checked_on_the_model_of_its_program(tmp_path, capsys):
    # project 135's Program1.script (no waypoint pairs, so no model to infer from them) was
    # checked on an assumed UR5e; the Program1.urp beside it keeps a UR5's factory table, on
    # which `urdsl check Program1.urp` checks it: the export is checked on that arm too
    ur10e = ('<kinematics><deltaTheta value="0, 0, 0, 0, 0, 0"/>'
             '<a value="0.0, -0.6127, -0.57155, 0.0, 0.0, 0.0"/>'
             '<d value="0.1807, 0.0, 0.0, 0.17415, 0.11985, 0.11655"/>'
             '<alpha value="1.5707963267948966, 0, 0, 1.5707963267948966, '
             '-1.5707963267948966, 0"/></kinematics>')
    (tmp_path / "far.urp").write_text(_program(
        '<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>', ur10e))
    export = tmp_path / "far.script"
    export.write_text("def far():\n  movej(p[1.0, 0.2, 0.3, 0, 3.1416, 0], a=1.0, v=0.5)\n"
                      "end\n")
    assert main(["check", str(export), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["robot"] == "ur10e"
    assert "calibration of far.urp's <kinematics>" in report["context"]
    assert report["inferred"]["robot"]["from"] == "the <kinematics> of far.urp (the arm's " \
        "calibration)" and "reason" not in report["inferred"]["robot"]
    # alone, it is checked on an assumed UR5e, which cannot reach the pose: a warning
    (tmp_path / "far.urp").unlink()
    assert main(["check", str(export), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["robot"] == "ur5e" and [f["severity"] for f in report["findings"]
                                          if f["code"] == "URS301"] == ["warning"]


def test_a_polyscope_1_program_is_urdsls_limit_not_the_programs_mistake(tmp_path, capsys):
    # a CB2 controller runs it; urdsl cannot read it: a warning, never an error
    program = tmp_path / "old.urp"
    program.write_bytes(b"<gui.program.ProgramRootNode/>")
    assert main(["lint", "--format", "json", str(program)]) == 0
    (found,) = json.loads(capsys.readouterr().out)
    assert found["severity"] == "warning" and found["message"].startswith("not linted: a "
                                                                          "PolyScope 1.x")
    assert main(["check", "--json", str(program)]) == 1  # nothing was checked
    report = json.loads(capsys.readouterr().out)
    assert report["checked"] is False and report["summary"]["error"] == 0


def _taught(name: str, joints: str, tcp: str) -> str:
    return (f'<Waypoint type="Fixed" name="{name}" kinematicsFlags="3"><motionParameters/>'
            f'<position><JointAngles angles="{joints}"/><TCPOffset pose="{tcp}"/></position>'
            '</Waypoint>')


UP = "0.0, -1.5707963, 0.0, -1.5707963, 0.0, 0.0"  # the arm stretched straight up
FLANGE_KINEMATICS = ('<kinematics><deltaTheta value="0, 0, 0, 0, 0, 0"/>'
                     '<a value="0.0, -0.425, -0.3922, 0.0, 0.0, 0.0"/>'
                     '<d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>'
                     '<alpha value="1.5707963267948966, 0, 0, 1.5707963267948966, '
                     '-1.5707963267948966, 0"/></kinematics>')


def test_without_its_installation_the_tcp_the_waypoints_were_taught_with(tmp_path, capsys):
    # the installation's preamble sets the active TCP; without it, the TCP PolyScope stored
    # with the taught waypoints: a pose taught straight up with a 0.19 m gripper is reached
    # with it, and lies out of reach of the flange
    program = tmp_path / "up.urp"
    move = ('<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">'
            '<children>{}</children></Move>')
    program.write_text(_program(move.format(
        _taught("Home", "0.3, -1.2, 1.2, -1.5, -1.5, 0.0", "0.0, 0.0, 0.19, 0.0, 0.0, 0.0")
        + _taught("Up", UP, "0.0, 0.0, 0.19, 0.0, 0.0, 0.0")), FLANGE_KINEMATICS))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert "TCP p[0, 0, 0.19, 0, 0, 0] the waypoints were taught with" in report["context"]
    assert main(["check", str(program), "--json", "--tcp", "0,0,0,0,0,0"]) == 1  # the flange
    assert any(f["code"] == "URS301" for f in json.loads(capsys.readouterr().out)["findings"])
    # taught with two TCPs: which one is active is the missing installation's to say
    program.write_text(_program(move.format(
        _taught("Home", "0.3, -1.2, 1.2, -1.5, -1.5, 0.0", "0.0, 0.0, 0.05, 0.0, 0.0, 0.0")
        + _taught("Up", UP, "0.0, 0.0, 0.19, 0.0, 0.0, 0.0")), FLANGE_KINEMATICS))
    assert main(["check", str(program), "--json"]) == 0
    (reach,) = [f for f in json.loads(capsys.readouterr().out)["findings"]
                if f["code"] == "URS301"]
    assert reach["severity"] == "warning" and "2 different TCPs" in reach["message"]


def test_the_variables_of_a_missing_installation_are_read_beside_it(tmp_path, capsys):
    # a repository that commits default.variables but not default.installation: the program's
    # variable waypoint is an installation variable, defined (seen: a 5.7 course exercise)
    program = tmp_path / "course.urp"
    program.write_text(_program(
        '<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">'
        '<children><Waypoint type="Variable" name="safe_pose" kinematicsFlags="-1">'
        '<motionParameters/><variable name="safe_pose"/></Waypoint></children></Move>'))
    (tmp_path / "default.variables").write_text(
        "#\n#Sun Apr 05 17:41:00 CEST 2020\nsafe_pose=[0, -0.78, -1.57, -2.15, 1.57, 0]\n")
    assert main(["lint", str(program)]) == 0
    assert "URS101" not in capsys.readouterr().out
    assert main(["compile", str(program)]) == 0
    assert "global safe_pose = [0, -0.78, -1.57, -2.15, 1.57, 0]" in capsys.readouterr().out


def test_an_io_another_installation_does_not_name_is_unknown_not_an_error(tmp_path, capsys):
    # the program names längs_multi.installation, which is not there; the folder's
    # default.installation is compiled with in its place, and cannot say what the program's
    # own names for its I/O are
    program = tmp_path / "stack.urp"
    program.write_text(_program(
        '<Set type="DigitalOutput"><pin referencedName="licht_start"/>'
        '<digitalValue>1</digitalValue></Set>').replace('installation="default"',
                                                         'installation="längs_multi"'))
    shutil.copy(DATA / "cell.installation", tmp_path / "default.installation")
    assert main(["lint", str(program)]) == 0
    captured = capsys.readouterr()
    assert "URS001" not in captured.out
    assert "the installation it names, längs_multi.installation, is not there; compiled " \
           "with default.installation beside it instead" in captured.err
    # named, the same installation's silence about the name is the program's mistake
    program.write_text(program.read_text().replace('"längs_multi"', '"default"'))
    assert main(["lint", str(program)]) == 1
    assert "'licht_start' is not named in the installation" in capsys.readouterr().out


def test_a_loop_holding_a_urcap_node_is_not_a_busy_loop(tmp_path, capsys):
    # a Robot Program that loops forever over one gripper node: the URCap's code (which
    # urdsl cannot see) waits for the gripper; a loop of nothing stays URS118
    program = tmp_path / "grip.urp"
    program.write_text(_program(URCAP).replace('runOnlyOnce="true"', 'runOnlyOnce="false"'))
    main(["lint", str(program)])
    assert "URS118" not in capsys.readouterr().out
    program.write_text(_program('<Comment comment="nothing"/>').replace(
        'runOnlyOnce="true"', 'runOnlyOnce="false"'))
    main(["lint", str(program)])
    assert "URS118" in capsys.readouterr().out


def test_safe_home_without_the_installation_moves_to_an_unknown_position(tmp_path, capsys):
    # the program is valid with its installation; the repository lacks the installation:
    # lint and check read the rest of it, the home position is a value they do not know
    from urdsl.polyscope.compile import SAFE_HOME

    program = tmp_path / "home.urp"
    program.write_text(_program(
        '<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">'
        '<children><SafeHome positionOptionType="SPEED_AND_ACCELERATION" speed="1.05" '
        'acceleration="1.4"/>'
        + _taught("Waypoint_1", "0.3, -1.2, 1.2, -1.5, -1.5, 0.0", "0, 0, 0, 0, 0, 0")
        + '</children></Move>', FLANGE_KINEMATICS))
    assert main(["lint", str(program)]) == 0
    out = capsys.readouterr().out
    assert "URS001" not in out and "error" not in out
    assert f"name '{SAFE_HOME}' is not defined: the safe home position of the installation " \
           "default.installation (not beside the program)" in out
    assert main(["check", str(program)]) == 0
    captured = capsys.readouterr()
    assert "URS001" not in captured.out and "1 move(s)" in captured.out  # the waypoint's
    assert f"{SAFE_HOME} (the safe home position)" in captured.err
    assert main(["send", str(program), "--host", "127.0.0.1", "--dry-run"]) == 1
    assert f"not sent: {SAFE_HOME} (the safe home position) only in the installation " \
           "default.installation" in capsys.readouterr().err


def test_waypoints_taught_with_another_tcp_than_the_installations_are_noted(tmp_path, capsys):
    # the installation was edited after the waypoints were taught (its TCP is 0.1 m, they
    # were taught with 0.19 m): PolyScope takes the active TCP to the taught poses, so the
    # arm stands elsewhere than taught, which the report says
    program = tmp_path / "edited.urp"
    move = ('<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">'
            '<children>{}</children></Move>')
    program.write_text(_program(move.format(
        _taught("Home", "0.3, -1.2, 1.2, -1.5, -1.5, 0.0", "0.0, 0.0, 0.19, 0.0, 0.0, 0.0")),
        FLANGE_KINEMATICS))
    shutil.copy(DATA / "cell.installation", tmp_path / "default.installation")
    main(["check", str(program), "--json"])
    context = json.loads(capsys.readouterr().out)["context"]
    assert "the waypoints were taught with TCP p[0, 0, 0.19, 0, 0, 0], the installation's " \
           "active TCP is p[0, 0, 0.1, 0, 0, 0]" in context
    program.write_text(program.read_text().replace("0.0, 0.0, 0.19,", "0.0, 0.0, 0.1,"))
    main(["check", str(program), "--json"])
    assert "were taught with TCP" not in json.loads(capsys.readouterr().out)["context"]


def test_what_a_urcaps_function_gives_is_unknown_not_none(tmp_path, capsys):
    # with a URCap in the program, a function only its code defines stands in as a device:
    # what it returns (a pose the program then indexes) is unknown, not none
    program = tmp_path / "urcap.urp"
    program.write_text(_program(
        URCAP + '<Script type="Line"><expression>'
        + _chars("pose = p_rel(get_actual_tcp_pose(), p[0, 0, 0.1, 0, 0, 0])")
        + '</expression></Script><Script type="Line"><expression>'
        + _chars("pose[2] = pose[2] + 0.01") + "</expression></Script>"))
    assert main(["check", str(program), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "functions defined by code urdsl cannot generate, taken as devices: p_rel" in \
        report["context"]


@pytest.mark.parametrize(("named", "severity"), [(True, "error"), (False, "warning")])
def test_limits_a_taught_waypoint_lies_beyond_in_a_borrowed_installation(cell, capsys, named,
                                                                          severity):
    # the cell's waypoints were taught above z = 0.3 m: an installation with a ceiling there
    # was not in force when they were taught. A program that names no installation (a sample
    # program copied into a cell's folder) is checked with the one beside it, and such a
    # ceiling is a warning that says so; the installation the program names keeps it an error
    _with_safety(cell, _safety(plane="[0.0, 0.0, -1.0]"))
    if not named:
        text = cell.read_text(encoding="utf-8")
        cell.write_text(text.replace(' installation="cell" installationRelativePath="cell"', ""),
                        encoding="utf-8")
    main(["check", str(cell), "--json"])
    report = json.loads(capsys.readouterr().out)
    planes = [f for f in report["findings"] if f["code"] == "URS308"]
    assert planes and {f["severity"] for f in planes} == {severity}
    assert all(("was taught beyond this limit of cell.installation" in f["message"])
               == (severity == "warning") for f in planes)


def test_an_empty_robot_program_says_it_holds_only_the_placeholder(tmp_path, capsys):
    # a looping program saved before anything was put in it (project 53's test.urp): the
    # runaway loop it would be says first that the program is unfinished
    program = tmp_path / "test.urp"
    program.write_text(_program("<Placeholder/>", loops=True))
    assert main(["check", str(program)]) == 1
    out = capsys.readouterr().out
    assert "the Robot Program holds only PolyScope's <empty> placeholder" in out
    assert "URS207" in out and "hint: put the program's nodes in the Robot Program" in out
    # a loop of something that takes no time is the plain runaway loop
    program.write_text(_program(
        '<Script type="Line"><expression>' + _chars("x = 1") + "</expression></Script>",
        loops=True))
    assert main(["check", str(program)]) == 1
    out = capsys.readouterr().out
    assert "URS207" in out and "placeholder" not in out
