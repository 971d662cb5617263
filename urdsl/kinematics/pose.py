"""URScript pose math with the controller's names and semantics, vectorised.

A URScript pose ``p[x, y, z, rx, ry, rz]`` is a position in m and a *rotation vector* (unit
axis × angle in rad) in the controller's Base frame. As a homogeneous matrix::

    T(p) = | R(rx, ry, rz)  (x, y, z)ᵀ |      R(r) = exp([r]×)   (Rodrigues)
           | 0   0   0            1    |

Every function accepts one pose (shape (6,)) or a batch (shape (N, 6)), and broadcasts a
single pose against a batch where that makes sense. Matrices have shape (4, 4) or (N, 4, 4).

Conventions (``docs/controller-facts.md`` §4 and the URScript manual):

* ``pose_trans(a, b) = T(a)·T(b)``: ``b`` expressed in the frame of ``a``.
* ``pose_add(a, b)``: positions added, rotations multiplied ``R = R_a·R_b`` (not pose_trans).
* ``pose_sub(a, b)``: the inverse of pose_add, ``P = P_a − P_b``, ``R = R_a·R_bᵀ``, so that
  ``pose_add(pose_sub(a, b), b) == a``.
* ``rotvec2rpy`` / ``rpy2rotvec``: roll-pitch-yaw with ``R = Rz(yaw)·Ry(pitch)·Rx(roll)``.
* Rotation vectors returned here have an angle in [0, π]. At exactly π, ``r`` and ``−r`` are
  the same rotation; the one returned is the one whose quaternion has ``w ≥ 0`` and, at
  ``w = 0``, a positive largest component. Compare rotations as matrices, never as vectors.
* ``pose_dist``: UR does not publish its formula [U]; see :func:`pose_dist`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "to_matrix", "from_matrix", "rotvec_to_matrix", "matrix_to_rotvec",
    "rpy_to_matrix", "matrix_to_rpy", "matrix_to_quaternion",
    "pose_trans", "pose_add", "pose_sub", "pose_inv", "pose_dist", "point_dist",
    "interpolate_pose", "rotvec2rpy", "rpy2rotvec", "d2r", "r2d", "rotation_angle",
]


def _array(values, last: int, name: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.ndim == 0 or array.shape[-1] != last:
        raise ValueError(f"{name} must have {last} numbers in its last axis, got shape "
                         f"{array.shape}")
    return array


# ---------------------------------------------------------------------------------------------
# rotations


def rotvec_to_matrix(rotvec) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3) [rad].

    ``R = I + (sin θ/θ)·K + ((1 − cos θ)/θ²)·K²`` with ``K = [r]×`` and ``θ = |r|``; both
    coefficients are evaluated through ``sinc`` so the formula is exact at and near θ = 0.
    """
    if isinstance(rotvec, np.ndarray) and rotvec.shape == (3,) and rotvec.dtype == float:
        return _one_matrix(0.0, 0.0, 0.0, *rotvec.tolist())[:3, :3].copy()  # one: scalar maths
    r = _array(rotvec, 3, "a rotation vector")
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    theta = np.sqrt(x * x + y * y + z * z)
    a = np.sinc(theta / np.pi)                     # sin θ / θ
    b = 0.5 * np.sinc(theta / (2.0 * np.pi)) ** 2  # (1 − cos θ) / θ²
    out = np.empty(r.shape[:-1] + (3, 3))
    xx, yy, zz, xy, xz, yz = x * x, y * y, z * z, x * y, x * z, y * z
    out[..., 0, 0] = 1.0 - b * (yy + zz)
    out[..., 0, 1] = b * xy - a * z
    out[..., 0, 2] = b * xz + a * y
    out[..., 1, 0] = b * xy + a * z
    out[..., 1, 1] = 1.0 - b * (xx + zz)
    out[..., 1, 2] = b * yz - a * x
    out[..., 2, 0] = b * xz - a * y
    out[..., 2, 1] = b * yz + a * x
    out[..., 2, 2] = 1.0 - b * (xx + yy)
    return out


