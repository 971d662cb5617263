"""Analytic inverse kinematics of the UR arm, vectorised over many poses.

The UR geometry (joints 2, 3, 4 parallel, wrist axes 5 ⟂ 4 and 6 ⟂ 5) gives up to eight
closed-form solutions per flange pose ``T = [x6 y6 z6 p]`` (the same structure as the FK in
:mod:`.dh`; ``n1 = (s1, −c1, 0)`` is the shoulder axis):

1. wrist centre ``p5 = p − d6·z6``; its distance to the base axis satisfies
   ``p5·n1 = d4``, so ``θ1 = φ + asin(d4/r)`` or ``φ + π − asin(d4/r)`` with
   ``r, φ`` the polar coordinates of ``p5`` in the xy plane (needs ``r ≥ |d4|``);
2. ``z6·n1 = cos θ5`` and ``|(x6·n1, y6·n1)| = |sin θ5|`` give ``θ5 = ±atan2(|…|, z6·n1)``
   (accurate near θ5 = 0, unlike an arccos; it always exists once θ1 does);
3. ``x6·n1 = s5·c6`` and ``y6·n1 = −s5·s6`` give θ6. At the wrist singularity (``s5 = 0``)
   only ``θ234 + cos θ5·θ6`` is determined: θ6 is taken from a hint (0 by default), moved
   just enough to keep the wrist-1 point within the arm's reach (see
   :func:`_wrist_singular_split`);
4. ``w = s6·x6 + c6·y6 = (−c1·S, −s1·S, C)`` gives ``θ234 = atan2(S, C)``;
5. the wrist-1 point ``p4 = p5 − d5·(c1·S, s1·S, −C)`` in the arm plane,
   ``(u, v) = (c1·p4x + s1·p4y, p4z − d1)``, is reached by the planar two-link arm a2, a3:
   ``cos θ3 = (u² + v² − a2² − a3²)/(2·a2·a3)``, ``θ3 = ±acos(…)``,
   ``θ2 = atan2(v, u) − atan2(a3·s3, a2 + a3·c3)``, ``θ4 = θ234 − θ2 − θ3``.

Solution ``k`` (0…7) takes shoulder branch ``k // 4``, wrist branch ``(k // 2) % 2`` and elbow
branch ``k % 2``. A branch that does not exist gives NaN. Its *miss* is how far (m) the pose is
out of reach for it: ``|d4| − r`` (wrist centre inside the shoulder cylinder) or the
distance of the wrist-1 point
outside the annulus ``||a2| − |a3|| ≤ √(u² + v²) ≤ |a2| + |a3|`` — the largest of these.
"""

from __future__ import annotations

import numpy as np

from . import pose as _pose
from .dh import dh_frames

__all__ = ["solve_ur", "wrap", "choose_nearest", "choose_sequence", "refine"]

#: Poses out of reach by less than this [m] are treated as on the boundary (rounding).
REACH_TOLERANCE = 1e-9
#: Joint values beyond a limit by at most this [rad] (rounding) count as on the limit.
LIMIT_TOLERANCE = 1e-9
#: |sin θ5| below this counts as the wrist singularity (θ6 then comes from the hint).
WRIST_SINGULAR = 1e-12


#: Poses per block: the temporaries of a block stay in the CPU cache (about 1.7x faster
#: than one pass over 200,000 poses on the development machine).
BLOCK = 2048

_TWO_PI = 2.0 * np.pi


def wrap(q: np.ndarray) -> np.ndarray:
    """Angles wrapped to (−π, π] [rad]."""
    out = np.pi - np.mod(np.pi - q, _TWO_PI)
    return np.where(out <= -np.pi, out + _TWO_PI, out)  # mod may round up to 2π


def _wrap_near(q: np.ndarray) -> np.ndarray:
    """Angles in (−3π, 3π) wrapped to (−π, π] with one ±2π step (cheaper than :func:`wrap`)."""
    return np.where(q > np.pi, q - _TWO_PI, np.where(q <= -np.pi, q + _TWO_PI, q))


