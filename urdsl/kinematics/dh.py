"""Forward kinematics of a standard-DH chain, vectorised over many joint vectors.

Two evaluations of the same product ``T_1·…·T_6`` with ``T_i = Rz(θ_i)·Tz(d_i)·Tx(a_i)·Rx(α_i)``:

* :func:`fk_ur` — closed form for the nominal UR structure (α = π/2, 0, 0, π/2, −π/2, 0 and
  a1 = a4 = a5 = a6 = d2 = d3 = 0). With ``c1 = cos θ1``, ``C = cos(θ2+θ3+θ4)``,
  ``S = sin(θ2+θ3+θ4)``, ``u = a2·c2 + a3·c23``, ``v = a2·s2 + a3·s23``::

      z5 = (c1·S, s1·S, −C)                                  (wrist-2 axis)
      x5 = (c1·C·c5 + s1·s5, s1·C·c5 − c1·s5, S·c5)
      y5 = (−c1·S, −s1·S, C)
      z6 = (−c1·C·s5 + s1·c5, −s1·C·s5 − c1·c5, −S·s5)       (tool Z, out of the flange)
      x6 = x5·c6 + y5·s6,   y6 = −x5·s6 + y5·c6
      p  = (c1·u + s1·d4, s1·u − c1·d4, d1 + v) + d5·z5 + d6·z6

  Only element-wise array arithmetic: this is what makes batched FK fast.
* :func:`dh_frames` — the general chain (any θ offsets, a, d, α, e.g. a calibrated robot),
  returning every intermediate frame, by batched 4x4 products.

Joint angles in rad, lengths in m; results are (N, 4, 4) transforms of DH frame 6 (the tool
flange, ROS ``tool0``) in the controller's Base frame.
"""

from __future__ import annotations

import numpy as np

__all__ = ["fk_ur", "ur_axes", "arm_terms", "dh_frames", "dh_transforms"]


#: Joint vectors per block: the temporaries stay in the CPU cache (1.8x faster than one
#: pass over 200,000 vectors on the development machine).
BLOCK = 4096


def fk_ur(q: np.ndarray, d1: float, a2: float, a3: float, d4: float, d5: float,
          d6: float) -> np.ndarray:
    """Flange poses (N, 4, 4) for joint vectors ``q`` (N, 6) of a nominal UR arm."""
    q = np.asarray(q, dtype=float)
    out = np.empty((q.shape[0], 4, 4))
    for start in range(0, q.shape[0], BLOCK):
        _fk_ur_block(q[start:start + BLOCK], d1, a2, a3, d4, d5, d6,
                     out[start:start + BLOCK])
    return out


def arm_terms(q: np.ndarray, a2: float, a3: float):
    """Cosines and sines (N, 6) of the joints, ``C``, ``S`` of θ2+θ3+θ4 and the arm-plane
    coordinates ``u``, ``v`` of the wrist-1 point (see the module docstring)."""
    c, s = np.cos(q), np.sin(q)
    q23 = q[:, 1] + q[:, 2]
    q234 = q23 + q[:, 3]
    u = a2 * c[:, 1] + a3 * np.cos(q23)
    v = a2 * s[:, 1] + a3 * np.sin(q23)
    return c, s, np.cos(q234), np.sin(q234), u, v


def _fk_ur_block(q: np.ndarray, d1: float, a2: float, a3: float, d4: float, d5: float,
                 d6: float, out: np.ndarray) -> None:
    c, s, cc, ss, u, v = arm_terms(q, a2, a3)
    c1, s1, c5, s5, c6, s6 = c[:, 0], s[:, 0], c[:, 4], s[:, 4], c[:, 5], s[:, 5]

    c1c = c1 * cc
    s1c = s1 * cc
    x5x, x5y, x5z = c1c * c5 + s1 * s5, s1c * c5 - c1 * s5, ss * c5
    y5x, y5y, y5z = -c1 * ss, -s1 * ss, cc
    out[:, 0, 0] = x5x * c6 + y5x * s6
    out[:, 1, 0] = x5y * c6 + y5y * s6
    out[:, 2, 0] = x5z * c6 + y5z * s6
    out[:, 0, 1] = y5x * c6 - x5x * s6
    out[:, 1, 1] = y5y * c6 - x5y * s6
    out[:, 2, 1] = y5z * c6 - x5z * s6
    z6x = s1 * c5 - c1c * s5
    z6y = -c1 * c5 - s1c * s5
    z6z = -ss * s5
    out[:, 0, 2] = z6x
    out[:, 1, 2] = z6y
    out[:, 2, 2] = z6z
    out[:, 0, 3] = c1 * u + s1 * d4 + d5 * c1 * ss + d6 * z6x
    out[:, 1, 3] = s1 * u - c1 * d4 + d5 * s1 * ss + d6 * z6y
    out[:, 2, 3] = d1 + v - d5 * cc + d6 * z6z
    out[:, 3, :3] = 0.0
    out[:, 3, 3] = 1.0


