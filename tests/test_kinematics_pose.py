"""URScript pose math: known values and laws (hypothesis), including rotations at and near
angles 0 and π where rotation vectors are hard."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.kinematics import pose

SPECIAL_ANGLES = [0.0, 1e-300, 1e-15, 1e-12, 1e-8, 1e-4, math.pi / 2, math.pi - 1e-4,
                  math.pi - 1e-8, math.pi - 1e-12, math.pi, math.pi + 1e-12, math.pi + 1e-8,
                  2 * math.pi - 1e-9, 2 * math.pi]

axes = st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(
    lambda v: np.linalg.norm(v) > 1e-3).map(lambda v: np.array(v) / np.linalg.norm(v))
angles = st.one_of(st.sampled_from(SPECIAL_ANGLES), st.floats(0, 2 * math.pi))
rotvecs = st.builds(lambda axis, angle: axis * angle, axes, angles)
positions = st.tuples(*[st.floats(-2, 2, allow_nan=False)] * 3).map(np.array)
poses = st.builds(lambda p, r: np.concatenate([p, r]), positions, rotvecs)


def same_transform(a, b, atol=1e-9) -> bool:
    return np.allclose(pose.to_matrix(a), pose.to_matrix(b), atol=atol, rtol=0)


@settings(max_examples=300, deadline=None)
@given(rotvecs)
def test_rotvec_matrix_round_trip(rv):
    rotation = pose.rotvec_to_matrix(rv)
    assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(rotation), 1.0, atol=1e-12)
    back = pose.matrix_to_rotvec(rotation)
    assert np.linalg.norm(back) <= math.pi + 1e-12
    assert np.allclose(pose.rotvec_to_matrix(back), rotation, atol=1e-12)
    angle = np.linalg.norm(rv)
    if angle < math.pi - 1e-6:  # below π the vector itself comes back
        assert np.allclose(back, rv, atol=1e-12)


@pytest.mark.parametrize("axis", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 1, -1),
                                  (-1, -2, 3), (0.3, -0.9, 0.1)])
def test_rotation_by_exactly_pi(axis):
    axis = np.array(axis, float) / np.linalg.norm(axis)
    rotation = pose.rotvec_to_matrix(math.pi * axis)
    back = pose.matrix_to_rotvec(rotation)
    assert np.isclose(np.linalg.norm(back), math.pi, atol=1e-12)
    # rv or −rv: the same rotation
    assert np.allclose(back, math.pi * axis, atol=1e-9) or np.allclose(back, -math.pi * axis,
                                                                      atol=1e-9)
    assert np.allclose(pose.rotvec_to_matrix(back), rotation, atol=1e-12)


def test_rotation_near_zero_is_exact():
    for angle in (1e-300, 1e-20, 1e-10, 1e-7):
        rv = np.array([angle, -2 * angle, 0.5 * angle])
        rotation = pose.rotvec_to_matrix(rv)
        assert np.allclose(pose.matrix_to_rotvec(rotation), rv, rtol=1e-9, atol=0)


@settings(max_examples=200, deadline=None)
@given(poses, poses)
def test_a_relative_waypoint_started_at_from_ends_at_to(a, b):
    """PolyScope's relative waypoint: pose_add(where the arm is, pose_sub(to, from))."""
    assert same_transform(pose.pose_add(b, pose.pose_sub(a, b)), a)


@settings(max_examples=200, deadline=None)
@given(poses, poses, st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))
def test_pose_add_undoes_pose_sub_for_positions_and_turns_about_one_axis(a, b, turn_a, turn_b):
    """The UR forum's pose_add(pose_sub(a, b), b) == a: the positions always, the rotations
    when they commute."""
    assert np.allclose(pose.pose_add(pose.pose_sub(a, b), b)[:3], np.asarray(a)[:3], atol=1e-9)
    axis = np.array([0.6, 0.0, 0.8])
    a2 = np.concatenate([np.asarray(a)[:3], turn_a * axis])
    b2 = np.concatenate([np.asarray(b)[:3], turn_b * axis])
    assert same_transform(pose.pose_add(pose.pose_sub(a2, b2), b2), a2)


