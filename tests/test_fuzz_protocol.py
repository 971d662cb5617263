"""Fuzzing every protocol decoder and state machine, and the virtual controller's servers.

Seeded and bounded: each target mutates valid packets (bit flips, interesting bytes, size
fields set to edge values, truncation, splicing, random tails) and random message sequences
for ``URDSL_FUZZ_SECONDS`` s (default 1 s; ``make fuzz`` runs longer) or at most
``URDSL_FUZZ_SECONDS * 20,000`` inputs, from the seed ``URDSL_FUZZ_SEED`` (default 14; each
target derives its own from it). The time budget only decides how much is tried; nothing
asserts on time. A failure names the seed, the target and the input, so that it can be
replayed.

Properties: a decoder or state machine raises only :class:`ProtocolError` (the sim's
sessions: their documented answer), its buffers stay bounded, and the simulator's servers
keep serving — no input reaches their last-resort handler (a dropped client with an
"internal error" is a bug the handler hid).
"""

from __future__ import annotations

import os
import random
import socket
import struct
import time
import zlib
from collections.abc import Callable

import pytest

from urdsl.protocol import dashboard as dash
from urdsl.protocol import primary as prim
from urdsl.protocol import realtime as rt
from urdsl.protocol import rtde
from urdsl.protocol.errors import ProtocolError

SECONDS = float(os.environ.get("URDSL_FUZZ_SECONDS", "1"))
SEED = int(os.environ.get("URDSL_FUZZ_SEED", "14"))
MAX_INPUTS = max(int(SECONDS * 20_000), 200)

INTERESTING_8 = (0, 1, 0x7F, 0x80, 0xFF)
INTERESTING_SIZES = (0, 1, 2, 3, 4, 5, 7, 8, 0x7F, 0xFF, 0x100, 0x7FFF, 0xFFFF, 0x10000,
                     0x7FFFFFFF, 0x80000000, 0xFFFFFFFF)


# ---- the engine ---------------------------------------------------------------------------------


def _rng(target: str) -> random.Random:
    return random.Random(SEED * 1_000_003 + zlib.crc32(target.encode()))


def mutate(rng: random.Random, seeds: list[bytes]) -> bytes:
    """A mutated copy of one of ``seeds`` (1-4 mutations), or random bytes."""
    if rng.random() < 0.05:
        return rng.randbytes(rng.choice((0, 1, 3, 8, 64, 700, 1500)))
    data = bytearray(rng.choice(seeds))
    for _ in range(rng.randint(1, 4)):
        choice = rng.random()
        if not data:
            data += rng.randbytes(rng.randint(1, 16))
        elif choice < 0.25:  # flip a bit
            i = rng.randrange(len(data))
            data[i] ^= 1 << rng.randrange(8)
        elif choice < 0.40:  # an interesting byte
            data[rng.randrange(len(data))] = rng.choice(INTERESTING_8)
        elif choice < 0.55:  # a size-like field at a random place (2 or 4 bytes)
            width = rng.choice((2, 4))
            value = rng.choice(INTERESTING_SIZES + (len(data), len(data) - 1, len(data) + 1))
            raw = (value % (1 << (8 * width))).to_bytes(width, "big")
            at = rng.choice((0, 0, rng.randrange(len(data))))
            data[at:at + width] = raw
        elif choice < 0.70:  # truncate
            del data[rng.randrange(len(data)):]
        elif choice < 0.80:  # random tail
            data += rng.randbytes(rng.randint(1, 64))
        elif choice < 0.90:  # splice another seed in
            other = rng.choice(seeds)
            at = rng.randrange(len(data) + 1)
            data[at:at] = other[:rng.randint(0, len(other))]
        else:  # repeat a chunk
            a = rng.randrange(len(data))
            b = min(len(data), a + rng.randint(1, 32))
            data[a:a] = data[a:b] * rng.randint(1, 8)
    return bytes(data)


def chunks(rng: random.Random, data: bytes) -> list[bytes]:
    """``data`` cut at random places (as TCP delivers it)."""
    out = []
    while data:
        cut = rng.choice((1, 2, 3, 7, 64, 1024, len(data)))
        out.append(data[:cut])
        data = data[cut:]
    return out


