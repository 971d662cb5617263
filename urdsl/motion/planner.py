"""The simulated arm that the interpreter drives: it plans each move as the controller does
and keeps the resulting trajectory as a list of :class:`Segment` objects.

Timing model
------------
* ``movej``: joint-space line, trapezoid of the *leading axis* (the joint with the longest
  time at ``a``/``v``); all joints start and stop together. ``t`` > 0 overrides ``a``/``v``.
* ``movel``: straight TCP line (orientation slerped), trapezoid on the path length (m); a
  rotation-only move is timed on the rotation angle with the same ``a``/``v`` in rad.
* ``movep``: like ``movel`` (constant tool speed comes from blending consecutive moves).
* ``movec``: circular arc through the via point's position, trapezoid on the arc length.

Blends
------
A move with blend radius ``r`` (m, at the TCP) does not stop at its waypoint: the next move
starts while it is still running, ``t_b`` s before its end, where ``t_b`` is the shorter of
the time this move needs for its last ``r`` metres and the time the next one needs for its
first ``r`` metres. In the overlap the joint motions add up (blending by superposition), so
the TCP leaves the waypoint on a smooth curve inside the blend sphere and the trajectory
stays continuous in position and speed. A blend therefore shortens the cycle by about
``t_b`` per blended waypoint. The controller's own blend curve is not published; this
model reproduces its topology (no stop, curve within the sphere) and its overlap rule, not
its exact timing.

Overlap rule (UR_FACTS.md §2): consecutive blend spheres must not overlap,
``r_prev + r > |P - P_prev|``, where the start point and a stop point count as ``r = 0``.
An offending move is skipped, with an "Overlapping Blends" warning, as the robot does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..script.nodes import Span
from .profiles import Trapezoid

__all__ = ["Segment", "MotionPlanner", "MotionWarning", "KinematicModel"]


class KinematicModel(Protocol):
    """What the planner needs of a robot model (see :mod:`urdsl.motion.adapter`)."""

    def fk(self, q: np.ndarray) -> np.ndarray: ...  # (6,) rad → (4, 4) TCP in Base, m

    def ik(self, pose: np.ndarray, q_near: np.ndarray) -> np.ndarray: ...  # raises

    def ik_many(self, poses: np.ndarray, q_near: np.ndarray) -> np.ndarray: ...  # (N,6), NaN


@dataclass
class MotionWarning:
    """Something the controller warns about while moving (not a program error)."""

    code: str
    message: str
    span: Span
    time: float


@dataclass
class Segment:
    """One planned move. Times in s (robot time), joints in rad, poses as 4x4 matrices.

    ``start`` is when it begins; ``profile`` maps time since start to path distance;
    ``radius`` is its blend radius (m); ``span`` the statement that commanded it.
    """

    kind: str
    start: float
    profile: Trapezoid
    q_start: np.ndarray
    q_end: np.ndarray
    pose_start: np.ndarray
    pose_end: np.ndarray
    radius: float
    span: Span
    params: dict = field(default_factory=dict)
    via: np.ndarray | None = None
    blend_with_next: float = 0.0

    @property
    def duration(self) -> float:
        return self.profile.duration

    @property
    def end(self) -> float:
        return self.start + self.profile.duration

    def path_poses(self, fraction: np.ndarray) -> np.ndarray:
        """TCP poses (N, 4, 4) at path fractions in [0, 1] (Cartesian moves)."""
        from .geometry import arc_points, slerp_rotations

        fraction = np.asarray(fraction, dtype=float)
        poses = np.repeat(np.eye(4)[None], len(fraction), axis=0)
        poses[:, :3, :3] = slerp_rotations(self.pose_start[:3, :3], self.pose_end[:3, :3],
                                           fraction)
        if self.kind == "movec" and self.via is not None:
            poses[:, :3, 3] = arc_points(self.pose_start[:3, 3], self.via, self.pose_end[:3, 3],
                                         fraction)
        else:
            start, end = self.pose_start[:3, 3], self.pose_end[:3, 3]
            poses[:, :3, 3] = start + fraction[:, None] * (end - start)
        return poses

    def joints(self, times: np.ndarray, kinematics: KinematicModel) -> np.ndarray:
        """Joint positions (N, 6) at robot times ``times`` (clipped to the segment)."""
        local = np.asarray(times, dtype=float) - self.start
        if self.profile.distance == 0.0:
            return np.repeat(self.q_end[None], len(local), axis=0)
        fraction = self.profile.position(local) / self.profile.distance
        if self.kind == "movej":
            return self.q_start + fraction[:, None] * (self.q_end - self.q_start)
        return kinematics.ik_many(self.path_poses(fraction), self.q_start)


class MotionPlanner:
    """Plans the moves of one program on one robot model, in robot time.

    ``start_joints`` (rad) is where the arm rests at time 0. Every motion method returns the
    robot time (s) at which the commanding script thread may go on: the end of the move, or
    the start of its blend when it has a blend radius.
    """

    def __init__(self, kinematics: KinematicModel, start_joints, step_time: float = 0.002
                 ) -> None:
        self.kinematics = kinematics
        self.q_start = np.asarray(start_joints, dtype=float).copy()
        self.step_time = step_time
        self.segments: list[Segment] = []
        self.warnings: list[MotionWarning] = []
        self.skipped: list[Segment] = []
        self._pending: Segment | None = None  # the last move, if it may still blend
        self._q = self.q_start.copy()  # joints at the end of the last planned move
        self._free_at = 0.0  # when the arm is at rest at _q (no pending blend)
        self.end_time = 0.0

    # ---- state -----------------------------------------------------------------------------

    @property
    def target_joints(self) -> np.ndarray:
        """Joints at the end of everything planned so far."""
        return self._q.copy()

    def joints_at(self, time: float) -> np.ndarray:
        """Planned joint positions at robot time ``time`` (s)."""
        from .trace import joints_at

        return joints_at(self, np.array([time]))[0]

    def tcp_at(self, time: float) -> np.ndarray:
        return self.kinematics.fk(self.joints_at(time))

    # ---- moves -----------------------------------------------------------------------------

    def movej(self, q: np.ndarray, a: float, v: float, t: float, r: float, span: Span,
              now: float) -> float:
        q = np.asarray(q, dtype=float)
        q_from = self._q
        delta = np.abs(q - q_from)
        lead = int(np.argmax(delta / max(v, 1e-12)))  # equal a, v for all joints
        profile = Trapezoid.plan(float(delta[lead]), v, a, t)
        pose_from, pose_to = self.kinematics.fk(q_from), self.kinematics.fk(q)
        return self._add(Segment("movej", now, profile, q_from.copy(), q, pose_from, pose_to,
                                 r, span, {"a": a, "v": v, "t": t, "lead": lead}), now)

    def movel(self, pose: np.ndarray, a: float, v: float, t: float, r: float, span: Span,
              now: float, kind: str = "movel") -> float:
        from .geometry import rotation_angle

        q_from = self._q
        pose_from = self.kinematics.fk(q_from)
        length = float(np.linalg.norm(pose[:3, 3] - pose_from[:3, 3]))
        if length < 1e-9:  # rotation only: time it on the angle
            length = rotation_angle(pose_from[:3, :3], pose[:3, :3])
        profile = Trapezoid.plan(length, v, a, t)
        q_to = self.kinematics.ik(pose, q_from)
        return self._add(Segment(kind, now, profile, q_from.copy(), q_to, pose_from, pose, r,
                                 span, {"a": a, "v": v, "t": t}), now)

    def movec(self, via: np.ndarray, pose: np.ndarray, a: float, v: float, r: float,
              mode: int, span: Span, now: float) -> float:
        from .geometry import arc_length

        q_from = self._q
        pose_from = self.kinematics.fk(q_from)
        length = arc_length(pose_from[:3, 3], via[:3, 3], pose[:3, 3])
        profile = Trapezoid.plan(length, v, a)
        q_to = self.kinematics.ik(pose, q_from)
        segment = Segment("movec", now, profile, q_from.copy(), q_to, pose_from, pose, r, span,
                          {"a": a, "v": v, "mode": mode}, via=via[:3, 3].copy())
        return self._add(segment, now)

    def stop_blending(self, now: float) -> None:
        """The script did something that waits (sleep, a stop): a pending blend ends in a
        stop at its waypoint."""
        if self._pending is not None:
            self._free_at = self._pending.end
            self._pending = None

    def finish(self, now: float) -> None:
        """The program ended: the last move runs to its end."""
        self.stop_blending(now)
        self.end_time = max([now] + [s.end for s in self.segments])

    # ---- planning --------------------------------------------------------------------------

    def _add(self, segment: Segment, now: float) -> float:
        previous = self._pending
        waypoint_from = segment.pose_start[:3, 3]
        distance = float(np.linalg.norm(segment.pose_end[:3, 3] - waypoint_from))
        previous_radius = previous.radius if previous is not None else 0.0
        if segment.radius > 0 or previous_radius > 0:
            if previous_radius + segment.radius > distance + 1e-12:
                self.warnings.append(MotionWarning(
                    "overlap",
                    f"Overlapping Blends: blend radii {previous_radius:g} m + "
                    f"{segment.radius:g} m exceed the {distance:.4g} m to the previous "
                    "waypoint; the robot skips this move",
                    segment.span, now))
                self.skipped.append(segment)
                return now
        if previous is not None:
            tail = _time_for_last(previous, min(previous.radius, _tcp_length(previous)))
            head = segment.profile.time_at(_path_fraction_for(segment, previous.radius)
                                           * segment.profile.distance)
            overlap = min(tail, head, previous.duration, segment.duration)
            previous.blend_with_next = overlap
            segment.start = max(previous.end - overlap, now)
        else:
            segment.start = max(now, self._free_at)
        self.segments.append(segment)
        self._q = segment.q_end.copy()
        self.end_time = max(self.end_time, segment.end)
        if segment.radius > 0:
            self._pending = segment
            blend_start = segment.end - _time_for_last(segment, min(segment.radius,
                                                                    _tcp_length(segment)))
            return max(blend_start, now)
        self._pending = None
        self._free_at = segment.end
        return segment.end


def _tcp_length(segment: Segment) -> float:
    if segment.kind in ("movel", "movep", "movec"):
        return segment.profile.distance
    return float(np.linalg.norm(segment.pose_end[:3, 3] - segment.pose_start[:3, 3]))


def _path_fraction_for(segment: Segment, tcp_distance: float) -> float:
    length = _tcp_length(segment)
    if length <= 0:
        return 1.0
    return min(tcp_distance / length, 1.0)


def _time_for_last(segment: Segment, tcp_distance: float) -> float:
    """Time the segment needs for its last ``tcp_distance`` metres of TCP travel."""
    fraction = _path_fraction_for(segment, tcp_distance)
    profile = segment.profile
    return profile.duration - profile.time_at((1.0 - fraction) * profile.distance)
