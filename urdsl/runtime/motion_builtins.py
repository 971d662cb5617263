"""Builtins that move the arm or read its state, and URScript pose maths.

Motion calls go to the interpreter's robot, a :class:`urdsl.motion.planner.MotionPlanner`:
it plans the move in robot time and says when the script may go on (the end of the move,
or the start of its blend), and the calling thread waits until then. Pose maths comes from
:mod:`urdsl.kinematics.pose`, inverse kinematics from the planner's robot model.

Units are the controller's: joints in rad, positions in m, speeds in rad/s or m/s,
accelerations in rad/s² or m/s², times in s, blend radii in m.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..kinematics import KinematicsError
from ..kinematics import pose as posemath
from ..kinematics.models import NOMINAL_ACCURACY
from .errors import ScriptRuntimeError, beyond_reach
from .registry import implements
from .values import ListValue, PoseValue, Unknown, is_number, type_name

__all__: list[str] = []


# ---- argument conversion ---------------------------------------------------------------------


def _arm(rt, node, resolve: bool = True):
    """The interpreter's robot, with every move planned so far solved (a target out of reach
    found now stops the program at that move's line). Straight-line moves pass
    ``resolve=False``: their targets are solved later, in batches."""
    if rt.robot is None:
        raise rt.error("unsupported", "this program runs without a robot: motion and robot "
                       "state are not available", node)
    if not resolve:
        return rt.robot
    try:
        rt.robot.resolve()
    except KinematicsError as error:
        raise _ik_error(rt, node, error) from None
    return rt.robot


def _ik_error(rt, node, error: KinematicsError):
    """The runtime error for a failed inverse kinematics: at the move whose target failed
    (when the planner found it later, in a batch), else at ``node``."""
    span = getattr(error, "span", None)
    if span is None:
        failed = rt.error("ik", f"inverse kinematics failed: {error}", node, _IK_HINT)
    else:
        failed = ScriptRuntimeError("ik", f"inverse kinematics failed: {error}", span,
                                    _IK_HINT, getattr(error, "time", rt.time))
    failed.beyond = beyond_reach(error)
    return failed


_IK_HINT = "the pose is out of reach of this robot with the active TCP"


def _numbers(rt, node, value: Any, count: int, what: str) -> np.ndarray:
    if type(value) is PoseValue or (type(value) is ListValue
                                     and all(is_number(v) for v in value)):
        if len(value) != count:
            raise rt.error("type", f"{what} needs {count} numbers, got {len(value)}", node,
                           "a joint vector has 6 angles in rad: [base, shoulder, elbow, "
                           "wrist1, wrist2, wrist3]" if count == 6 else None)
        array = np.array([float(v) for v in value])
        if not np.isfinite(array).all():
            raise rt.error("arithmetic", f"{what} contains a value that is not finite", node)
        return array
    raise rt.error("type", f"{what} must be a list of {count} numbers, not a "
                   f"{type_name(value)}", node)


def _number(rt, node, value: Any, what: str, minimum: float | None = 0.0) -> float:
    if not is_number(value):
        raise rt.error("type", f"{what} must be a number, not a {type_name(value)}", node)
    number = float(value)
    if not math.isfinite(number) or (minimum is not None and number < minimum):
        raise rt.error("arithmetic", f"{what} must be a finite number >= {minimum:g}, "
                       f"got {number:g}", node)
    return number


def _pose(rt, node, value: Any, what: str) -> np.ndarray:
    """A pose argument as a 6-vector; must be a pose (p[...])."""
    if type(value) is not PoseValue:
        raise rt.error("type", f"{what} must be a pose p[x, y, z, rx, ry, rz], not a "
                       f"{type_name(value)}", node)
    return np.array(value, dtype=float)


def _matrix(rt, node, value: Any, what: str) -> np.ndarray:
    """A Cartesian target as a 4x4 matrix: a pose, or joints turned into a pose by FK (the
    controller accepts joint vectors as targets of movel/movep/movec)."""
    arm = _arm(rt, node, resolve=False)
    if type(value) is PoseValue:
        return posemath.to_matrix(value)
    return arm.fk(_numbers(rt, node, value, 6, what))


def _joints_target(rt, node, value: Any) -> np.ndarray:
    """The joints of a movej target: a joint vector, or a pose solved by IK closest to where
    the arm is going."""
    arm = _arm(rt, node)
    if type(value) is PoseValue:
        return _solve(rt, node, arm, posemath.to_matrix(value), None)
    return _numbers(rt, node, value, 6, "the joint target")


def _solve(rt, node, arm, matrix: np.ndarray, near: np.ndarray | None) -> np.ndarray:
    try:
        return arm.ik(matrix, near)
    except KinematicsError as error:
        raise _ik_error(rt, node, error) from None


def _to_pose(matrix: np.ndarray) -> PoseValue:
    return PoseValue(posemath.from_matrix(matrix))


def _vector(values) -> ListValue:
    return ListValue([float(v) for v in values])


def _plan(rt, node, plan) -> None:
    """Run a planning call, turning the model's errors into runtime errors, and wait until
    the script may go on."""
    try:
        resume = plan()
    except KinematicsError as error:
        raise _ik_error(rt, node, error) from None
    except ValueError as error:
        raise rt.error("arithmetic", str(error), node) from None
    if resume > rt.time:
        rt.wait_until(resume)
    else:
        # a move that has nothing to do (the arm is at its target) still takes the motion
        # planner a controller frame: a looping PolyScope program of one waypoint runs on
        # the robot without "Runtime is too much behind" [U: inferred from that, not
        # documented]
        rt.sync()


# ---- moves -----------------------------------------------------------------------------------


@implements("movej")
def _movej(rt, node, q, a=1.4, v=1.05, t=0, r=0):
    arm = _arm(rt, node)
    target = _joints_target(rt, node, q)
    a, v = _number(rt, node, a, "a"), _number(rt, node, v, "v")
    t, r = _number(rt, node, t, "t"), _number(rt, node, r, "r")
    solved = type(q) is PoseValue  # joints the IK chose near where the arm is
    _plan(rt, node, lambda: arm.movej(target, a, v, t, r, node.span, rt.time,
                                      solved=solved))


def _linear(kind: str):
    def move(rt, node, pose, a=1.2, v=0.25, t=0, r=0):
        arm = _arm(rt, node, resolve=False)
        target = _matrix(rt, node, pose, "the target")
        a, v = _number(rt, node, a, "a"), _number(rt, node, v, "v")
        t, r = _number(rt, node, t, "t"), _number(rt, node, r, "r")
        _plan(rt, node, lambda: arm.movel(target, a, v, t, r, node.span, rt.time, kind=kind))

    return move


implements("movel")(_linear("movel"))
implements("movep", "servoc")(_linear("movep"))


@implements("movec")
def _movec(rt, node, pose_via, pose_to, a=1.2, v=0.25, r=0, mode=0):
    arm = _arm(rt, node, resolve=False)
    via = _matrix(rt, node, pose_via, "pose_via")
    target = _matrix(rt, node, pose_to, "pose_to")
    a, v, r = _number(rt, node, a, "a"), _number(rt, node, v, "v"), _number(rt, node, r, "r")
    if type(mode) is not int or mode not in (0, 1):
        raise rt.error("type", f"movec mode must be 0 (unconstrained) or 1 (fixed), not {mode}",
                       node)
    _plan(rt, node, lambda: arm.movec(via, target, a, v, r, mode, node.span, rt.time))


@implements("servoj")
def _servoj(rt, node, q, a=None, v=None, t=None, lookahead_time=0.1, gain=300):
    arm = _arm(rt, node)
    target = _numbers(rt, node, q, 6, "the joint target")
    step = rt.config.step_time
    t = step if t is None else _number(rt, node, t, "t")
    lookahead = _number(rt, node, lookahead_time, "lookahead_time")
    if not 0.03 <= lookahead <= 0.2:
        raise rt.error("arithmetic", f"servoj lookahead_time must be in [0.03, 0.2] s, got "
                       f"{lookahead:g}", node)
    if not 100 <= _number(rt, node, gain, "gain") <= 2000:
        raise rt.error("arithmetic", f"servoj gain must be in [100, 2000], got {gain}", node)
    _plan(rt, node, lambda: arm.servoj(target, t, node.span, rt.time))


@implements("speedj")
def _speedj(rt, node, qd, a, t=0):
    arm = _arm(rt, node)
    speeds = _numbers(rt, node, qd, 6, "the joint speeds")
    a, t = _number(rt, node, a, "a", 1e-9), _number(rt, node, t, "t")
    _plan(rt, node, lambda: arm.speedj(speeds, a, t, node.span, rt.time))


@implements("speedl")
def _speedl(rt, node, xd, a, t=0, aRot="a"):  # noqa: N803 - the catalog's parameter name
    arm = _arm(rt, node)
    speeds = _numbers(rt, node, xd, 6, "the tool speed")
    a, t = _number(rt, node, a, "a", 1e-9), _number(rt, node, t, "t")
    _plan(rt, node, lambda: arm.speedl(speeds, a, t, node.span, rt.time))


@implements("stopj", "stopl")
def _stop(rt, node, a, aRot="a"):  # noqa: N803
    arm = _arm(rt, node)
    _number(rt, node, a, "a", 1e-9)
    rt.wait_until(arm.stop(rt.time))


# ---- robot state -----------------------------------------------------------------------------


def _stopped_by_condition(rt, arm, tcp: Any = False) -> Unknown | None:
    """Where the arm is when something outside the program decided it, unknown offline
    until a move to a known target (:meth:`urdsl.motion.planner.MotionPlanner.unknown_position`):
    after a move that a condition stops (PolyScope's Direction node: until tool contact, an
    input); after ``freedrive_mode()`` or ``teach_mode()``, when the operator moves the arm by
    hand (PolyScope programs put the tool "close to the corner" this way, behind a popup that
    says so); after a move to an unknown target; at the start of a program that starts
    wherever the arm was left.

    ``tcp``: for a read of a TCP pose, that TCP (a pose in the flange frame; None: the
    flange): while the arm stands still where it is unknown, the value says so
    (:meth:`urdsl.motion.planner.MotionPlanner.relative_pose`); False: a read of anything
    else (joints)."""
    unknown_at = getattr(arm, "unknown_at", None)
    if unknown_at is None or not rt.unknown:
        return None
    why, span = unknown_at
    relative = None if tcp is False else arm.relative_pose(tcp, rt.current)
    return Unknown(f"the arm's position after {why}", span, relative=relative)


@implements("freedrive_mode", "teach_mode", "freedrive_mode_no_incorrect_payload_check")
def _freedrive(rt, node, **_arguments):
    """The arm is free to be moved by hand: from now on where it is, is unknown offline
    until a move to a known target (:func:`_stopped_by_condition`)."""
    if rt.robot is not None:
        rt.robot.unknown_position(f"freedrive at line {node.span.line}, where the operator "
                                  "moves the arm by hand", node.span)


@implements("end_freedrive_mode", "end_teach_mode")
def _end_freedrive(rt, node):
    """The arm is held again where the operator left it (still unknown offline)."""


@implements("get_actual_joint_positions", "get_target_joint_positions", "get_joint_positions")
def _joints(rt, node):
    """The arm's joints (rad); ``get_joint_positions`` is the undocumented name UR's External
    Control script reads them by [X]."""
    arm = _arm(rt, node)
    return _stopped_by_condition(rt, arm) or _vector(arm.joints_at(rt.time))


@implements("get_actual_tcp_pose", "get_target_tcp_pose")
def _tcp_pose(rt, node):
    arm = _arm(rt, node)
    return _stopped_by_condition(rt, arm, arm.tcp) or _to_pose(arm.tcp_at(rt.time))


@implements("get_actual_joint_speeds", "get_target_joint_speeds")
def _joint_speeds(rt, node):
    arm = _arm(rt, node)
    step = rt.config.step_time
    before = arm.joints_at(max(rt.time - step, 0.0))
    return _vector((arm.joints_at(rt.time) - before) / step if rt.time > 0 else np.zeros(6))


@implements("get_actual_tcp_speed", "get_target_tcp_speed")
def _tcp_speed(rt, node):
    arm = _arm(rt, node)
    step = rt.config.step_time
    if rt.time <= 0:
        return _vector(np.zeros(6))
    before, after = arm.tcp_at(rt.time - step), arm.tcp_at(rt.time)
    linear = (after[:3, 3] - before[:3, 3]) / step
    angular = posemath.from_matrix(np.vstack([np.hstack([after[:3, :3] @ before[:3, :3].T,
                                                         np.zeros((3, 1))]),
                                              [0, 0, 0, 1]]))[3:] / step
    return _vector(np.concatenate([linear, angular]))


@implements("get_forward_kin")
def _forward_kin(rt, node, q="current_joint_positions", tcp="active_tcp"):
    arm = _arm(rt, node)
    offset = arm.tcp if isinstance(tcp, str) else _pose(rt, node, tcp, "tcp")
    if isinstance(q, str) and (unknown := _stopped_by_condition(rt, arm, offset)) is not None:
        return unknown
    joints = arm.joints_at(rt.time) if isinstance(q, str) else _numbers(rt, node, q, 6, "q")
    return _to_pose(arm.kinematics.fk(joints, tcp=offset))


TAUGHT_POSITION = NOMINAL_ACCURACY
"""How far (m) the model puts a given ``qnear`` from the pose asked, within which
``get_inverse_kin`` takes ``qnear`` as the arm's own solution (see :func:`_inverse`): the
nominal model's accuracy."""
TAUGHT_ORIENTATION = 0.01
"""The same bound on the orientation (rad)."""
TAUGHT_JUMP = 0.05
"""How far (rad) the model's solution must lie from ``qnear`` for that to matter."""


