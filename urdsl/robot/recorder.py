"""Recording RTDE outputs to a CSV file (``urdsl record``), as UR's ``record.py`` does, better.

:func:`record` connects to RTDE (protocol 2, falling back to 1), sets up the output recipe
(``timestamp`` first, then the fields asked for), starts the stream and writes every sample
it receives — in order, none dropped by the client — to a :class:`urdsl.robot.csvfile.CsvWriter`.

It stops when ``duration`` seconds or ``samples`` samples are reached, when ``stop`` is set
(the CLI sets it on Ctrl-C), when the controller stays silent for ``stall_timeout``
seconds, or when the connection drops. In every case the file is flushed and closed and
holds every sample received, each one a complete line; :class:`RecordResult` says why it
stopped. Text messages the controller sends during the recording (warnings, errors) are
collected and do not stop it.

Samples the *controller* skipped (it always sends the newest when it is overloaded, UR's
RTDE guide) are counted in ``missed`` from gaps in ``timestamp``.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..protocol import rtde as r
from .csvfile import CsvWriter
from .errors import ConnectionLost, RobotError
from .rtde_session import PORT, RtdeSession

__all__ = ["record", "RecordResult", "RecordProgress", "DEFAULT_FIELDS", "parse_fields"]

DEFAULT_FIELDS = ("actual_q", "actual_qd", "actual_TCP_pose")
"""Recorded when no fields are given: joint positions and speeds, TCP pose."""

PROGRESS_PERIOD = 0.1
"""Seconds between progress callbacks."""

RECEIVE_SLICE = 0.2
"""Longest single wait for data (s): how quickly ``stop`` is noticed."""


def parse_fields(text: str | Sequence[str] | None) -> list[str]:
    """``"actual_q, actual_TCP_pose"`` → the recipe names, ``timestamp`` first, each once."""
    if text is None:
        names = list(DEFAULT_FIELDS)
    elif isinstance(text, str):
        names = [t.strip() for t in text.split(",") if t.strip()]
    else:
        names = [t.strip() for t in text if t.strip()]
    if not names:
        raise ValueError("no fields given")
    ordered = ["timestamp"]
    for name in names:
        if name not in ordered:
            ordered.append(name)
    return ordered


@dataclass
class RecordProgress:
    """Where a recording is: samples written, controller time covered (s), wall time (s),
    samples the controller skipped, the last controller text message."""

    samples: int
    span: float
    elapsed: float
    missed: int
    message: str | None = None
    stalled: float = 0.0


@dataclass
class RecordResult:
    """How a recording ended. ``stopped_by`` is ``"duration"``, ``"samples"``, ``"stop"``
    (Ctrl-C), ``"stall"`` or ``"connection lost"``; ``error`` holds the message for the last
    two. ``span`` is the controller time between the first and last sample (s)."""

    path: str
    fields: list[str]
    types: list[str]
    frequency: float
    protocol: int
    controller_version: str | None
    samples: int = 0
    span: float = 0.0
    elapsed: float = 0.0
    missed: int = 0
    stopped_by: str = "stop"
    error: str | None = None
    messages: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.error is None


def _expected_period(session: RtdeSession, frequency: float) -> float:
    rate = session.max_frequency
    if session.protocol < 2:
        return 1.0 / rate
    return max(1, math.floor(rate / frequency + 1e-9)) / rate


def record(host: str, path: str | Path, fields: str | Sequence[str] | None = None, *,
           frequency: float = 125.0, duration: float | None = None,
           samples: int | None = None, port: int = PORT, timeout: float = 5.0,
           stall_timeout: float = 10.0, stop: threading.Event | None = None,
           progress: Callable[[RecordProgress], None] | None = None,
           delimiter: str = " ") -> RecordResult:
    """Record RTDE ``fields`` from ``host`` into the CSV file ``path`` (see the module
    docstring). ``frequency`` in Hz (CB3 ≤ 125, e-Series ≤ 500); ``duration`` in s of wall
    time. Connection and setup failures raise (:mod:`urdsl.robot.errors`; the file is not
    created then); once recording, failures end it and are reported in the result."""
    names = parse_fields(fields)
    stop = stop or threading.Event()
    with RtdeSession(host, port, timeout=timeout) as session:
        recipe = session.setup_outputs(names, frequency)
        result = RecordResult(str(path), names, list(recipe.types), frequency,
                              session.protocol, session.controller_version)
        writer = CsvWriter(path, names, recipe.types, delimiter=delimiter)
        try:
            session.start()
            _loop(session, writer, result, duration, samples, stall_timeout, stop, progress,
                  _expected_period(session, frequency))
        finally:
            writer.close()
            result.samples = writer.rows
    return result


class _Sink:
    """Writes samples and keeps the time bookkeeping (span, controller-skipped samples)."""

    def __init__(self, writer: CsvWriter, result: RecordResult, limit: int | None,
                 period: float) -> None:
        self.writer = writer
        self.result = result
        self.limit = limit
        self.period = period
        self.first: float | None = None
        self.last: float | None = None
        self.last_data = time.monotonic()
        self.message: str | None = None

    @property
    def full(self) -> bool:
        return self.limit is not None and self.writer.rows >= self.limit

    def take(self, events: list) -> None:
        result = self.result
        for event in events:
            if isinstance(event, r.DataPackage):
                if self.full:
                    continue
                values = event.values
                self.writer.write([values[n] for n in result.fields])
                stamp = float(values["timestamp"])  # type: ignore[arg-type]
                if self.last is not None and self.period > 0:
                    gap = round((stamp - self.last) / self.period) - 1
                    if gap > 0:
                        result.missed += gap
                if self.first is None:
                    self.first = stamp
                self.last = stamp
                result.span = stamp - self.first
                self.last_data = time.monotonic()
            elif isinstance(event, r.RtdeTextMessage):
                level = {0: "exception", 1: "error", 2: "warning"}.get(event.level, "info")
                source = f"{event.source}: " if event.source else ""
                self.message = f"{level}: {source}{event.message}"
                result.messages.append(self.message)


def _loop(session: RtdeSession, writer: CsvWriter, result: RecordResult,
          duration: float | None, limit: int | None, stall_timeout: float,
          stop: threading.Event, progress: Callable[[RecordProgress], None] | None,
          period: float) -> None:
    sink = _Sink(writer, result, limit, period)
    begin = time.monotonic()
    last_progress = 0.0
    while True:
        now = time.monotonic()
        if stop.is_set():
            result.stopped_by = "stop"
            break
        if duration is not None and now - begin >= duration:
            result.stopped_by = "duration"
            break
        if sink.full:
            result.stopped_by = "samples"
            break
        if now - sink.last_data >= stall_timeout:
            result.stopped_by = "stall"
            result.error = (f"{session.where} sent no data for {stall_timeout:g} s; "
                            f"recording stopped")
            break
        wait = RECEIVE_SLICE
        if duration is not None:
            wait = min(wait, max(begin + duration - now, 0.0))
        try:
            sink.take(session.receive(max(wait, 0.001)))
        except ConnectionLost as error:
            result.stopped_by = "connection lost"
            result.error = f"{error.message}; recording stopped"
            break
        now = time.monotonic()
        result.elapsed = now - begin
        if progress is not None and now - last_progress >= PROGRESS_PERIOD:
            last_progress = now
            progress(RecordProgress(writer.rows, result.span, result.elapsed, result.missed,
                                    sink.message, now - sink.last_data))
    result.elapsed = time.monotonic() - begin
    if result.error is None:
        try:  # pause, and keep what arrived before the pause took effect
            session.pause(timeout=1.0)
            sink.take(session.drain())
        except RobotError:
            pass
    if progress is not None:
        progress(RecordProgress(writer.rows, result.span, result.elapsed, result.missed,
                                sink.message, 0.0))
