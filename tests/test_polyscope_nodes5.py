"""PolyScope compile: node variants found in the tune5 projects (bench/polyscope/pairs.tsv),
each as a fixture written for the test (the real programs are referenced, not copied)."""

from __future__ import annotations

from test_polyscope_variants import after, compiled


def test_a_set_node_with_a_payload_sets_it_after_its_action():
    # San28-cardenas/RBTC_MANIPULACION program3 (3.15.8): ``set_standard_digital_out(0,
    # True)`` then ``set_payload(1.0)``; loryburgess/Regal-Rexnord Main (3.12.1): a
    # NoAction Set with a payload is its marker and ``set_payload(1.5)``
    lines = compiled("""
        <Set type="DigitalOutput" payload="1.0" tcpAsCog="true">
          <pin referencedName="digital_out[0]"/>
          <digitalValue>1</digitalValue>
        </Set>
        <Set type="NoAction" payload="0.0" tcpAsCog="true"/>
        <Set type="DigitalOutput">
          <pin referencedName="digital_out[0]"/>
          <digitalValue>0</digitalValue>
        </Set>""")
    assert after(lines, '$ 2 "Set digital_out[0]=On"', 2) == [
        "set_standard_digital_out(0, True)", "set_payload(1.0)"]
    assert after(lines, '$ 3 "Set"', 1) == ["set_payload(0.0)"]
    # a Set without a payload sets none
    assert after(lines, '$ 4 "Set digital_out[0]=Off"', 1) == [
        "set_standard_digital_out(0, False)"]
    assert not any(line.startswith("set_payload") for line in
                   after(lines, '$ 4 "Set digital_out[0]=Off"', 3))


SWITCH_AND_THREAD = ("""
        <Switch>
          <expression><ExpressionToken token="mode"/></expression>
          <children>
            <Case caseValue="1"><children>
              <Wait type="Sleep"><waitTime>0.1</waitTime></Wait></children></Case>
            <Case caseValue="2"><children>
              <Wait type="Sleep"><waitTime>0.2</waitTime></Wait></children></Case>
          </children>
        </Switch>""", """<Thread><children>
          <Wait type="Sleep"><waitTime>0.5</waitTime></Wait></children></Thread>""")


def test_polyscope_3_10_writes_no_marker_for_cases_and_in_threads():
    # alan1982br/gs1_carnaval_Photobooth_robot_arm_UR (3.10.1): '$ 11 "Robot Program"',
    # ``switch_1 = Sel`` followed by ``if (1 == switch_1):`` and ``elif (2 == switch_1):``
    # with no "Case" marker, and a Thread node's body without markers (its own marker
    # '$ 82 "Thread_1"' numbered after the Robot Program's nodes; the fixture's is "Thread")
    lines = compiled(*SWITCH_AND_THREAD, version="3.10.1.76190")
    assert lines[lines.index("switch_1 = mode") + 1] == "if (1 == switch_1):"
    assert after(lines, "if (1 == switch_1):", 2) == ['$ 4 "Wait: 0.1"', "sleep(0.1)"]
    assert after(lines, "elif (2 == switch_1):", 2) == ['$ 6 "Wait: 0.2"', "sleep(0.2)"]
    assert after(lines, '$ 7 "Thread"', 3) == ["thread Thread():", "while (True):",
                                                  "sleep(0.5)"]
    assert '$ 1 "Robot Program"' in lines
    # 3.12.1 (kg398/kg_ursim) writes both, as 5.x does
    lines = compiled(*SWITCH_AND_THREAD, version="3.12.1.90940")
    assert after(lines, "switch_1 = mode", 2) == ['$ 3 "Case 1"', "if (1 == switch_1):"]
    assert after(lines, "elif (2 == switch_1):", 1) == ['$ 5 "Case 2"']
    assert after(lines, "thread Thread():", 2) == ["while (True):", '$ 8 "Wait: 0.5"']


def test_a_set_node_of_a_modbus_output_signal():
    # alan1982br/gs1_carnaval_Photobooth_robot_arm_UR venosa draft3 (3.10.1):
    # '$ 26 "Set vid_fim=On"' then ``modbus_set_output_signal("vid_fim", True)``
    lines = compiled("""
        <Set type="DigitalOutput"><pin referencedName="BRUSH"/>
          <digitalValue>1</digitalValue></Set>""")
    assert after(lines, '$ 2 "Set BRUSH=On"', 1) == ['modbus_set_output_signal("BRUSH", True)']