def run(target: str, step: Callable[[random.Random], object]) -> int:
    """Call ``step(rng)`` until the budget is spent; a failure names how to replay it."""
    rng = _rng(target)
    deadline = time.monotonic() + SECONDS
    count = 0
    while count < MAX_INPUTS and (count < 50 or time.monotonic() < deadline):
        try:
            step(rng)
        except Exception as error:
            raise AssertionError(
                f"fuzz target {target!r}, URDSL_FUZZ_SEED={SEED}, input #{count}: "
                f"{type(error).__name__}: {error}") from error
        count += 1
    print(f"fuzz {target}: {count} inputs, URDSL_FUZZ_SEED={SEED}")  # shown by make fuzz
    return count


def expect_protocol_error(call: Callable[[], object]) -> object:
    try:
        return call()
    except ProtocolError as error:
        assert str(error)
        return None


# ---- seeds ----------------------------------------------------------------------------------


def _realtime_seeds() -> list[bytes]:
    seeds = []
    for version in ("3.0", "3.2", "3.5", "3.10", "5.0", "5.10", "5.15"):
        try:
            state = rt.realtime_state(version, q_actual=(0.1, -1.2, 1.3, -1.4, 0.5, 0.6))
        except (TypeError, ProtocolError):
            state = rt.realtime_state(version)
        seeds.append(rt.encode_realtime(state))
    return seeds


def _sim_streams() -> tuple[list[bytes], list[bytes]]:
    """Primary messages and realtime packets as the virtual controller sends them."""
    from urdsl.sim import wire
    from urdsl.sim.controller import VirtualController
    from urdsl.sim.state import SafetyMode

    primary, realtime = [], []
    for robot in ("ur5e", "ur10"):
        sim = VirtualController(robot=robot)  # not started: no threads
        snap, version = sim.snapshot(), sim.version
        primary += [
            wire.encode_version_message(version, 1.0),
            wire.encode_robot_state(snap, version),
            wire.encode_robot_state(snap, version, sim.spec, (sim.kinematics.qd_max, sim.q_min,
                                                              sim.q_max), configuration=True),
            wire.encode_text_message("hello", 2.0),
            wire.encode_runtime_exception(3, 4, "name 'x' is not defined", 3.0),
            wire.encode_safety_message(153, 1, SafetyMode.PROTECTIVE_STOP, 4.0),
        ]
        realtime.append(wire.encode_realtime(snap, version))
    return primary, realtime


_PRIMARY, _SIM_REALTIME = _sim_streams()
_REALTIME = _realtime_seeds() + _SIM_REALTIME

_OUTPUTS = ["timestamp", "actual_q", "actual_TCP_pose", "robot_mode", "output_int_register_0",
            "actual_digital_output_bits", "speed_scaling", "no_such_field"]
_INPUTS = ["input_int_register_0", "input_double_register_1", "standard_digital_output_mask",
           "standard_digital_output", "speed_slider_fraction", "nothing_here"]


def _rtde_client_seeds() -> list[bytes]:
    seeds = []
    for protocol in (1, 2):
        for request in (rtde.RequestProtocolVersion(2), rtde.GetControllerVersion(),
                        rtde.SetupOutputs(tuple(_OUTPUTS[:4]), 125.0),
                        rtde.SetupInputs(tuple(_INPUTS[:2])), rtde.Start(), rtde.Pause()):
            try:
                seeds.append(rtde.encode_rtde(request, protocol))
            except (ProtocolError, TypeError):
                pass
    seeds.append(struct.pack(">HBBi", 8, ord("U"), 1, 42))
    seeds.append(rtde.RtdeClient().send_message("hello", "fuzz"))
    return seeds


def _rtde_server_seeds() -> list[bytes]:
    """Replies and data as a server sends them: driven through RtdeServer."""
    server = rtde.RtdeServer((5, 15, 0, 0))
    client = rtde.RtdeClient()
    out = []
    for request in (lambda: client.request_protocol_version(2), client.get_controller_version,
                    lambda: client.setup_outputs(_OUTPUTS[:5], 125.0),
                    lambda: client.setup_inputs(_INPUTS[:2]), client.start):
        server.receive_data(request())
        reply = server.data_to_send()
        client.receive_data(reply)
        out.append(reply)
    data = server.outputs({"timestamp": 1.5, "actual_q": [0.1] * 6,
                           "actual_TCP_pose": [0.2] * 6, "robot_mode": 7,
                           "output_int_register_0": 3}, 0)
    if data:
        out.append(data)
    return [d for d in out if d]


