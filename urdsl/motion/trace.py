"""The trajectory of a program, sampled at the controller rate.

Joint positions are the start joints plus the displacement of every move so far; moves
that overlap in time (blends) add up. :func:`sample` evaluates this on a regular time grid
with NumPy, one window per move, so that a program of thousands of moves samples in one
pass. Each sample also records which move was active (the latest started), so that a check
that fails at a sample can name the program line that commanded it.
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .._threads import shared_pool
from .tracking import track

__all__ = ["Trace", "sample", "joints_at", "tcp_groups"]


@dataclass
class Trace:
    """Samples of a planned trajectory.

    ``times`` (N,) in s; ``q`` (N, 6) in rad; ``qd`` (N, 6) rad/s and ``qdd`` (N, 6) rad/s²
    by finite differences (``qdd`` computed when first asked for, if given as None);
    ``segment`` (N,) the index into ``segments`` of the move active at each sample (-1 at
    rest before the first move); ``dt`` the sampling step in s; ``unreachable`` (N,) marks
    samples of a TCP path that inverse kinematics could not reach (their joints repeat the
    last reachable sample).
    """

    times: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    accelerations: np.ndarray | None
    segment: np.ndarray
    dt: float
    segments: list
    unreachable: np.ndarray
    cut: float | None = None
    """Robot time (s) where sampling stopped at the wall-clock bound (the samples end there,
    before the motion does); None when the whole motion was sampled."""

    @property
    def qdd(self) -> np.ndarray:
        """Joint accelerations (N, 6) in rad/s² (most checks need none: made on demand)."""
        if self.accelerations is None:
            self.accelerations = _derivative(self.qd, self.dt, shared_pool())
        return self.accelerations

    @property
    def duration(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0


CHUNK_SAMPLES = 32768
"""About how many (move, sample) entries :func:`_displacements` evaluates at once: the
arrays of a chunk stay in the CPU's cache, which makes a long program sample several times
faster than one pass over all of its samples would."""


def _displacements(planner, times: np.ndarray, pool: ThreadPoolExecutor):
    """Joint positions (N, 6) at sorted ``times``, the active segment per time, and which
    samples were out of reach.

    A sample's joints are the start joints, plus the whole displacement of every move that
    has ended, plus the part done so far of every move under way (moves overlap in blends).
    The moves are evaluated in chunks of consecutive moves (:data:`CHUNK_SAMPLES`), each
    chunk with one array entry per (move, sample inside the move): profiles vectorised,
    straight TCP paths solved at their knots (:data:`KNOT_TIME`) in one batched
    inverse-kinematics call and interpolated in between.
    """
    count = len(times)
    segments = planner.segments
    active = np.full(count, -1, dtype=np.int64)
    unreachable = np.zeros(count, dtype=bool)
    if not segments or count == 0:
        return planner.q_start + np.zeros((count, 6)), active, unreachable

    moves = _Moves(planner, segments, times)
    # what the moves that have ended add up to: constant from one move's end to the next
    by_end = np.argsort(moves.last, kind="stable")
    ends, first = np.unique(moves.last[by_end], return_index=True)
    completed = planner.q_start + np.cumsum(moves.q_delta[by_end], axis=0)
    reached = np.vstack([planner.q_start, completed[np.append(first[1:] - 1, -1)]])
    runs = np.diff(np.concatenate([[0], np.minimum(ends, count), [count]]))
    positions = np.repeat(reached, runs, axis=0)
    ends = np.cumsum(moves.lengths)
    cuts = np.searchsorted(ends, np.arange(CHUNK_SAMPLES, ends[-1], CHUNK_SAMPLES),
                           side="right")
    bounds = np.unique(np.concatenate([[0], cuts, [len(segments)]]))
    # Threads evaluate chunks side by side (NumPy lets go of the interpreter lock in its
    # loops); the main thread adds their windows up.
    chunks = zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True)
    for low, window in pool.map(lambda c: moves.dense_window(*c, unreachable), chunks):
        positions[low:low + len(window)] += window
    # the active move at a sample is the latest one started (blends overlap); samples after
    # a move's end but before the next one starts keep it
    sampled = np.flatnonzero(moves.lengths > 0)
    np.maximum.at(active, moves.first[sampled], sampled)
    np.maximum.accumulate(active, out=active)
    return positions, active, unreachable


class _Moves:
    """The moves of a program as arrays (index = move), and their sample windows."""

    def __init__(self, planner, segments, times: np.ndarray) -> None:
        from .planner import JOINT_SPACE

        self.planner, self.segments, self.times = planner, segments, times
        # one pass over the moves: start, then the profile (distance, accel, peak, t_acc,
        # t_flat), as in Trapezoid
        table = np.array([(s.start, (p := s.profile).distance, p.accel, p.peak, p.t_acc,
                            p.t_flat) for s in segments]).reshape(-1, 6)
        self.starts, self.profile = table[:, 0], table[:, 1:]
        durations = 2.0 * self.profile[:, 3] + self.profile[:, 4]
        self.first = np.searchsorted(times, self.starts, side="left")
        self.last = np.searchsorted(times, self.starts + durations, side="left")
        self.lengths = self.last - self.first
        self.q_start = np.array([s.q_start for s in segments])
        self.q_delta = np.array([s.q_end for s in segments]) - self.q_start
        kinds = [s.kind for s in segments]
        self.cartesian = np.array([kind not in JOINT_SPACE for kind in kinds])
        self.arcs = np.array([kind == "movec" for kind in kinds])
        self.paths = _Paths(segments) if self.cartesian.any() else None
        self.dt = times[1] - times[0] if len(times) > 1 else 1.0
        # straight TCP paths of non-zero length are interpolated between knots, unless the
        # model has no Jacobians (``jacobian_many``) or a step is as long as KNOT_TIME; the
        # samples of arcs are all solved
        every_sample = KNOT_TIME <= self.dt or not hasattr(planner.kinematics, "jacobian_many")
        self.interpolated = (self.cartesian & ~self.arcs & (self.profile[:, 0] > 0)
                             & (not every_sample))

    def knots(self, moves: np.ndarray) -> _Knots:
        """:meth:`solve_knots` of ``moves`` (sorted move indices), each distinct move solved
        once: a move is the same as another when it starts from the same joints toward the
        same target, along the same path, with the same speed profile and TCP (a loop that
        repeats a toolpath from the same place), and then so are its knots."""
        paths = self.paths
        rows = np.concatenate([self.q_start[moves], self.q_delta[moves], self.profile[moves],
                               paths.p0[moves], paths.p1[moves],
                               paths.r0[moves].reshape(-1, 9), paths.w[moves],
                               paths.tcp_group[moves, None].astype(float)], axis=1)
        if len(moves) < 2 or not np.isfinite(rows).all():
            return self.solve_knots(moves)
        _, keep, which = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        if len(keep) == len(moves):
            return self.solve_knots(moves)
        order = np.argsort(keep)  # the distinct moves by first occurrence
        rank = np.empty(len(keep), dtype=np.int64)
        rank[order] = np.arange(len(keep))
        solved = self.solve_knots(moves[keep[order]])
        counts = np.diff(np.append(solved.first, len(solved.t)))
        of_move = rank[which.reshape(-1)]  # each move's distinct move, in `solved`
        per_move = counts[of_move]
        first = np.cumsum(per_move) - per_move
        index = np.repeat(solved.first[of_move] - first, per_move) + np.arange(per_move.sum())
        return _Knots(moves, first, solved.t[index], solved.q[index], solved.velocity[index])

    def solve_knots(self, moves: np.ndarray) -> _Knots:
        """The knots of straight-line moves ``moves`` (sorted move indices), solved: each
        phase of the speed profile (accelerating, cruising, braking) split into equal steps
        of at most :data:`KNOT_TIME` (cruising: of at most ``max(KNOT_TIME, KNOT_PATH / v)``),
        so that no cubic spans a change of the acceleration. A move's first and last knot
        are its ends, at rest: their joints and speeds (0) are known; the others are solved
        by IK, with speeds from the Jacobian."""
        from .profiles import positions as profile_positions
        from .profiles import speeds as profile_speeds

        p = self.profile[moves]
        t_acc, t_flat = p[:, 3], p[:, 4]
        ramp = np.where(t_acc > 0, np.ceil(t_acc / KNOT_TIME - 1e-9), 0).astype(np.int64)
        cruise_step = np.divide(KNOT_PATH, p[:, 2], out=np.full(len(p), np.inf),
                                where=p[:, 2] > 0)
        # a move that turns the tool far along a short path: KNOT_ANGLE of rotation at most
        turn = self.paths.turn[moves] * np.divide(p[:, 2], p[:, 0], out=np.zeros(len(p)),
                                                  where=p[:, 0] > 0)
        cruise_step = np.maximum(KNOT_TIME, np.minimum(cruise_step, np.divide(
            KNOT_ANGLE, turn, out=np.full(len(p), np.inf), where=turn > 0)))
        cruise = np.where(t_flat > 0, np.ceil(t_flat / cruise_step - 1e-9), 0).astype(np.int64)
        ramp = np.maximum(ramp, np.where(cruise > 0, 0, 1))  # at least one step per move
        steps = 2 * ramp + cruise
        count = steps + 1  # knots per move
        move_of = np.repeat(np.arange(len(moves)), count)
        first = np.cumsum(count) - count
        j = np.arange(len(move_of)) - first[move_of]  # knot number inside its move
        r, c = ramp[move_of], cruise[move_of]
        ta, tf = t_acc[move_of], t_flat[move_of]
        with np.errstate(divide="ignore", invalid="ignore"):
            rising = j * (ta / r)
            flat = ta + (j - r) * (tf / np.maximum(c, 1))
            falling = ta + tf + (j - r - c) * (ta / r)
        t = np.where(j <= r, rising, np.where(j <= r + c, flat, falling))
        last = first + count - 1
        t[first] = 0.0
        t[last] = 2.0 * t_acc + t_flat
        segment = moves[move_of]
        pk = p[move_of]
        covered = profile_positions(t, pk[:, 0], pk[:, 1], pk[:, 2], pk[:, 3], pk[:, 4])
        fraction = covered / pk[:, 0]
        q = fraction[:, None] * self.q_delta[segment]  # displacement; ends exact, at rest
        velocity = np.zeros_like(q)
        inner = np.ones(len(t), dtype=bool)
        inner[first] = inner[last] = False
        inner = np.flatnonzero(inner)
        if len(inner):
            which = segment[inner]
            q[inner] = _cartesian(self.planner, self.paths, which, fraction[inner],
                                  self.q_start, q[inner])
            speed = profile_speeds(t[inner], pk[inner, 0], pk[inner, 1], pk[inner, 2],
                                   pk[inner, 3], pk[inner, 4])
            velocity[inner] = _joint_velocities(self.planner, self.paths, which,
                                                self.q_start, q[inner], speed / pk[inner, 0])
        return _Knots(moves, first, t, q, velocity)

    def dense_window(self, begin: int, stop: int, unreachable: np.ndarray):
        """:meth:`window` summed per sample: the first sample and the joint displacements
        (K, 6) of the moves at the K samples from there (blends: moves add up)."""
        entry_sample, moved = self.window(begin, stop, unreachable)
        if len(entry_sample) == 0:
            return 0, moved
        low, high = int(entry_sample[0]), int(entry_sample.max()) + 1
        local = entry_sample - low
        window = np.empty((high - low, 6))
        for joint in range(6):
            window[:, joint] = np.bincount(local, moved[:, joint], minlength=high - low)
        return low, window

    def window(self, begin: int, stop: int, unreachable: np.ndarray):
        """Entries of moves ``begin`` to ``stop`` − 1: the sample of each (sorted by move,
        then time) and the joint displacement (M, 6) of its move since the move's start.
        Marks samples out of reach in ``unreachable``."""
        from .profiles import positions as profile_positions

        lengths = self.lengths[begin:stop]
        entry_segment = np.repeat(np.arange(begin, stop), lengths)
        if len(entry_segment) == 0:
            return entry_segment, np.zeros((0, 6))
        offsets = np.cumsum(lengths) - lengths
        entry_sample = np.arange(len(entry_segment)) - np.repeat(
            offsets - self.first[begin:stop], lengths)
        local_t = self.times[entry_sample] - self.starts[entry_segment]
        # samples of straight TCP paths come from their knots; the others from the profile
        lines = self.interpolated[entry_segment]
        moved = np.empty((len(entry_segment), 6))
        solved = np.empty((0, 6))
        if lines.all():
            rows = np.arange(len(entry_segment))
        else:
            rows = np.flatnonzero(self.cartesian[entry_segment])
            other = np.flatnonzero(~lines)
            segment = entry_segment[other]
            p = self.profile[segment]
            covered = profile_positions(local_t[other], p[:, 0], p[:, 1], p[:, 2], p[:, 3],
                                        p[:, 4])
            fraction = np.divide(covered, p[:, 0], out=np.ones_like(covered),
                                 where=p[:, 0] > 0)
            moved[other] = fraction[:, None] * self.q_delta[segment]
            # arcs, and every path of a model without Jacobians: every sample solved
            solve = self.cartesian[segment] & (p[:, 0] > 0)
            if solve.any():
                which = other[solve]
                solved = _cartesian(self.planner, self.paths, entry_segment[which],
                                    fraction[solve], self.q_start, moved[which])
                moved[which] = solved
            lines = np.flatnonzero(lines)
        if len(lines):
            line_segment = entry_segment[lines]
            knots = self.knots(np.unique(line_segment))
            moved[lines] = knots.interpolate(line_segment, local_t[lines])
            solved = np.concatenate([solved, knots.q])
        if not np.isnan(solved).any():  # samples between solved ones are NaN only next to one
            return entry_sample, moved
        gaps = np.isnan(moved[rows]).any(axis=1)
        if gaps.any():
            unreachable[entry_sample[rows[gaps]]] = True
            moved[rows[gaps]] = np.nan
            moved = _fill_gaps(moved, entry_segment)
        return entry_sample, moved


KNOT_TIME = 0.032
"""Longest robot time (s) between the knots of a straight TCP path — the points solved by
inverse kinematics — while the move accelerates or brakes; the samples in between are cubic
Hermite interpolations of the joints, with the joint speeds at the knots from the Jacobian
(``q̇ = J⁻¹·twist``). Knots also sit exactly at the changes of the speed profile's phase and
at the move's ends, so that no cubic spans a jump of the acceleration. Joint paths of
straight-line moves are smooth away from singularities, where the error of this cubic is of
the order of ``(h/2)⁴·q⁗`` — below a micro-radian at 32 ms (3e-7 rad measured against
solving every sample); near a singularity the Jacobian's speeds grow, which is what the
checks look for."""

KNOT_PATH = 0.008
"""Longest path (m, or rad for a rotation-only move) between knots while a move cruises,
when that takes longer than :data:`KNOT_TIME`: at constant path speed ``v`` the joints'
fourth derivative is ``Q⁗(s)·v⁴`` (``Q`` the joints as a function of the path length
``s``), so the interpolation error depends on the path length between knots, not on their
time. 8 mm is what :data:`KNOT_TIME` gives at the controller's default movel speed
(0.25 m/s); a slow process move (a 0.1 m/s toolpath) is solved every 80 ms."""


KNOT_ANGLE = 0.032
"""Longest tool rotation (rad) between knots while a move cruises: what :data:`KNOT_TIME`
gives at a movel's default rotational speed (1 rad/s); it matters for moves that mostly
turn the tool, whose path length says little about how far the joints go."""


def _joint_velocities(planner, paths, which, q_start, moved, fraction_rate) -> np.ndarray:
    """Joint speeds (M, 6) rad/s at solved samples of straight TCP paths: the twist of the
    path (linear ``(p1 − p0)·ḟ``, angular ``R0·w·ḟ`` with ``w = log(R0ᵀR1)``) through the
    damped inverse of the TCP Jacobian,
    ``q̇ = (JᵀJ + λ²I)⁻¹Jᵀ·twist`` (λ = 1e-6: exact away from singularities, finite at
    them). ``fraction_rate`` is ḟ in 1/s."""
    q = q_start[which] + moved
    good = np.isfinite(q).all(axis=1)
    velocity = np.full_like(q, np.nan)
    if not good.any():
        return velocity
    rows = np.flatnonzero(good)
    which = which[rows]
    twist = np.concatenate([paths.p1[which] - paths.p0[which], paths.angular[which]],
                           axis=1) * fraction_rate[rows, None]
    groups = paths.tcp_group[which]
    for group in np.unique(groups):
        members = groups == group
        jacobian = planner.kinematics.jacobian_many(q[rows[members]],
                                                    tcp=paths.tcps[group])
        transposed = jacobian.transpose(0, 2, 1)
        normal = transposed @ jacobian + 1e-12 * np.eye(6)
        velocity[rows[members]] = np.linalg.solve(
            normal, transposed @ twist[members, :, None])[:, :, 0]
    return velocity


class _Knots:
    """Solved knots of straight-line moves: for move ``moves[m]``, knots ``first[m]`` on,
    at local times ``t`` (s since the move's start), with joint displacements ``q`` (K, 6)
    [rad] and speeds ``velocity`` (K, 6) [rad/s]."""

    def __init__(self, moves, first, t, q, velocity) -> None:
        self.moves, self.first, self.t, self.q, self.velocity = moves, first, t, q, velocity

    def interpolate(self, segment: np.ndarray, local_t: np.ndarray) -> np.ndarray:
        """Joint displacements (M, 6) at samples of these moves (``segment``: move index,
        ``local_t``: s since its start; sorted by move, then time): the cubic Hermite of the
        two knots around each sample, ``q0 + s·(c1 + s·(c2 + s·c3))`` with ``s`` in [0, 1].
        The samples of one interval are consecutive: each interval's cubic is set up once
        and repeated over them."""
        position = np.searchsorted(self.moves, segment)
        end = np.append(self.first[1:], len(self.t)) - 1  # each move's last knot
        # the knot at or before each sample: moves are in order and their knot times rise,
        # so (move position, time) sorts like the knots
        span = float(self.t.max()) + 1.0
        knot_key = np.repeat(np.arange(len(self.moves)), np.diff(np.append(self.first,
                                                                            len(self.t))))
        knot_key = knot_key * span + self.t
        left = np.searchsorted(knot_key, position * span + local_t, side="right") - 1
        left = np.minimum(left, end[position] - 1)
        runs = np.flatnonzero(np.diff(left)) + 1  # `left` rises: runs of one interval
        starts = np.concatenate([[0], runs])
        intervals = left[starts]
        counts = np.diff(np.append(starts, len(left)))
        t0 = self.t[intervals]
        h = self.t[intervals + 1] - t0
        q0, q1 = self.q[intervals], self.q[intervals + 1]
        v0 = h[:, None] * self.velocity[intervals]
        v1 = h[:, None] * self.velocity[intervals + 1]
        c2 = 3.0 * (q1 - q0) - 2.0 * v0 - v1
        c3 = 2.0 * (q0 - q1) + v0 + v1
        s = ((local_t - np.repeat(t0, counts)) / np.repeat(h, counts))[:, None]
        value = np.repeat(c3, counts, axis=0)
        value *= s
        value += np.repeat(c2, counts, axis=0)
        value *= s
        value += np.repeat(v0, counts, axis=0)
        value *= s
        value += np.repeat(q0, counts, axis=0)
        return value


class _Paths:
    """What the sampling needs of every move, as arrays indexed by move: path ends ``p0``,
    ``p1`` (m), start rotation ``r0``, rotation step ``w = log(R0ᵀR1)`` (rad), whether it is an
    arc, and a TCP group number (moves with the same TCP share one)."""

    def __init__(self, segments) -> None:
        from ..kinematics.pose import matrix_to_rotvec

        self.segments = segments
        starts = np.array([s.pose_start for s in segments])
        ends = np.array([s.pose_end for s in segments])
        self.p0, self.p1 = starts[:, :3, 3], ends[:, :3, 3]
        self.r0 = starts[:, :3, :3]
        self.w = matrix_to_rotvec(np.swapaxes(self.r0, 1, 2) @ ends[:, :3, :3])
        self.angular = (self.r0 @ self.w[:, :, None])[:, :, 0]  # rotation step in Base
        self.turn = np.linalg.norm(self.w, axis=1)  # rotation angle of each move, rad
        self.arc = np.array([s.kind == "movec" and s.via is not None for s in segments])
        self.tcp_group, self.tcps = tcp_groups(segments)


def tcp_groups(segments) -> tuple[np.ndarray, list]:
    """Moves grouped by their TCP: the group number of each move (an int array) and each
    group's TCP (a pose in the flange frame, or None for the flange)."""
    groups: dict = {}
    tcps: list = []
    numbers = []
    for segment in segments:
        key = None if segment.tcp is None else tuple(segment.tcp)
        if key not in groups:
            groups[key] = len(groups)
            tcps.append(None if key is None else np.array(key))
        numbers.append(groups[key])
    return np.array(numbers, dtype=np.int64), tcps


def _cartesian(planner, paths, which, fraction, q_start, linear):
    """Joint displacements of samples on TCP paths (rows sorted by move, then along the
    path): poses along each path, then inverse kinematics that follows one solution
    continuously along each move (:func:`urdsl.motion.tracking.track`), one batch per TCP."""
    from ..kinematics.pose import rotvec_to_matrix

    poses = np.repeat(np.eye(4)[None], len(which), axis=0)
    arc = paths.arc[which]
    for index in np.unique(which[arc]):  # arcs (rare): one call per move
        rows = np.flatnonzero(which == index)
        poses[rows] = paths.segments[index].path_poses(fraction[rows])
    rows = np.flatnonzero(~arc)
    if len(rows):
        seg, f = which[rows], fraction[rows][:, None]
        poses[rows, :3, 3] = paths.p0[seg] + f * (paths.p1[seg] - paths.p0[seg])
        poses[rows, :3, :3] = paths.r0[seg] @ rotvec_to_matrix(f * paths.w[seg])
    near = q_start[which] + linear
    solutions = np.empty((len(which), 6))
    groups = paths.tcp_group[which]
    for group in np.unique(groups):
        rows = np.flatnonzero(groups == group)
        solutions[rows] = track(planner.kinematics, poses[rows], near[rows],
                                 q_start[which[rows]], which[rows], paths.tcps[group])
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
    positions, _, _ = _displacements(planner, times[order], shared_pool())
    result = np.empty_like(positions)
    result[order] = positions
    return result


WINDOW_SAMPLES = 1 << 16
"""Samples :func:`sample` evaluates at once (131 s of robot time at the e-Series' 2 ms): a
window holds only the moves under way in it, so that memory and the time to the next look
at the deadline stay bounded however long the program runs."""


class _Window:
    """The moves ``segments`` of a planner under way in one window of samples, as
    :func:`_displacements` reads a planner: ``q_start`` is where the arm is before the first
    of them (every move starts where the one before it ends)."""

    def __init__(self, planner, segments: list, q_start: np.ndarray) -> None:
        self.kinematics = planner.kinematics
        self.segments = segments
        self.q_start = q_start


def sample(planner, dt: float | None = None, until: float | None = None,
           deadline: float | None = None, reserve: float = 0.0) -> Trace:
    """Sample the planned trajectory every ``dt`` s (default: the controller step), up to
    robot time ``until`` (s; default: the end of the last move).

    Samples are evaluated in windows of :data:`WINDOW_SAMPLES`, in time order. With a
    ``deadline`` (``time.monotonic()``) sampling stops at the first window boundary after
    it, or, with a ``reserve`` r, once the time sampling has taken times 1 + r would reach
    it (leaving the checks of the samples about r times the time it took to make them): the
    trace then ends there, less its last two samples (so that every kept speed is the
    central difference a complete trace has), and ``Trace.cut`` says at which robot
    time."""
    dt = dt or planner.step_time
    segments = planner.segments
    end = max(planner.end_time, max((s.end for s in segments), default=0.0))
    if until is not None:
        end = min(end, until)
    count = int(np.floor(end / dt + 1e-9)) + 1
    pool = shared_pool()
    starts = np.maximum.accumulate(np.array([s.start for s in segments] or [0.0]))
    ends = np.maximum.accumulate(np.array([s.end for s in segments] or [0.0]))
    q_parts, active_parts, unreachable_parts = [], [], []
    stop = count
    began = time.monotonic()
    for low in range(0, count, WINDOW_SAMPLES):
        now = time.monotonic()
        if deadline is not None and low > 0 and now + reserve * (now - began) > deadline:
            stop = low
            break
        times = np.arange(low, min(low + WINDOW_SAMPLES, count)) * dt
        # the moves under way in the window: every one before them has ended (ends rise
        # with starts: a blend starts a move before the previous one ends, never after
        # its end)
        first = min(int(np.searchsorted(ends, times[0], side="right")), len(segments))
        last = min(int(np.searchsorted(starts, times[-1], side="right")), len(segments))
        if first < len(segments):
            q_before = np.asarray(segments[first].q_start, dtype=float)
        else:
            q_before = np.asarray(segments[-1].q_end if segments else planner.q_start,
                                  dtype=float)
        window = _Window(planner, segments[first:max(first, last)], q_before)
        q, active, unreachable = _displacements(window, times, pool)
        q_parts.append(q)
        active_parts.append(np.where(active >= 0, active + first, first - 1))
        unreachable_parts.append(unreachable)
    q = np.concatenate(q_parts) if q_parts else np.zeros((0, 6))
    active = np.concatenate(active_parts) if active_parts else np.zeros(0, dtype=np.int64)
    unreachable = (np.concatenate(unreachable_parts) if unreachable_parts
                   else np.zeros(0, dtype=bool))
    qd = _derivative(q, dt, pool)
    cut = None
    if stop < count:
        keep = max(stop - 2, 0)
        cut = float(keep * dt)
        q, qd, active, unreachable = q[:keep], qd[:keep], active[:keep], unreachable[:keep]
    times = np.arange(len(q)) * dt
    return Trace(times, q, qd, None, active, dt, segments, unreachable, cut)


def _derivative(values: np.ndarray, dt: float, pool: ThreadPoolExecutor,
                block: int = 65536) -> np.ndarray:
    """``np.gradient(values, dt, axis=0)``: central differences inside, one-sided at both
    ends (zeros for a single sample), in blocks of rows shared out to the threads."""
    count = len(values)
    out = np.zeros_like(values)
    if count < 2:
        return out

    def rows(begin: int) -> None:
        end = min(begin + block, count)
        inner_begin, inner_end = max(begin, 1), min(end, count - 1)
        if inner_end > inner_begin:
            part = out[inner_begin:inner_end]
            np.subtract(values[inner_begin + 1:inner_end + 1],
                        values[inner_begin - 1:inner_end - 1], out=part)
            part /= 2.0 * dt
        if begin == 0:
            out[0] = (values[1] - values[0]) / dt
        if end == count:
            out[-1] = (values[-1] - values[-2]) / dt

    list(pool.map(rows, range(0, count, block)))
    return out

