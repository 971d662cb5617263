"""The demo story: write → check → send → observe, against the virtual controller.

:func:`demo_story` compiles a program from ``programs/`` (the DSL pick-and-place if it is
there, else the course examples), checks it offline, starts a virtual controller, records
RTDE while the program runs on it, stops the controller, and writes:

* ``report.txt`` — the checker's report and what the controller did (observed cycle time,
  largest gap between the planned and the recorded joints);
* ``<program>.script`` — the URScript that was sent;
* ``robot_data.csv`` — the RTDE recording, in the format of UR's ``record.py``
  (space-delimited, vector fields as ``name_0 … name_5``);
* ``robot_data.png`` — recorded joints over the planned ones.

Everything runs on 127.0.0.1 with ports chosen by the system, so it never collides with a
running ``urdsl sim``. Sending and recording use urdsl's own clients (:mod:`urdsl.robot`).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["demo_story", "StoryResult", "PROGRAMS"]

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"

FIELDS = ("timestamp", "actual_q", "actual_TCP_pose", "runtime_state")
PLAYING, STOPPED = 2, 1

AFTER = 1.0
"""Controller time (s) the recording goes on after the program has ended (then a little
wall time more, :data:`AFTER_WALL`), so that it holds the first STOPPED samples."""

START_TIMEOUT = 30.0
"""Wall time (s) the program may take to start on the controller (it is compiled first)."""

AFTER_WALL = 0.5
"""Wall time (s) the recorder gets to read what was published before it is stopped."""


@dataclass
class StoryResult:
    """Where the story wrote its files, and what it measured.

    ``planned_time``: the checker's cycle time (s); ``observed_time``: how long the
    controller reported PLAYING (s of controller time); ``max_deviation``: largest
    difference between recorded and planned joints (rad) over the run; ``samples``: RTDE
    samples recorded; ``sent``: False when the check found errors and nothing was sent;
    ``behind``: wall seconds the controller gave up keeping ``speed`` because the machine was
    too slow (its controller time, and so ``observed_time``, is not affected); ``held``:
    controller steps the program was held because one step's work took it too long in wall
    time (each makes ``observed_time`` one step longer; see :data:`urdsl.sim.controller.OVERRUN`).
    """

    program: Path
    report: Path
    csv: Path | None = None
    plot: Path | None = None
    samples: int = 0
    planned_time: float = 0.0
    observed_time: float = 0.0
    max_deviation: float = float("nan")
    sent: bool = False
    behind: float = 0.0
    held: int = 0
    messages: list[str] = field(default_factory=list)

    def paths(self) -> list[Path]:
        return [p for p in (self.report, self.program, self.csv, self.plot) if p is not None]


def _source(programs: Path) -> tuple[str, str]:
    """(name, URScript text) of the demo program."""
    from ..script.parser import parse
    from ..script.printer import format as format_tree

    dsl = programs / "pick_and_place.py"
    if dsl.exists():
        from ..dsl.command import load_program  # the DSL layer compiles .py programs

        program = load_program(dsl)
        return "pick_and_place", format_tree(program.tree())
    script = programs / "course_examples.script"
    text = script.read_text(encoding="utf-8")
    return "course_examples", format_tree(parse(text, str(script)))


def _read_csv(path: Path) -> np.ndarray:
    """The recording as rows of timestamp, actual_q (6), actual_TCP_pose (6), runtime_state."""
    columns = ["timestamp"] + [f"actual_q_{i}" for i in range(6)] + \
        [f"actual_TCP_pose_{i}" for i in range(6)] + ["runtime_state"]
    if not path.exists():
        return np.zeros((0, len(columns)))
    with open(path, encoding="utf-8") as handle:
        header = handle.readline().split()
        data = np.loadtxt(handle, ndmin=2)
    if len(data) == 0:
        return np.zeros((0, len(columns)))
    return data[:, [header.index(c) for c in columns]]


def _plot(path: Path, rows: np.ndarray, start: float, trace, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..verify.plot import JOINT_NAMES

    figure, axis = plt.subplots(figsize=(11, 5), constrained_layout=True)
    for joint in range(6):
        line, = axis.plot(rows[:, 0] - start, rows[:, 1 + joint], lw=1.6,
                          label=f"{JOINT_NAMES[joint]} (RTDE)")
        if trace is not None and len(trace.times):
            axis.plot(trace.times, trace.q[:, joint], "--", color=line.get_color(), lw=0.9)
    axis.set_xlabel("time since the program started (s)")
    axis.set_ylabel("joint position (rad)")
    axis.set_title(f"{title}: recorded by RTDE (solid) over the checker's plan (dashed)")
    axis.legend(ncol=3, fontsize=8)
    axis.grid(alpha=0.3)
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _wait_for_end(sim, timeout: float) -> None:
    """Wait (at most ``timeout`` s of wall time) until the controller has run a program to
    its end and :data:`AFTER` s of controller time more."""
    from .state import ProgramState

    deadline = time.monotonic() + timeout
    try:
        # a program that does not start (refused by the controller) ends the wait sooner
        sim.wait_snapshot(lambda s: s.program_state == ProgramState.PLAYING,
                          min(timeout, START_TIMEOUT))
        ended = sim.wait_snapshot(lambda s: s.program_state == ProgramState.STOPPED,
                                  max(deadline - time.monotonic(), 0.0)).time
        sim.wait_snapshot(lambda s: s.time >= ended + AFTER,
                          max(deadline - time.monotonic(), 0.0))
    except TimeoutError:  # the report says what was recorded
        pass


def demo_story(out_dir: str | Path = "out", *, robot: str = "ur5e", speed: float = 1.0,
               frequency: float = 125.0, programs: str | Path | None = None,
               timeout: float = 120.0) -> StoryResult:
    """Run the story (see the module docstring) and return where its files are.

    ``speed``: how much faster than real time the controller runs the program;
    ``frequency``: RTDE recording rate (Hz, at most 500 on e-Series); ``timeout``: wall
    seconds the program may take on the controller before the story gives up on it.
    The recording lasts as long as the program takes in controller time (plus
    :data:`AFTER`), however slowly a loaded machine runs the controller in wall time.
    """
    from ..verify.run import CheckOptions, check_text
    from .controller import VirtualController
    from .servers import STANDARD_PORTS

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name, text = _source(Path(programs) if programs is not None else PROGRAMS)
    program_path = out / f"{name}.script"
    program_path.write_text(text, encoding="utf-8")

    report = check_text(text, str(program_path), options=CheckOptions(robot=robot))
    result = StoryResult(program_path, out / "report.txt", planned_time=report.cycle_time)
    lines = [report.render_text(), ""]
    if report.has_errors:
        lines.append("not sent: the check found errors (a robot would stop for them)")
        result.report.write_text("\n".join(lines) + "\n", encoding="utf-8")
        return result

    from ..robot.recorder import record
    from ..robot.sender import send_program

    result.csv = out / "robot_data.csv"
    with VirtualController(robot=robot, speed=speed) as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        recording: dict = {}
        stop = threading.Event()

        def run_recorder() -> None:
            try:
                recording["rows"] = record("127.0.0.1", result.csv, list(FIELDS),
                                           frequency=frequency, duration=timeout,
                                           port=servers.ports["rtde"], stop=stop)
            except Exception as error:  # shown in the report, the story goes on
                recording["error"] = error

        recorder = threading.Thread(target=run_recorder, name="urdsl-story-rtde", daemon=True)
        recorder.start()
        time.sleep(0.3)  # the recorder is streaming before the program starts
        # checked above; the recording watches it, so the sender need not follow it
        send_program(text, "127.0.0.1", servers.ports["secondary"], check=False, follow=False)
        result.sent = True
        _wait_for_end(sim, timeout)
        time.sleep(AFTER_WALL)
        stop.set()
        recorder.join(10)
        result.messages = [f"{m.kind}: {m.text}" for m in sim.messages]
        result.behind = sim.stats.behind
        result.held = sim.stats.held
    if "error" in recording:
        result.messages.append(f"recorder: {recording['error']}")

    rows = _read_csv(result.csv)
    result.samples = len(rows)
    playing = rows[rows[:, -1] == PLAYING, 0] if len(rows) else np.zeros(0)
    started = float(playing[0]) if len(playing) else None
    after = rows[(rows[:, 0] > playing[-1]) & (rows[:, -1] == STOPPED), 0] \
        if len(playing) else np.zeros(0)
    begin = started if started is not None else (rows[0, 0] if len(rows) else 0.0)
    if started is not None and len(after):
        result.observed_time = float(after[0]) - started
    trace = report.trace
    if trace is not None and len(trace.times) and len(rows):
        local = rows[:, 0] - begin
        inside = (local >= 0) & (local <= trace.times[-1])
        if inside.any():
            planned = np.stack([np.interp(local[inside], trace.times, trace.q[:, j])
                                for j in range(6)], axis=1)
            result.max_deviation = float(np.max(np.abs(planned - rows[inside, 1:7])))
    result.plot = out / "robot_data.png"
    _plot(result.plot, rows, begin, trace, name)
    lines += [
        f"sent to the virtual controller ({robot}, speed x{speed:g}); RTDE recorded "
        f"{result.samples} samples at {frequency:g} Hz",
        f"planned cycle time {result.planned_time:.3f} s; observed PLAYING for "
        f"{result.observed_time:.3f} s of controller time",
        f"largest gap between recorded and planned joints: {result.max_deviation:.2e} rad",
    ]
    if result.behind:
        lines.append(f"the machine was too slow for speed x{speed:g}: the controller ran "
                     f"{result.behind:.2f} s of wall time behind (its controller time, in "
                     "lockstep with the program, is not affected)")
    if result.held:
        lines.append(f"the program overran its controller step and was held for {result.held} "
                     f"steps ({result.held * sim.step_time * speed:.3f} s of controller time)")
    if result.messages:
        lines += ["controller messages:"] + [f"  {m}" for m in result.messages]
    result.report.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return result
