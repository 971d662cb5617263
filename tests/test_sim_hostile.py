"""Hostile clients against the virtual controller's servers (issue 14): no input a client
sends may silence the network thread, and the dashboard is no oracle for files outside its
programs folder. Every socket has a timeout, so no test can hang."""

from __future__ import annotations

import gc
import socket
import struct
import time

import pytest
from _sim_clients import Dashboard, connect, read_exactly

from urdsl.sim import dashboard as sim_dashboard
from urdsl.sim import rtde as sim_rtde
from urdsl.sim.controller import VirtualController
from urdsl.sim.servers import STANDARD_PORTS

TIMEOUT = 5.0


@pytest.fixture
def sim(tmp_path):
    programs = tmp_path / "programs"
    programs.mkdir()
    (programs / "wave.script").write_text("def wave():\n  textmsg(\"hi\")\nend\n")
    (programs / "inside.urp").write_bytes(b"\x1f\x8b not URScript")
    (tmp_path / "secret.urp").write_bytes(b"\x1f\x8b secret")
    with VirtualController(programs_dir=programs) as controller:
        with controller.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
            controller.servers = servers
            controller.tmp = tmp_path
            yield controller


def rtde_ask(sock: socket.socket, kind: str, payload: bytes = b"") -> bytes:
    sock.sendall(struct.pack(">HB", len(payload) + 3, ord(kind)) + payload)
    while True:
        size, got = struct.unpack(">HB", read_exactly(sock, 3))
        data = read_exactly(sock, size - 3)
        if chr(got) == kind:
            return data


def still_served(sim) -> None:
    """A new dashboard client gets its welcome and an answer."""
    dash = Dashboard(sim)
    try:
        assert dash.welcome.startswith("Connected: Universal Robots Dashboard Server")
        assert dash.ask("robotmode") == "Robotmode: RUNNING"
    finally:
        dash.close()


# ---- the two remote kills ---------------------------------------------------------------------


def test_loading_a_300_character_file_name_answers_file_not_found(sim):
    dash = Dashboard(sim)
    name = "a" * 300 + ".script"
    assert dash.ask(f"load {name}") == f"File not found: {name}"
    assert dash.ask("load " + "d/" * 3000 + "x.script").startswith("File not found: ")
    assert dash.ask("load bad\x00name.script") == "File not found: bad\x00name.script"
    assert dash.ask("load wave.script") == "Loading program: wave.script"  # same client
    dash.close()
    still_served(sim)
    assert list(sim.servers.dropped) == []


def test_256_input_recipes_on_one_connection_refuse_the_256th_and_serve_on(sim):
    sock = connect(sim, "rtde")
    assert rtde_ask(sock, "V", struct.pack(">H", 2)) == b"\x01"
    ids = []
    for _ in range(256):
        reply = rtde_ask(sock, "I", b"input_int_register_0")
        ids.append(reply[0])
        assert reply[1:] == b"INT32"
    assert ids[:255] == list(range(1, 256))
    assert ids[255] == 0  # no id left: refused, like a recipe with an unknown field
    # the connection lives on, its recipes still work
    assert len(rtde_ask(sock, "v")) == 16
    sock.sendall(struct.pack(">HBBi", 8, ord("U"), 255, 1234))
    assert rtde_ask(sock, "S") == b"\x01"
    deadline = time.monotonic() + TIMEOUT
    while sim.env.input_int_registers[0] != 1234 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sim.env.input_int_registers[0] == 1234
    sock.close()
    still_served(sim)


def test_a_client_whose_input_makes_a_handler_raise_is_dropped_and_others_are_served(
        sim, monkeypatch, caplog):
    original = sim_dashboard.DashboardSession.command

    def command(self, line):
        if line == "boom":
            raise RuntimeError("a bug a client found")
        return original(self, line)

    monkeypatch.setattr(sim_dashboard.DashboardSession, "command", command)
    bystander = Dashboard(sim)
    victim = Dashboard(sim)
    victim.sock.sendall(b"boom\n")
    assert victim.file.read() == b""  # dropped: the server closed the connection
    victim.close()
    assert bystander.ask("robotmode") == "Robotmode: RUNNING"
    bystander.close()
    still_served(sim)
    assert ("dashboard", "internal error: RuntimeError: a bug a client found") \
        in sim.servers.dropped
    assert "a bug a client found" in caplog.text  # logged, with its traceback


@pytest.mark.parametrize("error", [struct.error("bad"), KeyError("x"), OverflowError("big"),
                                   MemoryError(), RecursionError("deep")])
def test_any_exception_in_the_rtde_handler_drops_only_that_client(sim, monkeypatch, error):
    def receive(self, data):
        raise error

    keeper = connect(sim, "rtde")
    assert rtde_ask(keeper, "V", struct.pack(">H", 2)) == b"\x01"
    monkeypatch.setattr(sim_rtde.RtdeSession, "receive", receive)
    victim = connect(sim, "rtde")
    victim.sendall(b"\x00\x03V")
    assert victim.recv(100) == b""
    victim.close()
    monkeypatch.undo()
    assert len(rtde_ask(keeper, "v")) == 16
    keeper.close()
    still_served(sim)


