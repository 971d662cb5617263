"""Checks over a sampled trace, one function per rule. Each takes the trace (and what it
needs of the robot model or the cell) and returns findings, at most one per move and rule,
placed at the statement that commanded the move."""

from __future__ import annotations

import numpy as np

from ..motion.trace import Trace
from .findings import Finding

__all__ = ["joint_limits", "joint_speeds", "joint_accelerations", "blend_radii"]

JOINTS = ("base", "shoulder", "elbow", "wrist 1", "wrist 2", "wrist 3")


def _per_segment(trace: Trace, mask: np.ndarray):
    """(segment index, first sample index) for each move with a flagged sample."""
    flagged = np.flatnonzero(mask.any(axis=1) if mask.ndim == 2 else mask)
    seen: set[int] = set()
    for sample in flagged:
        segment = int(trace.segment[sample])
        if segment in seen:
            continue
        seen.add(segment)
        yield segment, int(sample)


def _span(trace: Trace, segment: int):
    from ..script.nodes import NO_SPAN

    return trace.segments[segment].span if segment >= 0 else NO_SPAN


def joint_limits(trace: Trace, lower: np.ndarray, upper: np.ndarray) -> list[Finding]:
    """URS303: joint positions outside [lower, upper] (rad)."""
    outside = (trace.q < lower - 1e-9) | (trace.q > upper + 1e-9)
    findings = []
    for segment, sample in _per_segment(trace, outside):
        joint = int(np.argmax(outside[sample]))
        value = trace.q[sample, joint]
        bound = upper[joint] if value > upper[joint] else lower[joint]
        findings.append(Finding.of(
            "URS303",
            f"{JOINTS[joint]} joint reaches {np.degrees(value):.1f}° "
            f"(limit {np.degrees(bound):.1f}°) at t={trace.times[sample]:.3f} s",
            _span(trace, segment), float(trace.times[sample]),
            "choose a target closer to the current joints, or another IK solution"))
    return findings


def joint_speeds(trace: Trace, limits: np.ndarray) -> list[Finding]:
    """URS304: joint speeds above the model's limits (rad/s)."""
    over = np.abs(trace.qd) > limits * (1 + 1e-6)
    findings = []
    for segment, sample in _per_segment(trace, over):
        ratio = np.abs(trace.qd[sample]) / limits
        joint = int(np.argmax(ratio))
        peak = float(np.max(np.abs(trace.qd[trace.segment == segment, joint])))
        findings.append(Finding.of(
            "URS304",
            f"{JOINTS[joint]} joint turns at {peak:.2f} rad/s, over its limit of "
            f"{limits[joint]:.2f} rad/s",
            _span(trace, segment), float(trace.times[sample]),
            "lower v (rad/s for movej, m/s for movel) or lengthen t"))
    return findings


def joint_accelerations(trace: Trace, limits: np.ndarray) -> list[Finding]:
    """URS305: joint accelerations above the limits (rad/s²)."""
    over = np.abs(trace.qdd) > limits * (1 + 1e-6)
    findings = []
    for segment, sample in _per_segment(trace, over):
        joint = int(np.argmax(np.abs(trace.qdd[sample]) / limits))
        findings.append(Finding.of(
            "URS305",
            f"{JOINTS[joint]} joint accelerates at {abs(trace.qdd[sample, joint]):.1f} "
            f"rad/s², over {limits[joint]:.1f} rad/s²",
            _span(trace, segment), float(trace.times[sample]), "lower a"))
    return findings


def blend_radii(segments) -> list[Finding]:
    """URS310: a blend radius larger than half of the segment before or after it (a
    conservative house rule: UR's own rule is the overlap of blend spheres, URS309)."""
    findings = []
    for before, current in zip(segments, segments[1:], strict=False):
        if before.radius <= 0:
            continue
        length_before = float(np.linalg.norm(before.pose_end[:3, 3] - before.pose_start[:3, 3]))
        length_after = float(np.linalg.norm(current.pose_end[:3, 3] - current.pose_start[:3, 3]))
        shortest = min(length_before, length_after)
        if before.radius > shortest / 2:
            findings.append(Finding.of(
                "URS310",
                f"blend radius {before.radius:g} m is more than half of a neighbouring "
                f"segment ({shortest:.4g} m): the blend may be cut short",
                before.span, before.end, "use at most half the shorter segment"))
    return findings
