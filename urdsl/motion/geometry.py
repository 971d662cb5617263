"""Geometry of TCP paths: rotation interpolation and circular arcs, vectorised.

Rotations are 3x3 matrices; ``slerp_rotations`` interpolates along the geodesic
``R(s) = R0 · exp(s · log(R0ᵀ R1))`` for many ``s`` at once, with the rotation-vector maps of
:mod:`urdsl.kinematics.pose`. Positions in metres, angles in radians.
"""

from __future__ import annotations

import numpy as np

from ..kinematics.pose import matrix_to_rotvec, rotation_angle, rotvec_to_matrix

__all__ = ["rotation_angle", "slerp_rotations", "arc_points", "arc_length"]


def slerp_rotations(r0: np.ndarray, r1: np.ndarray, fraction: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) along the geodesic from ``r0`` (fraction 0) to ``r1`` (1)."""
    step = matrix_to_rotvec(r0.T @ r1)
    return r0 @ rotvec_to_matrix(np.asarray(fraction, dtype=float)[:, None] * step[None, :])


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


def arc_rotations(p0: np.ndarray, via: np.ndarray, p2: np.ndarray,
                  fraction: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) about the arc's axis by the angle the arc from ``p0`` through
    ``via`` to ``p2`` has turned at each path fraction: what ``movec``'s fixed mode
    (``mode=1``) turns the tool by, so that its orientation stays the same relative to the
    arc's tangent. The identity for points on a line."""
    fraction = np.asarray(fraction, dtype=float)
    circle = _circle(p0, via, p2)
    if circle is None:
        return np.repeat(np.eye(3)[None], len(fraction), axis=0)
    _centre, _radius, u, w, _, end = circle
    axis = np.cross(u, w)
    return rotvec_to_matrix(fraction[:, None] * end * axis[None, :])


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