def matrix_to_quaternion(rotation) -> np.ndarray:
    """Unit quaternions (..., 4) as (w, x, y, z) with w ≥ 0 of rotation matrices (..., 3, 3).

    Shepperd's method: the largest of 4w², 4x², 4y², 4z² is taken from the diagonal, the
    others from off-diagonal sums, so no component is computed from a small difference.
    """
    m = np.asarray(rotation, dtype=float)
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"a rotation matrix must be 3x3, got shape {m.shape}")
    m00, m01, m02 = m[..., 0, 0], m[..., 0, 1], m[..., 0, 2]
    m10, m11, m12 = m[..., 1, 0], m[..., 1, 1], m[..., 1, 2]
    m20, m21, m22 = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    squares = np.stack([1.0 + m00 + m11 + m22, 1.0 + m00 - m11 - m22,
                        1.0 - m00 + m11 - m22, 1.0 - m00 - m11 + m22], axis=-1)
    pick = np.argmax(squares, axis=-1)
    big = 0.5 * np.sqrt(np.maximum(np.take_along_axis(squares, pick[..., None], -1)[..., 0],
                                   1e-300))
    inv = 0.25 / big
    wx, wy, wz = (m21 - m12) * inv, (m02 - m20) * inv, (m10 - m01) * inv
    xy, xz, yz = (m01 + m10) * inv, (m02 + m20) * inv, (m12 + m21) * inv
    q = np.stack([
        np.select([pick == 0, pick == 1, pick == 2], [big, wx, wy], wz),
        np.select([pick == 0, pick == 1, pick == 2], [wx, big, xy], xz),
        np.select([pick == 0, pick == 1, pick == 2], [wy, xy, big], yz),
        np.select([pick == 0, pick == 1, pick == 2], [wz, xz, yz], big),
    ], axis=-1)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0.0, -q, q)


def matrix_to_rotvec(rotation) -> np.ndarray:
    """Rotation vectors (..., 3) [rad] of rotation matrices (..., 3, 3), angle in [0, π].

    Computed through the quaternion ``(w, v)``: ``θ = 2·atan2(|v|, w)``, which is accurate at
    θ = 0 and at θ = π (where the axis comes from the diagonal, see :func:`matrix_to_quaternion`).
    """
    if isinstance(rotation, np.ndarray) and rotation.shape == (3, 3):
        return np.array(_one_rotvec(rotation.tolist()))  # one matrix: scalar maths is faster
    q = matrix_to_quaternion(rotation)
    w, v = q[..., 0], q[..., 1:]
    norm = np.linalg.norm(v, axis=-1)
    angle = 2.0 * np.arctan2(norm, w)
    small = norm < 1e-12
    scale = np.where(small, 2.0 / np.where(small, w, 1.0), angle / np.where(small, 1.0, norm))
    return v * scale[..., None]


