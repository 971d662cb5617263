"""PolyScope compile: what the projects of round eight (``tune8``) showed (urp13): PolyScope
3.11's markers, and an installation saved in PolyScope 3.4 compiled by a later PolyScope
(its payload's centre of gravity and the safety transition). Fixtures are written here; the
expected forms are what PolyScope wrote (Grzegorr/Paper-Potato-UR5 ``kg_client``, 3.11.0,
with an installation last saved in 3.4.5)."""

from __future__ import annotations

from test_polyscope_nodes5 import SWITCH_AND_THREAD
from test_polyscope_preamble import _blocks, _urp
from test_polyscope_variants import after, compiled


def test_polyscope_3_11_marks_cases_and_the_nodes_of_a_thread():
    # kg_client (3.11.0): 'switch_1 = var_2[1]', '$ 16 "Case 0"', 'if (0 == switch_1):',
    # '$ 22 "Case 1"' first in its 'elif'; '$ 199 "Loop thread_flag== False "' inside
    # 'thread Thread_1():'; no flags on any marker (3.12 on write them)
    lines = compiled(*SWITCH_AND_THREAD, version="3.11.0.82155")
    assert after(lines, "switch_1 = mode", 2) == ['$ 3 "Case 1"', "if (1 == switch_1):"]
    assert after(lines, "elif (2 == switch_1):", 1) == ['$ 5 "Case 2"']
    assert after(lines, "thread Thread():", 2) == ["while (True):", '$ 8 "Wait: 0.5"']
    assert not any(line.startswith("$") and line.endswith(('"breakAfter"', '"noBreak"'))
                   for line in lines)


def _installation(version: str, cog: str = "", hardness: str = "") -> bytes:
    return f"""<Installation toolOutputVoltage="24">
  <LastSavedInVersion projectName="PolyScope" major="{version[0]}" minor="{version[2:]}"
    bugfix="5"/>
  <com.ur.view.tcp.domain.TCPSettingsImpl activePose="TCP" toolPayload="0.4" {cog}>
    <availablePoses>
      <tcp name="TCP_1" offset="0.0, 0.0, 0.24, 0.0, 0.0, 0.0"/>
      <tcp name="TCP" offset="0.01, 0.0, 0.11, 0.0, 0.0, 0.0"/>
    </availablePoses>
  </com.ur.view.tcp.domain.TCPSettingsImpl>
  {hardness}
</Installation>""".encode()


def test_a_3_4_installation_without_centre_of_gravity_has_it_at_the_active_tcp():
    # kg_client: 'set_payload(0.0,[0.0,0.0,0.11])' where the installation (3.4.5) has
    # toolPayload="0.0" and no centerOfGravity, its active TCP at 0, 0, 0.11
    blocks = _blocks(_urp("3.11.0.82155"), _installation("3.4"))
    assert blocks["payload"] == ["set_payload(0.4, [0.01, 0.0, 0.11])"]
    # one that gives its centre keeps it (ryanpennings/RTDE_UR rtde_ext, 3.4)
    blocks = _blocks(_urp("3.11.0.82155"),
                     _installation("3.4", cog='centerOfGravity="0.0, 0.0, 0.0"'))
    assert blocks["payload"] == ["set_payload(0.4, [0.0, 0.0, 0.0])"]
    # saved in 3.5 or later: the mass alone (Sander-ONeil 3.5.0, 3.15.8 ×7)
    assert _blocks(_urp("3.11.0.82155"), _installation("3.5"))["payload"] == \
        ["set_payload(0.4)"]
    # an old PolyScope with its own installation: the mass alone (nedlecky/UR
    # KeyenceRobotVisionSample, 3.2: 'set_payload(0.0)')
    assert _blocks(_urp("3.2.20175"), _installation("3.2"))["payload"] == ["set_payload(0.4)"]


def test_an_installation_without_transition_hardness_is_hard_in_later_polyscope():
    # kg_client (3.11.0, installation saved in 3.4.5 without SmoothTransitionSettings):
    # 'set_safety_mode_transition_hardness(0)'; Sander-ONeil (3.5.0) writes none
    assert _blocks(_urp("3.11.0.82155"), _installation("3.4"))["safety"] == \
        ["set_safety_mode_transition_hardness(0)"]
    assert "safety" not in _blocks(_urp("3.5.0.10584"), _installation("3.4"))
    soft = '<SmoothTransitionSettings transitionHardness="SOFT"/>'
    assert _blocks(_urp("3.11.0.82155"), _installation("3.4", hardness=soft))["safety"] == \
        ["set_safety_mode_transition_hardness(1)"]
