"""Realtime interface (30003): layouts per version, documented offsets, streaming, fuzzing."""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.realtime import (
    LAYOUTS,
    MAX_SIZE,
    RealtimeDecoder,
    decode_realtime,
    encode_realtime,
    layout_for_version,
    realtime_state,
)

# --- fixtures built from the documented byte offsets (docs/controller-facts.md §10), not from
# our tables ------------------------------------------------------------------------------------


def packet(size: int, doubles: dict[int, tuple[float, ...]]) -> bytes:
    """A packet of ``size`` bytes: the size field, zeros, and doubles at the given offsets."""
    data = bytearray(size)
    struct.pack_into(">i", data, 0, size)
    for offset, values in doubles.items():
        struct.pack_into(f">{len(values)}d", data, offset, *values)
    return bytes(data)


Q = (0.1, -1.2, 1.3, -1.7, -1.5, 0.4)
POSE = (0.4, -0.1, 0.3, 2.2, 2.2, 0.0)


def test_course_offsets_252_and_444_on_cb3():
    # The course reads q actual with struct.unpack at byte 252 and the TCP pose at 444.
    data = packet(1116, {4: (12.5,), 252: Q, 444: POSE, 540: (1, 2, 3, 4, 5, 6),
                         684: (5.0,), 756: (7.0,), 764: (253.0,) * 6, 812: (1.0,),
                         940: (0.5,), 1044: (3.0,), 1052: (2.0,), 1108: (1.0,)})
    state = decode_realtime(data)
    assert state.version == "3.10" and state.size == 1116
    assert state.time == 12.5
    assert state.q_actual == Q
    assert state.tcp_pose == POSE == state.tool_vector_actual
    assert state.tcp_force == (1, 2, 3, 4, 5, 6)
    assert state.digital_input_bits == 5  # bits 0 and 2, sent as the double 5.0
    assert (state.robot_mode, state.joint_modes, state.safety_mode) == (7, (253,) * 6, 1)
    assert state.speed_scaling == 0.5
    assert (state.digital_outputs, state.program_state, state.safety_status) == (3, 2, 1)
    assert isinstance(state.robot_mode, int) and isinstance(state.joint_modes[0], int)
    assert state.payload_mass is None  # 5.10 field, not in this layout


def test_cb2_sends_the_tcp_pose_at_588_and_force_at_540():
    data = packet(812, {252: Q, 540: (9, 8, 7, 6, 5, 4), 588: POSE, 756: (0.0,),
                        764: (253.0,) * 6})
    state = decode_realtime(data)
    assert state.version == "1.8"
    assert state.tcp_pose == POSE
    assert state.tcp_force == (9, 8, 7, 6, 5, 4)
    assert state.tool_vector_target is None and state.safety_mode is None


def test_e_series_510_payload_fields():
    data = packet(1220, {1140: (1.5,), 1148: (0.0, 0.0, 0.05), 1172: (1, 2, 3, 4, 5, 6)})
    state = decode_realtime(data)
    assert state.version == "5.10"
    assert state.payload_mass == 1.5 and state.payload_cog == (0.0, 0.0, 0.05)
    assert state.payload_inertia == (1, 2, 3, 4, 5, 6)


@pytest.mark.parametrize(("size", "version"), [
    (756, "1.6"), (764, "1.7"), (812, "1.8"), (1044, "3.0"), (1060, "3.2"), (1108, "3.5"),
    (1116, "3.10"), (1220, "5.10")])
def test_documented_sizes_choose_the_layout(size, version):
    assert decode_realtime(packet(size, {})).version == version
    assert LAYOUTS[version].size == size


@pytest.mark.parametrize(("version", "layout"), [
    ("1.6", "1.6"), ("1.8", "1.8"), ("3.1", "3.0"), ("3.4", "3.2"), ("3.9", "3.5"),
    ("3.13", "3.10"), ("3.15", "3.10"), ("5.0", "3.5"), ("5.3.1", "3.5"), ("5.4", "3.10"),
    ("5.9", "3.10"), ("5.10", "5.10"), ("5.23.0", "5.10")])
def test_versions_map_to_layouts(version, layout):
    assert layout_for_version(version).name == layout


def test_documented_offsets_come_out_of_the_tables():
    cb3 = LAYOUTS["5.10"]
    expected = {"time": 4, "q_target": 12, "q_actual": 252, "i_control": 396,
                "tool_vector_actual": 444, "tcp_force": 540, "tool_vector_target": 588,
                "digital_input_bits": 684, "robot_mode": 756, "joint_modes": 764,
                "safety_mode": 812, "tool_accelerometer_values": 868, "speed_scaling": 940,
                "v_actual": 996, "digital_outputs": 1044, "program_state": 1052,
                "elbow_position": 1060, "safety_status": 1108, "payload_mass": 1140,
                "payload_cog": 1148, "payload_inertia": 1172}
    assert {name: cb3.offset(name) for name in expected} == expected
    assert LAYOUTS["1.8"].offset("tool_vector_actual") == 588