_RTDE_CLIENT = _rtde_client_seeds()
_RTDE_SERVER = _rtde_server_seeds()
_DASH_COMMANDS = [dash.encode_command(spec.name, "x.script" if spec.argument else None)
                  for spec in dash.COMMANDS.values()]
_DASH_REPLIES = [(dash.format_reply(spec.name + (" a.script" if spec.argument else ""), True, 0,
                                    mode="RUNNING", bool=True, state="PLAYING", name="a",
                                    text=" x", version="5.15.0") + "\n").encode()
                 for spec in dash.COMMANDS.values()]


# ---- decoders of one packet ----------------------------------------------------------------------


def test_fuzz_realtime_decoder():
    def step(rng):
        data = mutate(rng, _REALTIME)
        expect_protocol_error(lambda: rt.decode_realtime(data))
        version = rng.choice((None, "3.0", "3.5", "5.10", "5.15", "9.9"))
        expect_protocol_error(lambda: rt.decode_realtime(data, version))

    assert run("realtime", step) >= 50


def test_fuzz_realtime_stream():
    def step(rng):
        decoder = rt.RealtimeDecoder()
        stream = b"".join(mutate(rng, _REALTIME) if rng.random() < 0.3 else rng.choice(_REALTIME)
                          for _ in range(rng.randint(1, 4)))
        for piece in chunks(rng, stream):
            try:
                decoder.feed(piece)
            except ProtocolError:
                break  # documented: the stream cannot be trusted after an error
            assert decoder.pending <= 1 << 16

    assert run("realtime-stream", step) >= 50


def test_fuzz_primary_decoder():
    def step(rng):
        data = mutate(rng, _PRIMARY)
        expect_protocol_error(lambda: prim.decode_primary(data))

    assert run("primary", step) >= 50


def test_fuzz_primary_stream():
    def step(rng):
        decoder = prim.PrimaryDecoder()
        stream = b"".join(mutate(rng, _PRIMARY) if rng.random() < 0.3 else rng.choice(_PRIMARY)
                          for _ in range(rng.randint(1, 5)))
        broken = False
        for piece in chunks(rng, stream):
            try:
                decoder.receive_data(piece)
            except ProtocolError:
                break  # documented: a broken framing refuses everything after
            for _ in range(len(stream) + 1):  # bounded: one message per byte at most
                pending = decoder.pending
                try:
                    if decoder.next_message() is None:
                        break
                except ProtocolError:
                    if decoder.pending == pending:  # nothing consumed: the framing broke
                        broken = True
                        break
                    # a malformed message inside good framing is consumed; go on
            if broken:
                break
            assert decoder.pending <= prim.MAX_MESSAGE

    assert run("primary-stream", step) >= 50


def test_fuzz_rtde_decoder_both_directions():
    recipe_sets = [None, {1: rtde.Recipe(1, ("input_int_register_0",), ("INT32",)),
                          None: rtde.Recipe(None, ("timestamp",), ("DOUBLE",))}]

    def step(rng):
        sender = rng.choice(("client", "server"))
        data = mutate(rng, _RTDE_CLIENT if sender == "client" else _RTDE_SERVER)
        expect_protocol_error(lambda: rtde.decode_rtde(
            data, sender=sender, protocol=rng.choice((1, 2)), recipes=rng.choice(recipe_sets)))

    assert run("rtde", step) >= 50


# ---- state machines -----------------------------------------------------------------------------


def test_fuzz_rtde_client_state_machine():
    def step(rng):
        client = rtde.RtdeClient()
        for _ in range(rng.randint(1, 6)):
            action = rng.randrange(6)
            try:
                if action == 0:
                    client.request_protocol_version(rng.choice((1, 2, 3)))
                elif action == 1:
                    client.get_controller_version()
                elif action == 2:
                    client.setup_outputs(rng.sample(_OUTPUTS, rng.randint(1, 4)),
                                         rng.choice((125.0, 500.0, 10.0)))
                elif action == 3:
                    client.setup_inputs(rng.sample(_INPUTS, rng.randint(1, 3)))
                elif action == 4:
                    client.start()
                else:
                    client.pause()
            except ProtocolError:
                pass  # documented refusals (pause first, no recipe, ...)
        stream = b"".join(mutate(rng, _RTDE_SERVER) if rng.random() < 0.5
                          else rng.choice(_RTDE_SERVER) for _ in range(rng.randint(1, 4)))
        for piece in chunks(rng, stream):
            try:
                client.receive_data(piece)
            except ProtocolError:
                break

    assert run("rtde-client", step) >= 50


