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
running ``urdsl sim``.
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["demo_story", "StoryResult", "PROGRAMS"]

PROGRAMS = Path(__file__).resolve().parents[2] / "programs"

FIELDS = ("timestamp", "actual_q", "actual_TCP_pose", "runtime_state")
_LAYOUT = struct.Struct(">Bd6d6dI")
PLAYING, STOPPED = 2, 1


@dataclass
class StoryResult:
    """Where the story wrote its files, and what it measured.

    ``planned_time``: the checker's cycle time (s); ``observed_time``: how long the
    controller reported PLAYING (s of controller time); ``max_deviation``: largest
    difference between recorded and planned joints (rad) over the run; ``samples``: RTDE
    samples recorded; ``sent``: False when the check found errors and nothing was sent.
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


class _Recorder:
    """A minimal RTDE v2 recording client (timestamp, actual_q, actual_TCP_pose,
    runtime_state) in a thread; every read has a timeout."""

    def __init__(self, port: int, frequency: float) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.rows: list[tuple] = []
        self._stop = threading.Event()
        self._ask(b"V", struct.pack(">H", 2))
        reply = self._ask(b"O", struct.pack(">d", frequency) + ",".join(FIELDS).encode())
        if b"NOT_FOUND" in reply:
            raise RuntimeError(f"RTDE recipe refused: {reply[1:].decode()}")
        self.recipe = reply[0]
        self._ask(b"S")
        self.thread = threading.Thread(target=self._run, name="urdsl-story-rtde", daemon=True)
        self.thread.start()

    def _recv(self, count: int) -> bytes:
        data = b""
        while len(data) < count:
            chunk = self.sock.recv(count - len(data))
            if not chunk:
                raise ConnectionError("RTDE closed")
            data += chunk
        return data

    def _package(self) -> tuple[int, bytes]:
        size, kind = struct.unpack(">HB", self._recv(3))
        return kind, self._recv(size - 3)

    def _ask(self, kind: bytes, payload: bytes = b"") -> bytes:
        self.sock.sendall(struct.pack(">HB", len(payload) + 3, kind[0]) + payload)
        for _ in range(10_000):
            got, data = self._package()
            if got == kind[0]:
                return data
        raise RuntimeError("no RTDE reply")

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                kind, data = self._package()
                if kind == ord("U") and data and data[0] == self.recipe:
                    self.rows.append(_LAYOUT.unpack(data)[1:])
        except OSError:
            return

    def close(self) -> None:
        self._stop.set()
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()
        self.thread.join(5)


def _send(port: int, text: str) -> None:
    try:
        from ..robot.sender import send_program
    except ImportError:
        send_program = None
    if send_program is not None:
        try:
            send_program(text, "127.0.0.1", port=port)
            return
        except TypeError:  # a sender without a port argument: use the socket below
            pass
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(text.encode("utf-8"))


def _write_csv(path: Path, rows: list[tuple]) -> None:
    header = ["timestamp"] + [f"actual_q_{i}" for i in range(6)] + \
        [f"actual_TCP_pose_{i}" for i in range(6)] + ["runtime_state"]
    with open(path, "w", encoding="ascii") as handle:
        handle.write(" ".join(header) + "\n")
        for row in rows:
            handle.write(" ".join(repr(float(v)) if i < 13 else str(int(v))
                                  for i, v in enumerate(row)) + "\n")


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


def demo_story(out_dir: str | Path = "out", *, robot: str = "ur5e", speed: float = 1.0,
               frequency: float = 125.0, programs: str | Path | None = None,
               timeout: float = 120.0) -> StoryResult:
    """Run the story (see the module docstring) and return where its files are.

    ``speed``: how much faster than real time the controller runs the program;
    ``frequency``: RTDE recording rate (Hz, at most 500 on e-Series); ``timeout``: wall
    seconds the program may take on the controller before the story gives up on it.
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

    with VirtualController(robot=robot, speed=speed) as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        recorder = _Recorder(servers.ports["rtde"], frequency)
        try:
            _send(servers.ports["secondary"], text)
            result.sent = True
            deadline = time.monotonic() + timeout
            started = finished = None
            while time.monotonic() < deadline:
                rows = recorder.rows
                if rows:
                    state, stamp = int(rows[-1][-1]), rows[-1][0]
                    if started is None and state == PLAYING:
                        started = next(r[0] for r in rows if int(r[-1]) == PLAYING)
                    if started is not None and state == STOPPED:
                        finished = stamp
                        break
                time.sleep(0.02)
            time.sleep(0.2)  # a few samples of the arm at rest
        finally:
            recorder.close()
        result.messages = [f"{m.kind}: {m.text}" for m in sim.messages]

    rows = np.array(recorder.rows, dtype=float).reshape(-1, 14)
    result.samples = len(rows)
    result.csv = out / "robot_data.csv"
    _write_csv(result.csv, recorder.rows)
    begin = started if started is not None else (rows[0, 0] if len(rows) else 0.0)
    if started is not None and finished is not None:
        result.observed_time = finished - started
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
    if result.messages:
        lines += ["controller messages:"] + [f"  {m}" for m in result.messages]
    result.report.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return result
