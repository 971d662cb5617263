"""Following one inverse-kinematics solution along a TCP path, as the controller does.

Used by the trace (:mod:`urdsl.motion.trace`) for every sampled straight-line or circular
move, and by the planner (:mod:`urdsl.motion.planner`) to find how far a move that a
condition stops can go.
"""

from __future__ import annotations

import numpy as np

__all__ = ["track", "TRACK_STEP"]


def track(model, poses: np.ndarray, near: np.ndarray, first: np.ndarray,
           owner: np.ndarray, tcp) -> np.ndarray:
    """Joints (N, 6) for ``poses`` (N, 4, 4) along TCP paths, following one IK solution
    continuously, as the controller does on a straight line: each sample takes the solution
    closest to the sample before it on the same move (``owner``: the move of each row; rows
    of a move in path order), the first sample of a move the one closest to where the move
    starts (``first``, rad). A branch change then shows only where no continuous solution
    exists — at a singularity or where the path leaves the workspace (URS302) — and not
    near a singularity, where the solution closest to the straight joint-space line between
    the move's ends (``near``, the first guess) may be another branch.

    The sequential rule is solved in rounds over all rows at once. The first guess is kept
    where it steps less than :data:`TRACK_STEP` from the row before; the other rows are
    chosen from the row before them, and each further round chooses again the rows after a
    row that changed (a toolpath needs no round at all). A row without a solution (NaN)
    hands ``near`` on to the next.
    """
    count = len(poses)
    if count == 0:
        return np.empty((0, 6))
    from ..kinematics.ik import choose_nearest

    starts = np.ones(count, dtype=bool)
    starts[1:] = owner[1:] != owner[:-1]
    analytic = hasattr(model, "ik_all_many") and not getattr(model, "calibrated", False)
    if analytic:
        every, _ = model.ik_all_many(poses, tcp=tcp)

        def choose(rows: np.ndarray, toward: np.ndarray) -> np.ndarray:
            return choose_nearest(every[rows], toward, model.q_min, model.q_max)[0]
    else:
        def choose(rows: np.ndarray, toward: np.ndarray) -> np.ndarray:
            return model.ik_many(poses[rows], toward, tcp=tcp)

    current = choose(np.arange(count), near)
    # rows that stay within TRACK_STEP of the row before are its continuation already
    before = np.where(starts[:, None], first, np.roll(current, 1, axis=0))
    step = np.abs(current - before).max(axis=1)
    active = np.flatnonzero(~(step <= TRACK_STEP))  # NaN too: choose again
    for _ in range(count):
        if len(active) == 0:
            break
        previous = np.where(starts[active, None], first[active], current[active - 1])
        lost = np.isnan(previous).any(axis=1)
        previous[lost] = near[active[lost]]
        chosen = choose(active, previous)
        old = current[active]
        same = ((chosen == old) | (np.isnan(chosen) & np.isnan(old))).all(axis=1)
        current[active] = chosen
        after = active[~same] + 1
        after = after[after < count]
        active = np.unique(after[~starts[after]])
    return current


TRACK_STEP = 0.25
"""Largest joint step (rad) between consecutive path samples (knots, at most 32 ms apart)
below which :func:`track` keeps the first guess, the solution closest to the joint-space
line: a joint moves at most 0.1 rad between knots at the fastest joint speed of a UR, and a
change of branch moves one by about π (as :data:`urdsl.verify.checks.JUMP_MIN`). Rows
stepping further are chosen again from the row before them, and so on along the move."""
