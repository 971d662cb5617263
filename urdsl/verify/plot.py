"""Plot of a checked program: joint positions and speeds against the model's limits, and the
TCP path seen from above and from the side. Drawn with matplotlib's Agg backend (no screen)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..kinematics.models import JOINT_NAMES

__all__ = ["plot_report"]

MAX_POINTS = 5000
"""Samples drawn per curve: more than a screen shows; a long program is thinned evenly."""



def plot_report(report, path: str | Path, robot=None) -> None:
    """Write the plot of ``report`` (a :class:`urdsl.verify.report.Report` with a trace)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if robot is None:
        from ..kinematics import Robot

        robot = Robot.model(report.robot)
    trace = report.trace
    figure = plt.figure(figsize=(13, 8), constrained_layout=True)
    grid = figure.add_gridspec(2, 3)
    ax_q = figure.add_subplot(grid[0, :2])
    ax_qd = figure.add_subplot(grid[1, :2], sharex=ax_q)
    ax_top = figure.add_subplot(grid[0, 2])
    ax_side = figure.add_subplot(grid[1, 2])
    figure.suptitle(f"{Path(report.file).name} on {report.robot}: cycle time "
                    f"{report.cycle_time:.3f} s, {report.count('error')} error(s), "
                    f"{report.count('warning')} warning(s)")
    if trace is None or len(trace.times) == 0:
        ax_q.text(0.5, 0.5, "no motion", ha="center", transform=ax_q.transAxes)
        figure.savefig(path)
        plt.close(figure)
        return
    stride = max(1, len(trace.times) // MAX_POINTS)
    times = trace.times[::stride]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for joint in range(6):
        colour = colours[joint % len(colours)]
        ax_q.plot(times, trace.q[::stride, joint], color=colour, label=JOINT_NAMES[joint])
        ax_qd.plot(times, trace.qd[::stride, joint], color=colour)
        limit = float(robot.qd_max[joint])
        ax_qd.axhline(limit, color=colour, linestyle=":", linewidth=0.8)
        ax_qd.axhline(-limit, color=colour, linestyle=":", linewidth=0.8)
    for bound in (robot.q_max, robot.q_min):  # UR3 wrist 3 is unlimited (infinite bound)
        finite = np.asarray(bound)[np.isfinite(bound)]
        if len(finite):
            ax_q.axhline(float(np.max(np.abs(finite)) * np.sign(finite[0])), color="grey",
                         linestyle="--", linewidth=0.8)
    for finding in report.findings:
        if finding.time is not None and finding.severity == "error":
            ax_q.axvline(finding.time, color="red", linewidth=0.8)
            ax_qd.axvline(finding.time, color="red", linewidth=0.8)
    ax_q.set_ylabel("joint position [rad]")
    ax_q.legend(loc="upper right", fontsize="small", ncol=3)
    ax_qd.set_ylabel("joint speed [rad/s] (dotted: limits)")
    ax_qd.set_xlabel("robot time [s]")

    tcp = robot.fk_many(trace.q[::stride])[:, :3, 3]
    ax_top.plot(tcp[:, 0], tcp[:, 1], linewidth=0.8)
    ax_top.plot(0, 0, "k+", markersize=10)
    ax_top.set_aspect("equal", adjustable="datalim")
    ax_top.set_title("TCP path (flange), top view")
    ax_top.set_xlabel("x [m]")
    ax_top.set_ylabel("y [m]")
    ax_side.plot(tcp[:, 0], tcp[:, 2], linewidth=0.8)
    ax_side.axhline(0.0, color="grey", linewidth=0.8)
    ax_side.set_aspect("equal", adjustable="datalim")
    ax_side.set_title("side view")
    ax_side.set_xlabel("x [m]")
    ax_side.set_ylabel("z [m]")
    figure.savefig(path)
    plt.close(figure)