def test_fuzz_rtde_server_state_machine():
    ownership = rtde.InputOwnership()

    def step(rng):
        server = rtde.RtdeServer(rng.choice(((5, 15, 0, 0), (3, 15, 0, 0))), ownership)
        stream = b"".join(mutate(rng, _RTDE_CLIENT) if rng.random() < 0.5
                          else rng.choice(_RTDE_CLIENT) for _ in range(rng.randint(1, 8)))
        try:
            for piece in chunks(rng, stream):
                server.receive_data(piece)
                server.data_to_send()
                if server.running and server.output_recipe is not None:
                    expect_protocol_error(lambda: server.outputs({}, rng.randrange(1000)))
        except ProtocolError:
            pass
        finally:
            server.close()

    assert run("rtde-server", step) >= 50


def test_fuzz_dashboard_client_state_machine():
    names = list(dash.COMMANDS)

    def step(rng):
        client = dash.DashboardClient()
        for _ in range(rng.randint(0, 4)):
            spec = dash.COMMANDS[rng.choice(names)]
            client.send(spec.name, "a.script" if spec.argument else None)
        lines = [dash.DashboardServer.greeting()] + [
            mutate(rng, _DASH_REPLIES) if rng.random() < 0.5 else rng.choice(_DASH_REPLIES)
            for _ in range(rng.randint(0, 5))]
        if rng.random() < 0.2:
            lines[0] = mutate(rng, lines[:1])
        for piece in chunks(rng, b"".join(lines)):
            try:
                client.receive_data(piece)
            except ProtocolError:
                break

    assert run("dashboard-client", step) >= 50


def test_fuzz_dashboard_server_state_machine():
    def step(rng):
        server = dash.DashboardServer()
        stream = b"".join(mutate(rng, _DASH_COMMANDS) if rng.random() < 0.6
                          else rng.choice(_DASH_COMMANDS) for _ in range(rng.randint(1, 6)))
        try:
            for piece in chunks(rng, stream):
                for command in server.receive_data(piece):
                    for ok in (True, False):
                        expect_protocol_error(lambda c=command, o=ok: server.reply(
                            c, o, 0, mode="RUNNING", bool=True, state="STOPPED", name="n",
                            text="t", version="5.15"))
        except ProtocolError:
            pass

    assert run("dashboard-server", step) >= 50


# ---- the virtual controller's sessions, without sockets ----------------------------------------


@pytest.fixture(scope="module")
def idle_sim(tmp_path_factory):
    from urdsl.sim.controller import VirtualController

    folder = tmp_path_factory.mktemp("programs")
    (folder / "a.script").write_text('def a():\n  textmsg("a")\nend\n')
    return VirtualController(programs_dir=folder)  # not started: play only queues the job


def test_fuzz_sim_dashboard_session(idle_sim):
    from urdsl.sim.dashboard import MAX_LINE, DashboardSession

    seeds = _DASH_COMMANDS + [b"load a.script\n", b"load ../../etc/passwd\n",
                              b"load " + b"z" * 400 + b".urp\n"]

    def step(rng):
        session = DashboardSession(idle_sim)
        stream = b"".join(mutate(rng, seeds) for _ in range(rng.randint(1, 6)))
        for piece in chunks(rng, stream):
            for reply in session.receive(piece):  # documented: always a reply line
                assert isinstance(reply, str) and "\n" not in reply
        assert session.pending <= MAX_LINE  # the protocol's one dashboard line limit

    assert run("sim-dashboard", step) >= 50


def test_fuzz_sim_rtde_session(idle_sim):
    from urdsl.sim.rtde import InputOwners, RtdeProtocolError, RtdeSession

    owners = InputOwners()

    def step(rng):
        session = RtdeSession(idle_sim.version, idle_sim.env, owners, idle_sim.frequency)
        stream = b"".join(mutate(rng, _RTDE_CLIENT) if rng.random() < 0.5
                          else rng.choice(_RTDE_CLIENT) for _ in range(rng.randint(1, 8)))
        try:
            for piece in chunks(rng, stream):
                reply = session.receive(piece)
                assert isinstance(reply, bytes)
                if session.started and session.output is not None and session.output.valid:
                    session.encode(idle_sim.snapshot())
        except RtdeProtocolError:
            pass  # documented: the connection is dropped
        finally:
            session.close()

    assert run("sim-rtde", step) >= 50


