"""Reading PolyScope installations: TCPs, payload, mounting; gzip or plain; bad files.

The fixtures are written here after the layouts PolyScope 1.x, 3.x and 5.x save (no real
installation is copied)."""

from __future__ import annotations

import gzip
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.polyscope.installation import (
    InstallationError,
    find_installation,
    parse_installation,
    read_installation,
)

E_SERIES = b"""<Installation directory="/programs/cell" fileName="cell">
  <IOs><DigitalInputNames value="a, b"/><SomethingNew flag="1"/></IOs>
  <Version projectName="URSoftware" major="5" minor="9" bugfix="4"/>
  <LastSavedInVersion projectName="URSoftware" major="5" minor="11" bugfix="9"/>
  <PayloadSettings>
    <Payload name="Empty" mass="0.5" defaultPayload="false" centerOfGravity="0, 0, 0.01"/>
    <Payload name="Gripper" mass="2.72" defaultPayload="true"
             centerOfGravity="-0.067, 0.195, 0.106"/>
  </PayloadSettings>
  <TCPSettings activePose="Torch">
    <availablePoses>
      <tcp id="a" name="Flange" offset="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
      <tcp id="b" name="Torch" offset="0.001, 0.01, 0.31, -0.5, -0.48, 1.44"/>
    </availablePoses>
  </TCPSettings>
  <SafetySettings>
[SafetyLimits Normal Values]
maxTcpSpeed = 1.5
  </SafetySettings>
  <Features><CameraView><worldTransform class="WorldTransform">
    <WorldtoMarshal showAxes="false" baseAngle="0.7853981633974483"
                    tiltAngle="3.141592653589793"/>
  </worldTransform></CameraView></Features>
  <Contributions><URCaps><Contributed ownerId="x" id="y"><data key="k" value="v"/>
  </Contributed></URCaps></Contributions>
</Installation>
"""

CB3 = b"""<Installation directory="/programs" fileName="default">
  <Version projectName="Polyscope" major="3" minor="2" bugfix="20175"/>
  <TCPSettings activePose="TCP" toolPayload="1.2">
    <availablePoses><tcp id="c" name="TCP" offset="0.0, 0.0, 0.15, 0.0, 0.0, 0.0"/>
    </availablePoses>
  </TCPSettings>
  <Features><CameraView><worldTransform class="WorldTransform">
    <WorldtoMarshal baseAngle="1.5707963267948966" tiltAngle="0.0"/>
  </worldTransform></CameraView></Features>
</Installation>
"""

CB2 = b"""<gui.installation.RobotInstallation>
  <featureContainer><x><mountingBaseAngle>0.0</mountingBaseAngle></x></featureContainer>
  <mountingTiltAngle>1.5707963267948966</mountingTiltAngle>
  <tcpTransform><double>0.0</double><double>0.0</double><double>0.1</double>
    <double>0.0</double><double>0.0</double><double>0.0</double></tcpTransform>
  <toolPayload>0.75</toolPayload>
</gui.installation.RobotInstallation>
"""


@pytest.mark.parametrize("compress", [False, True], ids=["plain", "gzip"])
def test_e_series_tcp_payload_mounting_and_version(compress):
    data = gzip.compress(E_SERIES) if compress else E_SERIES
    setup = parse_installation(data, "cell.installation")
    assert [t.name for t in setup.tcps] == ["Flange", "Torch"]
    assert setup.tcp.name == "Torch"
    assert setup.tcp.offset == (0.001, 0.01, 0.31, -0.5, -0.48, 1.44)
    assert setup.payload.name == "Gripper" and setup.payload.mass == 2.72
    assert setup.payload.cog == (-0.067, 0.195, 0.106)
    assert setup.version == "5.11.9"
    assert setup.mounting == pytest.approx((math.pi / 4, math.pi))
    # ceiling mounted: gravity points along +z of the base; as PolyScope writes set_gravity
    assert setup.gravity == pytest.approx((0.0, 0.0, -9.82), abs=1e-12)


def test_cb3_payload_on_the_tcp_settings_and_floor_mounting():
    setup = parse_installation(gzip.compress(CB3), "default.installation")
    assert setup.tcp.offset == (0.0, 0.0, 0.15, 0.0, 0.0, 0.0)
    assert setup.payload.mass == 1.2 and setup.payload.cog is None
    assert setup.version == "3.2.20175"
    assert setup.gravity == pytest.approx((0.0, 0.0, 9.82))


def test_cb2_serialised_installation():
    setup = parse_installation(gzip.compress(CB2), "old.installation")
    assert setup.tcp.offset == (0.0, 0.0, 0.1, 0.0, 0.0, 0.0)
    assert setup.payload.mass == 0.75
    assert setup.gravity == pytest.approx((9.82, 0.0, 0.0), abs=1e-12)   # wall mounted


def test_an_installation_without_tcp_or_payload_reads_as_empty():
    setup = parse_installation(b"<Installation/>", "bare.installation")
    assert setup.tcp is None and setup.payload is None and setup.mounting is None
    assert setup.gravity is None


@pytest.mark.parametrize("data, reason", [
    (gzip.compress(E_SERIES)[:60], "truncated"),
    (b"\x1f\x8b" + b"\x00" * 40, "corrupt"),
    (E_SERIES[:300], "not well-formed XML"),
    (b"<urp><Program/></urp>", "not a PolyScope installation (root element <urp>)"),
    (b"", "not well-formed XML"),
    (b"\x00\x01binary", "not well-formed XML"),
    (E_SERIES.replace(b'offset="0.0, 0.0, 0.0, 0.0, 0.0, 0.0"', b'offset="0, 0, x"'),
     "TCP 'Flange' offset is not 6 numbers"),
    (E_SERIES.replace(b'mass="2.72"', b'mass="nan"'), "payload 'Gripper' mass is not 1 finite"),
    (b'<!DOCTYPE x [<!ENTITY a "aaaa">]><Installation/>', "DOCTYPE or entities"),
])
def test_bad_files_are_one_clear_error_naming_the_file(data, reason):
    with pytest.raises(InstallationError) as error:
        parse_installation(data, "robot/default.installation")
    assert str(error.value).startswith("robot/default.installation: ")
    assert reason in str(error.value)


def test_reading_a_missing_file_names_it(tmp_path):
    with pytest.raises(InstallationError, match="nothere.installation: cannot read"):
        read_installation(tmp_path / "nothere.installation")


def test_the_installation_beside_a_program(tmp_path):
    program = tmp_path / "pick.script"
    program.write_text("textmsg(1)\n")
    assert find_installation(program) is None
    (tmp_path / "cell.installation").write_bytes(CB3)
    assert find_installation(program).name == "cell.installation"     # the only one
    (tmp_path / "default.installation").write_bytes(CB3)
    assert find_installation(program).name == "default.installation"
    (tmp_path / "pick.installation").write_bytes(CB3)
    assert find_installation(program).name == "pick.installation"     # named like the program
    assert read_installation(find_installation(program)).tcp.offset[2] == 0.15


@settings(max_examples=60, deadline=None)
@given(cut=st.integers(0, 10_000), flip=st.integers(0, 10_000), compress=st.booleans())
def test_law_a_damaged_file_reads_or_fails_with_the_one_clear_error(cut, flip, compress):
    data = bytearray(gzip.compress(E_SERIES) if compress else E_SERIES)
    if flip < len(data):
        data[flip] ^= 0x55
    data = data[:cut] if cut < len(data) else data
    try:
        setup = parse_installation(bytes(data), "x.installation")
    except InstallationError as error:
        assert str(error).startswith("x.installation: ")
    else:
        assert setup.path == "x.installation"
