"""The sans-I/O codecs: byte offsets against UR's published layouts, encode∘decode laws for
every message, streams split anywhere, and random or truncated input (rejected with
ProtocolError, never a crash or a hang)."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol import ProtocolError, dashboard, primary, realtime, rtde

finite = st.floats(-1e6, 1e6, allow_nan=False)
six = st.tuples(*[finite] * 6)


# ---- realtime -------------------------------------------------------------------------------


@pytest.mark.parametrize("size,offsets", [
    (1220, {"q_actual": 252, "tool_vector_actual": 444, "tcp_force": 540,
            "tool_vector_target": 588, "robot_mode": 756, "joint_modes": 764,
            "safety_mode": 812, "speed_scaling": 940, "program_state": 1052,
            "safety_status": 1108, "payload_mass": 1140}),
    (812, {"q_actual": 252, "tcp_force": 540, "tool_vector_actual": 588, "robot_mode": 756,
           "joint_modes": 764}),
])
def test_realtime_fields_sit_at_ur_s_byte_offsets(size, offsets):
    for name, offset in offsets.items():
        packet = bytearray(realtime.encode({}, size))
        struct.pack_into(">d", packet, offset, 7.0)
        value = getattr(realtime.decode(bytes(packet)), name)
        assert (value if not isinstance(value, tuple) else value[0]) == 7, name


@pytest.mark.parametrize("size,last", [(756, "test_value"), (764, "robot_mode"),
                                       (812, "joint_modes"), (1044, "v_actual"),
                                       (1060, "program_state"), (1108, "elbow_velocity"),
                                       (1116, "safety_status"), (1220, "payload_inertia")])
def test_every_known_size_decodes_its_whole_layout(size, last):
    state = realtime.decode(realtime.encode({}, size))
    assert last in state.fields and state.tail == b""


def test_a_field_the_layout_lacks_is_refused():
    with pytest.raises(ProtocolError, match="'robot_mode' does not fit in a 756-byte"):
        realtime.encode({"robot_mode": 7}, 756)


def test_an_unknown_longer_packet_keeps_its_tail():
    packet = realtime.encode({"q_actual": (1, 2, 3, 4, 5, 6)}, 1220)
    longer = struct.pack(">i", 1236) + packet[4:] + struct.pack(">dd", 1.5, 2.5)
    state = realtime.decode(longer)
    assert state.q_actual == (1, 2, 3, 4, 5, 6) and state.tail == struct.pack(">dd", 1.5, 2.5)


@settings(max_examples=60, deadline=None)
@given(six, six, st.integers(-1, 8), st.sampled_from(sorted(set(realtime.SIZES) - {756})))
def test_realtime_encode_decode(q, pose, mode, size):
    fields = {"q_actual": q, "tool_vector_actual": pose, "robot_mode": mode}
    state = realtime.decode(realtime.encode(fields, size))
    assert state.q_actual == q and state.tool_vector_actual == pose
    assert state.robot_mode == mode and state.size == size


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(1, 900), max_size=8))
def test_realtime_stream_split_anywhere(cuts):
    packets = [realtime.encode({"time": float(i)}, 1116) for i in range(3)]
    stream = b"".join(packets)
    decoder, times = realtime.RealtimeDecoder(), []
    position = 0
    for cut in sorted(cuts) + [len(stream)]:
        times += [s.time for s in decoder.feed(stream[position:cut])]
        position = max(position, cut)
    assert times == [0.0, 1.0, 2.0]
    assert realtime.RealtimeDecoder().latest(stream).time == 2.0


# ---- primary --------------------------------------------------------------------------------


def state_message(q, pose, mode) -> primary.RobotState:
    return primary.RobotState({
        0: primary.RobotModeData(12, True, True, True, False, False, True, False, mode, 0,
                                 1.0, 0.5, 1.0, b"\x00"),
        1: primary.JointData(q, q, (0.0,) * 6, (0.0,) * 6, (48.0,) * 6, (30.0,) * 6,
                             (0.0,) * 6, (253,) * 6),
        4: primary.CartesianInfo(pose, (0.0,) * 6),
        9: primary.RawPackage(9, b"\x01\x02\x03"),
    })


@settings(max_examples=40, deadline=None)
@given(six, six, st.integers(-1, 8))
def test_robot_state_encode_decode(q, pose, mode):
    message = state_message(q, pose, mode)
    assert primary.decode_message(primary.encode_robot_state(message)) == message


MESSAGES = [
    primary.VersionMessage(1, -2, "URControl", 5, 15, 0, 12345, "Jan 1 2026"),
    primary.TextMessage(2, -2, "hello ümlaut"),
    primary.LabelMessage(3, -2, 7, "Waypoint_1"),
    primary.PopupMessage(4, -2, 1, 0, True, False, False, "Title", "the text"),
    primary.SafetyModeMessage(5, -2, 209, 3, 3, 0, b""),
    primary.ErrorCodeMessage(6, -2, 100, 1, 2, 0, 0, "error text"),
    primary.KeyMessage(7, -2, 1, 2, "key", "pressed"),
    primary.RuntimeExceptionMessage(8, -2, 12, 5, "name 'x' is not defined"),
]


@pytest.mark.parametrize("message", MESSAGES, ids=lambda m: type(m).__name__)
def test_robot_messages_encode_decode(message):
    assert primary.decode_message(primary.encode_robot_message(message)) == message


def test_unknown_message_types_are_skipped_by_size():
    unknown = struct.pack(">iB", 9, 99) + b"abcd"
    known = primary.encode_robot_message(MESSAGES[1])
    decoded = primary.PrimaryDecoder().feed(unknown + known)
    assert isinstance(decoded[0], primary.RawMessage) and decoded[0].type == 99
    assert decoded[1] == MESSAGES[1]


# ---- RTDE ---------------------------------------------------------------------------------


def test_rtde_client_handshake_and_data_v2():
    client = rtde.RtdeClient()
    assert client.request_protocol_version(2) == struct.pack(">HBH", 5, 86, 2)
    assert client.feed(rtde.encode_package(86, b"\x01")) == [rtde.ProtocolVersion(True)]
    request = client.setup_outputs(["timestamp", "actual_q"], 500.0)
    assert request[3:11] == struct.pack(">d", 500.0) and request[11:] == b"timestamp,actual_q"
    (setup,) = client.feed(rtde.encode_package(79, b"\x01DOUBLE,VECTOR6D"))
    assert setup.valid and setup.recipe_id == 1
    payload = struct.pack(">Bd6d", 1, 0.5, *range(6))
    (data,) = client.feed(rtde.encode_package(85, payload))
    assert data.values == {"timestamp": 0.5, "actual_q": (0, 1, 2, 3, 4, 5)}


def test_rtde_v1_has_no_frequency_and_no_recipe_byte():
    client = rtde.RtdeClient()
    client.request_protocol_version(1)
    client.feed(rtde.encode_package(86, b"\x01"))
    assert client.setup_outputs(["timestamp"], 125.0)[3:] == b"timestamp"
    client.feed(rtde.encode_package(79, b"DOUBLE"))
    (data,) = client.feed(rtde.encode_package(85, struct.pack(">d", 2.0)))
    assert data.values == {"timestamp": 2.0}


def test_not_found_and_in_use():
    client = rtde.RtdeClient()
    client.request_protocol_version(2)
    client.feed(rtde.encode_package(86, b"\x01"))
    client.setup_outputs(["timestamp", "nope"])
    (setup,) = client.feed(rtde.encode_package(79, b"\x00DOUBLE,NOT_FOUND"))
    assert not setup.valid and setup.not_found == ["nope"]
    client.setup_inputs(["input_int_register_24"])
    (inputs,) = client.feed(rtde.encode_package(73, b"\x00IN_USE"))
    assert not inputs.valid and inputs.problems == ["input_int_register_24 (IN_USE)"]
    with pytest.raises(ProtocolError, match="not set up"):
        client.send_inputs(0, {"input_int_register_24": 1})


def test_rtde_text_messages_v1_and_v2():
    v2 = rtde.RtdeClient()
    v2.request_protocol_version(2)
    v2.feed(rtde.encode_package(86, b"\x01"))
    (message,) = v2.feed(rtde.encode_package(77, b"\x05hello\x03src\x02"))
    assert message == rtde.Message(2, "hello", "src")
    (old,) = rtde.RtdeClient().feed(rtde.encode_package(77, b"\x01oops"))
    assert old == rtde.Message(1, "oops")


def test_every_output_type_is_known():
    assert set(rtde.OUTPUTS.values()) <= set(rtde.TYPES)
    assert rtde.OUTPUTS["tool_output_voltage"] == "INT32"  # not a double (UR_FACTS §8.5)


# ---- dashboard ------------------------------------------------------------------------------


@pytest.mark.parametrize("command,line,ok,value", [
    ("robotmode", "Robotmode: RUNNING", True, "RUNNING"),
    ("safetymode", "Safetymode: PROTECTIVE_STOP", True, "PROTECTIVE_STOP"),
    ("running", "Program running: true", True, "true"),
    ("load pick.urp", "Loading program: pick.urp", True, "pick.urp"),
    ("load pick.urp", "File not found: pick.urp", False, None),
    ("play", "Failed to execute: play", False, None),
    ("power on", "Powering on", True, "Powering on"),
])
def test_dashboard_replies(command, line, ok, value):
    reply = dashboard.interpret(command, line)
    assert (reply.ok, reply.value) == (ok, value)


def test_dashboard_lines_split_anywhere():
    decoder = dashboard.LineDecoder()
    assert decoder.feed(b"Connected: Universal Robots Dash") == []
    assert decoder.feed(b"board Server\r\nRobotmode: ID") == [
        "Connected: Universal Robots Dashboard Server"]
    assert decoder.feed(b"LE\n") == ["Robotmode: IDLE"]
    with pytest.raises(ProtocolError):
        dashboard.encode_command("play\nstop")


# ---- fuzzing: reject, never crash or hang -----------------------------------------------------


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=3000))
def test_random_bytes_never_crash_the_decoders(data):
    for feed in (realtime.RealtimeDecoder().feed, primary.PrimaryDecoder().feed,
                 rtde.RtdeClient().feed, dashboard.LineDecoder().feed):
        try:
            feed(data)
        except ProtocolError:
            pass


@settings(max_examples=100, deadline=None)
@given(st.data())
def test_truncated_and_corrupted_messages_are_rejected(data):
    whole = [realtime.encode({"time": 1.0}, 1116),
             primary.encode_robot_state(state_message((0.0,) * 6, (0.0,) * 6, 7)),
             *(primary.encode_robot_message(m) for m in MESSAGES)]
    message = data.draw(st.sampled_from(whole))
    cut = data.draw(st.integers(0, len(message) - 1))
    flip = data.draw(st.integers(0, len(message) - 1))
    corrupted = bytearray(message)
    corrupted[flip] ^= data.draw(st.integers(1, 255))
    for candidate in (message[:cut], bytes(corrupted)):
        for decode in (realtime.decode, primary.decode_message):
            try:
                decode(candidate)
            except ProtocolError:
                pass