def _one_rotvec(m: list) -> tuple[float, float, float]:
    """:func:`matrix_to_rotvec` of one rotation matrix given as nested lists (3x3), with the
    same formulas (Shepperd's quaternion, then ``θ = 2·atan2(|v|, w)``)."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = (row[:3] for row in m[:3])
    squares = (1.0 + m00 + m11 + m22, 1.0 + m00 - m11 - m22, 1.0 - m00 + m11 - m22,
               1.0 - m00 - m11 + m22)
    pick = max(range(4), key=squares.__getitem__)
    big = 0.5 * math.sqrt(max(squares[pick], 1e-300))
    inv = 0.25 / big
    wx, wy, wz = (m21 - m12) * inv, (m02 - m20) * inv, (m10 - m01) * inv
    xy, xz, yz = (m01 + m10) * inv, (m02 + m20) * inv, (m12 + m21) * inv
    w, x, y, z = ((big, wx, wy, wz), (wx, big, xy, xz), (wy, xy, big, yz),
                  (wz, xz, yz, big))[pick]
    length = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:
        length = -length
    w, x, y, z = w / length, x / length, y / length, z / length
    norm = math.sqrt(x * x + y * y + z * z)
    scale = 2.0 / w if norm < 1e-12 else 2.0 * math.atan2(norm, w) / norm
    return x * scale, y * scale, z * scale


def rotation_angle(r0, r1) -> np.ndarray | float:
    """The angle [rad] in [0, π] of the rotation taking ``r0`` to ``r1`` (3x3 or (N,3,3))."""
    relative = np.swapaxes(np.asarray(r0, float), -1, -2) @ np.asarray(r1, float)
    angle = np.linalg.norm(matrix_to_rotvec(relative), axis=-1)
    return float(angle) if np.ndim(angle) == 0 else angle


def rpy_to_matrix(rpy) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of (roll, pitch, yaw) [rad]: ``Rz(yaw)·Ry(pitch)·Rx(roll)``."""
    rpy = _array(rpy, 3, "an RPY vector")
    cr, sr = np.cos(rpy[..., 0]), np.sin(rpy[..., 0])
    cp, sp = np.cos(rpy[..., 1]), np.sin(rpy[..., 1])
    cy, sy = np.cos(rpy[..., 2]), np.sin(rpy[..., 2])
    out = np.empty(rpy.shape[:-1] + (3, 3))
    out[..., 0, 0] = cy * cp
    out[..., 0, 1] = cy * sp * sr - sy * cr
    out[..., 0, 2] = cy * sp * cr + sy * sr
    out[..., 1, 0] = sy * cp
    out[..., 1, 1] = sy * sp * sr + cy * cr
    out[..., 1, 2] = sy * sp * cr - cy * sr
    out[..., 2, 0] = -sp
    out[..., 2, 1] = cp * sr
    out[..., 2, 2] = cp * cr
    return out


def matrix_to_rpy(rotation) -> np.ndarray:
    """(roll, pitch, yaw) [rad] of rotation matrices, pitch in [−π/2, π/2].

    ``yaw = atan2(R10, R00)``; roll and pitch are then read from ``M = Rz(−yaw)·R =
    Ry(pitch)·Rx(roll)``, which keeps the three angles consistent near gimbal lock
    (pitch = ±π/2, where only roll ∓ yaw is defined; exactly there yaw is returned as 0).
    """
    m = np.asarray(rotation, dtype=float)
    yaw = np.arctan2(m[..., 1, 0], m[..., 0, 0])
    cy, sy = np.cos(yaw), np.sin(yaw)
    m00 = cy * m[..., 0, 0] + sy * m[..., 1, 0]
    m11 = cy * m[..., 1, 1] - sy * m[..., 0, 1]
    m12 = cy * m[..., 1, 2] - sy * m[..., 0, 2]
    pitch = np.arctan2(-m[..., 2, 0], m00)
    roll = np.arctan2(-m12, m11)
    return np.stack([roll, pitch, yaw], axis=-1)


# ---------------------------------------------------------------------------------------------
# poses <-> matrices


def to_matrix(pose) -> np.ndarray:
    """Homogeneous matrices (..., 4, 4) of URScript poses (..., 6)."""
    if isinstance(pose, (tuple, list)) and len(pose) == 6 \
            and all(isinstance(v, (int, float)) for v in pose):
        return _one_matrix(*map(float, pose))  # one pose of numbers: scalar maths is faster
    if isinstance(pose, np.ndarray) and pose.shape == (6,) and pose.dtype == float:
        return _one_matrix(*pose.tolist())
    p = _array(pose, 6, "a pose")
    out = np.zeros(p.shape[:-1] + (4, 4))
    out[..., :3, :3] = rotvec_to_matrix(p[..., 3:])
    out[..., :3, 3] = p[..., :3]
    out[..., 3, 3] = 1.0
    return out