def _inverse(rt, node, x, qnear, maxPositionError, maxOrientationError, tcp):  # noqa: N803
    """The controller's solution for pose ``x`` nearest ``qnear`` (rad). PolyScope writes a
    waypoint as ``get_inverse_kin(Waypoint_p, qnear=Waypoint_q)``: the pose and the joints
    the arm had there, so on the arm itself the answer is ``qnear``. On a model a few
    millimetres off that arm, near a singularity (wrist 2 at 0°) the model's nearest solution
    can split wrist 1 and 3 a radian apart from the taught ones; when the model puts
    ``qnear`` within :data:`TAUGHT_POSITION`/:data:`TAUGHT_ORIENTATION` of the pose and its
    own solution more than :data:`TAUGHT_JUMP` from it, ``qnear`` is the answer. So it is
    when the model has no solution at all while it puts ``qnear`` that close: a waypoint
    taught with the arm stretched out (PolyScope's upright home) lies a fraction of a
    millimetre beyond the nominal model's reach."""
    arm = _arm(rt, node)
    target = posemath.to_matrix(_pose(rt, node, x, "x"))
    near = arm.joints_at(rt.time) if qnear is None else _numbers(rt, node, qnear, 6, "qnear")
    offset = arm.tcp if isinstance(tcp, str) else _pose(rt, node, tcp, "tcp")
    _number(rt, node, maxPositionError, "maxPositionError")
    _number(rt, node, maxOrientationError, "maxOrientationError")
    try:
        solution = arm.kinematics.ik(target, near, tcp=offset)
    except KinematicsError:
        if qnear is not None and _taught_there(arm.kinematics, near, target, offset):
            return np.asarray(near, dtype=float)
        raise
    if qnear is not None and np.max(np.abs(solution - near)) > TAUGHT_JUMP and \
            _taught_there(arm.kinematics, near, target, offset):
        return np.asarray(near, dtype=float)
    return solution


