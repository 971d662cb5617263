"""get_forward_kin / get_inverse_kin / get_inverse_kin_has_solution with controller semantics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from urdsl.kinematics import (
    Calibration,
    KinematicsError,
    Robot,
    get_forward_kin,
    get_inverse_kin,
    get_inverse_kin_has_solution,
    pose,
)

Q = np.array([0.2, -1.3, 1.5, -1.8, -1.6, 0.3])
TCP = [0.0, 0.0, 0.12, 0.0, 0.0, 0.0]


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.model("ur5e")


def test_forward_kin_is_a_pose_with_the_tcp(robot):
    flange = get_forward_kin(robot, Q)
    tool = get_forward_kin(robot, Q, TCP)
    assert flange.shape == (6,)
    assert np.allclose(tool, pose.pose_trans(flange, TCP))
    assert np.allclose(pose.to_matrix(flange), robot.fk(Q), atol=1e-12)


def test_inverse_kin_round_trip_closest_to_qnear(robot):
    x = get_forward_kin(robot, Q, TCP)
    assert np.allclose(get_inverse_kin(robot, x, Q, tcp=TCP), Q, atol=1e-9)
    # a qnear next to another solution of the same pose picks that one
    others = [s for s in robot.ik_all(pose.pose_trans(x, pose.pose_inv(TCP)))
              if not np.allclose(s, Q, atol=1e-6)]
    assert len(others) >= 3
    for other in others:
        q = get_inverse_kin(robot, x, other + 0.05, tcp=TCP)
        assert np.allclose(q, other, atol=1e-9)
        assert np.allclose(pose.to_matrix(get_forward_kin(robot, q, TCP)), pose.to_matrix(x),
                           atol=1e-9)


def test_has_solution(robot):
    x = get_forward_kin(robot, Q)
    assert get_inverse_kin_has_solution(robot, x, Q)
    far = [1.5, 0.0, 0.2, 0.0, math.pi, 0.0]
    assert not get_inverse_kin_has_solution(robot, far, Q)
    with pytest.raises(KinematicsError, match="out of reach") as info:
        get_inverse_kin(robot, far, Q)
    assert info.value.distance > 0.4


def test_tolerances_are_checked():
    # a calibrated arm's solutions come from Newton steps: exact to ~1e-15, not to 0
    robot = Robot.model("ur5e", Calibration(delta_d=[1e-4, 0, 0, 0, 0, 0]))
    x = get_forward_kin(robot, Q)
    assert np.allclose(get_inverse_kin(robot, x, Q), Q, atol=1e-9)
    assert get_inverse_kin_has_solution(robot, x, Q, 1e-10, 1e-10)
    with pytest.raises(KinematicsError, match="≥ 0"):
        get_inverse_kin(robot, x, Q, maxPositionError=-1.0)


def test_qnear_is_required(robot):
    with pytest.raises(KinematicsError, match="qnear"):
        get_inverse_kin(robot, get_forward_kin(robot, Q), None)