def ur_axes(q: np.ndarray, d1: float, a2: float, a3: float, d4: float, d5: float,
            d6: float) -> tuple[np.ndarray, np.ndarray]:
    """Joint axes and origins of a nominal UR arm in closed form (the same structure as
    :func:`fk_ur`): axes ``z_0…z_5`` (N, 6, 3) — unit vectors, joint ``i + 1`` turns about
    ``z_i`` — and the origins ``o_0…o_6`` (N, 7, 3) [m] of DH frames 0…6 (``o_6`` is the
    flange). With ``n1 = (s1, −c1, 0)`` (the shoulder axis, shared by joints 2, 3 and 4)::

        z_0 = (0, 0, 1),  z_1 = z_2 = z_3 = n1,  z_4 = z5 of fk_ur,  z_5 = z6 of fk_ur
        o_1 = (0, 0, d1),  o_2 = o_1 + a2·(c1·c2, s1·c2, s2),  o_3 = (c1·u, s1·u, d1 + v)
        o_4 = o_3 + d4·n1,  o_5 = o_4 + d5·z_4,  o_6 = o_5 + d6·z_5

    These are the columns of the geometric Jacobian without any 4x4 product (much faster
    than :func:`dh_frames` for many joint vectors).
    """
    q = np.asarray(q, dtype=float)
    n = q.shape[0]
    c, s, cc, ss, u, v = arm_terms(q, a2, a3)
    c1, s1, c2, s2, c5, s5 = c[:, 0], s[:, 0], c[:, 1], s[:, 1], c[:, 4], s[:, 4]
    axes = np.zeros((n, 6, 3))
    axes[:, 0, 2] = 1.0
    axes[:, 1:4, 0] = s1[:, None]
    axes[:, 1:4, 1] = -c1[:, None]
    axes[:, 4, 0], axes[:, 4, 1], axes[:, 4, 2] = c1 * ss, s1 * ss, -cc
    axes[:, 5, 0] = s1 * c5 - c1 * cc * s5
    axes[:, 5, 1] = -c1 * c5 - s1 * cc * s5
    axes[:, 5, 2] = -ss * s5
    origins = np.zeros((n, 7, 3))
    origins[:, 1, 2] = d1
    origins[:, 2, 0], origins[:, 2, 1], origins[:, 2, 2] = a2 * c1 * c2, a2 * s1 * c2, \
        d1 + a2 * s2
    origins[:, 3, 0], origins[:, 3, 1], origins[:, 3, 2] = c1 * u, s1 * u, d1 + v
    origins[:, 4] = origins[:, 3] + d4 * axes[:, 1]
    origins[:, 5] = origins[:, 4] + d5 * axes[:, 4]
    origins[:, 6] = origins[:, 5] + d6 * axes[:, 5]
    return axes, origins


def dh_transforms(q: np.ndarray, theta_offset: np.ndarray, a: np.ndarray, d: np.ndarray,
                  alpha: np.ndarray) -> np.ndarray:
    """The link transforms ``T_i`` (N, 6, 4, 4) for joint vectors ``q`` (N, 6)."""
    theta = np.asarray(q, dtype=float) + theta_offset
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    out = np.zeros(theta.shape + (4, 4))
    out[..., 0, 0] = ct
    out[..., 0, 1] = -st * ca
    out[..., 0, 2] = st * sa
    out[..., 0, 3] = a * ct
    out[..., 1, 0] = st
    out[..., 1, 1] = ct * ca
    out[..., 1, 2] = -ct * sa
    out[..., 1, 3] = a * st
    out[..., 2, 1] = sa
    out[..., 2, 2] = ca
    out[..., 2, 3] = d
    out[..., 3, 3] = 1.0
    return out


def dh_frames(q: np.ndarray, theta_offset: np.ndarray, a: np.ndarray, d: np.ndarray,
              alpha: np.ndarray) -> np.ndarray:
    """Frames 0…6 (N, 7, 4, 4) of the chain in the Base frame (frame 0 is the identity,
    frame 6 the flange) for joint vectors ``q`` (N, 6)."""
    links = dh_transforms(q, theta_offset, a, d, alpha)
    frames = np.empty((links.shape[0], 7, 4, 4))
    frames[:, 0] = np.eye(4)
    for i in range(6):
        frames[:, i + 1] = frames[:, i] @ links[:, i]
    return frames