def _taught_there(model, near: np.ndarray, target: np.ndarray, offset) -> bool:
    """Whether joints ``near`` (rad, inside the model's limits) put the TCP ``offset`` within
    :data:`TAUGHT_POSITION` and :data:`TAUGHT_ORIENTATION` of ``target`` (a 4x4 pose) on
    ``model``: the arm's own joints for a pose its calibration computed."""
    there = model.fk(near, tcp=offset)
    turn = there[:3, :3].T @ target[:3, :3]
    angle = float(np.arccos(np.clip((np.trace(turn) - 1) / 2, -1.0, 1.0)))
    return bool(np.linalg.norm(there[:3, 3] - target[:3, 3]) <= TAUGHT_POSITION
                and angle <= TAUGHT_ORIENTATION and np.all(near >= model.q_min)
                and np.all(near <= model.q_max))


@implements("get_inverse_kin")
def _inverse_kin(rt, node, x, qnear=None, maxPositionError=1e-10,  # noqa: N803
                 maxOrientationError=1e-10, tcp="active_tcp"):
    try:
        return _vector(_inverse(rt, node, x, qnear, maxPositionError, maxOrientationError, tcp))
    except KinematicsError as error:
        failed = rt.error("ik", f"get_inverse_kin found no solution: {error}", node,
                          "test with get_inverse_kin_has_solution() first")
        failed.beyond = beyond_reach(error)
        raise failed from None