def _one_matrix(x: float, y: float, z: float, rx: float, ry: float, rz: float) -> np.ndarray:
    """:func:`to_matrix` of one pose, with the same formula as :func:`rotvec_to_matrix`
    (``b = 2·sin²(θ/2)/θ²``, exact at θ = 0)."""
    theta = math.sqrt(rx * rx + ry * ry + rz * rz)
    if theta > 0.0:
        half = math.sin(0.5 * theta) / (0.5 * theta)
        a, b = math.sin(theta) / theta, 0.5 * half * half
    else:
        a, b = 1.0, 0.5
    xx, yy, zz, xy, xz, yz = rx * rx, ry * ry, rz * rz, rx * ry, rx * rz, ry * rz
    return np.array([1.0 - b * (yy + zz), b * xy - a * rz, b * xz + a * ry, x,
                     b * xy + a * rz, 1.0 - b * (xx + zz), b * yz - a * rx, y,
                     b * xz - a * ry, b * yz + a * rx, 1.0 - b * (xx + yy), z,
                     0.0, 0.0, 0.0, 1.0]).reshape(4, 4)


def from_matrix(matrix) -> np.ndarray:
    """URScript poses (..., 6) of homogeneous matrices (..., 4, 4)."""
    m = np.asarray(matrix, dtype=float)
    if m.shape[-2:] != (4, 4):
        raise ValueError(f"a transform must be 4x4, got shape {m.shape}")
    if m.shape == (4, 4):  # one matrix: scalar maths is faster
        rows = m.tolist()
        return np.array([rows[0][3], rows[1][3], rows[2][3], *_one_rotvec(rows)])
    return np.concatenate([m[..., :3, 3], matrix_to_rotvec(m[..., :3, :3])], axis=-1)


