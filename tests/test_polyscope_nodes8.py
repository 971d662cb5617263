"""PolyScope compile: what the projects of round seven (``tune7``) showed (urp12): PolyScope
5 before 5.6 and its markers, PolyScope 3's suppressed nodes, relative waypoints and Force
nodes, and 3.4's Script file nodes. Fixtures are written here; the expected forms are what
PolyScope wrote."""

from __future__ import annotations

import pytest
from test_polyscope_nodes3 import OLD_NODES
from test_polyscope_nodes6 import FORCE
from test_polyscope_variants import WAYPOINT, WAYPOINT_MOVE, compiled


def markers(lines: list[str]) -> list[str]:
    return [line for line in lines if line.startswith("$")]


@pytest.mark.parametrize("version", ["5.4.2.76197", "5.5.1.82186"])
def test_polyscope_5_before_5_6_writes_markers_without_flags(version):
    # Multi-Access-Edge-Computing-Playground rtde_control_loop (5.4.2) '$ 3 "Waypoint_1"',
    # nagmik/URCap-Webservice example-1 (5.5.1) '$ 3 "Waypoint_1"' before each movej
    assert markers(compiled(WAYPOINT_MOVE, version=version)) == [
        '$ 1 "Robot Program"', '$ 2 "MoveJ"', '$ 3 "Start"']


def test_polyscope_5_7_on_flags_a_waypoint_marker():
    assert markers(compiled(WAYPOINT_MOVE, version="5.7.0.90932"))[-1] == \
        '$ 3 "Start" "breakAfter"'


def test_polyscope_5_before_5_6_still_marks_the_nodes_in_a_thread():
    # nagmik example-1 (5.5.1): '$ 6 "Thread_1"', then '$ 7 "Wait: 0.5"' inside it
    thread = """<Thread><children>
        <Wait type="Sleep"><waitTime>0.5</waitTime></Wait></children></Thread>"""
    lines = compiled(WAYPOINT_MOVE, others=thread, version="5.5.1.82186")
    assert '$ 5 "Wait: 0.5"' in lines


SUPPRESSED = f"""
        <SuppressedNode>
          <suppressedNode class="Move" motionType="MoveJ" speed="1.05" acceleration="1.4"
                          useActiveTCP="true">
            <children>{WAYPOINT.format(name="Old")}</children>
          </suppressedNode>
        </SuppressedNode>
        <Wait type="Sleep"><waitTime>0.01</waitTime></Wait>"""


def test_polyscope_3_5_numbers_a_suppressed_node_as_one():
    # jmtc7 7_4_pruebas_modbus (3.5.4): a suppressed MoveJ holding a waypoint is $ 2 alone;
    # the node after it is '$ 3'
    lines = compiled(SUPPRESSED, version="3.5.4.10845")
    assert markers(lines) == ['$ 1 "Robot Program"', '$ 3 "Wait: 0.01"']


@pytest.mark.parametrize("version", ["3.15.4.106291", "5.11.5"])
def test_later_polyscope_numbers_every_node_in_a_suppressed_one(version):
    # 3.15 (Usaakm, PakBot) and 5.x number the suppressed MoveJ and its waypoint
    assert markers(compiled(SUPPRESSED, version=version))[-1].startswith('$ 4 "Wait: 0.01"')


def test_polyscope_3_force_does_not_zero_a_force_sensor():
    # ati-ia (3.15.6), ic-sw1821 (3.15.8): 'sleep(0.02)' then force_mode(…); PolyScope 5
    # zeroes the e-Series sensor in between
    body = WAYPOINT_MOVE
    old = compiled(FORCE.format(body=body), version="3.15.8.106339")
    at = old.index("sleep(0.02)")
    assert old[at + 1].startswith("force_mode(")
    assert "zero_ftsensor()" not in old
    new = compiled(FORCE.format(body=body))
    assert new[new.index("sleep(0.02)") + 1] == "zero_ftsensor()"


def test_polyscope_3_4_marks_a_script_file():
    # ryanpennings/RTDE_UR rtde_2 (3.4.0): '$ 8 "Script: int"' before the file's code;
    # 3.2 writes none (test_polyscope_nodes3)
    lines = compiled(OLD_NODES, version="3.4.0.30319")
    assert '$ 2 "Script: hello.script"' in lines
    assert lines[lines.index('$ 2 "Script: hello.script"') + 1] == "def hello():"