def test_version_override_where_sizes_collide():
    data = packet(1108, {756: (7.0,)})
    assert decode_realtime(data).version == "3.5"
    assert decode_realtime(data, version="5.2").version == "5.2"
    decoder = RealtimeDecoder(version="5.6")
    (state,) = decoder.feed(packet(1116, {}))
    assert state.version == "5.6" and state.safety_status == 0


def test_override_refuses_a_packet_too_short_for_the_version():
    with pytest.raises(ProtocolError, match="version 5.10 packet has at least 1220 bytes"):
        decode_realtime(packet(1116, {}), version="5.10")


def test_unknown_longer_packets_keep_their_tail():
    data = packet(1116 + 24, {1116: (1.0, 2.0, 3.0)})  # e.g. 3.14 with 3 more doubles
    state = decode_realtime(data)
    assert state.version == "3.10" and state.tail == struct.pack(">3d", 1.0, 2.0, 3.0)
    assert encode_realtime(state) == data


@pytest.mark.parametrize(("data", "message"), [
    (b"\x00\x00", "cannot hold the 4-byte size field"),
    (struct.pack(">i", 12) + bytes(8), "size field says 12 bytes"),
    (struct.pack(">i", 10**6), "size field says 1000000 bytes"),
    (packet(1116, {})[:-8], "size field says 1116 bytes but the packet has 1108"),
    (packet(1116, {756: (math.nan,)}), "robot_mode at offset 756 should hold an integer"),
    (packet(1116, {772: (1.5,)}), "joint_modes at offset 772 should hold an integer, got 1.5"),
])
def test_malformed_packets_are_refused_with_a_reason(data, message):
    with pytest.raises(ProtocolError, match=message):
        decode_realtime(data)


def test_encode_needs_every_field_of_the_layout():
    with pytest.raises(ProtocolError, match="field time is not set"):
        encode_realtime(realtime_state("3.10").__class__(version="3.10"))
    with pytest.raises(TypeError, match="has no field"):
        realtime_state("3.0", payload_mass=1.0)


# --- laws -----------------------------------------------------------------------------------

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
integer = st.integers(min_value=-(2**53), max_value=2**53)


VERSIONS = ["1.6", "1.7", "1.8", "3.0", "3.2", "3.5", "3.10", "5.10", "5.4", "3.14"]


@st.composite
def states(draw, version=None):
    version = version or draw(st.sampled_from(VERSIONS))
    layout = layout_for_version(version)
    values = {}
    for item in layout.table:
        element = integer if item.kind == "int" else finite
        values[item.name] = (draw(element) if item.count == 1
                             else tuple(draw(st.lists(element, min_size=item.count,
                                                      max_size=item.count))))
    tail = draw(st.binary(max_size=40).map(lambda b: b[: len(b) // 8 * 8]))
    return realtime_state(version, tail=tail, **values)


@settings(max_examples=150, deadline=None)
@given(states())
def test_decode_of_encode_is_identity(state):
    data = encode_realtime(state)
    assert len(data) == state.size
    assert decode_realtime(data, version=state.version) == state


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(VERSIONS).flatmap(
    lambda v: st.lists(states(v), min_size=1, max_size=4)), st.data())
def test_streaming_with_arbitrary_chunk_splits(sequence, data):
    # One connection speaks one version; the decoder is told it, as a 1.6 packet with an
    # 8-byte tail cannot be told from a 1.7 packet by its size.
    stream = b"".join(encode_realtime(s) for s in sequence)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=8), label="cuts"))
    decoder = RealtimeDecoder(version=sequence[0].version)
    got = []
    for begin, end in zip([0, *cuts], [*cuts, len(stream)], strict=True):
        got += decoder.feed(stream[begin:end])
    assert got == sequence
    assert decoder.pending == 0


def test_latest_drains_and_hands_out_only_the_newest_packet():
    decoder = RealtimeDecoder()
    packets = [encode_realtime(realtime_state("5.10", time=t * 0.002)) for t in range(5)]
    stream = b"".join(packets) + packets[0][:100]  # and the start of a sixth
    state = decoder.latest(stream)
    assert state.time == 4 * 0.002
    assert decoder.skipped == 4 and decoder.pending == 100
    assert decoder.latest() is None  # nothing new: no stale packet handed out again
    assert decoder.latest(packets[1][100:]).time == 0.0


def test_decoder_refuses_input_after_a_broken_stream():
    decoder = RealtimeDecoder()
    with pytest.raises(ProtocolError, match="size field"):
        decoder.feed(struct.pack(">i", MAX_SIZE + 1))
    with pytest.raises(ProtocolError, match="reconnect"):
        decoder.feed(packet(1116, {}))


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=2500))
def test_garbage_is_rejected_or_decoded_never_crashes(data):
    try:
        decode_realtime(data)
    except ProtocolError:
        pass
    decoder = RealtimeDecoder()
    try:
        for state in decoder.feed(data):
            assert state.size >= 756
    except ProtocolError:
        pass


@settings(max_examples=100, deadline=None)
@given(states(), st.data())
def test_truncated_packets_wait_or_fail_cleanly(state, data):
    whole = encode_realtime(state)
    cut = data.draw(st.integers(0, len(whole) - 1), label="cut")
    assert RealtimeDecoder().feed(whole[:cut]) == []  # incomplete: wait for the rest
    with pytest.raises(ProtocolError):
        decode_realtime(whole[:cut])