def test_pose_sub_is_the_change_in_the_from_tool_frame():
    """A tool turned -90 deg about its own z axis: the change is that turn, whatever the
    from pose's orientation (here the tool pointing down, as PolyScope's default)."""
    down = [0.4, -0.1, 0.3, 0.0, math.pi, 0.0]
    turned = pose.pose_trans(down, [0, 0, 0, 0, 0, -math.pi / 2])
    assert np.allclose(pose.pose_sub(turned, down), [0, 0, 0, 0, 0, -math.pi / 2], atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(poses)
def test_pose_trans_with_inverse_is_identity(a):
    assert np.allclose(pose.to_matrix(pose.pose_trans(a, pose.pose_inv(a))), np.eye(4),
                       atol=1e-9)
    assert np.allclose(pose.to_matrix(pose.pose_trans(pose.pose_inv(a), a)), np.eye(4),
                       atol=1e-9)
    assert same_transform(pose.pose_inv(pose.pose_inv(a)), a)


@settings(max_examples=100, deadline=None)
@given(poses, poses, poses)
def test_pose_trans_is_associative(a, b, c):
    left = pose.pose_trans(pose.pose_trans(a, b), c)
    right = pose.pose_trans(a, pose.pose_trans(b, c))
    assert same_transform(left, right, atol=1e-8)


@settings(max_examples=200, deadline=None)
@given(rotvecs)
def test_rpy_round_trip(rv):
    rpy = pose.rotvec2rpy(rv)
    assert -math.pi / 2 - 1e-12 <= rpy[1] <= math.pi / 2 + 1e-12
    assert np.allclose(pose.rotvec_to_matrix(pose.rpy2rotvec(rpy)), pose.rotvec_to_matrix(rv),
                       atol=1e-9)


def test_rpy_known_values():
    # yaw only: a rotation about z
    assert np.allclose(pose.rotvec2rpy([0, 0, 0.5]), [0, 0, 0.5])
    assert np.allclose(pose.rpy2rotvec([0.3, 0, 0]), [0.3, 0, 0])
    # R = Rz(yaw)·Ry(pitch)·Rx(roll): extrinsic x, then y, then z
    roll, pitch, yaw = 0.1, 0.2, 0.3
    rx = pose.rotvec_to_matrix([roll, 0, 0])
    ry = pose.rotvec_to_matrix([0, pitch, 0])
    rz = pose.rotvec_to_matrix([0, 0, yaw])
    assert np.allclose(pose.rotvec_to_matrix(pose.rpy2rotvec([roll, pitch, yaw])), rz @ ry @ rx)
    # gimbal lock keeps the rotation
    locked = pose.rpy2rotvec([0.4, math.pi / 2, -0.2])
    assert np.allclose(pose.rotvec_to_matrix(pose.rpy2rotvec(pose.rotvec2rpy(locked))),
                       pose.rotvec_to_matrix(locked), atol=1e-9)


def test_pose_add_is_not_pose_trans():
    a = [0.2, 0.5, 0.1, 1.57, 0, 0]
    b = [0.2, 0.5, 0.6, 1.57, 0, 0]
    added = pose.pose_add(a, b)
    assert np.allclose(added[:3], [0.4, 1.0, 0.7])
    assert np.allclose(added[3:], [3.14, 0, 0])
    # pose_trans rotates b's translation by a's rotation (the UR forum example)
    assert np.allclose(pose.pose_trans(a, b), [0.4, -0.0996, 0.60048, 3.14, 0, 0], atol=2e-4)


def test_pose_sub_known_value():
    assert np.allclose(pose.pose_sub([1, 2, 3, 0, 0, 0.5], [0.5, 0.5, 0.5, 0, 0, 0.2]),
                       [0.5, 1.5, 2.5, 0, 0, 0.3])


@settings(max_examples=100, deadline=None)
@given(poses, poses)
def test_interpolate_pose_end_points_and_middle(a, b):
    assert same_transform(pose.interpolate_pose(a, b, 0.0), a)
    assert same_transform(pose.interpolate_pose(a, b, 1.0), b, atol=1e-8)
    middle = pose.interpolate_pose(a, b, 0.5)
    assert np.allclose(middle[:3], (a[:3] + b[:3]) / 2)
    ra, rb, rm = (pose.rotvec_to_matrix(p[3:]) for p in (a, b, middle))
    total = pose.rotation_angle(ra, rb)
    if total < math.pi - 1e-6:  # the geodesic is unique below π
        assert np.isclose(pose.rotation_angle(ra, rm), total / 2, atol=1e-9)
        assert np.isclose(pose.rotation_angle(rm, rb), total / 2, atol=1e-9)


def test_interpolate_pose_batched_and_extrapolated():
    a, b = [0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 1.0]
    out = pose.interpolate_pose(a, b, np.array([-0.5, 0.0, 0.25, 2.0]))
    assert out.shape == (4, 6)
    assert np.allclose(out[:, 0], [-0.5, 0, 0.25, 2.0])
    assert np.allclose(out[:, 5], [-0.5, 0, 0.25, 2.0])


def test_pose_dist_and_point_dist():
    a = [0.1, 0.2, 0.3, 0, 0, 0]
    assert pose.pose_dist(a, a) == 0.0
    moved = [0.4, 0.6, 0.3, 0, 0, 0]
    assert np.isclose(pose.point_dist(a, moved), 0.5)
    assert np.isclose(pose.pose_dist(a, moved), 0.5)       # no rotation: Euclidean
    turned = [0.1, 0.2, 0.3, 0, 0, 0.2]
    assert pose.point_dist(a, turned) == 0.0
    assert np.isclose(pose.pose_dist(a, turned), 0.2)       # pure rotation counts
    far = [2.1, 0.2, 0.3, 0, 0, 0.01]                      # long move, small rotation
    assert abs(pose.pose_dist(a, far) - pose.point_dist(a, far)) < 1e-4


def test_d2r_r2d():
    assert pose.d2r(180) == math.pi and pose.r2d(math.pi) == 180.0
    assert np.allclose(pose.d2r([90, -90]), [math.pi / 2, -math.pi / 2])
    assert np.allclose(pose.r2d(pose.d2r(np.array([12.5, -370.0]))), [12.5, -370.0])


@settings(max_examples=30, deadline=None)
@given(st.lists(poses, min_size=1, max_size=6), st.lists(poses, min_size=1, max_size=6))
def test_batched_functions_equal_the_loop(first, second):
    n = min(len(first), len(second))
    a, b = np.array(first[:n]), np.array(second[:n])
    for function in (pose.pose_trans, pose.pose_add, pose.pose_sub):
        batched = function(a, b)
        assert batched.shape == (n, 6)
        for i in range(n):
            # as transforms: at a half turn r and -r are the same rotation, and the batched
            # and single paths may pick either (axis [0, 2.94, 1.10] at exactly pi)
            assert np.allclose(pose.to_matrix(batched[i]),
                               pose.to_matrix(function(a[i], b[i])), atol=1e-12)
    assert np.allclose(pose.from_matrix(pose.to_matrix(a))[:, :3], a[:, :3])
    looped = [pose.pose_dist(x, y) for x, y in zip(a, b, strict=True)]
    assert np.allclose(pose.pose_dist(a, b), looped)


def test_wrong_shapes_are_rejected():
    with pytest.raises(ValueError, match="6 numbers"):
        pose.to_matrix([1, 2, 3])
    with pytest.raises(ValueError, match="4x4"):
        pose.from_matrix(np.eye(3))


@settings(max_examples=300, deadline=None)
@given(poses)
def test_one_pose_as_a_sequence_matches_the_batched_formula(p):
    """to_matrix of one pose given as a tuple or list (scalar maths, the interpreter's path)
    equals the vectorised formula on an array, also at and near the angles 0 and π."""
    batched = pose.to_matrix(np.asarray(p)[None])[0]
    for one in (tuple(p), list(p)):
        assert np.allclose(pose.to_matrix(one), batched, atol=1e-14, rtol=0)


def test_six_poses_in_a_list_are_a_batch_and_bad_input_says_so():
    six = [[0.1 * i, 0.0, 0.2, 0.0, 3.1, 0.0] for i in range(6)]
    assert np.allclose(pose.to_matrix(six), pose.to_matrix(np.array(six)))
    with pytest.raises(ValueError, match="6 numbers"):
        pose.to_matrix(5.0)
