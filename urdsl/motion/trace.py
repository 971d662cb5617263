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
    samples were out of reach.

    All moves are evaluated together: one array entry per (move, sample inside the move),
    profiles and straight TCP paths vectorised, and one batched inverse-kinematics call for
    every Cartesian sample of the program.
    """
    from .geometry import _exp_many, _log
    from .planner import JOINT_SPACE
    from .profiles import positions as profile_positions

    count = len(times)
    segments = planner.segments
    steps = np.zeros((count + 1, 6))
    window = np.zeros((count, 6))
    active = np.full(count, -1, dtype=np.int64)
    unreachable = np.zeros(count, dtype=bool)
    if not segments or count == 0:
        return planner.q_start + np.zeros((count, 6)), active, unreachable

    starts = np.array([s.start for s in segments])
    durations = np.array([s.profile.duration for s in segments])
    first = np.searchsorted(times, starts, side="left")
    last = np.searchsorted(times, starts + durations, side="left")
    q_start = np.array([s.q_start for s in segments])
    q_delta = np.array([s.q_end for s in segments]) - q_start
    np.add.at(steps, last, q_delta)

    lengths = last - first
    entry_segment = np.repeat(np.arange(len(segments)), lengths)
    if len(entry_segment):
        offsets = np.cumsum(lengths) - lengths
        entry_sample = np.arange(len(entry_segment)) - np.repeat(offsets - first, lengths)
        profile = np.array([(s.profile.distance, s.profile.accel, s.profile.peak,
                             s.profile.t_acc, s.profile.t_flat) for s in segments])
        p = profile[entry_segment]
        covered = profile_positions(times[entry_sample] - starts[entry_segment],
                                    p[:, 0], p[:, 1], p[:, 2], p[:, 3], p[:, 4])
        fraction = np.divide(covered, p[:, 0], out=np.ones_like(covered), where=p[:, 0] > 0)
        moved = fraction[:, None] * q_delta[entry_segment]
        cartesian = np.array([s.kind not in JOINT_SPACE for s in segments])
        rows = np.flatnonzero(cartesian[entry_segment] & (p[:, 0] > 0))
        if len(rows):
            moved[rows] = _cartesian(planner, segments, entry_segment[rows], fraction[rows],
                                     q_start, moved[rows], _exp_many, _log)
            gaps = np.isnan(moved[rows]).any(axis=1)
            if gaps.any():
                unreachable[entry_sample[rows[gaps]]] = True
                moved[rows[gaps]] = np.nan
                moved = _fill_gaps(moved, entry_segment)
        np.add.at(window, entry_sample, moved)
        # the active move at a sample is the latest one started (blends overlap)
        np.maximum.at(active, entry_sample, entry_segment)
    positions = planner.q_start + np.cumsum(steps[:-1], axis=0) + window
    # samples after a segment's end but before the next one starts keep the latest index
    np.maximum.accumulate(active, out=active)
    return positions, active, unreachable


def _cartesian(planner, segments, which, fraction, q_start, linear, exp_many, log):
    """Joint displacements of samples on TCP paths: poses along each path, then one batched
    IK call; each sample takes the solution closest to the joint-space interpolation of its
    move's ends (``linear``), which keeps the arm on the branch of its end points."""
    poses = np.repeat(np.eye(4)[None], len(which), axis=0)
    for index in np.unique(which):
        segment = segments[index]
        rows = np.flatnonzero(which == index)
        if segment.kind == "movec" and segment.via is not None:
            poses[rows] = segment.path_poses(fraction[rows])
    plain = np.array([segments[i].kind != "movec" or segments[i].via is None for i in which])
    if plain.any():
        unique = np.unique(which[plain])
        p0 = np.zeros((len(segments), 3))
        p1 = np.zeros((len(segments), 3))
        r0 = np.zeros((len(segments), 3, 3))
        w = np.zeros((len(segments), 3))
        for index in unique:
            segment = segments[index]
            p0[index], p1[index] = segment.pose_start[:3, 3], segment.pose_end[:3, 3]
            r0[index] = segment.pose_start[:3, :3]
            w[index] = log(segment.pose_start[:3, :3].T @ segment.pose_end[:3, :3])
        rows = np.flatnonzero(plain)
        seg, f = which[rows], fraction[rows][:, None]
        poses[rows, :3, 3] = p0[seg] + f * (p1[seg] - p0[seg])
        poses[rows, :3, :3] = r0[seg] @ exp_many(f * w[seg])
    near = q_start[which] + linear
    solutions = np.empty((len(which), 6))
    tcps = [None if s.tcp is None else tuple(s.tcp) for s in segments]
    keys = np.array([hash(tcps[i]) for i in which])
    for key in np.unique(keys):
        rows = np.flatnonzero(keys == key)
        tcp = tcps[which[rows[0]]]
        solutions[rows] = planner.kinematics.ik_many(
            poses[rows], near[rows], tcp=None if tcp is None else np.array(tcp))
    return solutions - q_start[which]


def _fill_gaps(values: np.ndarray, owner: np.ndarray) -> np.ndarray:
    """Unreachable entries (NaN rows) take the last reachable value of the same move (or no
    displacement at its start), so that the trace stays finite; the verifier reports the
    unreachable stretch itself."""
    result = values.copy()
    for i in np.flatnonzero(np.isnan(result).any(axis=1)):
        result[i] = result[i - 1] if i > 0 and owner[i - 1] == owner[i] else 0.0
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
