"""Primary/secondary interface: framing, robot state sub-packages, robot messages."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol._binary import Group, Row, Table
from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.primary import (
    ROBOT_MESSAGES,
    SUB_PACKAGES,
    AdditionalInfo,
    CalibrationData,
    CartesianInfo,
    JointData,
    KeyMessage,
    KinematicsInfo,
    MasterboardData,
    PopupMessage,
    PrimaryDecoder,
    RobotModeData,
    RobotState,
    RuntimeExceptionMessage,
    SafetyData,
    SafetyModeMessage,
    TextMessage,
    UnknownMessage,
    UnknownPackage,
    UnknownRobotMessage,
    VersionMessage,
    decode_primary,
    encode_primary,
)

# --- fixtures built by hand from UR's documented layouts (docs/controller-facts.md §11) -----------

Q = (0.1, -1.2, 1.3, -1.7, -1.5, 0.4)


def sub(kind: int, payload: bytes) -> bytes:
    return struct.pack(">IB", len(payload) + 5, kind) + payload


def message(kind: int, body: bytes) -> bytes:
    return struct.pack(">iB", len(body) + 5, kind) + body


def robot_mode_payload_35() -> bytes:
    # uint64 timestamp; 7 bools; int8 robotMode; uint8 controlMode; 3 doubles; uint8 reserved
    return struct.pack(">Q7?bBdddB", 123456, True, True, True, False, False, True, False,
                       7, 0, 1.0, 0.5, 1.0, 0)


def joint_payload() -> bytes:
    return b"".join(struct.pack(">dddffffB", q, q + 0.01, 0.2, 1.5, 48.0, 30.0, 35.0, 253)
                    for q in Q)


def cartesian_payload() -> bytes:
    return struct.pack(">12d", 0.4, -0.1, 0.3, 2.2, 2.2, 0.0, 0, 0, 0.15, 0, 0, 0)


def test_cb3_robot_state_fixture():
    data = message(16, sub(0, robot_mode_payload_35()) + sub(1, joint_payload())
                   + sub(4, cartesian_payload()) + sub(99, b"\x01\x02"))
    assert len(sub(0, robot_mode_payload_35())) == 47  # the documented 3.5+/5.x size
    assert len(sub(1, joint_payload())) == 251
    assert len(sub(4, cartesian_payload())) == 101
    state = decode_primary(data)
    assert isinstance(state, RobotState)
    mode = state.robot_mode_data
    assert (mode.variant, mode.timestamp, mode.robot_mode, mode.speed_scaling) == (
        "3.5", 123456, 7, 0.5)
    assert mode.is_robot_power_on and mode.is_program_running and not mode.is_program_paused
    joints = state.joint_data
    assert joints.q_actual == Q
    assert joints.joint_mode == (253,) * 6
    assert joints.v_actual == (48.0,) * 6
    assert state.cartesian_info.tcp_pose == (0.4, -0.1, 0.3, 2.2, 2.2, 0.0)
    assert state.cartesian_info.tcp_offset[2] == 0.15
    assert state.packages[-1] == UnknownPackage(variant="raw", type=99, payload_bytes=b"\x01\x02")
    assert encode_primary(state) == data


@pytest.mark.parametrize(("payload", "variant", "limit"), [
    (robot_mode_payload_35()[:33], "3.0", None),
    (robot_mode_payload_35()[:41], "3.2", 1.0),
])
def test_older_robot_mode_layouts(payload, variant, limit):
    (mode,) = RobotState.decode_body(sub(0, payload)).packages
    assert mode.variant == variant and mode.target_speed_fraction_limit == limit
    assert mode.speed_scaling == 0.5


def test_kinematics_info_carries_the_calibration():
    payload = struct.pack(">6I24dI", *range(1, 7), *([0.001] * 6), *([-0.425] * 6),
                          *([0.089] * 6), *([1.5708] * 6), 1)
    assert len(payload) + 5 == 225
    (info,) = RobotState.decode_body(sub(5, payload)).packages
    assert isinstance(info, KinematicsInfo)
    assert info.checksum == (1, 2, 3, 4, 5, 6) and info.calibration_status == 1
    assert info.dh_a == (-0.425,) * 6 and info.dh_theta == (0.001,) * 6


def test_masterboard_with_and_without_euromap():
    head = struct.pack(">IIBBddbbddffffB??", 0b101, 0b10, 0, 1, 0.5, 0.7, 0, 1, 0.1, 0.2,
                       35.0, 48.0, 1.2, 0.1, 1, False, True)
    euromap = struct.pack(">IIff", 3, 4, 24.0, 0.5)
    tail = struct.pack(">IB?B", 0, 1, True, 0)  # e-Series
    (board,) = RobotState.decode_body(sub(3, head + euromap + tail)).packages
    assert isinstance(board, MasterboardData)
    assert board.variant == "5.0" and board.digital_input_bits == 5
    assert (board.euromap_input_bits, board.euromap_voltage_24v) == (3, 24.0)
    assert board.three_position_enabling_device_input is True
    head_no_euromap = head[:-1] + b"\x00"
    (cb3,) = RobotState.decode_body(sub(3, head_no_euromap + tail[:6])).packages
    assert cb3.variant == "3.2" and cb3.euromap_input_bits is None and cb3.reserved_2 is None


def test_runtime_exception_fixture():
    text = "compile_error_name_not_found:foo:"
    data = message(20, struct.pack(">QbBII", 99, -2, 10, 12, 5) + text.encode())
    error = decode_primary(data)
    assert isinstance(error, RuntimeExceptionMessage)
    assert (error.line, error.column, error.text, error.source) == (12, 5, text, -2)
    assert encode_primary(error) == data


def test_version_message_fixture_and_pre_312_layout():
    new = message(20, struct.pack(">QbBb9sBBii", 0, -2, 3, 9, b"URControl", 5, 11, 1, 108318)
                  + b"13-01-2022, 10:00:00")
    version = decode_primary(new)
    assert (version.project_name, version.version, version.build_number) == (
        "URControl", (5, 11, 1), 108318)
    assert version.build_date == "13-01-2022, 10:00:00"
    old = message(20, struct.pack(">QbBb9sBBi", 0, -2, 3, 9, b"URControl", 3, 1, 18024)
                  + b"12-11-2015, 11:32:04")
    version = decode_primary(old)
    assert version.version == (3, 1, 18024) and version.build_number is None
    assert encode_primary(version) == old


def test_key_and_popup_fixtures():
    key = message(20, struct.pack(">QbBiiB", 1, 7, 7, 4, 0, 6) + b"PROGRAMstarted")
    decoded = decode_primary(key)
    assert isinstance(decoded, KeyMessage)
    assert (decoded.title, decoded.text) == ("PROGRA", "Mstarted")
    popup = message(20, struct.pack(">QbBII???B", 1, -3, 2, 7, 8, True, False, True, 5)
                    + b"Hello" + b"World")
    decoded = decode_primary(popup)
    assert isinstance(decoded, PopupMessage)
    assert (decoded.title, decoded.text, decoded.warning, decoded.blocking) == (
        "Hello", "World", True, True)


def test_unknown_types_are_kept_raw():
    for data, cls in [(message(25, b"\x00\x01garbage"), UnknownMessage),
                      (message(20, struct.pack(">QbB", 1, 2, 42) + b"??"), UnknownRobotMessage)]:
        decoded = decode_primary(data)
        assert isinstance(decoded, cls)
        assert encode_primary(decoded) == data


@pytest.mark.parametrize(("data", "reason"), [
    (b"\x00\x00", "cannot hold the 5-byte message header"),
    (message(16, b"")[:4], "cannot hold"),
    (struct.pack(">iB", 3, 16), "size field says 3 bytes"),
    (struct.pack(">iB", 1 << 30, 16), "size field says 1073741824 bytes"),
    (message(16, struct.pack(">IB", 300, 1) + b"x" * 10), "says 300 bytes; 15 remain"),
    (message(16, struct.pack(">IB", 2, 1)), "says 2 bytes"),
    (message(16, b"\x00\x00"), "too few for a 5-byte sub-package header"),
    (message(16, sub(0, robot_mode_payload_35()[:20])), "shortest known layout \\(3.0\\) has 38"),
    (message(20, struct.pack(">QbB", 1, 1, 10) + b"\x00\x00"), "runtime exception message"),
    (message(20, b"\x00" * 5), "shorter than its 15-byte header"),
    (message(20, struct.pack(">QbBiiB", 1, 7, 7, 4, 0, 200) + b"short"), "title of 200 bytes"),
])
def test_malformed_messages_are_refused_with_a_reason(data, reason):
    with pytest.raises(ProtocolError, match=reason):
        decode_primary(data)


# --- python-urx reads what we encode (independent parser) ------------------------------------


def test_python_urx_parses_our_robot_state():
    ursecmon = pytest.importorskip("urx.ursecmon")
    state = RobotState((
        RobotModeData(variant="3.2", timestamp=5, is_robot_power_on=True, robot_mode=7,
                      target_speed_fraction=1.0, speed_scaling=0.25,
                      target_speed_fraction_limit=1.0),
        JointData(variant="3.0", q_actual=Q, q_target=Q, qd_actual=(0.0,) * 6,
                  i_actual=(1.0,) * 6, v_actual=(48.0,) * 6, t_motor=(30.0,) * 6,
                  t_micro=(31.0,) * 6, joint_mode=(253,) * 6),
        CartesianInfo(variant="3.2", tcp_pose=(0.4, -0.1, 0.3, 2.2, 2.2, 0.0),
                      tcp_offset=(0.0, 0.0, 0.1, 0.0, 0.0, 0.0)),
    ))
    parsed = ursecmon.ParserUtils().parse(encode_primary(state))
    assert parsed["RobotModeData"]["robotMode"] == 7
    assert parsed["RobotModeData"]["speedScaling"] == 0.25
    assert [parsed["JointData"][f"q_actual{i}"] for i in range(6)] == list(Q)
    assert parsed["CartesianInfo"]["X"] == 0.4 and parsed["CartesianInfo"]["tcpOffsetZ"] == 0.1


# --- laws -----------------------------------------------------------------------------------

_FORMATS = {
    "d": st.floats(allow_nan=False, width=64),
    "f": st.floats(allow_nan=False, width=32),
    "?": st.booleans(),
    "B": st.integers(0, 255), "b": st.integers(-128, 127),
    "h": st.integers(-(2**15), 2**15 - 1),
    "I": st.integers(0, 2**32 - 1), "i": st.integers(-(2**31), 2**31 - 1),
    "Q": st.integers(0, 2**64 - 1),
}


def table_values(table: Table) -> st.SearchStrategy[dict]:
    parts = {}
    for item in table.items:
        rows = item.rows if isinstance(item, Group) else (item,)
        count = item.count
        for row in rows:
            n = count if isinstance(item, Group) else row.count
            element = _FORMATS[row.fmt]
            parts[row.name] = element if (n == 1 and isinstance(item, Row)) else st.lists(
                element, min_size=n, max_size=n).map(tuple)
    return st.fixed_dictionaries(parts)


@st.composite
def sub_packages(draw):
    cls = draw(st.sampled_from(sorted(SUB_PACKAGES.values(), key=lambda c: c.TYPE)))
    if cls in (CalibrationData, SafetyData):
        return cls(variant="raw", payload_bytes=draw(st.binary(max_size=60)))
    label, table = draw(st.sampled_from(cls.VARIANTS))
    values = draw(table_values(table))
    if cls is MasterboardData:
        from urdsl.protocol.primary import _EUROMAP, _MASTERBOARD_HEAD
        values.update(draw(table_values(_MASTERBOARD_HEAD)))
        if values["euromap67_installed"]:
            values.update(draw(table_values(_EUROMAP)))
    return cls(variant=label, **values)


text = st.text(st.characters(blacklist_categories=("Cs",)), max_size=40)
short_text = st.text(st.characters(codec="ascii"), max_size=40)
head = {"timestamp": _FORMATS["Q"], "source": _FORMATS["b"]}

robot_messages = st.one_of(
    st.builds(TextMessage, text=text, **head),
    st.builds(RuntimeExceptionMessage, line=_FORMATS["I"], column=_FORMATS["I"], text=text,
              **head),
    st.builds(KeyMessage, code=_FORMATS["i"], argument=_FORMATS["i"], title=short_text,
              text=text, **head),
    st.builds(PopupMessage, request_id=_FORMATS["I"], requested_type=_FORMATS["I"],
              warning=st.booleans(), error=st.booleans(), blocking=st.booleans(),
              title=short_text, text=text, **head),
    st.builds(VersionMessage, project_name=short_text, major=_FORMATS["B"],
              minor=_FORMATS["B"], bugfix=_FORMATS["i"], build_number=st.integers(0, 2**24),
              build_date=text, **head),
    st.builds(SafetyModeMessage, code=_FORMATS["i"], argument=_FORMATS["i"],
              safety_mode_type=_FORMATS["B"], report_data_type=st.just(2),
              report_data=_FORMATS["i"], **head),
    st.builds(SafetyModeMessage, code=_FORMATS["i"], argument=_FORMATS["i"],
              safety_mode_type=_FORMATS["B"], report_data_type=st.just(3),
              report_data=_FORMATS["f"], **head),
    st.builds(UnknownRobotMessage, kind=st.integers(11, 255), body=st.binary(max_size=30),
              **head),
    *(st.builds(cls, **{name: text if name == "text" else _FORMATS[fmt]
                        for name, fmt in fields}, **head)
      for cls, fields in [
          (ROBOT_MESSAGES[1], [("id", "i"), ("text", "")]),
          (ROBOT_MESSAGES[6], [("code", "i"), ("argument", "i"), ("report_level", "i"),
                               ("data_type", "I"), ("data", "I"), ("text", "")]),
          (ROBOT_MESSAGES[9], [("request_id", "I"), ("requested_type", "I"), ("text", "")]),
      ]),
)

messages = st.one_of(
    st.lists(st.one_of(sub_packages(), st.builds(
        UnknownPackage, variant=st.just("raw"), type=st.integers(13, 255),
        payload_bytes=st.binary(max_size=20))), max_size=6).map(
            lambda p: RobotState(tuple(p))),
    robot_messages,
    st.builds(UnknownMessage, type=st.sampled_from([5, 22, 23, 24, 25, 255]),
              body=st.binary(max_size=40)),
)


@settings(max_examples=300, deadline=None)
@given(messages)
def test_decode_of_encode_is_identity(msg):
    assert decode_primary(encode_primary(msg)) == msg


@settings(max_examples=50, deadline=None)
@given(st.lists(messages, min_size=1, max_size=5), st.data())
def test_streaming_with_arbitrary_chunk_splits(sequence, data):
    stream = b"".join(encode_primary(m) for m in sequence)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=8), label="cuts"))
    decoder = PrimaryDecoder()
    got = []
    for begin, end in zip([0, *cuts], [*cuts, len(stream)], strict=True):
        got += decoder.feed(stream[begin:end])
    assert got == sequence and decoder.pending == 0


def test_decoder_continues_after_a_malformed_message_and_tracks_the_version():
    good = TextMessage(text="hello").encode()
    bad = message(20, struct.pack(">QbB", 1, 1, 10))  # runtime exception without fields
    version = VersionMessage(major=5, minor=11, bugfix=2, build_number=1, build_date="x")
    decoder = PrimaryDecoder()
    decoder.receive_data(version.encode() + bad + good)
    assert decoder.next_message() == version and decoder.version == (5, 11, 2)
    with pytest.raises(ProtocolError, match="runtime exception"):
        decoder.next_message()
    assert decoder.next_message() == TextMessage(text="hello")
    assert decoder.next_message() is None


def test_decoder_refuses_input_after_broken_framing():
    decoder = PrimaryDecoder()
    with pytest.raises(ProtocolError, match="size field"):
        decoder.feed(struct.pack(">iB", -7, 16))
    with pytest.raises(ProtocolError, match="reconnect"):
        decoder.feed(TextMessage(text="x").encode())


def test_encoders_refuse_values_that_do_not_fit():
    with pytest.raises(ProtocolError, match="key title is 300 bytes"):
        KeyMessage(title="x" * 300).encode()
    with pytest.raises(ProtocolError, match="field q_actual needs 6 values"):
        JointData(variant="3.0", q_actual=(1.0,)).encode()
    with pytest.raises(ProtocolError, match="unknown layout"):
        AdditionalInfo(variant="9.9").encode()
    with pytest.raises(ProtocolError, match="cannot encode"):
        RuntimeExceptionMessage(line=-1).encode()


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=600))
def test_garbage_is_rejected_or_decoded_never_crashes(data):
    try:
        decode_primary(data)
    except ProtocolError:
        pass
    decoder = PrimaryDecoder()
    decoder.receive_data(data)
    for _ in range(len(data) + 1):  # each call consumes a message or stops: bounded
        try:
            if decoder.next_message() is None:
                break
        except ProtocolError:
            if decoder._broken is not None:
                break


@settings(max_examples=150, deadline=None)
@given(messages, st.data())
def test_truncated_messages_are_refused(msg, data):
    whole = encode_primary(msg)
    cut = data.draw(st.integers(0, len(whole) - 1), label="cut")
    with pytest.raises(ProtocolError):
        decode_primary(whole[:cut])
    assert PrimaryDecoder().feed(whole[:cut]) == []
