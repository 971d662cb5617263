"""The URScript kinematics builtins with the controller's semantics.

* ``get_forward_kin(q, tcp)``: the TCP pose for joints ``q`` with the *calibrated* kinematics
  and the given TCP (the interpreter passes the active TCP and the current joints for the
  omitted arguments).
* ``get_inverse_kin(x, qnear, maxPositionError=1e-10, maxOrientationError=1e-10, tcp)``: the
  joint vector closest to ``qnear`` (see :meth:`urdsl.kinematics.Robot.ik`) whose TCP pose
  differs from ``x`` by at most ``maxPositionError`` [m] and ``maxOrientationError`` [rad];
  raises :class:`KinematicsError` otherwise (the controller stops the program).
* ``get_inverse_kin_has_solution(...)``: the same test, as a bool.

urdsl solves analytically, so a solution is exact to rounding (about 1e-15 m); the two
tolerances are checked on the result. A pose out of reach by less than ``maxPositionError`` is
not approximated by a boundary configuration [U: what the controller's numeric solver does
there is not documented].
"""

from __future__ import annotations

import numpy as np

from . import pose as _pose
from .errors import KinematicsError
from .robot import Robot

__all__ = ["get_forward_kin", "get_inverse_kin", "get_inverse_kin_has_solution"]


def get_forward_kin(robot: Robot, q, tcp=None) -> np.ndarray:
    """``get_forward_kin(q, tcp)``: the TCP pose ``p[x, y, z, rx, ry, rz]`` (6,) in Base for
    joints ``q`` [rad]; ``tcp`` is the TCP offset pose in the flange frame (None: flange)."""
    return robot.fk_pose(q, tcp)


def get_inverse_kin(robot: Robot, x, qnear, maxPositionError: float = 1e-10,  # noqa: N803
                    maxOrientationError: float = 1e-10, tcp=None) -> np.ndarray:  # noqa: N803
    """``get_inverse_kin(x, qnear, maxPositionError, maxOrientationError, tcp)``: joints (6,)
    [rad] reaching pose ``x`` (6,) with ``tcp``, the solution closest to ``qnear``.

    Raises :class:`KinematicsError` (with ``distance`` in m) when there is no solution.
    """
    if qnear is None:
        raise KinematicsError("get_inverse_kin needs qnear (the current joint positions when "
                              "the script omits it)")
    if maxPositionError < 0 or maxOrientationError < 0:
        raise KinematicsError("maxPositionError and maxOrientationError must be ≥ 0")
    target = _pose.to_matrix(np.asarray(x, dtype=float)) if np.shape(x) == (6,) else \
        np.asarray(x, dtype=float)
    q = robot.ik(target, qnear, tcp)
    reached = robot.fk(q, tcp)
    position_error = float(np.linalg.norm(reached[:3, 3] - target[:3, 3]))
    orientation_error = float(_pose.rotation_angle(reached[:3, :3], target[:3, :3]))
    if position_error > maxPositionError or orientation_error > maxOrientationError:
        raise KinematicsError(
            f"inverse kinematics reached the pose only to {position_error:.3g} m and "
            f"{orientation_error:.3g} rad (allowed {maxPositionError:g} m, "
            f"{maxOrientationError:g} rad)", distance=position_error)
    return q


def get_inverse_kin_has_solution(robot: Robot, x, qnear, maxPositionError: float = 1e-10,  # noqa: N803
                                 maxOrientationError: float = 1e-10,  # noqa: N803
                                 tcp=None) -> bool:
    """``get_inverse_kin_has_solution(...)``: True when :func:`get_inverse_kin` would succeed."""
    try:
        get_inverse_kin(robot, x, qnear, maxPositionError, maxOrientationError, tcp)
    except KinematicsError:
        return False
    return True
