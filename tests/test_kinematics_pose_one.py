"""One pose at a time (the interpreter's ``pose_trans``, ``pose_inv``, forward kinematics of
one move) is computed in scalar maths: it must give what the batched NumPy formulas give,
also at and near the angles 0 and π."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.kinematics import pose

ANGLE = st.one_of(st.floats(0.0, np.pi), st.sampled_from([0.0, 1e-13, 1e-7, np.pi - 1e-9,
                                                           np.pi]))
AXIS = st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda v: np.linalg.norm(v) > 1e-3)
POSITION = st.tuples(*[st.floats(-2.0, 2.0)] * 3)


def rotvec(axis, angle) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    return axis / np.linalg.norm(axis) * angle


@settings(max_examples=300)
@given(AXIS, ANGLE)
def test_one_rotation_matrix_to_rotvec_is_the_batched_result(axis, angle):
    matrix = pose.rotvec_to_matrix(rotvec(axis, angle)[None])  # batched: (1, 3, 3)
    one = pose.matrix_to_rotvec(matrix[0])
    batched = pose.matrix_to_rotvec(matrix)[0]
    if angle > np.pi - 1e-6:  # at π, r and −r are the same rotation
        assert np.allclose(pose.rotvec_to_matrix(one[None])[0], matrix[0], atol=1e-9)
    else:
        assert np.allclose(one, batched, atol=1e-12, rtol=0)


@settings(max_examples=300)
@given(POSITION, AXIS, ANGLE)
def test_one_pose_to_matrix_and_back_is_the_batched_result(position, axis, angle):
    p = np.concatenate([position, rotvec(axis, angle)])
    assert np.allclose(pose.to_matrix(p), pose.to_matrix(p[None])[0], atol=1e-15, rtol=0)
    assert np.allclose(pose.rotvec_to_matrix(p[3:]), pose.rotvec_to_matrix(p[None, 3:])[0],
                       atol=1e-15, rtol=0)
    matrix = pose.to_matrix(p[None])
    assert np.allclose(pose.from_matrix(matrix[0])[:3], pose.from_matrix(matrix)[0, :3],
                       atol=0, rtol=0)
    inverse = pose.pose_inv(p)
    assert np.allclose(pose.to_matrix(pose.pose_trans(p, inverse)), np.eye(4), atol=1e-12)
