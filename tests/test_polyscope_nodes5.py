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
