"""Recording RTDE outputs to CSV, and plotting a recording.

The CSV is the format of UR's own ``record.py`` (so UR's ``csv_reader`` and plotting
examples read it): space-delimited, one header row, ``timestamp`` first, vectors expanded to
``name_0`` … ``name_5``. Rows are flushed every 0.5 s, so an interrupted recording keeps what
was received. :func:`plot_csv` reads space- and comma-delimited files.
"""

from __future__ import annotations

import csv
import time
from collections.abc import Callable
from pathlib import Path

from ..protocol import rtde
from .connection import Deadline, RobotConnectionError, connect, read_until

__all__ = ["record", "plot_csv", "DEFAULT_FIELDS"]

DEFAULT_FIELDS = ["timestamp", "actual_q", "actual_qd", "actual_TCP_pose", "runtime_state"]


def record(host: str, output: str | Path, fields: list[str] | None = None,
           frequency: float = 125.0, duration: float | None = None, port: int = 30004,
           timeout: float = 5.0, progress: Callable[[int, float], None] | None = None,
           messages: list | None = None) -> int:
    """Record ``fields`` at ``frequency`` Hz to ``output`` for ``duration`` s (None: until
    Ctrl-C). Returns the number of rows. Controller text messages go to ``messages``."""
    fields = list(fields or DEFAULT_FIELDS)
    if "timestamp" in fields:
        fields.remove("timestamp")
    fields.insert(0, "timestamp")
    unknown = [f for f in fields if f not in rtde.OUTPUTS]
    if unknown:
        raise ValueError(f"unknown RTDE output {unknown[0]!r} (see `urdsl record --help`)")
    if not 0 < frequency <= 500:
        raise ValueError(f"RTDE frequency must be in (0, 500] Hz, got {frequency:g}")
    sock = connect(host, port, timeout)
    client = rtde.RtdeClient()
    deadline = Deadline(timeout)

    pending: list = []  # events that arrived with a reply (data right after "started")

    def expect(kind):
        while True:
            if not pending:
                pending.extend(client.feed(read_until(sock, deadline, "an RTDE reply", host,
                                                      port)))
            event = pending.pop(0)
            if isinstance(event, kind):
                return event
            if isinstance(event, rtde.Message) and messages is not None:
                messages.append(event)

    rows = 0
    try:
        sock.sendall(client.request_protocol_version(2))
        if not expect(rtde.ProtocolVersion).accepted:
            sock.sendall(client.request_protocol_version(1))
            if not expect(rtde.ProtocolVersion).accepted:
                raise RobotConnectionError(f"{host}:{port}: RTDE protocol 1 and 2 refused")
        sock.sendall(client.setup_outputs(fields, frequency))
        setup = expect(rtde.OutputSetup)
        if not setup.valid:
            raise RobotConnectionError(f"{host}:{port}: the controller has no output "
                                       f"{', '.join(setup.not_found)}")
        sock.sendall(client.start())
        if not expect(rtde.Started).accepted:
            raise RobotConnectionError(f"{host}:{port}: the controller refused to start RTDE")
        columns = rtde.expand_names(list(setup.names), list(setup.types))
        stop = Deadline(duration) if duration is not None else None
        with open(output, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle, delimiter=" ")
            writer.writerow(columns)
            flushed = time.monotonic()
            try:
                while stop is None or not stop.passed:
                    wait = Deadline(min(timeout, stop.left) if stop else timeout)
                    data = read_until(sock, wait, "RTDE data", host, port) if wait.left else b""
                    events, pending[:] = pending + client.feed(data), []
                    for event in events:
                        if isinstance(event, rtde.DataPackage):
                            row = []
                            for name in setup.names:
                                value = event.values[name]
                                row.extend(value if isinstance(value, tuple) else (value,))
                            writer.writerow(row)
                            rows += 1
                        elif isinstance(event, rtde.Message) and messages is not None:
                            messages.append(event)
                    if time.monotonic() - flushed > 0.5:
                        handle.flush()
                        flushed = time.monotonic()
                        if progress is not None:
                            progress(rows, duration or 0.0)
            except KeyboardInterrupt:
                pass  # the rows so far are written; the file closes cleanly
        try:
            sock.sendall(client.pause())
        except OSError:
            pass
    finally:
        sock.close()
    return rows


def plot_csv(csv_path: str | Path, png_path: str | Path, columns: list[str] | None = None
             ) -> list[str]:
    """Plot ``columns`` (names or prefixes such as ``actual_q``; default: every joint
    position and speed column) against ``timestamp``; returns the columns drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    with open(csv_path, newline="", encoding="utf-8") as handle:
        first = handle.readline()
        handle.seek(0)
        reader = csv.reader(handle, delimiter="," if "," in first else " ")
        try:
            header = next(reader)
        except StopIteration:
            raise ValueError(f"{csv_path} is empty") from None
        rows = [row for row in reader if row]
    if "timestamp" not in header:
        raise ValueError(f"{csv_path} has no timestamp column")
    if not rows:
        raise ValueError(f"{csv_path} has a header but no rows")
    data = np.array(rows, dtype=float)
    time_column = data[:, header.index("timestamp")]
    wanted = columns or ["actual_q", "actual_qd"]
    groups = []
    for name in wanted:
        chosen = [c for c in header if c == name or c.startswith(name + "_")]
        if not chosen:
            raise ValueError(f"{csv_path} has no column {name!r}; it has: "
                             f"{', '.join(header)}")
        groups.append((name, chosen))
    figure, axes = plt.subplots(len(groups), 1, sharex=True, squeeze=False,
                                figsize=(10, 3 * len(groups)), constrained_layout=True)
    drawn = []
    for axis, (name, chosen) in zip(axes[:, 0], groups, strict=True):
        for column in chosen:
            axis.plot(time_column - time_column[0], data[:, header.index(column)], label=column)
            drawn.append(column)
        axis.set_ylabel(name)
        axis.legend(loc="upper right", fontsize="small", ncol=3)
    axes[-1, 0].set_xlabel("time since the first sample [s]")
    figure.suptitle(f"{Path(csv_path).name}: {len(rows)} samples")
    figure.savefig(png_path)
    plt.close(figure)
    return drawn