def solve_ur(T: np.ndarray, d1: float, a2: float, a3: float, d4: float, d5: float, d6: float,
             q6_hint: np.ndarray | None = None,
             reach_tolerance: float = REACH_TOLERANCE) -> tuple[np.ndarray, np.ndarray]:
    """All analytic solutions for flange poses ``T`` (N, 4, 4) (see :func:`_solve_block`),
    computed in blocks of :data:`BLOCK` poses."""
    T = np.asarray(T, dtype=float)
    n = T.shape[0]
    if n <= BLOCK:
        return _solve_block(T, d1, a2, a3, d4, d5, d6, q6_hint, reach_tolerance)
    solutions = np.empty((n, 8, 6))
    miss = np.empty((n, 8))
    for start in range(0, n, BLOCK):
        block = slice(start, start + BLOCK)
        hint = None if q6_hint is None else np.asarray(q6_hint, dtype=float)[block]
        solutions[block], miss[block] = _solve_block(T[block], d1, a2, a3, d4, d5, d6, hint,
                                                     reach_tolerance)
    return solutions, miss


def _solve_block(T: np.ndarray, d1: float, a2: float, a3: float, d4: float, d5: float,
                 d6: float, q6_hint: np.ndarray | None,
                 reach_tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """All analytic solutions for flange poses ``T`` (N, 4, 4).

    Returns ``(solutions, miss)``: joint vectors (N, 8, 6) wrapped to (−π, π] with NaN rows
    for branches that do not exist, and (N, 8) distances out of reach [m] (0 where solved).
    ``q6_hint`` (N,) is used for θ6 at the wrist singularity. Branches out of reach by less
    than ``reach_tolerance`` [m] are still solved (on the boundary; their miss is reported),
    which lets a calibrated arm refine them.
    """
    T = np.asarray(T, dtype=float)
    n = T.shape[0]
    x6, y6, z6, p = T[:, :3, 0], T[:, :3, 1], T[:, :3, 2], T[:, :3, 3]
    p5 = p - d6 * z6

    # 1. shoulder: two θ1 per pose, shape (N, 2)
    r = np.hypot(p5[:, 0], p5[:, 1])
    phi = np.arctan2(p5[:, 1], p5[:, 0])
    miss_shoulder = np.maximum(abs(d4) - r, 0.0)
    ratio = np.clip(d4 / np.maximum(r, 1e-300), -1.0, 1.0)
    ratio = np.where(r > 0.0, ratio, np.sign(d4))
    offset = np.arcsin(ratio)
    theta1 = _wrap_near(np.stack([phi + offset, phi + np.pi - offset], axis=1))
    c1, s1 = np.cos(theta1), np.sin(theta1)

    # 2. wrist 2: two θ5 per θ1, shape (N, 2, 2); cos θ5 = z6·n1, |sin θ5| = |(x6·n1, y6·n1)|
    z6n = z6[:, 0, None] * s1 - z6[:, 1, None] * c1
    x6n = x6[:, 0, None] * s1 - x6[:, 1, None] * c1
    y6n = y6[:, 0, None] * s1 - y6[:, 1, None] * c1
    t5 = np.arctan2(np.hypot(x6n, y6n), z6n)
    theta5 = np.stack([t5, np.where(t5 >= np.pi, t5, -t5)], axis=2)   # keep π, not −π
    s5 = np.sin(theta5)

    # 3. wrist 3
    sign5 = np.where(theta5 < 0.0, -1.0, 1.0)
    theta6 = np.arctan2(-y6n[:, :, None] * sign5, x6n[:, :, None] * sign5)
    singular = np.abs(s5) < WRIST_SINGULAR
    if np.any(singular):
        hint = np.zeros(n) if q6_hint is None else np.asarray(q6_hint, dtype=float)
        theta6 = np.where(singular, hint[:, None, None], theta6)
    c6, s6 = np.cos(theta6), np.sin(theta6)

    # 4. θ2 + θ3 + θ4
    c1b, s1b = c1[:, :, None], s1[:, :, None]
    wx = x6[:, 0, None, None] * s6 + y6[:, 0, None, None] * c6
    wy = x6[:, 1, None, None] * s6 + y6[:, 1, None, None] * c6
    wz = x6[:, 2, None, None] * s6 + y6[:, 2, None, None] * c6
    big_s = -(c1b * wx + s1b * wy)
    big_c = wz
    theta234 = np.arctan2(big_s, big_c)
    near_singular = np.abs(s5) < 1e-6
    if np.any(near_singular):
        split234, split6 = _wrist_singular_split(theta234, theta6, near_singular,
                                                 np.cos(theta5),
                                                 c1b * p5[:, 0, None, None]
                                                 + s1b * p5[:, 1, None, None],
                                                 p5[:, 2, None, None] - d1, a2, a3, d5)
        # near (not at) the singularity, moving θ234 turns the tool by |s5|·Δθ234: accept
        # the move only while that stays at rounding level
        accept = singular | (np.abs(s5) * np.abs(split234 - theta234) <= 1e-11)
        theta234 = np.where(accept, split234, theta234)
        theta6 = np.where(accept, split6, theta6)
        big_s, big_c = np.sin(theta234), np.cos(theta234)

    # 5. planar two-link arm, two θ3 per (θ1, θ5): shape (N, 2, 2, 2)
    p4x = p5[:, 0, None, None] - d5 * c1b * big_s
    p4y = p5[:, 1, None, None] - d5 * s1b * big_s
    p4z = p5[:, 2, None, None] + d5 * big_c
    u = c1b * p4x + s1b * p4y
    v = p4z - d1
    length = np.hypot(u, v)
    outer, inner = abs(a2) + abs(a3), abs(abs(a2) - abs(a3))
    miss_elbow = np.maximum(np.maximum(length - outer, inner - length), 0.0)
    c3 = np.clip((u * u + v * v - a2 * a2 - a3 * a3) / (2.0 * a2 * a3), -1.0, 1.0)
    t3 = np.arccos(c3)
    theta3 = np.stack([t3, -t3], axis=3)
    s3 = np.sin(theta3)
    theta2 = (np.arctan2(v, u)[..., None]
              - np.arctan2(a3 * s3, a2 + a3 * c3[..., None]))
    theta2 = _wrap_near(theta2)
    theta4 = wrap(theta234)[..., None] - theta2 - theta3

    out = np.empty((n, 2, 2, 2, 6))
    out[..., 0] = theta1[:, :, None, None]
    out[..., 1] = _wrap_near(theta2)
    out[..., 2] = np.where(theta3 <= -np.pi, np.pi, theta3)
    out[..., 3] = _wrap_near(theta4)
    out[..., 4] = theta5[:, :, :, None]
    out[..., 5] = wrap(theta6)[..., None]
    solutions = out.reshape(n, 8, 6)
    miss = np.repeat(np.maximum(miss_shoulder[:, None, None], miss_elbow), 2,
                     axis=2).reshape(n, 8)
    solutions[miss > max(reach_tolerance, REACH_TOLERANCE)] = np.nan
    return solutions, np.where(miss > REACH_TOLERANCE, miss, 0.0)


def _wrist_singular_split(theta234, theta6, singular, c5, u5, v5, a2, a3, d5):
    """At the wrist singularity (sin θ5 = 0) only ``θ234 + cos θ5·θ6`` is fixed by the
    orientation, while θ234 alone places the wrist-1 point on a circle of radius d5 around
    the wrist centre ``(u5, v5)`` in the arm plane. Keep θ6 from the hint when that point is
    reachable by the two-link arm; otherwise move θ234 (and θ6 with it) the least amount that
    brings the point onto the reachable annulus.

    With ``|c| = |(u5, v5)|`` and ``ψ = atan2(−u5, v5)`` the wrist-1 distance is
    ``L² = |c|² + d5² + 2·d5·|c|·cos(θ234 − ψ)``.
    """
    centre = np.hypot(u5, v5)
    psi = np.arctan2(-u5, v5)
    outer, inner = abs(a2) + abs(a3), abs(abs(a2) - abs(a3))
    denominator = 2.0 * d5 * np.maximum(centre, 1e-300)
    k_out = (outer ** 2 - centre ** 2 - d5 ** 2) / denominator
    k_in = (inner ** 2 - centre ** 2 - d5 ** 2) / denominator
    low = np.arccos(np.clip(k_out, -1.0, 1.0))    # |θ234 − ψ| ≥ low keeps L ≤ outer
    high = np.arccos(np.clip(k_in, -1.0, 1.0))    # |θ234 − ψ| ≤ high keeps L ≥ inner
    delta = wrap(theta234 - psi)
    side = np.where(delta < 0.0, -1.0, 1.0)
    clamped = psi + side * np.clip(np.abs(delta), low, np.maximum(high, low))
    adjust = singular & (centre > 1e-12) & (low <= high)
    move = np.where(adjust, wrap(clamped - theta234), 0.0)
    return theta234 + move, theta6 - c5 * move


def choose_nearest(solutions: np.ndarray, q_near: np.ndarray, q_min: np.ndarray,
                   q_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The controller's choice among ``solutions`` (N, K, 6): the one closest to ``q_near``
    (N, 6) in the sum of squared joint differences [rad²], each joint first moved by a
    multiple of 2π to the value nearest ``q_near`` that lies within ``[q_min, q_max]``.

    Returns ``(q, found)``: (N, 6) with NaN rows where no solution fits the limits, (N,) bool.
    Works in blocks of :data:`BLOCK` rows.
    """
    n = solutions.shape[0]
    if n <= BLOCK:
        return _choose_block(solutions, q_near, q_min, q_max)
    chosen = np.empty((n, 6))
    found = np.empty(n, dtype=bool)
    for start in range(0, n, BLOCK):
        block = slice(start, start + BLOCK)
        chosen[block], found[block] = _choose_block(solutions[block], q_near[block], q_min,
                                                    q_max)
    return chosen, found


def choose_sequence(solutions: np.ndarray, q_first: np.ndarray, q_min: np.ndarray,
                    q_max: np.ndarray, rounds: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The controller's choices along a sequence of targets (N, K, 6): target 0 takes the
    solution closest to ``q_first`` (6,), each later target the one closest to the choice
    before it — as :func:`choose_nearest` row by row, but in batches.

    Every round chooses all rows at once, each from the previous round's choice of the row
    before it. A prefix on which two rounds agree is consistent and therefore final (row 0 is
    always right, and a row chosen from a final row is final); the next round starts at the
    first row that changed. Toolpaths settle in two or three rounds; after ``rounds`` the
    rest is chosen row by row. Rows after the first row without a solution are NaN.

    Returns ``(q, found)`` like :func:`choose_nearest`.
    """
    n = solutions.shape[0]
    chosen = np.full((n, 6), np.nan)
    found = np.zeros(n, dtype=bool)
    if n == 0:
        return chosen, found
    first = np.asarray(q_first, dtype=float)
    start = 0  # rows before it are final
    guess, _ = choose_nearest(solutions, np.broadcast_to(first, (n, 6)), q_min, q_max)
    for _ in range(rounds):
        near = np.empty((n - start, 6))
        near[0] = first if start == 0 else chosen[start - 1]
        near[1:] = guess[start:-1]
        new, ok = choose_nearest(solutions[start:], near, q_min, q_max)
        same = ((new == guess[start:]) | (np.isnan(new) & np.isnan(guess[start:]))).all(axis=1)
        # row 0 of a round is final; row j + 1 is, if row j is and did not change
        changed = np.flatnonzero(~same)
        settled = n - start if len(changed) == 0 else int(changed[0]) + 1
        chosen[start:start + settled] = new[:settled]
        found[start:start + settled] = ok[:settled]
        missing = np.flatnonzero(~ok[:settled])
        if len(missing):  # nothing after a target without a solution is chosen
            return _cut_after(chosen, found, start + int(missing[0]))
        guess[start:] = new
        start += settled
        if start == n:
            return chosen, found
    for row in range(start, n):
        near = first if row == 0 else chosen[row - 1]
        q, ok = _choose_block(solutions[row:row + 1], near[None], q_min, q_max)
        chosen[row], found[row] = q[0], ok[0]
        if not ok[0]:
            return _cut_after(chosen, found, row)
    return chosen, found


def _cut_after(chosen: np.ndarray, found: np.ndarray, row: int):
    chosen[row:] = np.nan
    found[row:] = False
    return chosen, found


def _choose_block(solutions, q_near, q_min, q_max):
    near = q_near[:, None, :]
    difference = solutions - near
    difference -= _TWO_PI * np.rint(difference / _TWO_PI)      # nearest turn: [−π, π]
    shifted = near + difference
    # a value beyond a limit by rounding only (≤ LIMIT_TOLERANCE) is put on the limit
    upper, lower = q_max + LIMIT_TOLERANCE, q_min - LIMIT_TOLERANCE
    fits = None
    if np.any(shifted > q_max) or np.any(shifted < q_min):
        shifted = shifted - _TWO_PI * np.ceil(np.maximum(shifted - upper, 0.0) / _TWO_PI)
        shifted = shifted + _TWO_PI * np.ceil(np.maximum(lower - shifted, 0.0) / _TWO_PI)
        fits = np.all((shifted >= lower) & (shifted <= upper), axis=2)
        shifted = np.clip(shifted, q_min, q_max)
        difference = shifted - near
    cost = np.einsum("nkj,nkj->nk", difference, difference)
    invalid = np.isnan(cost) if fits is None else (np.isnan(cost) | ~fits)
    cost[invalid] = np.inf
    best = np.argmin(cost, axis=1)
    rows = np.arange(solutions.shape[0])
    chosen = shifted[rows, best]
    found = np.isfinite(cost[rows, best])
    chosen[~found] = np.nan
    return chosen, found


def refine(q: np.ndarray, target: np.ndarray, theta_offset: np.ndarray, a: np.ndarray,
           d: np.ndarray, alpha: np.ndarray, iterations: int = 20,
           tolerance: float = 1e-14) -> tuple[np.ndarray, np.ndarray]:
    """Newton steps on the general DH chain from guesses ``q`` (M, 6) to flange poses
    ``target`` (M, 4, 4): ``J·Δq = e`` with ``e = (p* − p, log(R*·Rᵀ))`` in the Base frame and
    the geometric Jacobian (columns ``z_i × (p − o_i)``, ``z_i``).

    Returns ``(q, error)``: refined joints and the final error norm (m and rad mixed).
    """
    q = np.array(q, dtype=float)
    error_norm = np.full(q.shape[0], np.inf)
    active = np.ones(q.shape[0], dtype=bool)
    for _ in range(iterations):
        if not np.any(active):
            break
        frames = dh_frames(q[active], theta_offset, a, d, alpha)
        flange = frames[:, 6]
        goal = target[active]
        e_pos = goal[:, :3, 3] - flange[:, :3, 3]
        e_rot = _pose.matrix_to_rotvec(goal[:, :3, :3] @ np.swapaxes(flange[:, :3, :3], 1, 2))
        error = np.concatenate([e_pos, e_rot], axis=1)
        norm = np.linalg.norm(error, axis=1)
        error_norm[active] = norm
        axes = frames[:, :6, :3, 2]
        origins = frames[:, :6, :3, 3]
        jacobian = np.concatenate(
            [np.cross(axes, flange[:, None, :3, 3] - origins), axes], axis=2)
        jacobian = np.swapaxes(jacobian, 1, 2)
        damping = 1e-12 * np.eye(6)
        jjt = jacobian @ np.swapaxes(jacobian, 1, 2) + damping
        step = np.swapaxes(jacobian, 1, 2) @ np.linalg.solve(jjt, error[:, :, None])
        index = np.flatnonzero(active)
        q[index] += step[:, :, 0]
        done = norm < tolerance
        active[index[done]] = False
    if np.any(active):
        frames = dh_frames(q[active], theta_offset, a, d, alpha)[:, 6]
        goal = target[active]
        e_pos = goal[:, :3, 3] - frames[:, :3, 3]
        e_rot = _pose.matrix_to_rotvec(goal[:, :3, :3] @ np.swapaxes(frames[:, :3, :3], 1, 2))
        error_norm[active] = np.linalg.norm(np.concatenate([e_pos, e_rot], axis=1), axis=1)
    return q, error_norm
