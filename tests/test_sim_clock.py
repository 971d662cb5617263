"""The virtual controller's clock runs in lockstep with its interpreter: every published step
carries the controller time of the program's state, also when the program (or the machine)
is too slow for ``speed`` — then the controller runs slower in wall time, never ahead of the
program, and skips no step."""

from __future__ import annotations

import logging
import threading

import numpy as np
import pytest

from urdsl.runtime.interpreter import Interpreter
from urdsl.sim.controller import VirtualController
from urdsl.sim.servers import STANDARD_PORTS
from urdsl.sim.state import ProgramState

FRAMES = 256
"""Interpreter frames (2 ms each) the counting program runs: 0.512 s, a whole number of the
controller's steps at speed 4 (8 ms each)."""

FRAME = 0.002


def counting(frames: int = FRAMES, work: int = 0) -> str:
    """A program that writes its frame number to output integer register 0 at every frame,
    after ``work`` loop turns of arithmetic in the same frame."""
    return (f"def counting():\n"
            f"  i = 0\n"
            f"  while i < {frames}:\n"
            f"    j = 0\n"
            f"    x = 0.0\n"
            f"    while j < {work}:\n"
            f"      x = x + sin(j) * cos(i)\n"
            f"      j = j + 1\n"
            f"    end\n"
            f"    write_output_integer_register(0, i)\n"
            f"    i = i + 1\n"
            f"    sync()\n"
            f"  end\n"
            f"end\n")


def run_recorded(sim: VirtualController, program: str,
                 timeout: float = 60.0) -> list[tuple[float, int, int, float]]:
    """Run ``program`` and return every state published from its start to the first step
    after its end: (controller time s, program state, output integer register 0, speed
    scaling)."""
    steps: list[tuple[float, int, int, float]] = []
    ended = threading.Event()

    def watch(snap) -> None:
        if ended.is_set():
            return
        if snap.program_state == ProgramState.PLAYING or steps:
            steps.append((snap.time, int(snap.program_state), snap.output_int_registers[0],
                          snap.speed_scaling))
            if snap.program_state == ProgramState.STOPPED:
                ended.set()

    sim.subscribe(watch)
    sim.submit(program)
    assert ended.wait(timeout), "the program did not end"
    sim.unsubscribe(watch)
    return steps


def assert_lockstep(sim: VirtualController, steps: list[tuple[float, int, int, float]],
                    frames: int = FRAMES) -> None:
    times = np.array([t for t, *_ in steps])
    step = sim.step_time * sim.speed
    # every step published, in order: consecutive states are exactly one step apart
    assert np.allclose(np.diff(times), step, atol=1e-9)
    start = times[0]
    for time_, state, register, scaling in steps:
        if state == ProgramState.PLAYING:
            # the program has done exactly the frames due by the step's controller time
            assert scaling == 1.0
            assert register == min(round((time_ - start) / FRAME), frames - 1)
    # the program took its own time in controller time, however long it took in wall time
    assert steps[-1][1] == ProgramState.STOPPED
    assert times[-1] - start == pytest.approx(frames * FRAME, abs=1e-9)


def test_a_slow_interpreter_slows_the_controller_down_instead_of_falling_behind(
        monkeypatch, caplog):
    import time

    original = Interpreter.sync

    def slow_sync(self) -> None:
        time.sleep(0.003)  # 3 ms of wall time per 2 ms frame: too slow for speed 4
        original(self)

    monkeypatch.setattr(Interpreter, "sync", slow_sync)
    with caplog.at_level(logging.WARNING, logger="urdsl.sim"), \
            VirtualController(speed=4.0) as sim:
        steps = run_recorded(sim, counting())
        assert_lockstep(sim, steps)
        # it ran slower than 4x in wall time, and said so once
        assert sim.stats.slowdowns >= 1 and sim.stats.behind > 0.1
    warnings = [r for r in caplog.records if "behind speed x4" in r.getMessage()]
    assert len(warnings) == 1


