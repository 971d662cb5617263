"""Dashboard server line protocol: commands, documented replies, both state machines."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.protocol.dashboard import (
    COMMANDS,
    WELCOME,
    DashboardClient,
    DashboardCommand,
    DashboardReply,
    DashboardServer,
    DashboardWelcome,
    LineBuffer,
    decode_command,
    encode_command,
    format_reply,
    parse_reply,
)
from urdsl.protocol.errors import ProtocolError

# Reply texts as UR documents them (docs/controller-facts.md §13), with the meaning a client
# must see.
DOCUMENTED = [
    ("load", "Loading program: /programs/pick.urp", True, None),
    ("load", "File not found: /programs/pick.urp", False, None),
    ("load", "Error while loading program: /programs/pick.urp", False, None),
    ("play", "Starting program", True, None),
    ("play", "Failed to execute: play", False, None),
    ("stop", "Stopped", True, None),
    ("pause", "Pausing program", True, None),
    ("power on", "Powering on", True, None),
    ("power off", "Powering off", True, None),
    ("brake release", "Brake releasing", True, None),
    ("robotmode", "Robotmode: RUNNING", True, "RUNNING"),
    ("robotmode", "Robotmode: POWER_OFF", True, "POWER_OFF"),
    ("safetymode", "Safetymode: PROTECTIVE_STOP", True, "PROTECTIVE_STOP"),
    ("safetystatus", "Safetystatus: NORMAL", True, "NORMAL"),
    ("running", "Program running: true", True, True),
    ("running", "Program running: false", True, False),
    ("running", "Robot running: True", True, True),
    ("get loaded program", "Loaded program: /programs/pick.urp", True, "/programs/pick.urp"),
    ("get loaded program", "No program loaded", True, None),
    ("programState", "PLAYING pick.urp", True, "PLAYING"),
    ("programState", "STOPPED <unnamed>", True, "STOPPED"),
    ("is in remote control", "true", True, True),
    ("is in remote control", "false", True, False),
    ("PolyscopeVersion", "URSoftware 5.11.1.108318 (Jan 13 2022)", True, "5.11.1.108318"),
    ("unlock protective stop", "Protective stop releasing", True, None),
    ("quit", "Disconnected", True, None),
    ("shutdown", "Shutting down", True, None),
    ("isProgramSaved", "false pick.urp", True, False),
]


@pytest.mark.parametrize(("command", "text", "ok", "value"), DOCUMENTED)
def test_documented_replies_mean_what_ur_says(command, text, ok, value):
    reply = parse_reply(command, text)
    assert reply.ok is ok
    assert reply.value == value


def test_program_state_names_the_program():
    reply = parse_reply("programState", "PAUSED /programs/pick.urp")
    assert (reply.value, reply.field("name")) == ("PAUSED", "/programs/pick.urp")


def test_e_series_refusal_is_a_failed_reply_not_an_exception():
    reply = parse_reply("play", "Command is not allowed due to safety reasons")
    assert not reply.ok and reply.text.startswith("Command is not allowed")


def test_encode_commands():
    assert encode_command("robotmode") == b"robotmode\n"
    assert encode_command("load", "pick.urp") == b"load pick.urp\n"
    assert encode_command("brake release") == b"brake release\n"


@pytest.mark.parametrize(("name", "arg", "message"), [
    ("Robotmode", None, "did you mean 'robotmode'"),
    ("load", None, "needs an argument"),
    ("play", "now", "takes no argument"),
    ("popup", "two\nlines", "line break"),
])
def test_bad_commands_are_refused_by_name(name, arg, message):
    with pytest.raises(ProtocolError, match=message):
        encode_command(name, arg)


def test_decode_command_prefers_the_longest_name():
    assert decode_command("load installation default.installation\r\n") == DashboardCommand(
        "load installation", "default.installation")
    assert decode_command("load pick.urp") == DashboardCommand("load", "pick.urp")
    assert decode_command("make coffee").known is False


def test_unknown_command_reply():
    assert format_reply("make coffee") == "could not understand: 'make coffee'"


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(sorted(COMMANDS)), st.data())
def test_format_then_parse_is_identity(name, data):
    spec = COMMANDS[name]
    arg = None
    if spec.argument:
        arg = data.draw(st.text(st.characters(min_codepoint=33, max_codepoint=126), min_size=1,
                                max_size=20), label="arg")
    command = DashboardCommand(name, arg)
    assert decode_command(encode_command(name, arg).decode()) == command
    fields = {"mode": "RUNNING", "bool": data.draw(st.booleans(), label="bool"),
              "state": "PLAYING", "name": "prog.urp", "version": "5.11.1.108318",
              "text": " (Jan 13 2022)"}
    for ok in (True, False):
        templates = spec.ok if ok else spec.fail
        for variant in range(len(templates)):
            text = format_reply(command, ok, variant, **fields)
            reply = parse_reply(name, text)
            assert reply.ok is ok, text
            if ok and spec.value and "{" + spec.value + "}" in templates[variant]:
                assert reply.value == fields[spec.value]


def test_client_and_server_talk():
    client, server = DashboardClient(), DashboardServer()
    events = client.receive_data(server.greeting())
    assert events == [DashboardWelcome(WELCOME)]
    wire = client.send("load", "pick.urp") + client.send("robotmode") + client.send("running")
    assert client.awaiting == ("load", "robotmode", "running")
    commands = server.receive_data(wire)
    assert [c.name for c in commands] == ["load", "robotmode", "running"]
    back = (server.reply(commands[0]) + server.reply(commands[1], mode="IDLE")
            + server.reply(commands[2], bool=False))
    replies = []
    for i in range(len(back)):  # one byte at a time: lines may arrive split anywhere
        replies += client.receive_data(back[i:i + 1])
    assert [(r.command, r.ok, r.value) for r in replies] == [
        ("load", True, None), ("robotmode", True, "IDLE"), ("running", True, False)]
    assert isinstance(replies[0], DashboardReply) and replies[0].text == "Loading program: pick.urp"
    assert client.awaiting == ()


def test_client_rejects_lines_nobody_asked_for():
    client = DashboardClient()
    with pytest.raises(ProtocolError, match="welcome"):
        client.receive_data(b"Robotmode: IDLE\n")
    client = DashboardClient()
    client.receive_data(DashboardServer.greeting())
    with pytest.raises(ProtocolError, match="no command was sent"):
        client.receive_data(b"Robotmode: IDLE\n")


def test_server_quit_closes():
    server = DashboardServer()
    (command,) = server.receive_data(b"quit\n")
    assert server.reply(command) == b"Disconnected\n" and server.closed


def test_line_buffer_is_bounded():
    buffer = LineBuffer()
    with pytest.raises(ProtocolError, match="without a line break"):
        buffer.feed(b"x" * 70000)


@settings(max_examples=100, deadline=None)
@given(st.binary(max_size=300))
def test_garbage_never_crashes_the_server(data):
    server = DashboardServer()
    for command in server.receive_data(data):
        assert isinstance(server.reply(command, ok=True, mode="IDLE", bool=True, state="STOPPED",
                                       name="x", version="5.0.0", text="")
                          if command.known else server.reply(command), bytes)


def test_server_echoes_odd_arguments():
    server = DashboardServer()
    (command,) = server.receive_data(b"load a\rb.urp\n")
    assert server.reply(command) == b"Loading program: a\rb.urp\n"


def test_decode_command_ignoring_case_gives_the_documented_name():
    assert not decode_command("PROGRAMSTATE").known  # the real server is case-sensitive
    assert decode_command("Load Installation My.installation", ignore_case=True) == \
        DashboardCommand("load installation", "My.installation")
    assert decode_command("PROGRAMSTATE", ignore_case=True) == DashboardCommand("programState")
    assert not decode_command("fly", ignore_case=True).known