@implements("get_inverse_kin_has_solution")
def _has_solution(rt, node, pose, qnear=None, maxPositionError=1e-10,  # noqa: N803
                  maxOrientationError=1e-10, tcp="active_tcp"):
    try:
        _inverse(rt, node, pose, qnear, maxPositionError, maxOrientationError, tcp)
    except KinematicsError:
        return False
    return True


@implements("set_tcp")
def _set_tcp(rt, node, pose):
    arm = _arm(rt, node)
    arm.tcp = _pose(rt, node, pose, "the TCP")


@implements("get_tcp_offset")
def _get_tcp_offset(rt, node):
    arm = _arm(rt, node)
    return PoseValue(np.zeros(6) if arm.tcp is None else arm.tcp)


@implements("set_payload")
def _set_payload(rt, node, m, cog=None):
    arm = _arm(rt, node)
    arm.payload_mass = _number(rt, node, m, "the payload mass (kg)")
    if cog is not None:
        arm.payload_cog = _numbers(rt, node, cog, 3, "the centre of gravity (m)")


@implements("set_payload_mass")
def _set_payload_mass(rt, node, m):
    _arm(rt, node).payload_mass = _number(rt, node, m, "the payload mass (kg)")


@implements("set_payload_cog")
def _set_payload_cog(rt, node, cog):
    _arm(rt, node).payload_cog = _numbers(rt, node, cog, 3, "the centre of gravity (m)")