@pytest.mark.filterwarnings("ignore:notifyAll:DeprecationWarning")
def test_python_urx_reads_our_packets_at_the_same_offsets():
    # An independent parser: python-urx's realtime monitor, fed from memory (no socket use).
    urrtmon = pytest.importorskip("urx.urrtmon")
    target = (0.5, 0.1, 0.2, 0.0, 3.1, 0.0)
    data = encode_realtime(realtime_state("3.10", q_actual=Q, tool_vector_actual=POSE,
                                          tool_vector_target=target, tcp_force=(1,) * 6))
    monitor = urrtmon.URRTMonitor("127.0.0.1")
    monitor._rtSock.close()
    chunks = iter([data[:4], data[4:]])
    monitor._URRTMonitor__recv_bytes = lambda count: next(chunks)
    monitor._URRTMonitor__recvTime = 0.0
    monitor._URRTMonitor__recv_rt_data()
    assert tuple(monitor._qActual) == Q
    assert tuple(monitor._tcp_force) == (1,) * 6
    # urx indexes 3.x packets with the 1.x order: its "tcp" is the target pose at 588
    # (docs/controller-facts.md §10: python-urx), which urdsl reads by name instead.
    assert tuple(monitor._tcp) == target == decode_realtime(data).tool_vector_target


def test_slot_is_where_a_field_sits_among_the_doubles():
    layout = LAYOUTS["5.10"]
    assert layout.slot("q_actual") == slice(31, 37)  # byte 252 = 4 + 8 * 31
    assert layout.slot("time") == slice(0, 1)
    with pytest.raises(KeyError):
        LAYOUTS["3.0"].slot("payload_mass")


def test_encode_refuses_vectors_of_the_wrong_length_even_when_the_total_fits():
    # q_target one short, qd_target one long: the count of doubles is right, the fields not
    state = realtime_state("3.10")._replace(q_target=(0.0,) * 5, qd_target=(0.0,) * 7)
    with pytest.raises(ProtocolError, match="field q_target needs 6 values, got 5"):
        encode_realtime(state)


@pytest.mark.parametrize(("value", "whole"), [
    (math.inf, False), (-math.inf, False), (-2.5, False), (2.0**51 + 0.5, False),
    (1e300, True), (-0.0, True)])
def test_integer_fields_hold_integers_or_the_packet_is_refused(value, whole):
    data = packet(1116, {756: (value,)})
    if whole:
        assert decode_realtime(data).robot_mode == int(value)  # huge, but a whole number
    else:
        with pytest.raises(ProtocolError, match="robot_mode at offset 756 should hold an integer"):
            decode_realtime(data)


def test_states_compare_as_states_and_keep_their_field_names():
    state = realtime_state("5.10", q_actual=Q)
    assert state == realtime_state("5.10", q_actual=Q) and state != tuple(state)
    assert hash(state) == hash(realtime_state("5.10", q_actual=Q))
    assert state._replace(robot_mode=3).robot_mode == 3
    assert decode_realtime(encode_realtime(state)).q_actual == Q


def test_a_chunk_as_long_as_one_layout_holding_a_shorter_packet_is_framed_by_its_size():
    # 1220 bytes (the 5.10 length) that hold a 1116-byte packet and the start of the next
    first = packet(1116, {756: (7.0,)})
    decoder = RealtimeDecoder()
    (state,) = decoder.feed(first + first[:104])
    assert state.version == "3.10" and state.robot_mode == 7 and decoder.pending == 104
    assert decoder.feed(first[104:]) == [state]


@pytest.mark.parametrize(("value", "offset", "field"), [
    (math.nan, 756, "robot_mode"), (math.inf, 764, "joint_modes"),
    (-math.inf, 1212, "payload_inertia"), (1.5, 1108, "safety_status")])
def test_a_whole_packet_with_a_bad_integer_breaks_the_stream(value, offset, field):
    # the decoder's fast path (one chunk, one whole packet) checks exactly as decode_realtime
    data = packet(1220, {offset: (value,)})
    decoder = RealtimeDecoder()
    if field == "payload_inertia":  # a measured value: any double is taken as it is
        assert decoder.feed(data)[0].payload_inertia[-1] == value
        return
    with pytest.raises(ProtocolError, match=f"{field} at offset {offset} should hold an "
                                            f"integer, got {value!r}"):
        decoder.feed(data)
    with pytest.raises(ProtocolError, match="reconnect"):
        decoder.feed(packet(1220, {}))


def test_a_told_version_labels_whole_packets_and_refuses_shorter_ones():
    decoder = RealtimeDecoder(version="5.7")
    (state,) = decoder.feed(packet(1116, {1108: (1.0,)}))
    assert state.version == "5.7" and state.safety_status == 1
    assert RealtimeDecoder().feed(packet(1116, {}))[0].version == "3.10"
    with pytest.raises(ProtocolError, match="version 5.10 packet has at least 1220 bytes"):
        RealtimeDecoder(version="5.10").feed(packet(1116, {}))
