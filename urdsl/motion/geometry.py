"""Geometry of TCP paths: rotation interpolation and circular arcs, vectorised.

Rotations are 3x3 matrices; ``slerp_rotations`` interpolates along the geodesic
``R(s) = R0 · exp(s · log(R0ᵀ R1))``, evaluated for many ``s`` at once with Rodrigues'
formula. Positions in metres, angles in radians.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rotation_angle", "rotation_matrix", "slerp_rotations", "arc_points", "arc_length"]


def _log(rotation: np.ndarray) -> np.ndarray:
    """Rotation vector (axis · angle, rad) of a rotation matrix; exact near 0 and π."""
    cos_angle = np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0)
    angle = float(np.arccos(cos_angle))
    if angle < 1e-9:
        return np.zeros(3)
    if np.pi - angle < 1e-6:  # near π: the axis from the symmetric part
        symmetric = (rotation + np.eye(3)) / 2.0
        axis = symmetric[int(np.argmax(np.diag(symmetric)))]
        axis = axis / np.linalg.norm(axis)
        return axis * angle
    axis = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
                     rotation[1, 0] - rotation[0, 1]]) / (2.0 * np.sin(angle))
    return axis * angle


def _exp_many(vectors: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of rotation vectors (N, 3) (Rodrigues)."""
    angles = np.linalg.norm(vectors, axis=1)
    safe = np.where(angles > 1e-12, angles, 1.0)
    axes = vectors / safe[:, None]
    x, y, z = axes[:, 0], axes[:, 1], axes[:, 2]
    zero = np.zeros_like(x)
    cross = np.stack([np.stack([zero, -z, y], 1), np.stack([z, zero, -x], 1),
                      np.stack([-y, x, zero], 1)], 1)
    sin, cos = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    result = np.eye(3) + sin * cross + (1.0 - cos) * (cross @ cross)
    result[angles <= 1e-12] = np.eye(3)
    return result


def rotation_matrix(vector: np.ndarray) -> np.ndarray:
    """Rotation matrix (3x3) of a rotation vector (axis · angle, rad)."""
    return _exp_many(np.asarray(vector, dtype=float).reshape(1, 3))[0]


def rotation_angle(r0: np.ndarray, r1: np.ndarray) -> float:
    """The angle (rad) of the rotation from ``r0`` to ``r1``."""
    return float(np.linalg.norm(_log(r0.T @ r1)))


def slerp_rotations(r0: np.ndarray, r1: np.ndarray, fraction: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) along the geodesic from ``r0`` (fraction 0) to ``r1`` (1)."""
    step = _log(r0.T @ r1)
    return r0 @ _exp_many(np.asarray(fraction, dtype=float)[:, None] * step[None, :])


def _circle(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray):
    """Centre, radius, in-plane basis and the angles of p1 and p2 on the circle through the
    three points, or None when they are (nearly) on a line."""
    a, b = p1 - p0, p2 - p0
    normal = np.cross(a, b)
    norm2 = float(normal @ normal)
    if norm2 < 1e-18:
        return None
    centre = p0 + (np.cross(normal, a) * (b @ b) + np.cross(b, normal) * (a @ a)) / (2 * norm2)
    radius = float(np.linalg.norm(p0 - centre))
    u = (p0 - centre) / radius
    w = np.cross(normal / np.sqrt(norm2), u)

    def angle(p: np.ndarray) -> float:
        d = p - centre
        value = float(np.arctan2(d @ w, d @ u))
        return value % (2 * np.pi)

    return centre, radius, u, w, angle(p1), angle(p2)


def arc_length(p0: np.ndarray, via: np.ndarray, p2: np.ndarray) -> float:
    """Length (m) of the circular arc from ``p0`` through ``via`` to ``p2``."""
    circle = _circle(p0, via, p2)
    if circle is None:
        return float(np.linalg.norm(p2 - p0))
    _, radius, _, _, _, end = circle
    return radius * end


def arc_points(p0: np.ndarray, via: np.ndarray, p2: np.ndarray,
               fraction: np.ndarray) -> np.ndarray:
    """Points (N, 3) at path fractions along the arc from ``p0`` through ``via`` to ``p2``."""
    fraction = np.asarray(fraction, dtype=float)
    circle = _circle(p0, via, p2)
    if circle is None:
        return p0 + fraction[:, None] * (p2 - p0)
    centre, radius, u, w, _, end = circle
    angles = fraction * end
    return centre + radius * (np.cos(angles)[:, None] * u + np.sin(angles)[:, None] * w)
