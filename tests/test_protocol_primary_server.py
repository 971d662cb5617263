"""The controller's side of the primary and secondary interfaces (``PrimaryServer``) and the
script framing it shares with the realtime port: what a client connecting to 30001/30002
receives first, when robot states are due, where robot messages go, how script text is cut."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol import primary as p
from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.script_framing import ScriptFramer

VERSION = p.VersionMessage(major=5, minor=15, bugfix=0, build_number=1, build_date="today")
STATE = p.RobotState((p.RobotModeData(variant="3.5", robot_mode=7, reserved=0,
                                      target_speed_fraction_limit=1.0),))


def test_a_client_gets_the_version_message_first_then_the_state():
    server = p.PrimaryServer(VERSION)
    messages = p.PrimaryDecoder().feed(server.greeting(STATE))
    assert [type(m) for m in messages] == [p.VersionMessage, p.RobotState]
    assert messages[0].version == (5, 15, 0)
    assert messages[1].robot_mode_data.robot_mode == 7
    # already encoded messages go out as they are (a host serving many clients encodes once)
    assert p.PrimaryServer(VERSION.encode()).greeting(STATE.encode()) == server.greeting(STATE)


def test_robot_messages_go_out_on_the_primary_interface_only():
    text = p.TextMessage(text="hello")
    assert p.PrimaryServer(VERSION).robot_message(text) == text.encode()
    assert p.PrimaryServer(VERSION, read_only=True).robot_message(text) == text.encode()
    assert p.PrimaryServer(VERSION, interface="secondary").robot_message(text) == b""


def test_script_text_is_cut_into_programs_and_read_only_ports_take_none():
    text = b"textmsg(1)\ndef a():\n  x = 1\nend\nsec b():\n"
    server = p.PrimaryServer(VERSION, interface="secondary")
    assert [c.kind for c in server.receive_data(text)] == ["bare", "def"]
    assert server.framer.pending  # sec b() has not ended: cut off if the connection ends
    assert [c.text for c in server.receive_data(b"  y = 2\nend\n")] == [
        "sec b():\n  y = 2\nend\n"]
    read_only = p.PrimaryServer(VERSION, read_only=True)
    assert read_only.receive_data(text) == [] and read_only.framer is None


def test_a_program_over_the_limit_is_a_protocol_error_of_the_port():
    server = p.PrimaryServer(VERSION, script_limit=100)
    with pytest.raises(ProtocolError, match="primary: a program larger than 100 bytes"):
        server.receive_data(b"def p():\n" + b"  x = 1\n" * 20)
    framer = ScriptFramer(limit=100, interface="realtime")
    with pytest.raises(ProtocolError, match="realtime: a line longer than 100 bytes"):
        for _ in range(20):  # a line without its newline, in pieces
            framer.feed(b"x" * 10)


def test_states_are_due_on_the_period_grid_and_missed_ones_are_not_owed():
    server = p.PrimaryServer(VERSION, period=0.1)
    due = [t for t in (5.05, 5.06, 5.0999, 5.1, 5.15, 5.2001, 5.35, 5.39, 5.4)
           if server.state_due(t)]
    assert due == [5.05, 5.1, 5.2001, 5.35, 5.4]
    greeted = p.PrimaryServer(VERSION, period=0.1)
    greeted.greeting(STATE, now=5.05)  # the greeting carried a state: the next at 5.1
    assert not greeted.state_due(5.06) and greeted.until_state(5.06) == pytest.approx(0.04)
    assert greeted.state_due(5.1) and greeted.until_state(5.1) == pytest.approx(0.1)


@settings(max_examples=80, deadline=None)
@given(st.lists(st.floats(min_value=0.0001, max_value=0.05), min_size=1, max_size=60),
       st.floats(min_value=0, max_value=0.3))
def test_connections_opened_at_different_times_get_their_states_together(steps, opened):
    # the host's clock steps by less than a period; one connection exists from 0, the other
    # from ``opened``: once both exist, they are due at the same calls (one encoding serves)
    first, second = p.PrimaryServer(VERSION), p.PrimaryServer(VERSION)
    now = 0.0
    first.greeting(STATE, now=now)
    greeted = False
    for step in steps:
        now += step
        if not greeted and now >= opened:
            second.greeting(STATE, now=now)
            greeted = True
            first.state_due(now)
            continue
        if greeted:
            assert first.state_due(now) == second.state_due(now)


def test_a_connection_is_primary_or_secondary_with_a_positive_period():
    with pytest.raises(ValueError, match="'primary' or 'secondary'"):
        p.PrimaryServer(VERSION, interface="realtime")
    with pytest.raises(ValueError, match="period must be > 0"):
        p.PrimaryServer(VERSION, period=0.0)
