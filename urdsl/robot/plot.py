"""``urdsl plot``: a recording (CSV) as a PNG — UR's ``example_plotting.py`` job, better.

One panel per field, against time in seconds from the first sample: joint fields get one
curve per joint with the joint's name, Cartesian 6-vectors (``actual_TCP_pose``,
``actual_TCP_speed``, ``actual_TCP_force``) get two panels, translation and rotation, because
metres and radians do not share an axis. Axes are labelled with units. Drawn with
matplotlib's Agg backend (no screen needed).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..kinematics.models import JOINT_NAMES
from .csvfile import Recording, read_recording

__all__ = ["plot_recording", "PlotSummary", "DEFAULT_FIELDS", "MAX_POINTS"]

MAX_POINTS = 20000
"""Samples drawn per curve; a longer recording (40 s at 500 Hz) is thinned evenly, which a
PNG of ordinary width cannot show the difference of."""

DEFAULT_FIELDS = ("actual_q", "actual_qd")
"""Plotted when no fields are asked for (falling back to target_q/target_qd, then to the
first fields of the file)."""

_CARTESIAN = ("x", "y", "z", "rx", "ry", "rz")


@dataclass(frozen=True)
class PlotSummary:
    """What was drawn: the fields, the number of samples and the time they span (s)."""

    path: str
    fields: tuple[str, ...]
    samples: int
    duration: float


def _joint_field(name: str) -> bool:
    lower = name.lower()
    return lower.endswith(("_q", "_qd", "_qdd", "_current", "_moment", "joint_temperatures",
                           "_joint_voltage", "joint_control_output", "joint_mode",
                           "_current_window", "_current_as_torque"))


def _cartesian_field(name: str) -> bool:
    lower = name.lower()
    return ("tcp" in lower or "wrench" in lower) and not lower.endswith("force_scalar")


def _units(name: str, degrees: bool) -> tuple[str, str]:
    """Units of a field's (translation, rotation) parts; joint fields use the first."""
    lower = name.lower()
    angle = "deg" if degrees else "rad"
    if lower.endswith("_qdd"):
        return f"{angle}/s²", ""
    if lower.endswith("_qd"):
        return f"{angle}/s", ""
    if lower.endswith("_q"):
        return angle, ""
    if "force" in lower or "wrench" in lower:
        return "N", "N·m"
    if "pose" in lower or "offset" in lower:
        return "m", angle
    if "speed" in lower and "tcp" in lower:
        return "m/s", f"{angle}/s"
    if "acceleration" in lower or "accelerometer" in lower:
        return "m/s²", ""
    if "current" in lower:
        return "A", ""
    if "moment" in lower or "torque" in lower:
        return "N·m", ""
    if "voltage" in lower:
        return "V", ""
    if "temperature" in lower:
        return "°C", ""
    if lower in ("timestamp", "actual_execution_time", "target_execution_time"):
        return "s", ""
    return "", ""


def _angular(name: str) -> bool:
    lower = name.lower()
    return lower.endswith(("_q", "_qd", "_qdd"))


def _choose(recording: Recording, fields: Sequence[str] | None) -> list[str]:
    available = recording.fields()
    if fields:
        missing = [f for f in fields if f not in available and f not in recording.columns]
        if missing:
            raise KeyError(f"{recording.path} has no field {', '.join(map(repr, missing))}; "
                           f"it has: {', '.join(available)}")
        return list(fields)
    for pair in (DEFAULT_FIELDS, ("target_q", "target_qd")):
        chosen = [f for f in pair if f in available]
        if chosen:
            return chosen
    return [f for f in available if f != "timestamp"][:4]


def plot_recording(path: str | Path, output: str | Path, fields: Sequence[str] | None = None,
                   *, degrees: bool = False, title: str | None = None) -> PlotSummary:
    """Draw the recording at ``path`` into the PNG ``output``.

    ``fields`` are field names (``actual_q``, ``actual_TCP_pose``, ``speed_scaling``) or
    single columns (``actual_q_1``); ``degrees`` shows joint angles and speeds in degrees.
    Raises :class:`urdsl.robot.csvfile.RecordingFormatError` for an unreadable file and
    ``KeyError`` (naming what exists) for a field the file lacks.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    recording = read_recording(path)
    chosen = _choose(recording, fields)
    n = recording.rows
    if "timestamp" in recording.columns and n:
        stamps = recording.columns["timestamp"]
        times = stamps - stamps[0]
        xlabel = "time since the first sample [s]"
    else:
        times = np.arange(n, dtype=float)
        xlabel = "sample"
    step = max(1, -(-n // MAX_POINTS))
    index = slice(None, None, step)

    panels: list[tuple[str, np.ndarray, Sequence[str], str]] = []
    for name in chosen:
        values = recording.field(name)
        if values.ndim == 1:
            values = values[:, None]
        translation, rotation = _units(name, degrees)
        if degrees and _angular(name):
            values = np.degrees(values)
        if values.shape[1] == 6 and _cartesian_field(name):
            panels.append((f"{name} (position)" if rotation else name, values[:, :3],
                           _CARTESIAN[:3], translation))
            rotated = np.degrees(values[:, 3:]) if degrees and "force" not in name.lower() \
                and "wrench" not in name.lower() else values[:, 3:]
            panels.append((f"{name} (rotation)", rotated, _CARTESIAN[3:], rotation))
        elif values.shape[1] == 6 and _joint_field(name):
            panels.append((name, values, JOINT_NAMES, translation))
        else:
            labels = [name] if values.shape[1] == 1 else [f"{name}_{i}"
                                                         for i in range(values.shape[1])]
            panels.append((name, values, labels, translation))

    figure, axes = plt.subplots(len(panels), 1, figsize=(11, 2.6 * len(panels) + 1.0),
                                sharex=True, squeeze=False, constrained_layout=True)
    duration = float(times[-1] - times[0]) if n > 1 else 0.0
    rate = f", {(n - 1) / duration:.0f} Hz" if duration > 0 else ""
    figure.suptitle(title or f"{Path(path).name}: {n} samples over {duration:.3f} s{rate}")
    for ax, (label, values, names, unit) in zip(axes[:, 0], panels, strict=True):
        for column, curve_name in enumerate(names):
            ax.plot(times[index], values[index, column], label=curve_name, linewidth=1.0)
        ax.set_ylabel(f"{label}\n[{unit}]" if unit else label)
        ax.grid(True, alpha=0.3)
        if len(names) > 1:
            ax.legend(loc="upper right", fontsize="small", ncol=min(len(names), 6))
        if n == 0:
            ax.text(0.5, 0.5, "no samples", ha="center", va="center", transform=ax.transAxes)
    axes[-1, 0].set_xlabel(xlabel)
    figure.savefig(output, dpi=100)
    plt.close(figure)
    return PlotSummary(str(output), tuple(chosen), n, duration)
