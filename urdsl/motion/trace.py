"""The trajectory of a program, sampled at the controller rate.

Joint positions are the start joints plus the displacement of every move so far; moves
that overlap in time (blends) add up. :func:`sample` evaluates this on a regular time grid
with NumPy, one window per move, so that a program of thousands of moves samples in one
pass. Each sample also records which move was active (the latest started), so that a check
that fails at a sample can name the program line that commanded it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Trace", "sample", "joints_at"]


@dataclass
class Trace:
    """Samples of a planned trajectory.

    ``times`` (N,) in s; ``q`` (N, 6) in rad; ``qd`` (N, 6) rad/s and ``qdd`` (N, 6) rad/s²
    by finite differences; ``segment`` (N,) the index into ``segments`` of the move active at
    each sample (-1 at rest before the first move); ``dt`` the sampling step in s;
    ``unreachable`` (N,) marks samples of a TCP path that inverse kinematics could not reach
    (their joints repeat the last reachable sample).
    """

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    segment: np.ndarray
    dt: float
    segments: list
    unreachable: np.ndarray

    @property
    def duration(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0


def _displacements(planner, times: np.ndarray):
    """Joint positions (N, 6) at sorted ``times``, the active segment per time, and which
    samples were out of reach."""
    count = len(times)
    steps = np.zeros((count + 1, 6))
    window = np.zeros((count, 6))
    active = np.full(count, -1, dtype=np.int64)
    unreachable = np.zeros(count, dtype=bool)
    for index, segment in enumerate(planner.segments):
        first = int(np.searchsorted(times, segment.start, side="left"))
        last = int(np.searchsorted(times, segment.end, side="left"))
        full = segment.q_end - segment.q_start
        if last > first:
            inside = segment.joints(times[first:last], planner.kinematics) - segment.q_start
            gaps = np.isnan(inside).any(axis=1)
            if gaps.any():
                unreachable[first:last] |= gaps
                inside = _fill_gaps(inside)
            window[first:last] += inside
            active[first:last] = index
        steps[last] += full
    positions = planner.q_start + np.cumsum(steps[:-1], axis=0) + window
    # samples after a segment's start but before the next one keep the latest index
    np.maximum.accumulate(active, out=active)
    return positions, active, unreachable


def _fill_gaps(values: np.ndarray) -> np.ndarray:
    """Unreachable samples (NaN from IK) take the last reachable value, so that the trace
    stays finite; the verifier reports the unreachable stretch itself."""
    result = values.copy()
    bad = np.isnan(result).any(axis=1)
    last = np.zeros(6)
    for i in np.flatnonzero(bad):
        result[i] = result[i - 1] if i > 0 else last
    return result


def joints_at(planner, times: np.ndarray) -> np.ndarray:
    """Planned joint positions (N, 6) at robot times ``times`` (any order)."""
    times = np.asarray(times, dtype=float)
    order = np.argsort(times)
    positions, _, _ = _displacements(planner, times[order])
    result = np.empty_like(positions)
    result[order] = positions
    return result


def sample(planner, dt: float | None = None) -> Trace:
    """Sample the planned trajectory every ``dt`` s (default: the controller step)."""
    dt = dt or planner.step_time
    end = max(planner.end_time, max((s.end for s in planner.segments), default=0.0))
    count = int(np.floor(end / dt + 1e-9)) + 1
    times = np.arange(count) * dt
    q, active, unreachable = _displacements(planner, times)
    qd = np.gradient(q, dt, axis=0) if count > 1 else np.zeros_like(q)
    qdd = np.gradient(qd, dt, axis=0) if count > 1 else np.zeros_like(q)
    return Trace(times, q, qd, qdd, active, dt, planner.segments, unreachable)