def test_heavy_computation_in_every_frame_keeps_controller_time_in_lockstep():
    with VirtualController(speed=4.0) as sim:
        assert_lockstep(sim, run_recorded(sim, counting(frames=64, work=150)), frames=64)


def test_rtde_carries_the_controller_time_of_the_programs_state(monkeypatch, tmp_path):
    """On the wire: at 500 Hz every RTDE package's timestamp matches the frame count the
    program wrote into the register it carries, with no package missing."""
    import time

    from urdsl.robot.recorder import record

    original = Interpreter.sync

    def slow_sync(self) -> None:
        time.sleep(0.002)
        original(self)

    monkeypatch.setattr(Interpreter, "sync", slow_sync)
    csv = tmp_path / "steps.csv"
    stop = threading.Event()
    with VirtualController(speed=4.0) as sim, \
            sim.serve(ports={name: 0 for name in STANDARD_PORTS}) as servers:
        recorder = threading.Thread(target=record, args=("127.0.0.1", csv), kwargs=dict(
            fields=["timestamp", "runtime_state", "output_int_register_0"], frequency=500.0,
            duration=60.0, port=servers.ports["rtde"], stop=stop))
        recorder.start()
        sim.wait_snapshot(lambda s: csv.exists(), 10)  # the recorder has its recipe
        time.sleep(0.2)  # and streams
        run_recorded(sim, counting())
        ended = sim.now()
        sim.wait_snapshot(lambda s: s.time >= ended + 0.2, 10)
        time.sleep(0.3)
        stop.set()
        recorder.join(10)
    header, *rows = csv.read_text().splitlines()
    data = np.array([[float(v) for v in row.split()] for row in rows])
    assert header.split() == ["timestamp", "runtime_state", "output_int_register_0"]
    assert np.allclose(np.diff(data[:, 0]), 0.008, atol=1e-9)  # no package missing
    playing = data[data[:, 1] == ProgramState.PLAYING]
    assert len(playing) == FRAMES * FRAME / 0.008
    expected = np.minimum(np.round((playing[:, 0] - playing[0, 0]) / FRAME), FRAMES - 1)
    assert np.array_equal(playing[:, 2], expected)


def test_a_program_that_overruns_a_step_is_held_while_the_streams_go_on(monkeypatch):
    """A step's work that takes longer than OVERRUN s of wall time (here one frame that
    sleeps 0.6 s): the steps are still published, one after the other, with the program held
    (speed scaling 0, its time standing still) until it has done that step's work; the arm
    and the program agree throughout, and the program takes the held steps longer."""
    import time

    from urdsl.sim.controller import OVERRUN

    original = Interpreter.sync
    calls = []

    def stuck_once(self) -> None:
        calls.append(1)
        if len(calls) == 20:
            time.sleep(OVERRUN + 0.35)
        original(self)

    monkeypatch.setattr(Interpreter, "sync", stuck_once)
    with VirtualController(speed=4.0) as sim:
        steps = run_recorded(sim, counting(frames=64))
        held_total = sim.stats.held
    step = sim.step_time * sim.speed
    times = np.array([t for t, *_ in steps])
    assert np.allclose(np.diff(times), step, atol=1e-9)  # published on, none skipped
    held = np.array([state == ProgramState.PLAYING and scaling == 0.0
                     for _, state, _, scaling in steps])
    # about (0.6 s - OVERRUN) of held steps at 500 Hz; at least a few, however loaded
    assert held.sum() == held_total >= 10
    program_time = times - times[0] - step * np.cumsum(held)
    overrun = np.roll(held, -1) & ~held  # the step published mid-way through the work
    for (_, state, register, _), t, mid in zip(steps, program_time, overrun | held, strict=True):
        if state == ProgramState.PLAYING:
            expected = min(round(t / FRAME), 63)
            assert register <= expected if mid else register == expected
    assert steps[-1][1] == ProgramState.STOPPED
    assert program_time[-1] == pytest.approx(64 * FRAME, abs=1e-9)