def test_fuzz_sim_script_framer():
    from urdsl.protocol.script_framing import ScriptFramer

    seeds = [b'def p():\n  textmsg("x")\nend\n', b"sec s():\n  x = 1\nend\n",
             b"textmsg(1)\nmovej([0,0,0,0,0,0])\n", b"def q():\r\n  y = 2\r\nend # done\r\n"]

    def step(rng):
        framer = ScriptFramer(limit=4096)
        stream = b"".join(mutate(rng, seeds) for _ in range(rng.randint(1, 6)))
        for piece in chunks(rng, stream):
            try:
                for chunk in framer.feed(piece):
                    assert chunk.kind in ("def", "sec", "bare")
            except ProtocolError:
                break  # documented: a program or line over the limit

    assert run("sim-framer", step) >= 50


# ---- the virtual controller's servers over loopback --------------------------------------------


def _ask_dashboard(port: int) -> str:
    with socket.create_connection(("127.0.0.1", port), 5) as sock:
        sock.settimeout(5)
        file = sock.makefile("rb")
        assert file.readline().startswith(b"Connected: ")
        sock.sendall(b"robotmode\n")
        return file.readline().decode()


def _ask_rtde_version(port: int) -> bytes:
    with socket.create_connection(("127.0.0.1", port), 5) as sock:
        sock.settimeout(5)
        sock.sendall(struct.pack(">HB", 3, ord("v")))
        data = b""
        while len(data) < 3 or len(data) < struct.unpack_from(">H", data)[0]:
            chunk = sock.recv(4096)
            assert chunk, "the RTDE server closed the connection"
            data += chunk
        return data


def test_fuzz_sim_servers_keep_serving(tmp_path):
    from urdsl.sim.controller import VirtualController
    from urdsl.sim.servers import STANDARD_PORTS

    (tmp_path / "a.script").write_text('def a():\n  textmsg("a")\nend\n')
    seeds = {
        "dashboard": _DASH_COMMANDS + [b"load " + b"n" * 300 + b".script\n"],
        "rtde": _RTDE_CLIENT,
        "primary": [b'def f():\n  textmsg("f")\nend\n', b"textmsg(1)\n", b"sec s():\nend\n"],
        "secondary": [b'def g():\n  x = 1\nend\n'],
        "realtime": [b"def h():\n  sleep(0.01)\nend\n"],
        "primary_ro": [b"anything\n"], "secondary_ro": [b"x\n"], "realtime_ro": [b"y\n"],
    }
    kinds = list(seeds)
    rng = _rng("sim-servers")
    with VirtualController(speed=20, programs_dir=tmp_path) as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        deadline = time.monotonic() + max(SECONDS * 3, 2.0)
        rounds = 0
        while rounds < 10 or (time.monotonic() < deadline and rounds < MAX_INPUTS // 100):
            rounds += 1
            open_clients = []
            for _ in range(rng.randint(1, 6)):
                kind = rng.choice(kinds)
                sock = socket.create_connection(("127.0.0.1", servers.ports[kind]), 5)
                sock.settimeout(5)
                stream = b"".join(mutate(rng, seeds[kind]) for _ in range(rng.randint(1, 5)))
                try:
                    for piece in chunks(rng, stream):
                        sock.sendall(piece)
                except OSError:
                    pass  # the server may drop a client that broke the framing
                open_clients.append(sock)
            for sock in open_clients:
                how = rng.random()
                if how < 0.3:  # reset
                    sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                elif how < 0.6:
                    try:
                        sock.shutdown(socket.SHUT_WR)
                    except OSError:
                        pass
                sock.close()
            internal = [d for d in list(servers.dropped) if d[1].startswith("internal error")]
            assert not internal, f"URDSL_FUZZ_SEED={SEED}, round {rounds}: {internal}"
        print(f"fuzz sim-servers: {rounds} rounds of 1-6 clients, URDSL_FUZZ_SEED={SEED}, "
              f"{len(servers.dropped)} drops")
        # still serving: every interface answers a new client
        assert _ask_dashboard(servers.ports["dashboard"]).startswith("Robotmode: ")
        assert _ask_rtde_version(servers.ports["rtde"])[2] == ord("v")
        for kind in ("primary", "secondary", "realtime"):
            with socket.create_connection(("127.0.0.1", servers.ports[kind]), 5) as sock:
                sock.settimeout(5)
                assert sock.recv(4)
        assert servers._thread is not None and servers._thread.is_alive()
