"""RTDE v1/v2: package layouts, recipes, field table, client and server state machines."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol.errors import ProtocolError
from urdsl.protocol.rtde import (
    ERROR,
    IN_USE,
    NOT_FOUND,
    ControllerVersion,
    DataPackage,
    GetControllerVersion,
    InputOwnership,
    InputSetupReply,
    OutputSetupReply,
    Pause,
    PauseReply,
    ProtocolVersionReply,
    Recipe,
    RequestProtocolVersion,
    RtdeClient,
    RtdeFramer,
    RtdeServer,
    RtdeTextMessage,
    SetupInputs,
    SetupOutputs,
    Start,
    StartReply,
    decode_rtde,
    encode_rtde,
)
from urdsl.protocol.rtde_fields import FIELDS, TYPES, field_available, output_fields

# --- fixtures built from UR's RTDE guide (docs/controller-facts.md §12), not from our encoder -----


def package(code: str, payload: bytes) -> bytes:
    return struct.pack(">HB", len(payload) + 3, ord(code)) + payload


def test_v2_output_setup_request_starts_with_the_frequency():
    data = package("O", struct.pack(">d", 125.0) + b"timestamp,actual_q")
    assert decode_rtde(data, sender="client") == SetupOutputs(("timestamp", "actual_q"), 125.0)
    assert encode_rtde(SetupOutputs(("timestamp", "actual_q"), 125.0)) == data


def test_v1_output_setup_has_no_frequency_and_no_recipe_id():
    data = package("O", b"timestamp,actual_q")
    assert decode_rtde(data, sender="client", protocol=1) == SetupOutputs(
        ("timestamp", "actual_q"), None)
    reply = package("O", b"DOUBLE,VECTOR6D")
    assert decode_rtde(reply, sender="server", protocol=1) == OutputSetupReply(
        None, ("DOUBLE", "VECTOR6D"))


def test_v2_replies_and_data_package_fixture():
    assert decode_rtde(package("O", b"\x01DOUBLE,VECTOR6D,INT32"), sender="server") == \
        OutputSetupReply(1, ("DOUBLE", "VECTOR6D", "INT32"))
    recipe = Recipe(1, ("timestamp", "actual_q", "robot_mode"), ("DOUBLE", "VECTOR6D", "INT32"))
    sample = package("U", struct.pack(">Bd6di", 1, 12.5, 0.1, -1.2, 1.3, -1.7, -1.5, 0.4, 7))
    decoded = decode_rtde(sample, sender="server", recipes={1: recipe})
    assert decoded == DataPackage(1, {"timestamp": 12.5,
                                      "actual_q": (0.1, -1.2, 1.3, -1.7, -1.5, 0.4),
                                      "robot_mode": 7})
    assert encode_rtde(decoded, recipe=recipe) == sample


def test_controller_version_and_accept_replies():
    assert decode_rtde(package("v", struct.pack(">IIII", 5, 11, 1, 108318)),
                       sender="server") == ControllerVersion(5, 11, 1, 108318)
    assert decode_rtde(package("V", b"\x00"), sender="server") == ProtocolVersionReply(False)
    assert decode_rtde(package("V", struct.pack(">H", 2)), sender="client") == \
        RequestProtocolVersion(2)


def test_text_messages_v1_and_v2():
    v2 = package("M", b"\x05hello\x06urdsl!\x02")
    assert decode_rtde(v2, sender="server") == RtdeTextMessage("hello", "urdsl!", 2)
    v1 = package("M", b"\x01oops")
    assert decode_rtde(v1, sender="server", protocol=1) == RtdeTextMessage("oops", "", ERROR)


@pytest.mark.parametrize(("data", "kwargs", "reason"), [
    (b"\x00", {}, "cannot hold the 3-byte package header"),
    (package("V", b"\x00")[:-1], {}, "size field says 4 bytes"),
    (package("V", b"\x00\x02\x00"), {"sender": "client"}, "must have 2"),
    (package("v", b"\x00" * 15), {}, "must have 16"),
    (package("O", b"\x00\x00"), {"sender": "client"}, "8-byte frequency"),
    (package("M", b"\x09abc"), {}, "message of 9 bytes does not fit"),
    (package("U", b"\x03" + bytes(8)), {}, "recipe 3, which was never set up"),
    (package("X", b""), {}, "unknown package type 88"),
    (package("I", b"x" * 2049), {"sender": "client"}, "at most 2048"),
])
def test_malformed_packages_are_refused_with_a_reason(data, kwargs, reason):
    kwargs = {"sender": "server", **kwargs}
    with pytest.raises(ProtocolError, match=reason):
        decode_rtde(data, **kwargs)


def test_data_package_of_the_wrong_length():
    recipe = Recipe(1, ("timestamp",), ("DOUBLE",))
    with pytest.raises(ProtocolError, match="has 4 bytes of values; the recipe .* needs 8"):
        decode_rtde(package("U", b"\x01" + bytes(4)), sender="server", recipes={1: recipe})


# --- the field table -------------------------------------------------------------------------


def test_field_table_types_from_the_guide():
    expected = {"timestamp": "DOUBLE", "actual_q": "VECTOR6D", "joint_mode": "VECTOR6INT32",
                "robot_mode": "INT32", "safety_mode": "INT32", "runtime_state": "UINT32",
                "tool_output_voltage": "INT32", "actual_digital_input_bits": "UINT64",
                "elbow_position": "VECTOR3D", "output_bit_register_64": "BOOL",
                "input_double_register_47": "DOUBLE", "speed_slider_mask": "UINT32",
                "standard_digital_output": "UINT8", "payload_inertia": "VECTOR6D"}
    assert {name: FIELDS[name].type for name in expected} == expected
    assert FIELDS["input_int_register_30"].input and FIELDS["input_int_register_30"].output
    assert not FIELDS["actual_q"].input and not FIELDS["speed_slider_mask"].output
    assert set(TYPES) >= {f.type for f in FIELDS.values()}


@pytest.mark.parametrize(("name", "version", "available"), [
    ("actual_q", (3, 4, 0), True), ("safety_status", (3, 9, 0), False),
    ("safety_status", (3, 10, 0), True), ("safety_status", (5, 3, 0), False),
    ("safety_status", (5, 4, 0), True), ("ft_raw_wrench", (3, 15, 0), False),
    ("ft_raw_wrench", (5, 9, 0), True), ("output_int_register_30", (3, 8, 0), False),
    ("output_int_register_30", (5, 3, 0), True), ("payload", (5, 5, 1), True),
    ("payload", (5, 5, 0), False), ("actual_current_as_torque", (5, 22, 0), False),
])
def test_field_availability_by_version(name, version, available):
    assert field_available(FIELDS[name], version) is available


# --- client and server talking -------------------------------------------------------------


def talk(client: RtdeClient, server: RtdeServer, request: bytes) -> list:
    server.receive_data(request)
    return client.receive_data(server.data_to_send())


def handshake(version=(5, 11, 1, 108318), ownership=None, protocol=2):
    client, server = RtdeClient(), RtdeServer(version, ownership)
    assert talk(client, server, client.request_protocol_version(protocol)) == [
        ProtocolVersionReply(True)]
    assert talk(client, server, client.get_controller_version()) == [ControllerVersion(*version)]
    return client, server


def test_record_py_session():
    client, server = handshake()
    names = ["timestamp", "actual_q", "actual_TCP_pose", "robot_mode", "runtime_state"]
    (reply,) = talk(client, server, client.setup_outputs(names, 125))
    assert reply.types == ("DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "UINT32")
    assert client.output_recipe.valid and server.decimation == 4  # 500 Hz / 125 Hz
    assert talk(client, server, client.start()) == [StartReply(True)] and client.running
    sample = {"timestamp": 0.0, "actual_q": (0.0,) * 6, "actual_TCP_pose": (0.1,) * 6,
              "robot_mode": 7, "runtime_state": 2, "unused": 1}
    stream = b"".join(server.outputs({**sample, "timestamp": c * 0.002}, c) or b""
                      for c in range(12))
    received = []
    for i in range(0, len(stream), 7):  # arbitrary chunks
        received += client.receive_data(stream[i:i + 7])
    assert [p.values["timestamp"] for p in received] == [0.0, 0.008, 0.016]
    assert received[0].recipe_id == reply.recipe_id
    assert talk(client, server, client.pause()) == [PauseReply(True)] and not client.running
    assert server.outputs(sample, 0) is None


def test_not_found_outputs_stream_nothing():
    client, server = handshake(version=(3, 5, 0, 0))
    (reply,) = talk(client, server, client.setup_outputs(["actual_q", "safety_status"], 125))
    assert reply.types == ("VECTOR6D", NOT_FOUND)  # safety_status needs 3.10
    assert client.output_recipe.not_found == ("safety_status",)
    with pytest.raises(ProtocolError, match="not found: safety_status"):
        client.start()
    server.receive_data(encode_rtde(Start()))
    assert server.data_to_send() == encode_rtde(StartReply(False))
    assert server.outputs({"actual_q": (0.0,) * 6}, 0) is None


def test_inputs_owned_by_another_client_are_in_use():
    ownership = InputOwnership()
    first, first_server = handshake(ownership=ownership)
    second, second_server = handshake(ownership=ownership)
    (reply,) = talk(first, first_server, first.setup_inputs(["input_int_register_24"]))
    assert reply == InputSetupReply(1, ("INT32",))
    (reply,) = talk(second, second_server,
                    second.setup_inputs(["input_int_register_24", "input_int_register_25"]))
    assert reply == InputSetupReply(0, (IN_USE, "INT32"))
    assert second.input_recipes == {}
    with pytest.raises(ProtocolError, match="never set up"):
        second.send_inputs(0, {"input_int_register_24": 1})
    first_server.close()  # the first client disconnects: the input is free again
    (reply,) = talk(second, second_server, second.setup_inputs(["input_int_register_24"]))
    assert reply == InputSetupReply(1, ("INT32",))


def test_inputs_reach_the_server():
    client, server = handshake()
    talk(client, server, client.setup_inputs(["speed_slider_mask", "speed_slider_fraction"]))
    assert talk(client, server, client.start()) == [StartReply(True)]
    events = server.receive_data(client.send_inputs(
        1, {"speed_slider_mask": 1, "speed_slider_fraction": 0.3}))
    assert events == [DataPackage(1, {"speed_slider_mask": 1, "speed_slider_fraction": 0.3})]


def test_cb3_decimation_and_frequency_limits():
    client, server = handshake(version=(3, 15, 0, 0))
    talk(client, server, client.setup_outputs(["timestamp"], 50))
    assert server.decimation == 2  # floor(125 / 50): every 2nd cycle, 62.5 Hz
    events = talk(client, server, client.setup_outputs(["timestamp"], 500))
    assert events[0] == RtdeTextMessage("output frequency 500.0 Hz outside (0, 125]",
                                        "urdsl sim", ERROR)
    assert events[1].types == (NOT_FOUND,)


def test_protocol_v1_session():
    client, server = handshake(protocol=1)
    assert client.protocol == 1
    (reply,) = talk(client, server, client.setup_outputs(["timestamp", "robot_mode"]))
    assert reply == OutputSetupReply(None, ("DOUBLE", "INT32"))
    talk(client, server, client.start())
    data = server.outputs({"timestamp": 1.0, "robot_mode": 7}, 0)
    assert data == package("U", struct.pack(">di", 1.0, 7))  # v1: no recipe id
    assert client.receive_data(data) == [DataPackage(None, {"timestamp": 1.0, "robot_mode": 7})]


def test_unsupported_protocol_version_is_refused():
    client, server = RtdeClient(), RtdeServer()
    assert talk(client, server, client.request_protocol_version(3)) == [
        ProtocolVersionReply(False)]
    assert client.protocol == 1


def test_setup_while_streaming_is_refused():
    client, server = handshake()
    talk(client, server, client.setup_outputs(["timestamp"]))
    talk(client, server, client.start())
    with pytest.raises(ProtocolError, match="pause before"):
        client.setup_outputs(["actual_q"])
    server.receive_data(encode_rtde(SetupInputs(("input_int_register_30",))))
    events = [decode_rtde(p, sender="server") for p in RtdeFramer().feed(server.data_to_send())]
    assert "pause first" in events[0].message  # a text message, then the refusal
    assert events[1] == InputSetupReply(0, (NOT_FOUND,))


def test_client_rejects_replies_nobody_asked_for():
    client = RtdeClient()
    with pytest.raises(ProtocolError, match="no request was sent"):
        client.receive_data(encode_rtde(StartReply(True)))
    client.get_controller_version()
    with pytest.raises(ProtocolError, match="while waiting for the reply to GetController"):
        client.receive_data(encode_rtde(StartReply(True)))


def test_framer_refuses_an_impossible_size():
    framer = RtdeFramer()
    with pytest.raises(ProtocolError, match="less than the 3-byte header"):
        framer.feed(b"\x00\x01U")
    with pytest.raises(ProtocolError, match="reconnect"):
        framer.feed(b"")


# --- laws -----------------------------------------------------------------------------------

_VALUES = {
    "BOOL": st.booleans(), "UINT8": st.integers(0, 255), "UINT32": st.integers(0, 2**32 - 1),
    "UINT64": st.integers(0, 2**64 - 1), "INT32": st.integers(-(2**31), 2**31 - 1),
    "DOUBLE": st.floats(allow_nan=False),
}


def value_of(type_: str) -> st.SearchStrategy:
    code, count = TYPES[type_]
    by_code = {"d": _VALUES["DOUBLE"], "i": _VALUES["INT32"], "I": _VALUES["UINT32"]}
    element = _VALUES[type_] if type_ in _VALUES else by_code[code]
    return element if count == 1 else st.lists(element, min_size=count,
                                                max_size=count).map(tuple)


@st.composite
def recipes_and_samples(draw):
    names = draw(st.lists(st.sampled_from(sorted(FIELDS)), min_size=1, max_size=8,
                          unique=True))
    recipe = Recipe(draw(st.integers(0, 255)), tuple(names),
                    tuple(FIELDS[n].type for n in names))
    values = {n: draw(value_of(FIELDS[n].type)) for n in names}
    return recipe, DataPackage(recipe.id, values)


text = st.text(st.characters(blacklist_categories=("Cs",)), max_size=30).filter(
    lambda s: len(s.encode()) <= 255)
name_lists = st.lists(st.sampled_from(sorted(FIELDS)), min_size=1, max_size=10).map(tuple)
requests = st.one_of(
    st.builds(RequestProtocolVersion, st.integers(0, 0xFFFF)),
    st.just(GetControllerVersion()), st.just(Start()), st.just(Pause()),
    st.builds(SetupOutputs, name_lists, st.floats(1, 500)),
    st.builds(SetupInputs, name_lists),
    st.builds(RtdeTextMessage, text, text, st.integers(0, 3)),
)
replies = st.one_of(
    st.builds(ProtocolVersionReply, st.booleans()), st.builds(StartReply, st.booleans()),
    st.builds(PauseReply, st.booleans()),
    st.builds(ControllerVersion, *[st.integers(0, 2**32 - 1)] * 4),
    st.builds(OutputSetupReply, st.integers(0, 255),
              st.lists(st.sampled_from([*TYPES, NOT_FOUND, IN_USE]), min_size=1).map(tuple)),
    st.builds(InputSetupReply, st.integers(0, 255),
              st.lists(st.sampled_from([*TYPES, IN_USE]), min_size=1).map(tuple)),
    st.builds(RtdeTextMessage, text, text, st.integers(0, 3)),
)


@settings(max_examples=200, deadline=None)
@given(requests, replies)
def test_decode_of_encode_is_identity_for_every_package(request, reply):
    assert decode_rtde(encode_rtde(request), sender="client") == request
    assert decode_rtde(encode_rtde(reply), sender="server") == reply


@settings(max_examples=150, deadline=None)
@given(recipes_and_samples())
def test_data_packages_round_trip_by_recipe(recipe_and_sample):
    recipe, sample = recipe_and_sample
    data = encode_rtde(sample, recipe=recipe)
    for sender in ("client", "server"):
        assert decode_rtde(data, sender=sender, recipes={recipe.id: recipe}) == sample


@settings(max_examples=40, deadline=None)
@given(st.lists(replies, min_size=1, max_size=6), st.data())
def test_framing_with_arbitrary_chunk_splits(sequence, data):
    stream = b"".join(encode_rtde(r) for r in sequence)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=6), label="cuts"))
    framer = RtdeFramer()
    packages = []
    for begin, end in zip([0, *cuts], [*cuts, len(stream)], strict=True):
        packages += framer.feed(stream[begin:end])
    assert [decode_rtde(p, sender="server") for p in packages] == sequence


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=200))
def test_garbage_never_crashes_the_server_or_the_client(data):
    server = RtdeServer()
    try:
        server.receive_data(data)
    except ProtocolError:
        pass
    client = RtdeClient()
    client.get_controller_version()
    try:
        client.receive_data(data)
    except ProtocolError:
        pass


def test_every_output_field_can_be_streamed_by_the_server():
    client, server = handshake(version=(5, 23, 0, 0))
    names = [f.name for f in output_fields((5, 23, 0))]
    chunks = [names[i:i + 40] for i in range(0, len(names), 40)]  # 2048-byte name limit
    for chunk in chunks:
        (reply,) = talk(client, server, client.setup_outputs(chunk, 500))
        assert NOT_FOUND not in reply.types, chunk


def test_setup_names_drop_empty_entries_as_the_controller_does():
    # ur_rtde ends its name list with a comma
    data = package("O", struct.pack(">d", 125.0) + b"timestamp,actual_q,")
    assert decode_rtde(data, sender="client") == SetupOutputs(("timestamp", "actual_q"), 125.0)


def test_a_malformed_request_is_refused_and_the_server_goes_on():
    client, server = handshake()
    bad = package("V", b"\x00")  # one byte where a uint16 belongs
    (whole,) = server.packages(bad)
    with pytest.raises(ProtocolError):
        server.receive_package(whole)
    server.refuse(whole, "protocol version request payload has 1 bytes")
    events = [decode_rtde(p, sender="server") for p in RtdeFramer().feed(server.data_to_send())]
    assert events[0].level == ERROR and "package ignored" in events[0].message
    assert events[1] == ProtocolVersionReply(False)
    assert talk(client, server, client.get_controller_version()) == [
        ControllerVersion(5, 11, 1, 108318)]


def test_the_256th_input_recipe_is_refused_with_id_0_and_its_types():
    client, server = handshake()
    for expected in range(1, 256):
        (reply,) = talk(client, server, client.setup_inputs(["input_int_register_0"]))
        assert reply == InputSetupReply(expected, ("INT32",))
    server.receive_data(encode_rtde(SetupInputs(("input_int_register_0",))))
    events = [decode_rtde(p, sender="server") for p in RtdeFramer().feed(server.data_to_send())]
    assert "255 per connection" in events[0].message
    assert events[1] == InputSetupReply(0, ("INT32",))
    assert 0 not in server.input_recipes


def test_output_package_is_the_data_package_of_the_recipe():
    client, server = handshake()
    talk(client, server, client.setup_outputs(["timestamp", "actual_q", "robot_mode"], 500))
    talk(client, server, client.start())
    values = {"timestamp": 2.5, "actual_q": (0.1, 0.2, 0.3, 0.4, 0.5, 0.6), "robot_mode": 7}
    fast = server.output_package([2.5, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 7])
    assert fast == server.outputs(values, 0)
    assert client.receive_data(fast) == [DataPackage(1, values)]


def test_a_data_package_whose_size_field_lies_is_refused():
    recipe = Recipe(1, ("timestamp",), ("DOUBLE",))
    data = bytearray(encode_rtde(DataPackage(1, {"timestamp": 1.5}), recipe=recipe))
    data[1] += 1  # the size field says one byte more than the package has
    with pytest.raises(ProtocolError, match="size field says 13 bytes but the package has 12"):
        decode_rtde(bytes(data), sender="server", recipes={1: recipe})


def test_only_data_packages_take_the_recipe_path():
    # a text message as long as a data package of recipe 3, its first payload byte 3
    recipe = Recipe(3, ("robot_mode", "flag"), ("INT32", "BOOL"))
    text = encode_rtde(RtdeTextMessage("abc", "", 3), protocol=2)
    assert len(text) == 3 + 1 + recipe.size and text[3] == 3
    assert decode_rtde(text, sender="server", recipes={3: recipe}) == RtdeTextMessage("abc", "", 3)


def test_data_packages_compare_and_hash_as_packages():
    sample = DataPackage(1, {"timestamp": 1.0})
    assert sample == DataPackage(1, {"timestamp": 1.0}) and sample != DataPackage(2, sample.values)
    assert sample != (1, {"timestamp": 1.0})  # not equal to a plain tuple
    assert hash(sample) == hash(DataPackage(1, {})) and DataPackage().values == {}
    assert DataPackage().values is not DataPackage().values


def test_v1_output_package_has_no_recipe_id_and_bad_values_are_refused():
    client, server = RtdeClient(), RtdeServer((3, 10, 0, 0))
    talk(client, server, client.setup_outputs(["timestamp", "robot_mode"]))
    talk(client, server, client.start())
    data = server.output_package([1.5, 7])
    assert data == struct.pack(">HBdi", 15, ord("U"), 1.5, 7)
    assert client.receive_data(data) == [DataPackage(None, {"timestamp": 1.5, "robot_mode": 7})]
    with pytest.raises(ProtocolError, match="data package for recipe None"):
        server.output_package([1.5, 2**40])


def test_recipe_names_are_data_not_code():
    # a remote client picks the names; the generated reader binds them, never compiles them
    names = ("x': 1}; raise SystemExit #", "k0", "flat[0]", "\n\t\\")
    recipe = Recipe(7, names, ("DOUBLE", "VECTOR3D", "INT32", "BOOL"))
    values = dict(zip(names, (1.5, (1.0, 2.0, 3.0), -4, True), strict=True))
    data = encode_rtde(DataPackage(7, values), recipe=recipe)
    assert decode_rtde(data, sender="client", recipes={7: recipe}) == DataPackage(7, values)
    assert decode_rtde(data, sender="server", recipes={7: recipe}).values == values
