"""The simulated arm that the interpreter drives: it plans each move as the controller does
and keeps the resulting trajectory as a list of :class:`Segment` objects.

Timing model
------------
* ``movej``: joint-space line, trapezoid of the *leading axis* (the joint with the longest
  time at ``a``/``v``); all joints start and stop together. ``t`` > 0 overrides ``a``/``v``.
* ``movel``: straight TCP line (orientation slerped), trapezoid on the path length (m) and
  one on the rotation angle (rad, with ``4·v`` and ``4·a`` [U]); the longer one sets the
  time (:func:`line_profile`).
* ``movep``: like ``movel`` (constant tool speed comes from blending consecutive moves).
* ``movec``: circular arc through the via point's position, trapezoid on the arc length.
* ``speedj``/``speedl``: accelerate with ``a`` toward the speed, hold it, return after
  ``t``, then decelerate with ``a`` unless another speed command goes on. The manual: "if
  provided the function will return after time t, regardless of the target speed has been
  reached", so a ``t`` shorter than the ramp reaches only ``a·t``. Consecutive identical
  speed commands (the same speed and ``a``, each given at the time the one before returns:
  a loop that streams one speed until a force or a distance stops it) are one motion that
  does not slow down between them; they are planned as one command with the sum of their
  ``t`` (:class:`_SpeedChain`). Different speeds in a row are planned one after the other,
  each from rest [U].

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

Overlap rule (docs/controller-facts.md §4): consecutive blend spheres must not overlap,
``r_prev + r > |P - P_prev|``, where the start point and a stop point count as ``r = 0``.
An offending move is skipped, with an "Overlapping Blends" warning, as the robot does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..kinematics.errors import KinematicsError
from ..runtime.values import Relative
from ..script.nodes import Span
from .drift import Drift, drift_error
from .profiles import Trapezoid

__all__ = ["Segment", "MotionPlanner", "MotionWarning", "KinematicModel", "JOINT_SPACE",
           "UnreachableTarget", "line_profile", "ROTATION_PER_METRE", "continue_branch",
           "branch_path"]

BLENDABLE_INTO = frozenset({"movej", "movel", "movep", "movec"})
"""Moves the previous move may blend into (servoj and speedj start from rest)."""

JOINT_SPACE = frozenset({"movej", "servoj", "speedj"})
"""Moves that interpolate in joint space (the others follow a TCP path)."""


class KinematicModel(Protocol):
    """What the planner needs of a robot model (:class:`urdsl.kinematics.Robot` is one).

    ``tcp`` is the TCP as a pose (m, rotation vector) in the flange frame; None = flange.
    """

    def fk(self, q: np.ndarray, tcp=None) -> np.ndarray: ...  # (6,) rad → (4, 4) in Base, m

    def ik(self, pose: np.ndarray, q_near: np.ndarray, tcp=None) -> np.ndarray: ...  # raises

    def ik_many(self, poses: np.ndarray, q_near: np.ndarray, tcp=None) -> np.ndarray:
        ...  # (N, 6), rows of NaN where a pose is out of reach


def unreachable_reason(distance: float) -> str:
    """Why a pose has no joint solution, for messages: ``distance`` (m) beyond the reach, or
    0 when it is reachable only outside the joint limits."""
    if distance <= 0:
        return "reachable only outside the joint limits"
    if distance < 5e-5:  # would print as 0.0 mm
        return "just out of reach (by less than 0.1 mm)"
    return f"out of reach by {distance * 1000:.1f} mm"


class UnreachableTarget(KinematicsError):
    """A straight-line move's target is out of reach (found when its joints were solved).

    ``span`` is the statement of the move, ``time`` (s) when the robot would have started it,
    ``distance`` (m) how far the pose is out of reach (0: reachable only outside the joint
    limits).
    """

    def __init__(self, segment: Segment, distance: float) -> None:
        where = segment.pose_end[:3, 3]
        reason = unreachable_reason(distance)
        super().__init__(f"the {segment.kind} target at [{where[0]:.4f}, {where[1]:.4f}, "
                         f"{where[2]:.4f}] m is {reason}")
        self.span = segment.span
        self.time = segment.start
        self.distance = distance
        self.position = tuple(float(v) for v in where) if distance > 0 else None


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
    tcp: np.ndarray | None = None

    @property
    def duration(self) -> float:
        return self.profile.duration

    @property
    def end(self) -> float:
        return self.start + self.profile.duration

    def path_poses(self, fraction: np.ndarray) -> np.ndarray:
        """TCP poses (N, 4, 4) at path fractions in [0, 1] (Cartesian moves)."""
        from .geometry import arc_points, arc_rotations, slerp_rotations

        fraction = np.asarray(fraction, dtype=float)
        poses = np.repeat(np.eye(4)[None], len(fraction), axis=0)
        if self.kind == "movec" and self.via is not None and self.params.get("mode") == 1:
            # fixed mode: the tool turns with the arc, its orientation constant relative to
            # the arc's tangent (the manual's movec, mode 1)
            poses[:, :3, :3] = arc_rotations(self.pose_start[:3, 3], self.via,
                                             self.pose_end[:3, 3], fraction) \
                @ self.pose_start[:3, :3]
        else:
            poses[:, :3, :3] = slerp_rotations(self.pose_start[:3, :3],
                                               self.pose_end[:3, :3], fraction)
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
        linear = self.q_start + fraction[:, None] * (self.q_end - self.q_start)
        if self.kind in JOINT_SPACE:
            return linear
        # Each sample's IK solution is the one closest to the joint-space interpolation
        # between the two ends, which keeps the arm on the branch of its end points; a
        # branch flip shows as a jump between samples (the verifier's URS302).
        return kinematics.ik_many(self.path_poses(fraction), linear, tcp=self.tcp)


@dataclass
class _SpeedChain:
    """The speed command planned last, while the next one may go on from it: ``segment`` is
    its motion (from the chain's start), ``kind`` speedj/speedl, ``vector`` its speed (rad/s
    or m/s and rad/s), ``a`` its acceleration, ``t`` the summed ``t`` (s) of the chain's
    commands, ``returns`` the robot time (s) the last one returned, ``now`` the time the
    first one was given, ``state`` the planner's state before the first one
    (:meth:`MotionPlanner._state`)."""

    segment: Segment
    kind: str
    vector: np.ndarray
    a: float
    t: float
    returns: float
    now: float
    state: tuple


class MotionPlanner:
    """Plans the moves of one program on one robot model, in robot time.

    ``start_joints`` (rad) is where the arm rests at time 0; ``tcp`` (a pose in the flange
    frame, m and rad) is the active TCP, changed by ``set_tcp``. Every motion method returns
    the robot time (s) at which the commanding script thread may go on: the end of the move,
    or the start of its blend when it has a blend radius.
    """

    def __init__(self, kinematics: KinematicModel, start_joints, step_time: float = 0.002,
                 lazy_ik: bool = False) -> None:
        self.kinematics = kinematics
        self.q_start = np.asarray(start_joints, dtype=float).copy()
        self.step_time = step_time
        self.payload_mass = 0.0  # kg
        self.payload_cog = np.zeros(3)  # m, in the flange frame
        self.segments: list[Segment] = []
        self.warnings: list[MotionWarning] = []
        self.skipped: list[Segment] = []
        self.failure: UnreachableTarget | None = None
        # spans of the movel/movep calls that a condition may stop before their target
        # (PolyScope's Direction node: :func:`urdsl.motion.direction.stoppable_moves`)
        self.stoppable: frozenset = frozenset()
        # where the arm is, when something outside the program decided it (see
        # :meth:`unknown_position`): what left it there, and that statement's span
        self.unknown_at: tuple[str, Span] | None = None
        # while unknown_at is set: what is known of the TCP's position (moves relative to an
        # unknown start, :mod:`urdsl.motion.drift`), or None
        self.drift: Drift | None = None
        # whether the model is only assumed (not given nor inferred): a bound that must hold
        # for the real arm then takes the widest UR model's
        self.model_assumed = False
        self._tcp: np.ndarray | None = None
        self._pending: Segment | None = None  # the last move, if it may still blend
        self._q_end = self.q_start.copy()  # joints at the end of the last resolved move
        self._end_pose: np.ndarray | None = None  # TCP at the end of everything planned
        self._unresolved: list[Segment] = []  # Cartesian moves whose joints are not solved
        self._free_at = 0.0  # when the arm is at rest at _q (no pending blend)
        self.end_time = 0.0
        self._speed_chain: _SpeedChain | None = None  # the last speed command (speedj/l)
        self._poses: dict[tuple, np.ndarray] = {}  # see _pose_of
        # Solving the targets of straight-line moves in batches is what makes checking a
        # long toolpath fast; only a model that gives all analytic solutions at once can.
        self.lazy_ik = (lazy_ik and hasattr(kinematics, "ik_all_many")
                        and not getattr(kinematics, "calibrated", False))

    @property
    def tcp(self) -> np.ndarray | None:
        """The active TCP: a pose (m, rad) in the flange frame; None is the flange."""
        return self._tcp

    @tcp.setter
    def tcp(self, value) -> None:
        self.resolve()  # moves planned so far keep the TCP they were planned with
        self._tcp = None if value is None else np.asarray(value, dtype=float).copy()
        self._end_pose = None

    @property
    def _q(self) -> np.ndarray:
        self.resolve()
        return self._q_end

    def _end_matrix(self) -> np.ndarray:
        """TCP (4x4) at the end of everything planned, without solving pending moves."""
        if self._end_pose is None:
            self._end_pose = self._pose_of(self._q)
        return self._end_pose

    def resolve(self) -> None:
        """Solve the joints of the straight-line moves planned since the last call: all their
        targets in one batched call for every analytic solution, then, move by move, where
        the controller ends up: the continuation of the joints the move starts from along the
        straight line, i.e. the target's solution on the same IK branch
        (:func:`continue_branch`).

        Raises :class:`UnreachableTarget` for the first target out of reach; that move and
        everything planned after it are dropped, as the robot stops there.
        """
        if not self._unresolved:
            return
        pending, self._unresolved = self._unresolved, []
        model = self.kinematics
        targets = np.array([segment.pose_end for segment in pending])
        solutions, miss = model.ik_all_many(targets, tcp=pending[0].tcp)
        chosen, found = continue_branch(model, solutions, self._q_end, pending[0].tcp)
        previous = self._q_end.copy()
        turns = np.zeros(6)  # whole turns the path added to each joint so far
        for index, segment in enumerate(pending):
            if not found[index]:
                self._drop_from(segment)
                distance = float(np.min(miss[index]))
                raise UnreachableTarget(segment, distance)
            segment.q_start = previous
            end = chosen[index] + turns
            along = continuous_end(model, segment, previous, end)
            turns += along - end
            segment.q_end = previous = along
        self._q_end = previous.copy()

    def _drop_from(self, segment: Segment) -> None:
        """The robot stops before ``segment``: forget it and everything after it."""
        index = self.segments.index(segment)
        self.segments = self.segments[:index]
        self._unresolved = []
        self._pending = None
        if self.segments:
            self.segments[-1].blend_with_next = 0.0
        self._free_at = max([segment.start] + [s.end for s in self.segments])
        self.end_time = self._free_at
        self._end_pose = None

    # ---- state -----------------------------------------------------------------------------

    @property
    def target_joints(self) -> np.ndarray:
        """Joints at the end of everything planned so far."""
        return self._q.copy()

    @property
    def free_at(self) -> float:
        """Robot time (s) at which the arm is at rest after everything planned so far."""
        if self._pending is not None:
            return self._pending.end
        return self._free_at

    def joints_at(self, time: float) -> np.ndarray:
        """Planned joint positions (rad) at robot time ``time`` (s).

        Every move starts where the one before it ends (``q_start`` = previous ``q_end``), so
        the position is the start of the earliest move still running plus what every running
        move has done so far; only the last few moves need looking at.
        """
        self.resolve()
        active: list[Segment] = []
        for segment in reversed(self.segments):
            if segment.start > time:
                continue
            if segment.end <= time:
                if not active:
                    return segment.q_end.copy()
                break
            active.append(segment)
        if not active:
            return self.q_start.copy()
        position = active[-1].q_start.copy()
        stamp = np.array([time])
        for segment in active:
            moved = segment.joints(stamp, self.kinematics)[0] - segment.q_start
            if not np.isnan(moved).any():
                position += moved
        return position

    def tcp_at(self, time: float) -> np.ndarray:
        """TCP (4x4, m) of the active TCP at robot time ``time`` (s)."""
        return self.kinematics.fk(self.joints_at(time), tcp=self.tcp)

    def fk(self, q: np.ndarray) -> np.ndarray:
        """TCP pose (4x4, m) of joints ``q`` (rad) with the active TCP."""
        return self.kinematics.fk(q, tcp=self.tcp)

    def _pose_of(self, q: np.ndarray) -> np.ndarray:
        """:meth:`fk`, remembered: a move's start is the previous move's end, and a loop
        commands the same targets again and again (a read-only matrix; the cache holds at
        most :data:`POSE_CACHE` poses)."""
        q = np.asarray(q, dtype=float)
        key = (q.tobytes(), None if self._tcp is None else self._tcp.tobytes())
        pose = self._poses.get(key)
        if pose is None:
            if len(self._poses) >= POSE_CACHE:
                self._poses.clear()
            pose = np.array(self.fk(q), dtype=float)
            pose.setflags(write=False)
            self._poses[key] = pose
        return pose

    def ik(self, pose: np.ndarray, q_near: np.ndarray | None = None) -> np.ndarray:
        """Joints (rad) for a TCP pose (4x4) with the active TCP, closest to ``q_near``
        (default: where the planned motion ends). Raises the model's KinematicsError."""
        near = self._q if q_near is None else q_near
        return self.kinematics.ik(pose, near, tcp=self.tcp)

    def _line_end(self, pose: np.ndarray, q_from: np.ndarray) -> np.ndarray:
        """Joints (rad) where a straight-line or circular move from ``q_from`` to ``pose``
        ends: the target's solution on the IK branch the move starts on, as
        :meth:`resolve` chooses it for a batch (:func:`continue_branch`) and as the trace
        follows the path (:func:`urdsl.motion.tracking.track`). The solution closest to
        ``q_from`` may be another branch when the move turns the tool far (a 150° arc):
        the next move would then start where the traced path did not end. Raises the
        model's KinematicsError for a pose out of reach."""
        model = self.kinematics
        if not hasattr(model, "ik_all_many"):
            return self.ik(pose, q_from)
        solutions, _ = model.ik_all_many(np.asarray(pose, dtype=float)[None], tcp=self.tcp)
        chosen, found = continue_branch(model, solutions, q_from, self.tcp)
        if not found[0]:
            return self.ik(pose, q_from)  # raises: out of reach or outside the joint limits
        return chosen[0]

    # ---- moves -----------------------------------------------------------------------------

    def movej(self, q: np.ndarray, a: float, v: float, t: float, r: float, span: Span,
              now: float, solved: bool = False) -> float:
        """Joint-space move to ``q`` (rad): ``a`` rad/s², ``v`` rad/s, ``t`` s, ``r`` m.
        ``solved``: ``q`` is the IK solution of a pose target nearest to where the arm was
        (kept in the segment's params: its joints depend on the moves before)."""
        q = np.asarray(q, dtype=float)
        q_from = self._q
        delta = np.abs(q - q_from)
        lead = int(np.argmax(delta))  # equal a, v for all joints: the longest way leads
        speed = self._joint_speed(delta, lead, v)
        profile = Trapezoid.plan(float(delta[lead]), speed, a, t)
        params = {"a": a, "v": v, "t": t, "lead": lead}
        if t > 0:  # what its a and v alone would take (see urdsl.verify.checks.SCALED_MARGIN)
            params["t_free"] = Trapezoid.plan(float(delta[lead]), speed, a).duration
        if solved:
            params["solved"] = True
        return self._add(self._segment("movej", profile, q_from, q, r, span, params), now)

    def _joint_speed(self, delta: np.ndarray, lead: int, v: float) -> float:
        """The leading axis's speed (rad/s) for a movej asked for ``v``: at most what keeps
        every joint within the model's top speed (joint ``i`` turns ``delta[i]/delta[lead]``
        as fast as the leading one). The controller's trajectory generator knows each joint's
        top speed (the primary interface's configuration data sends them) and PolyScope's
        MoveJ offers 180 °/s on models whose base tops at 120 °/s: a faster ``v`` is taken
        as the fastest the joints allow, not a stop [U: no UR text states it]."""
        qd_max = getattr(self.kinematics, "qd_max", None)
        if qd_max is None or delta[lead] <= 0.0:
            return v
        ratios = delta / delta[lead]
        moving = ratios > 1e-12
        if not moving.any():
            return v
        return min(v, float(np.min(np.asarray(qd_max, dtype=float)[moving] / ratios[moving])))

    def movel(self, pose: np.ndarray, a: float, v: float, t: float, r: float, span: Span,
              now: float, kind: str = "movel", a_rot: float | None = None,
              v_rot: float | None = None) -> float:
        """Straight TCP line to ``pose`` (4x4): ``a`` m/s², ``v`` m/s, ``t`` s, ``r`` m.

        The orientation has its own limits, ``v_rot`` rad/s and ``a_rot`` rad/s² (default
        :data:`ROTATION_PER_METRE` times ``v`` and ``a``); the move takes the longer of the
        two profiles (see :func:`line_profile`)."""
        pose_from = self._end_matrix()
        params = {"a": a, "v": v, "t": t}
        if span in self.stoppable:
            far = self._far(pose)
            beyond = None if far else self._beyond_reach(pose)
            target = pose
            pose, stopped, followed = self._until_out_of_reach(pose_from, pose)
            if stopped:
                params["until"] = True  # checked up to where it could stop
                if beyond is not None:
                    self.warnings.append(self._search_warning(target, beyond, span, now))
                elif not far:
                    self.warnings.append(self._broken_line_warning(
                        _distance(target, pose_from), followed, span, now))
        turn_rule = v_rot is None and kind in ("movel", "movep")
        if v_rot is None:
            v_rot = ROTATION_PER_METRE * v
        if a_rot is None:
            a_rot = ROTATION_PER_METRE * a
        profile = line_profile(pose_from, pose, v, a, t, v_rot, a_rot)
        if t > 0:  # what its a and v alone would take (see urdsl.verify.checks.SCALED_MARGIN)
            params["t_free"] = line_profile(pose_from, pose, v, a, 0.0, v_rot, a_rot).duration
        length = float(np.linalg.norm(pose[:3, 3] - pose_from[:3, 3]))
        if turn_rule and t <= 0 and \
                profile.duration > Trapezoid.plan(length, v, a).duration + 1e-9:
            params["turn_timed"] = True  # timed by its tool turn at ROTATION_PER_METRE·v [U]
        end = self._add_cartesian(kind, profile, pose_from, pose, r, span, params, now)
        if params.get("until"):
            # where the arm ends depends on the condition
            self.unknown_at = (f"the move at line {span.line}, which a condition stops", span)
            self.drift = None
        return end

    def unknown_position(self, why: str, span: Span, still: str | None = None,
                         holder=None) -> None:
        """From now on the arm stands where something outside the program put it, unknown
        offline, until a move to a known target: ``why`` says what (``"freedrive at line
        12, where the operator moves the arm by hand"``), ``span`` is that statement.

        ``still``: when the arm stands still there (the program's start; the end of a move
        that does not blend), that place for messages ("where the arm stood when the program
        started"): reads of the TCP pose are then followed relative to it
        (:meth:`relative_pose`); ``holder`` is the only thread that may read it (None: any).
        None: the arm may be moving (by hand, a speed command), nothing is followed."""
        self.unknown_at = (why, span)
        self.drift = None if still is None else Drift(still, holder=holder)

    def relative_pose(self, tcp, holder) -> Relative | None:
        """What a read by ``holder`` of the pose of the TCP ``tcp`` (a pose in the flange
        frame, or None for the flange) knows while the arm's position is unknown: the
        unknown start plus a known displacement (:class:`Relative`), or None."""
        if self.unknown_at is None or self.drift is None:
            return None
        return self.drift.read(_tcp_position(tcp), holder)

    def relative_move(self, relative: Relative, why: str, span: Span, settles: bool,
                      holder) -> str | None:
        """A move (at ``span``, by ``holder``) to a pose relative to an unknown start: why no
        start makes it reachable (:func:`urdsl.motion.drift.drift_error`; the move then
        does not happen), or None, and the arm's position is then unknown (``why``), known
        relative to that start when the move ends there (``settles``: it does not blend, and
        no condition stops it: :attr:`stoppable`)."""
        tcp = _tcp_position(self._tcp)
        self.unknown_at = (why, span)
        if span in self.stoppable:
            # a condition may stop it on the way (a Direction node aims far away on purpose):
            # the target is no destination, and where the arm stops is unknown
            self.drift = None
            return None
        spec = getattr(self.kinematics, "spec", None)
        problem = drift_error(relative, tcp, span, spec, self.model_assumed)
        if problem is not None:
            return problem
        self.drift = Drift.after(relative, tcp, span, holder) if settles else None
        return None

    def _far(self, pose: np.ndarray) -> bool:
        """Whether a target (4x4) lies further from the base than :data:`FAR_TARGET` times
        the model's reach: no taught waypoint does, while a Direction node aims 1000 m
        away (see :meth:`_beyond_reach` for stoppable moves to nearer unreachable targets)."""
        spec = getattr(self.kinematics, "spec", None)
        reach = getattr(spec, "reach", None) or STOP_SEARCH / (2.0 * FAR_TARGET)
        return float(np.linalg.norm(pose[:3, 3])) > FAR_TARGET * reach

    def _beyond_reach(self, pose: np.ndarray) -> KinematicsError | None:
        """Why a stoppable move's target (4x4) has no joint solution, or None when it has.

        A search move (``movel`` toward a point past the box wall, killed on tool contact)
        aims beyond the arm's reach on purpose: where it stops depends on the outside world
        (the contact, an input), unknown offline. Such a move is checked up to where the arm
        could follow it, and the unreachable target is a warning (URS210), not URS301: on the
        controller the arm stops at the condition or, if it never holds, at the edge of its
        workspace [U: the controller plans a movel's path as it goes and does not refuse an
        unreachable target up front, as PolyScope's Direction node, whose target is 1000 m
        away, shows]."""
        try:
            self.ik(pose)
        except KinematicsError as error:
            return error
        return None

    def _search_warning(self, target: np.ndarray, why: KinematicsError, span: Span,
                        now: float) -> MotionWarning:
        """The URS210 note for a stoppable move whose target (4x4) is out of reach."""
        where = ", ".join(f"{x:.4f}" for x in target[:3, 3])
        distance = getattr(why, "distance", 0.0) or 0.0
        reason = unreachable_reason(distance)
        return MotionWarning(
            "condition", f"the target of this move at [{where}] m is {reason}: the arm stops "
            "at the edge of its workspace only if the condition that stops the move (tool "
            "contact, an input) has not held before, which depends on the outside world; "
            "checked up to where the arm could follow the line", span, now)

    @staticmethod
    def _broken_line_warning(length: float, followed: float, span: Span, now: float
                             ) -> MotionWarning:
        """The URS210 note for a stoppable move to a reachable target whose straight line
        (``length`` m) the arm can follow only ``followed`` m: where it goes on past a
        singularity or out of the workspace, the controller would stop it; the condition
        (tool contact on the part the move is made to touch) may stop it before."""
        return MotionWarning(
            "condition", f"the arm can follow this line only {1000 * followed:.0f} mm of its "
            f"{1000 * length:.0f} mm (then it leaves the workspace or passes a singularity); "
            "it gets there only if the condition that stops the move (tool contact, an input) "
            "has not held before, which depends on the outside world: checked up to "
            f"{1000 * STOP_MARGIN:.0f} mm before there, and where the arm stops is unknown",
            span, now)

    def _until_out_of_reach(self, pose_from: np.ndarray, pose: np.ndarray
                            ) -> tuple[np.ndarray, bool, float]:
        """A straight line that a condition stops (a Direction node's move toward a point
        far away) goes at most as far as the arm can follow it: the pose (4x4) where the line
        leaves the workspace or its IK solution can no longer continue, less
        :data:`STOP_MARGIN`; whether the line was cut there; and how far (m) the arm can
        follow it. A line the arm can follow to its end is kept."""
        from .geometry import slerp_rotations
        from .tracking import track

        length = _distance(pose, pose_from)
        if length < 1e-9:
            return pose, False, 0.0
        q_from = self._q
        model, tcp = self.kinematics, self.tcp

        def continuous(fractions: np.ndarray, q_first: np.ndarray, jump: float
                       ) -> tuple[int, np.ndarray]:
            """How many of ``fractions`` (rising) the arm reaches continuously from
            ``q_first``, and the joints (N, 6) there."""
            poses = np.repeat(np.eye(4)[None], len(fractions), axis=0)
            poses[:, :3, :3] = slerp_rotations(pose_from[:3, :3], pose[:3, :3], fractions)
            poses[:, :3, 3] = pose_from[:3, 3] + fractions[:, None] * (pose[:3, 3]
                                                                         - pose_from[:3, 3])
            q = track(model, poses, np.repeat(q_first[None], len(fractions), axis=0),
                       np.repeat(q_first[None], len(fractions), axis=0),
                       np.zeros(len(fractions), dtype=np.int64), tcp)
            steps = np.abs(np.diff(np.vstack([q_first, q]), axis=0)).max(axis=1)
            bad = np.flatnonzero(~(steps <= jump))  # NaN: out of reach
            return (len(fractions) if len(bad) == 0 else int(bad[0])), q

        high = min(1.0, STOP_SEARCH / length)
        coarse = np.linspace(0.0, high, 257)[1:]
        good, q_coarse = continuous(coarse, q_from, 2.0 * STOP_JUMP)
        if good == len(coarse) and high == 1.0:
            return pose, False, length
        if good == len(coarse):
            reached = high
        else:
            low = coarse[good - 1] if good > 0 else 0.0
            q_low = q_coarse[good - 1] if good > 0 else q_from
            fine = np.linspace(low, coarse[good], 66)[1:-1]
            reached = low
            count, _ = continuous(fine, q_low, STOP_JUMP)
            if count > 0:
                reached = float(fine[count - 1])
        followed = reached * length
        reached = max(0.0, reached - STOP_MARGIN / length)
        cut = pose_from.copy()
        cut[:3, :3] = slerp_rotations(pose_from[:3, :3], pose[:3, :3], np.array([reached]))[0]
        cut[:3, 3] = pose_from[:3, 3] + reached * (pose[:3, 3] - pose_from[:3, 3])
        return cut, True, followed

    def _add_cartesian(self, kind: str, profile: Trapezoid, pose_from: np.ndarray,
                       pose: np.ndarray, r: float, span: Span, params: dict, now: float,
                       via: np.ndarray | None = None) -> float:
        if self.lazy_ik:
            if len(self._unresolved) >= RESOLVE_BATCH:
                self.resolve()  # as it runs, so that the run's time bound covers it
            segment = self._segment(kind, profile, None, None, r, span, params, pose_from, pose)
        else:
            q_from = self._q
            segment = self._segment(kind, profile, q_from, self._line_end(pose, q_from), r,
                                    span, params, pose_from, pose)
        if via is not None:
            segment.via = via[:3, 3].copy()
        if not self.lazy_ik:
            segment.q_end = continuous_end(self.kinematics, segment, segment.q_start,
                                           segment.q_end)
        return self._add(segment, now)

    def movec(self, via: np.ndarray, pose: np.ndarray, a: float, v: float, r: float,
              mode: int, span: Span, now: float) -> float:
        """Circular arc from the current TCP through ``via``'s position to ``pose``."""
        from .geometry import arc_length, arc_rotations

        pose_from = self._end_matrix()
        length = arc_length(pose_from[:3, 3], via[:3, 3], pose[:3, 3])
        profile = Trapezoid.plan(length, v, a)
        if mode == 1:  # fixed mode: the target's orientation is not used; the tool ends
            # turned by the arc's angle from where it started (the manual's movec, mode 1)
            pose = pose.copy()
            pose[:3, :3] = arc_rotations(pose_from[:3, 3], via[:3, 3], pose[:3, 3],
                                         np.array([1.0]))[0] @ pose_from[:3, :3]
        return self._add_cartesian("movec", profile, pose_from, pose, r, span,
                                   {"a": a, "v": v, "mode": mode}, now, via=via)

    def servoj(self, q: np.ndarray, t: float, span: Span, now: float) -> float:
        """Reach ``q`` (rad) in ``t`` s at constant joint speed (servoj ignores a and v)."""
        q = np.asarray(q, dtype=float)
        q_from = self._q
        distance = float(np.max(np.abs(q - q_from)))
        t = max(t, self.step_time)
        profile = Trapezoid(distance, 0.0, distance / t, 0.0, t)
        return self._add(self._segment("servoj", profile, q_from, q, 0.0, span, {"t": t}),
                         now)

    def speedj(self, qd: np.ndarray, a: float, t: float, span: Span, now: float) -> float:
        """Accelerate with ``a`` rad/s² (leading axis) to joint speeds ``qd`` (rad/s), keep
        them until ``t`` s, then decelerate to rest (the stop a following ``stopj`` or the
        end of the program commands). A ``t`` shorter than the ramp reaches ``a·t`` on the
        leading axis. Returns when the cruise ends (after ``t``)."""
        qd = np.asarray(qd, dtype=float)
        return self._speed("speedj", qd, a, t, span, now, self._plan_speedj)

    def _plan_speedj(self, qd: np.ndarray, a: float, t: float, span: Span, now: float
                     ) -> float:
        lead = float(np.max(np.abs(qd)))
        q_from = self._q
        if lead == 0.0:  # a zero speed command still lasts its t
            return max(self.stop(now), now + t)
        t = t if t > 0 else lead / a
        cruise = min(lead, a * t)  # the speed reached when the function returns
        profile = Trapezoid.plan(cruise * t, cruise, a)
        q_to = q_from + qd / lead * profile.distance
        segment = self._segment("speedj", profile, q_from, q_to, 0.0, span,
                                {"a": a, "t": t, "qd": qd.tolist()})
        unknown = self.unknown_at
        self._add(segment, now)
        self._still_unknown(unknown)
        return segment.start + profile.duration - profile.t_acc

    def _still_unknown(self, unknown: tuple[str, Span] | None) -> None:
        """After a speed move (``speedj``/``speedl``) from where the arm's position is
        unknown (``unknown``: :attr:`unknown_at` before it): a speed has no target, so the
        arm is still somewhere unknown (seen: an edge search, ``speedl`` until a force,
        after a move to a taught point the project does not hold; two such searches read
        the same "known" pose and the program's distance check halted it)."""
        if unknown is not None:
            self.unknown_at = unknown
            self.drift = None

    def speedl(self, xd: np.ndarray, a: float, t: float, span: Span, now: float) -> float:
        """Tool speed ``xd`` (m/s, rad/s in Base) like :meth:`speedj`, as a straight line."""
        xd = np.asarray(xd, dtype=float)
        return self._speed("speedl", xd, a, t, span, now, self._plan_speedl)

    def _plan_speedl(self, xd: np.ndarray, a: float, t: float, span: Span, now: float
                     ) -> float:
        from ..kinematics.pose import rotvec_to_matrix

        linear = float(np.linalg.norm(xd[:3]))
        angular = float(np.linalg.norm(xd[3:]))
        if linear == 0.0 and angular == 0.0:
            return max(self.stop(now), now + t)
        speed = linear if linear > 0 else angular
        t = t if t > 0 else speed / a
        scale = min(1.0, a * t / speed)  # to the speed reached when the function returns
        xd, linear, angular = xd * scale, linear * scale, angular * scale
        pose_from = self._end_matrix()
        pose = pose_from.copy()
        pose[:3, 3] += xd[:3] * t
        pose[:3, :3] = rotvec_to_matrix(xd[3:] * t) @ pose_from[:3, :3]
        # speedl's rotational part is in rad/s and rad/s² as given (aRot defaults to a)
        unknown = self.unknown_at
        count = len(self.segments)
        end = self.movel(pose, a, max(linear, 1e-12), 0.0, 0.0, span, now, kind="speedl",
                         a_rot=a, v_rot=max(angular, 1e-12))
        self._still_unknown(unknown)
        ramp = self.segments[-1].profile.t_acc if len(self.segments) > count else 0.0
        return end - min(ramp, end - now)

    def _speed(self, kind: str, vector: np.ndarray, a: float, t: float, span: Span,
               now: float, plan) -> float:
        """Plan a speed command with ``plan``; one identical to the last speed command and
        given when that one returned goes on from it (:class:`_SpeedChain`): the chain is
        planned again from its start as one command lasting the sum of their ``t``."""
        chain = self._speed_chain
        self._speed_chain = None
        if (chain is not None and t > 0 and chain.kind == kind and chain.a == a
                and np.array_equal(chain.vector, vector) and abs(now - chain.returns) <= 1e-9
                and self.segments and self.segments[-1] is chain.segment
                and chain.state[-1] == self._tcp_key()):
            self._restore(chain.state)
            total, first = chain.t + t, chain.now
        else:
            chain = None
            total, first = t, now
        state = self._state() if chain is None else chain.state
        count = len(self.segments)
        returns = plan(vector, a, total, span, first)
        if t > 0 and len(self.segments) > count:
            self._speed_chain = _SpeedChain(self.segments[-1], kind, vector.copy(), a, total,
                                            returns, first, state)
        return returns

    def _tcp_key(self) -> tuple | None:
        return None if self._tcp is None else tuple(self._tcp.tolist())

    def _state(self) -> tuple:
        """What planning a move changes, to plan a speed chain again from its start."""
        return (self._q_end.copy(), self._end_pose, list(self._unresolved), self._free_at,
                self.end_time, self._pending, self.unknown_at, self.drift, len(self.segments),
                self._tcp_key())

    def _restore(self, state: tuple) -> None:
        (self._q_end, self._end_pose, unresolved, self._free_at, self.end_time,
         self._pending, self.unknown_at, self.drift, count, _) = state
        self._q_end = self._q_end.copy()
        self._unresolved = list(unresolved)
        self.segments = self.segments[:count]

    def stop(self, now: float) -> float:
        """``stopj``/``stopl``: no blend into what follows; returns when the arm is at rest."""
        self.stop_blending(now)
        return max(now, self._free_at)

    def stop_blending(self, now: float) -> None:
        """The script did something that waits (sleep, a stop): a pending blend ends in a
        stop at its waypoint."""
        if self._pending is not None:
            self._free_at = self._pending.end
            self._pending = None

    def finish(self, now: float) -> None:
        """The program ended: the last move runs to its end. A target found out of reach
        while solving the last moves is kept in :attr:`failure` (the program had ended)."""
        try:
            self.resolve()
        except UnreachableTarget as failure:
            self.failure = failure
        self.stop_blending(now)
        self.end_time = max([now] + [s.end for s in self.segments])

    def _segment(self, kind: str, profile: Trapezoid, q_from: np.ndarray, q_to: np.ndarray,
                 r: float, span: Span, params: dict, pose_from: np.ndarray | None = None,
                 pose_to: np.ndarray | None = None) -> Segment:
        if pose_from is None:
            pose_from = self._pose_of(q_from)
        if pose_to is None:
            pose_to = self._pose_of(q_to)
        tcp = None if self.tcp is None else self.tcp.copy()
        q_from = None if q_from is None else np.asarray(q_from, dtype=float).copy()
        q_to = None if q_to is None else np.asarray(q_to, dtype=float).copy()
        return Segment(kind, 0.0, profile, q_from, q_to, pose_from, pose_to, r, span, params,
                       tcp=tcp)

    # ---- planning --------------------------------------------------------------------------

    def _add(self, segment: Segment, now: float) -> float:
        if self.unknown_at is not None:  # its path from there is not known; its target is
            segment.params["from_unknown"] = self.unknown_at[0]
        self.unknown_at = None  # a move to a known target: the arm's position is known again
        self.drift = None
        previous = self._pending
        radius = segment.radius
        previous_radius = previous.radius if previous is not None else 0.0
        if radius > 0 or previous_radius > 0:
            distance = _distance(segment.pose_end, segment.pose_start)
            if previous_radius + radius > distance + 1e-12:
                self.warnings.append(MotionWarning(
                    "overlap",
                    f"Overlapping Blends: blend radii {previous_radius:g} m + "
                    f"{radius:g} m exceed the {distance:.4g} m to the previous "
                    "waypoint; the robot skips this move",
                    segment.span, now))
                self.skipped.append(segment)
                return now
        if previous is not None and segment.kind not in BLENDABLE_INTO:
            self.stop_blending(now)
            previous = None
        profile = segment.profile
        duration = profile.duration
        if previous is not None:
            previous_duration = previous.profile.duration
            tail = _time_for_last(previous, previous_radius)
            head = profile.time_at(_path_fraction_for(segment, previous_radius)
                                   * profile.distance)
            overlap = min(tail, head, previous_duration, duration)
            previous.blend_with_next = overlap
            start = max(previous.start + previous_duration - overlap, now)
        else:
            start = max(now, self._free_at)
        segment.start = start
        end = start + duration
        self.segments.append(segment)
        if segment.q_end is None:
            self._unresolved.append(segment)
        else:
            self._q_end = segment.q_end.copy()
        self._end_pose = segment.pose_end
        if end > self.end_time:
            self.end_time = end
        if radius > 0:
            self._pending = segment
            return max(end - _time_for_last(segment, radius), now)
        self._pending = None
        self._free_at = end
        return end