@implements("is_within_safety_limits")
def _within_limits(rt, node, pose):
    arm = _arm(rt, node)
    try:
        q = arm.ik(posemath.to_matrix(_pose(rt, node, pose, "pose")), arm.joints_at(rt.time))
    except KinematicsError:
        return False
    model = arm.kinematics
    return bool(np.all(q >= model.q_min) and np.all(q <= model.q_max))


# ---- pose maths ------------------------------------------------------------------------------


@implements("pose_trans")
def _pose_trans(rt, node, p_from, p_from_to):
    return PoseValue(posemath.pose_trans(_pose(rt, node, p_from, "p_from"),
                                         _pose(rt, node, p_from_to, "p_from_to")))


@implements("pose_add")
def _pose_add(rt, node, p_1, p_2):
    return PoseValue(posemath.pose_add(_pose(rt, node, p_1, "p_1"), _pose(rt, node, p_2, "p_2")))


@implements("pose_sub")
def _pose_sub(rt, node, p_to, p_from):
    return PoseValue(posemath.pose_sub(_pose(rt, node, p_to, "p_to"),
                                       _pose(rt, node, p_from, "p_from")))


@implements("pose_inv")
def _pose_inv(rt, node, p_from):
    return PoseValue(posemath.pose_inv(_pose(rt, node, p_from, "p_from")))


@implements("pose_dist")
def _pose_dist(rt, node, p_from, p_to):
    return float(posemath.pose_dist(_pose(rt, node, p_from, "p_from"),
                                    _pose(rt, node, p_to, "p_to")))


@implements("point_dist")
def _point_dist(rt, node, p_from, p_to):
    a, b = _pose(rt, node, p_from, "p_from"), _pose(rt, node, p_to, "p_to")
    return float(np.linalg.norm(a[:3] - b[:3]))


@implements("interpolate_pose")
def _interpolate_pose(rt, node, p_from, p_to, alpha):
    return PoseValue(posemath.interpolate_pose(_pose(rt, node, p_from, "p_from"),
                                               _pose(rt, node, p_to, "p_to"),
                                               _number(rt, node, alpha, "alpha", None)))


@implements("rotvec2rpy")
def _rotvec2rpy(rt, node, rotation_vector):
    vector = _numbers(rt, node, rotation_vector, 3, "the rotation vector")
    return _vector(posemath.rotvec2rpy(vector))


@implements("rpy2rotvec")
def _rpy2rotvec(rt, node, rpy_vector):
    return _vector(posemath.rpy2rotvec(_numbers(rt, node, rpy_vector, 3, "the RPY vector")))