def _inverse_matrix(m: np.ndarray) -> np.ndarray:
    out = np.zeros_like(m)
    rt = np.swapaxes(m[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rt, m[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


# ---------------------------------------------------------------------------------------------
# URScript functions


def pose_trans(p_from, p_from_to) -> np.ndarray:
    """``pose_trans(p_from, p_from_to)``: the pose ``T(p_from)·T(p_from_to)``.

    ``p_from_to`` is expressed in the frame of ``p_from`` (e.g. a tool offset).
    """
    return from_matrix(to_matrix(p_from) @ to_matrix(p_from_to))


def pose_inv(p_from) -> np.ndarray:
    """``pose_inv(p)``: the inverse transform, ``pose_trans(p, pose_inv(p))`` is the identity."""
    return from_matrix(_inverse_matrix(to_matrix(p_from)))


def pose_add(p_1, p_2) -> np.ndarray:
    """``pose_add(p_1, p_2)``: ``P = P_1 + P_2`` and ``R = R_1·R_2`` (m, rotation vector)."""
    a, b = _array(p_1, 6, "p_1"), _array(p_2, 6, "p_2")
    rotation = rotvec_to_matrix(a[..., 3:]) @ rotvec_to_matrix(b[..., 3:])
    return np.concatenate([a[..., :3] + b[..., :3], matrix_to_rotvec(rotation)], axis=-1)


def pose_sub(p_to, p_from) -> np.ndarray:
    """``pose_sub(p_to, p_from)``: ``P = P_to − P_from``, ``R = R_fromᵀ·R_to`` (m, rotation
    vector).

    The rotation is the change from ``p_from`` to ``p_to`` in ``p_from``'s tool frame, so that
    PolyScope's relative waypoint, ``pose_add(get_target_tcp_pose(), pose_sub(to, from))``,
    started at ``from`` ends at ``to``: ``pose_add(b, pose_sub(a, b)) == a``. The manual gives
    no formula for ``pose_sub`` [U]; this order is the one that reproduces the joints PolyScope
    stored for the waypoints taught after such moves in a real program (o2ac
    ``bearing_orient_totb.script``: 9 of 9 within 0.01 rad, against 3 of 9, the other six a full
    wrist-3 turn off, with ``R_to·R_fromᵀ``). A UR forum answer's
    ``pose_add(pose_sub(a, b), b) == a`` holds for the positions, and for the rotations when
    they commute (turns about one axis).
    """
    a, b = _array(p_to, 6, "p_to"), _array(p_from, 6, "p_from")
    rotation = np.swapaxes(rotvec_to_matrix(b[..., 3:]), -1, -2) @ rotvec_to_matrix(a[..., 3:])
    return np.concatenate([a[..., :3] - b[..., :3], matrix_to_rotvec(rotation)], axis=-1)


def point_dist(p_from, p_to) -> np.ndarray | float:
    """``point_dist``: Euclidean distance [m] of the positions, orientation ignored."""
    a, b = _array(p_from, 6, "p_from"), _array(p_to, 6, "p_to")
    distance = np.linalg.norm(b[..., :3] - a[..., :3], axis=-1)
    return float(distance) if np.ndim(distance) == 0 else distance


def pose_dist(p_from, p_to) -> np.ndarray | float:
    """``pose_dist``: a combined distance, ``sqrt(|ΔP|² + θ²)`` with ``θ`` the rotation angle
    [rad] between the orientations, counting 1 rad like 1 m.

    UR does not publish the formula [U]; UR staff describe it as non-zero for a pure rotation,
    equal to the Euclidean distance for long moves with little rotation and dominated by the
    rotation for short moves with large rotations — which this formula satisfies.
    """
    a, b = _array(p_from, 6, "p_from"), _array(p_to, 6, "p_to")
    position = np.linalg.norm(b[..., :3] - a[..., :3], axis=-1)
    angle = rotation_angle(rotvec_to_matrix(a[..., 3:]), rotvec_to_matrix(b[..., 3:]))
    distance = np.sqrt(position ** 2 + np.asarray(angle) ** 2)
    return float(distance) if np.ndim(distance) == 0 else distance


def interpolate_pose(p_from, p_to, alpha) -> np.ndarray:
    """``interpolate_pose(p_from, p_to, alpha)``: position on the straight line, orientation
    on the shortest rotation (slerp); alpha 0 → p_from, 1 → p_to, extrapolates outside [0, 1].

    ``alpha`` may be an array (N,) to get N poses at once.
    """
    a, b = _array(p_from, 6, "p_from"), _array(p_to, 6, "p_to")
    alpha = np.asarray(alpha, dtype=float)
    r_from = rotvec_to_matrix(a[..., 3:])
    step = matrix_to_rotvec(np.swapaxes(r_from, -1, -2) @ rotvec_to_matrix(b[..., 3:]))
    rotation = r_from @ rotvec_to_matrix(alpha[..., None] * step)
    position = a[..., :3] + alpha[..., None] * (b[..., :3] - a[..., :3])
    return np.concatenate([position, matrix_to_rotvec(rotation)], axis=-1)


def rotvec2rpy(rotation_vector) -> np.ndarray:
    """``rotvec2rpy``: [roll, pitch, yaw] [rad] of a rotation vector (``Rz·Ry·Rx`` order)."""
    return matrix_to_rpy(rotvec_to_matrix(rotation_vector))


def rpy2rotvec(rpy_vector) -> np.ndarray:
    """``rpy2rotvec``: the rotation vector [rad] of [roll, pitch, yaw] (``Rz·Ry·Rx`` order)."""
    return matrix_to_rotvec(rpy_to_matrix(rpy_vector))


def d2r(d):
    """``d2r``: degrees to radians, ``d/180·π``."""
    return np.asarray(d, dtype=float) / 180.0 * np.pi if np.ndim(d) else float(d) / 180.0 * np.pi


def r2d(r):
    """``r2d``: radians to degrees, ``r·180/π``."""
    return np.asarray(r, dtype=float) * 180.0 / np.pi if np.ndim(r) else float(r) * 180.0 / np.pi