def test_an_exception_while_encoding_a_clients_stream_drops_only_that_client(sim,
                                                                             monkeypatch):
    def encode(self, snap):
        raise ZeroDivisionError("encoder bug")

    keeper = Dashboard(sim)
    sock = connect(sim, "rtde")
    assert rtde_ask(sock, "V", struct.pack(">H", 2)) == b"\x01"
    assert rtde_ask(sock, "O", struct.pack(">d", 125.0) + b"timestamp")[0] == 1
    monkeypatch.setattr(sim_rtde.RtdeSession, "encode", encode)
    sock.sendall(struct.pack(">HB", 3, ord("S")))
    while sock.recv(65536):  # a timeout here fails the test: the client must be dropped
        pass
    sock.close()
    assert any(reason == "internal error: ZeroDivisionError: encoder bug"
               for _kind, reason in sim.servers.dropped)
    assert keeper.ask("robotmode") == "Robotmode: RUNNING"
    keeper.close()


# ---- no file-existence oracle -----------------------------------------------------------------


def test_load_of_a_urp_outside_the_programs_folder_answers_alike_whether_it_exists(sim):
    dash = Dashboard(sim)
    outside = sim.tmp
    for existing, missing in [("../secret.urp", "../nothing.urp"),
                              (str(outside / "secret.urp"), str(outside / "nothing.urp"))]:
        assert (outside / existing.rsplit("/", 1)[-1]).exists()
        got_existing = dash.ask(f"load {existing}")
        got_missing = dash.ask(f"load {missing}")
        assert got_existing == f"File not found: {existing}"
        assert got_missing == f"File not found: {missing}"
    # inside the folder the controller says what it found
    assert dash.ask("load inside.urp") == "Error while loading program: inside.urp"
    assert dash.ask("load absent.urp") == "File not found: absent.urp"
    dash.close()


# ---- memory: the controller runs for months ---------------------------------------------------


def _rss_mib() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def _soak_program(index: int) -> str:
    lines = [f"def soak{index}():", "  pts = [0, 0, 0, 0]", "  total = 0"]
    for k in range(1, 200):
        if k % 50 == 0:
            lines.append(f"  movej([{0.05 * (k // 50)}, -1.5708, 1.5708, -1.5708, -1.5708, 0],"
                         " a=14, v=3)")
        else:
            lines.append(f"  pts[{k % 4}] = pts[{(k + 1) % 4}] + {k}.5 - total")
    lines += [f'  textmsg("soak {index}")', "end"]
    return "\n".join(lines) + "\n"


@pytest.mark.skipif(not hasattr(gc, "get_freeze_count"), reason="CPython collector")
def test_sixty_programs_in_a_row_leave_memory_flat():
    """Before the fix every finished program stayed in memory: about 17,000 objects and
    1.5 MiB per 200-line program (90 MiB over these 60)."""
    with VirtualController(speed=100) as sim:
        def run(index: int) -> None:
            seen = len(sim.messages)
            sim.submit(_soak_program(index))
            deadline = time.monotonic() + 60
            while not any(m.text == f"soak {index}" for m in sim.messages[seen:]):
                assert time.monotonic() < deadline, sim.messages[seen:]
                time.sleep(0.005)
            while sim.program_state.name != "STOPPED":
                assert time.monotonic() < deadline
                time.sleep(0.005)

        for index in range(10):
            run(index)
        objects, rss = len(gc.get_objects()), _rss_mib()
        for index in range(10, 60):
            run(index)
        grown_objects = len(gc.get_objects()) - objects
        grown_rss = _rss_mib() - rss
        assert sim.stats.programs == 60 and sim.stats.errors == 0
    assert grown_objects < 100_000, grown_objects  # was ~850,000
    assert grown_rss < 30.0, grown_rss  # MiB; was ~75


# ---- a program cut off by its connection ------------------------------------------------------


@pytest.mark.parametrize("reset", [False, True])
def test_a_program_cut_off_by_its_connection_is_reported_not_silently_lost(sim, reset):
    primary = connect(sim, "primary")
    seen = len(sim.messages)
    sender = connect(sim, "secondary")
    sender.sendall(b"def cut():\n  textmsg(\"never\")\n")
    deadline = time.monotonic() + TIMEOUT
    while not sim.servers._clients or not any(  # the sim has read the partial program
            c.framer is not None and c.framer.pending for c in list(sim.servers._clients)):
        assert time.monotonic() < deadline
        time.sleep(0.01)
    if reset:  # close with SO_LINGER 0: the kernel sends a reset
        sender.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    else:  # an orderly end: half-close, read until the sim closes too
        sender.shutdown(socket.SHUT_WR)
        while sender.recv(65536):
            pass
    sender.close()
    how = "was reset" if reset else "ended"
    while not any(how in m.text for m in sim.messages[seen:]):
        assert time.monotonic() < deadline, sim.messages[seen:]
        time.sleep(0.01)
    message = next(m for m in sim.messages[seen:] if how in m.text)
    assert message.kind == "runtime_exception"
    assert message.text.startswith(f"<secondary {sim.servers.ports['secondary']}>: the "
                                   f"connection {how} before the program's 'end' line")
    primary.close()