def continue_branch(model, solutions: np.ndarray, q_first: np.ndarray, tcp=None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The joints (N, 6) at the end of a chain of straight-line moves to targets with the
    analytic solutions ``solutions`` (N, 8, 6), starting from ``q_first`` (rad), and which
    were found (N,).

    On a straight TCP line the controller follows one IK solution continuously, so a move
    ends on the IK branch (shoulder, elbow, wrist: :mod:`urdsl.kinematics.ik`) it started on
    unless the path passes a singularity — where the trace shows the jump (URS302). Each
    target therefore takes the solution of the branch the chain is on, each joint turned by
    the multiple of 2π nearest the previous joints. Where that branch does not exist or
    leaves the joint limits (and at a singular start, where the branch is ambiguous) the
    target takes the solution closest to the previous joints, and the chain goes on from
    its branch. The closest solution and the continuation differ only for moves that pass
    near a singularity: a line passing the base at a small distance turns the base by
    far more than the closest solution would.
    """
    from ..kinematics.ik import choose_nearest, choose_sequence

    count = solutions.shape[0]
    chosen = np.full((count, 6), np.nan)
    found = np.zeros(count, dtype=bool)
    previous = np.asarray(q_first, dtype=float)
    row = 0
    branch = _branch_of(model, previous, tcp)
    while row < count:
        if branch is None:  # no branch to continue: the controller's nearest choice
            rest, ok = choose_sequence(solutions[row:], previous, model.q_min, model.q_max)
            chosen[row:], found[row:] = rest, ok
            return chosen, found
        rest, ok = choose_sequence(solutions[row:, branch:branch + 1], previous,
                                   model.q_min, model.q_max)
        missing = np.flatnonzero(~ok)
        stop = len(ok) if len(missing) == 0 else int(missing[0])
        chosen[row:row + stop], found[row:row + stop] = rest[:stop], True
        if stop:
            previous = rest[stop - 1]
        row += stop
        if row == count:
            break
        q, ok = choose_nearest(solutions[row:row + 1], previous[None], model.q_min,
                               model.q_max)
        if not ok[0]:
            return chosen, found  # out of reach: this target and the rest stay unfound
        chosen[row], found[row] = q[0], True
        previous = q[0]
        branch = _matching_branch(solutions[row], previous)
        row += 1
    return chosen, found


TURN_CHECK = np.pi / 3
"""A Cartesian move whose tool turns by more than this (rad), or one of whose joints the
chosen end turns by more than half a turn less this, has its end's whole turns checked along
its path (:func:`continuous_end`)."""

PATH_SAMPLES = 16
"""Points on a Cartesian move's path at which :func:`continuous_end` follows the joints: a
tool turn of at most 180° gives at most about 11° between points, well within half a turn."""


def continuous_end(model, segment: Segment, q_from: np.ndarray, end: np.ndarray) -> np.ndarray:
    """``end`` (rad, the move's target solution with each joint at the whole turn nearest
    ``q_from``), turned by the whole turns the joints make when they follow the path from
    ``q_from`` continuously on the same IK branch.

    Nearest is wrong when a joint travels more than half a turn: a movel that turns the tool
    174° (o2ac ``flip_endcap``) turns wrist 3 by 183° one way, and its nearest end lay 177°
    the other way; the trace then followed the path and jumped a full turn at the end (a
    false URS302 and a 10.98 rad/s URS304). Straight lines that turn the tool little, with no
    joint near half a turn, are left as they are (an arc is always followed); a path that
    leaves the reach or the branch keeps ``end`` (the trace shows it)."""
    q_from = np.asarray(q_from, dtype=float)
    end = np.asarray(end, dtype=float)
    if not hasattr(model, "ik_all_many") or segment.kind not in ("movel", "movep", "movec"):
        return end
    rotation = segment.pose_start[:3, :3].T @ segment.pose_end[:3, :3]
    turned = float(np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)))
    if turned <= TURN_CHECK and float(np.max(np.abs(end - q_from))) <= np.pi - TURN_CHECK \
            and segment.kind != "movec":
        return end
    fractions = np.arange(1, PATH_SAMPLES + 1) / PATH_SAMPLES
    solutions, _ = model.ik_all_many(segment.path_poses(fractions), tcp=segment.tcp)
    path, found = continue_branch(model, solutions, q_from, segment.tcp)
    if not found.all():
        return end
    turns = np.rint((path[-1] - end) / (2.0 * np.pi))
    if not np.allclose(path[-1], end + 2.0 * np.pi * turns, atol=1e-6):
        return end  # the path changes branch: the trace reports it
    return end + 2.0 * np.pi * turns


def branch_path(model, segment: Segment, fractions: np.ndarray) -> np.ndarray | None:
    """The joints (N, 6, rad) of a straight-line or circular move at path ``fractions``,
    followed continuously from its start on the IK branch it starts on, with no regard to
    the joint limits; NaN from the first point where that branch ends (out of reach) or
    jumps (a singularity). None for joint moves, a singular start or a model without
    analytic solutions.

    Inverse kinematics keeps every point of a path inside the limits, so where this path
    runs out of them (wrist 3 wound to -350° and then turned on) the trace jumps to another
    branch; the controller aborts the program there instead (CB3 user manual, Joint Limits;
    that it does not switch solutions is [U])."""
    if not hasattr(model, "ik_all_many") or segment.kind not in ("movel", "movep", "movec"):
        return None
    from ..kinematics.ik import choose_sequence

    fractions = np.asarray(fractions, dtype=float)
    branch = _branch_of(model, segment.q_start, segment.tcp)
    if branch is None or len(fractions) == 0:
        return None
    solutions, _ = model.ik_all_many(segment.path_poses(fractions), tcp=segment.tcp)
    endless = np.full(6, np.inf)
    path, found = choose_sequence(solutions[:, branch:branch + 1], segment.q_start,
                                  -endless, endless)
    steps = np.abs(np.diff(np.vstack([segment.q_start, path]), axis=0))
    broken = np.flatnonzero(~found | ~(steps <= STOP_JUMP).all(axis=1))
    if len(broken):
        path[int(broken[0]):] = np.nan
    return path


def _branch_of(model, q: np.ndarray, tcp) -> int | None:
    """The IK branch (0…7) the joints ``q`` are on, or None at a singular pose (where
    branches meet) or for a model without analytic solutions."""
    every, _ = model.ik_all_many(model.fk(q, tcp=tcp)[None], tcp=tcp)
    return _matching_branch(every[0], q)


def _matching_branch(solutions: np.ndarray, q: np.ndarray, tolerance: float = 1e-6
                     ) -> int | None:
    """Index of the solution (8, 6) equal to ``q`` up to whole turns of each joint, if just
    one is (two equal ones: a singular pose)."""
    difference = solutions - q
    difference -= 2.0 * np.pi * np.rint(difference / (2.0 * np.pi))
    cost = np.einsum("kj,kj->k", difference, difference)
    matches = np.flatnonzero(cost < tolerance)  # NaN (missing branches) never matches
    if len(matches) != 1:
        return None
    return int(matches[0])


RESOLVE_BATCH = 4096
"""Most straight-line moves whose joints are left unsolved (:meth:`MotionPlanner.resolve`
solves them in one batch): a toolpath of a million moves is solved in batches as the
program runs, not all after it."""

POSE_CACHE = 4096
"""Most TCP poses :meth:`MotionPlanner._pose_of` keeps (then it starts again)."""

STOP_SEARCH = 4.0
"""How far (m) along a line that a condition stops the planner looks for where the arm can
no longer follow it: twice the reach of the largest UR (UR20: 1.75 m), plus room."""

FAR_TARGET = 1.5
"""A target further from the base than this many times the arm's reach is a direction to
move in, not a destination (see :meth:`MotionPlanner._far`)."""

STOP_JUMP = 0.25
"""Joint step (rad) between neighbouring points of such a line that counts as the end of a
continuous solution (as :data:`urdsl.verify.checks.JUMP_MIN`)."""

STOP_MARGIN = 0.05
"""How far (m) before the edge of the workspace a line that a condition stops is checked
to: the arm reaches the edge only if the condition never fires, and the checks'
singularity margins (2 to 5 cm, URS307) would otherwise warn about a stretched arm that the
program does not ask for."""


ROTATION_PER_METRE = 4.0
"""Rotational speed and acceleration limits of a ``movel``/``movep`` per unit of its tool
speed and acceleration: ``v_rot = 4·v`` rad/s and ``a_rot = 4·a`` rad/s² (1 rad/s and
4.8 rad/s² at the defaults v = 0.25 m/s, a = 1.2 m/s²). [U] The script manual documents only
the m/s and m/s² of the position; this rule is a user's measurement reported on the UR
forum ("MoveL: Tool Angular Speed", forum.universal-robots.com/t/movel-tool-angular-speed/
15912): position and orientation each get a trapezoid, the longer one sets the move's time
and the other is slowed down to it."""


def line_profile(pose_from: np.ndarray, pose_to: np.ndarray, v: float, a: float, t: float,
                 v_rot: float, a_rot: float) -> Trapezoid:
    """The speed profile of a straight TCP line from ``pose_from`` to ``pose_to`` (4x4, m).

    The controller plans two trapezoids, one for the path length ``L`` (m) with ``v`` m/s and
    ``a`` m/s², one for the rotation angle ``θ`` (rad) with ``v_rot`` rad/s and ``a_rot``
    rad/s², and moves on the longer one; position and orientation progress by the same path
    fraction, so the shorter one is slowed down to it [U: see :data:`ROTATION_PER_METRE`].
    A time ``t`` > 0 stretches the result as for any move.

    The profile's distance stays the path length in m (what blends and the TCP speed use);
    a move that only turns the tool has its angle in rad as distance. A 1 cm move that turns
    the tool by 120° at the defaults takes about 2.3 s, not the 0.18 s of its 1 cm.
    """
    start, end = pose_from.tolist(), pose_to.tolist()  # scalar maths: the planner's hot path
    length = math.dist((start[0][3], start[1][3], start[2][3]),
                       (end[0][3], end[1][3], end[2][3]))
    angle = _turn(start, end)
    rotation = Trapezoid.plan(angle, v_rot, a_rot) if angle > 1e-9 else None
    if length < 1e-9:  # the tool only turns: time it on the angle
        return rotation.stretched(t) if rotation is not None and t > 0 else (
            rotation if rotation is not None else Trapezoid.plan(0.0, v, a, t))
    profile = Trapezoid.plan(length, v, a)
    if rotation is not None and rotation.duration > profile.duration:
        scale = length / angle  # the rotation's timing, with the path's distance
        profile = Trapezoid(length, rotation.accel * scale, rotation.peak * scale,
                            rotation.t_acc, rotation.t_flat)
    return profile.stretched(t) if t > 0 else profile


def _turn(start: list, end: list) -> float:
    """Angle (rad, in [0, π]) of the rotation between the orientations of two poses given as
    nested lists (4x4): ``atan2(sin θ, cos θ)`` from the trace and the skew part of
    ``R = R0ᵀ·R1`` (accurate at 0 and π)."""
    a, b = start, end
    if a[0][:3] == b[0][:3] and a[1][:3] == b[1][:3] and a[2][:3] == b[2][:3]:
        return 0.0  # the same orientation (most toolpath moves)

    def entry(i: int, j: int) -> float:  # (R0ᵀ·R1)[i][j]
        return a[0][i] * b[0][j] + a[1][i] * b[1][j] + a[2][i] * b[2][j]

    cosine = (entry(0, 0) + entry(1, 1) + entry(2, 2) - 1.0) / 2.0
    sine = math.hypot(entry(2, 1) - entry(1, 2), entry(0, 2) - entry(2, 0),
                      entry(1, 0) - entry(0, 1)) / 2.0
    return math.atan2(sine, cosine)


def _distance(pose: np.ndarray, other: np.ndarray) -> float:
    """Distance (m) between the positions of two 4x4 poses (scalar maths: one move at a time
    is the planner's hot path)."""
    return math.dist(pose[:3, 3].tolist(), other[:3, 3].tolist())


def _tcp_position(tcp) -> np.ndarray:
    """The position (m) of a TCP (a pose in the flange frame, or None: the flange)."""
    return np.zeros(3) if tcp is None else np.asarray(tcp, dtype=float)[:3]


def _tcp_length(segment: Segment) -> float:
    if segment.kind in ("movel", "movep", "movec"):
        return segment.profile.distance
    return _distance(segment.pose_end, segment.pose_start)


def _path_fraction_for(segment: Segment, tcp_distance: float) -> float:
    length = _tcp_length(segment)
    if length <= 0:
        return 1.0
    return min(tcp_distance / length, 1.0)


def _time_for_last(segment: Segment, tcp_distance: float) -> float:
    """Time the segment needs for its last ``tcp_distance`` metres of TCP travel (all of
    it when ``tcp_distance`` is longer than the segment)."""
    fraction = _path_fraction_for(segment, tcp_distance)
    profile = segment.profile
    return profile.duration - profile.time_at((1.0 - fraction) * profile.distance)