@implements("wrench_trans")
def _wrench_trans(rt, node, T_from_to, w_from):  # noqa: N803 - the catalog's parameter name
    """Move a wrench [Fx, Fy, Fz, Mx, My, Mz] (N, N·m) into the frame ``T_from_to`` (the
    new frame's pose in the old one): ``f' = Rᵀf``, ``m' = Rᵀ(m − p × f)`` [U: the manual
    gives no formula; this is the rigid-body transformation of a wrench]."""
    matrix = posemath.to_matrix(_pose(rt, node, T_from_to, "T_from_to"))
    wrench = _numbers(rt, node, w_from, 6, "w_from")
    rotation, offset = matrix[:3, :3], matrix[:3, 3]
    force = rotation.T @ wrench[:3]
    moment = rotation.T @ (wrench[3:] - np.cross(offset, wrench[:3]))
    return _vector(np.concatenate([force, moment]))


@implements("get_actual_tool_flange_pose")
def _flange_pose(rt, node):
    arm = _arm(rt, node)
    return (_stopped_by_condition(rt, arm, None)
            or _to_pose(arm.kinematics.fk(arm.joints_at(rt.time))))


@implements("get_target_waypoint")
def _target_waypoint(rt, node):
    """Where the current (or last) move goes: the end of everything planned so far; while
    the arm's position is unknown offline (see :func:`_stopped_by_condition`), as unknown as
    the TCP pose there (PolyScope's Direction node aims from it)."""
    arm = _arm(rt, node)
    return _stopped_by_condition(rt, arm, arm.tcp) or _to_pose(arm.fk(arm.target_joints))


@implements("is_steady")
def _is_steady(rt, node):
    return bool(rt.time >= _arm(rt, node).free_at)


@implements("get_jacobian")
def _get_jacobian(rt, node, q="current_joint_positions", tcp="active_tcp"):
    """The 6x6 geometric Jacobian at the TCP, rows (v m/s, ω rad/s) in Base axes, columns
    per joint speed (rad/s) [U: row order and reference point as in UR's 5.22 examples]."""
    arm = _arm(rt, node)
    joints = arm.joints_at(rt.time) if isinstance(q, str) else _numbers(rt, node, q, 6, "q")
    offset = arm.tcp if isinstance(tcp, str) else _pose(rt, node, tcp, "tcp")
    return _matrix_value(_tcp_jacobian(arm, joints, offset))


def _tcp_jacobian(arm, joints: np.ndarray, offset) -> np.ndarray:
    jacobian = np.array(arm.kinematics.jacobian(joints), dtype=float)
    if offset is not None:  # move the reference point from the flange to the TCP
        flange = arm.kinematics.fk(joints)
        lever = flange[:3, :3] @ np.asarray(offset, dtype=float)[:3]
        jacobian[:3] -= np.cross(lever, jacobian[3:].T).T
    return jacobian


def _matrix_value(matrix: np.ndarray) -> ListValue:
    return ListValue([ListValue([float(v) for v in row]) for row in matrix])


@implements("get_jacobian_time_derivative")
def _get_jacobian_dot(rt, node, q="current_joint_positions", qd="current_joint_speeds",
                      tcp="active_tcp"):
    """dJ/dt at joints ``q`` moving with ``qd`` (rad/s), by a central difference along qd."""
    arm = _arm(rt, node)
    joints = arm.joints_at(rt.time) if isinstance(q, str) else _numbers(rt, node, q, 6, "q")
    if isinstance(qd, str):
        speeds = np.array(_joint_speeds(rt, node), dtype=float)
    else:
        speeds = _numbers(rt, node, qd, 6, "qd")
    offset = arm.tcp if isinstance(tcp, str) else _pose(rt, node, tcp, "tcp")
    step = 1e-6
    ahead = _tcp_jacobian(arm, joints + step * speeds, offset)
    behind = _tcp_jacobian(arm, joints - step * speeds, offset)
    return _matrix_value((ahead - behind) / (2 * step))


@implements("direct_torque")
def _direct_torque(rt, node, torques, friction_comp=True):
    """Torque control is not simulated (urdsl has no dynamics): the arm holds still, and the
    call lasts one controller step, as on the robot, so that control loops advance time."""
    _numbers(rt, node, torques, 6, "torques")
    rt.event_once("unsupported", "direct_torque() is not simulated: the arm holds still",
                  node.span)
    rt.wait(rt.config.step_time)
