"""PolyScope programs sent and played: ``urdsl send X.urp`` (compiled, checked, sent) and the
virtual controller's dashboard ``load X.urp`` / ``play``, over loopback."""

from __future__ import annotations

import numpy as np
import pytest
from _robot_fakes import LOOPBACK, FakeController, FakeServer
from _sim_clients import Dashboard, wait_until

from urdsl.cli import main
from urdsl.sim.controller import VirtualController
from urdsl.sim.servers import STANDARD_PORTS

TIMEOUT = 5.0
TARGET = [0.6, -1.4, 1.3, -1.5, -1.6, 0.2]


def _move_program(joints=TARGET, extra: str = "") -> str:
    """A PolyScope 5 program: MoveJ to one fixed waypoint (by its joint angles), then
    ``extra`` nodes; runs once."""
    angles = ", ".join(str(v) for v in joints)
    return f"""<URProgram name="go" installation="default" createdIn="5.11.1" lastSavedIn="5.11.1">
  <kinematics status="LINEARIZED" validChecksum="true">
    <deltaTheta value="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
    <a value="0.0, -0.425, -0.3922, 0.0, 0.0, 0.0"/>
    <d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>
    <alpha value="1.5707963267948966, 0.0, 0.0, 1.5707963267948966, -1.5707963267948966, 0.0"/>
  </kinematics>
  <children>
    <MainProgram runOnlyOnce="true">
      <children>
        <Move motionType="MoveJ" speed="1.0471975511965976"
              acceleration="1.3962634015954636" useActiveTCP="true">
          <children>
            <Waypoint type="Fixed" name="Waypoint_1" kinematicsFlags="3">
              <motionParameters/>
              <position>
                <JointAngles angles="{angles}"/>
                <TCPOffset pose="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
              </position>
              <BaseToFeature pose="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
            </Waypoint>
          </children>
        </Move>{extra}
      </children>
    </MainProgram>
  </children>
</URProgram>
"""


# ---- the virtual controller's dashboard ------------------------------------------------------


@pytest.fixture
def sim(tmp_path):
    (tmp_path / "go.urp").write_text(_move_program())
    (tmp_path / "broken.urp").write_bytes(b"\x1f\x8b not a program")
    (tmp_path / "alone.urp").write_text(_move_program(
        extra='<Set type="DigitalOutput"><pin referencedName="gripper"/>'
              '<digitalValue>1</digitalValue></Set>'))  # its installation is not there
    with VirtualController(speed=2.0, programs_dir=tmp_path) as controller:
        with controller.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
            controller.servers = servers
            yield controller


def test_dashboard_loads_and_plays_a_polyscope_program(sim):
    dash = Dashboard(sim)
    try:
        assert dash.ask("load go.urp") == "Loading program: go.urp"
        assert dash.ask("get loaded program") == "Loaded program: go.urp"
        assert dash.ask("play") == "Starting program"
        assert wait_until(lambda: np.allclose(sim.snapshot().q, TARGET, atol=1e-6))
        assert wait_until(lambda: dash.ask("running") == "Program running: false")
        assert dash.ask("load broken.urp") == "Error while loading program: broken.urp"
        assert dash.ask("load absent.urp") == "File not found: absent.urp"
        assert dash.ask("load alone.urp") == "Error while loading program: alone.urp"
    finally:
        dash.close()


# ---- urdsl send ------------------------------------------------------------------------------


def _runs(ticks: int = 3):
    def behaviour(program: str):
        return [("run", ticks)]
    return behaviour


def test_send_compiles_checks_and_sends_a_polyscope_program(tmp_path, capsys):
    program = tmp_path / "go.urp"
    program.write_text(_move_program())
    fake = FakeController(_runs())
    with FakeServer(fake.primary, connections=4) as server:
        status = main(["send", str(program), "--host", LOOPBACK, "--port", str(server.port),
                       "--timeout", "5"])
    err = capsys.readouterr().err
    assert status == 0, err
    assert f"checked {program} (compiled) on ur5e: no errors" in err
    assert "calibration of the program's <kinematics>" in err
    assert len(fake.programs) == 1
    sent = fake.programs[0]
    assert sent.startswith("def go():") and '$ 2 "MoveJ"' in sent and "movej(" in sent


def test_send_refuses_a_polyscope_program_the_check_rejects(tmp_path, capsys):
    program = tmp_path / "bad.urp"
    chars = "".join(f'<ExpressionChar character="{c}"/>' for c in "x = 1 / 0")
    program.write_text(_move_program(extra=f'<Script type="Line"><expression>{chars}'
                                     '</expression></Script>'))
    fake = FakeController(_runs())
    with FakeServer(fake.primary, connections=4) as server:
        status = main(["send", str(program), "--host", LOOPBACK, "--port", str(server.port)])
    err = capsys.readouterr().err
    assert status == 1 and not fake.programs  # nothing sent
    assert "node Robot Program > Script" in err and "URS2" in err


def test_send_of_a_program_that_cannot_be_compiled_is_one_message(tmp_path, capsys):
    program = tmp_path / "nowhere.urp"
    program.write_text(_move_program(extra='<Set type="DigitalOutput"><pin referencedName='
                                     '"nowhere"/><digitalValue>1</digitalValue></Set>'))
    assert main(["send", str(program), "--host", LOOPBACK, "--port", "9", "--dry-run"]) == 1
    err = capsys.readouterr().err
    # 'nowhere' may be a name of the installation, which is not there: read, checked and
    # linted as an unknown value, but never sent
    assert f"{program}: not sent: nowhere (an I/O) only in the installation" in err
    assert "Traceback" not in err


def test_send_dry_run_prints_the_compiled_program(tmp_path, capsys):
    program = tmp_path / "go.urp"
    program.write_text(_move_program())
    assert main(["send", str(program), "--host", LOOPBACK, "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("def go():") and "Waypoint_1_p" in out
