"""Moves relative to where the arm is, while the checker does not know where that is.

A PolyScope program without a taught start (``urdsl check`` then starts with the arm's
position unknown) whose loop makes one relative move,
``movej(pose_add(get_target_tcp_pose(), d))``, moves the TCP by the same displacement ``d``
at every pass. Wherever the arm started, after ``k`` passes its target lies ``k·|d|`` from
that start: once that is more than any two points the TCP can reach are apart, no start
makes the target reachable and the controller stops the program there ("inverse
kinematics failed"). This module holds what is known of such poses and that bound.

What is followed (:class:`urdsl.runtime.values.Relative`): the TCP point read while the arm
stands still at an unknown place (an :class:`~urdsl.runtime.values.Anchor`), plus known
displacements: ``pose_add(P, d)``/``pose_add(d, P)`` (position ``P + d`` exactly, whatever
the rotations) and ``pose_sub(P, d)`` (``P − d``), and the arm's TCP after a move to such a
pose. Everything else (``pose_trans`` with its unknown rotation, arithmetic on elements, a
difference of two such poses) is plainly unknown.

The bound (:func:`flange_reach`): UR arms have the standard DH table
``a = (0, a2, a3, 0, 0, 0)``, ``d = (d1, 0, 0, d4, d5, d6)``, ``α = (π/2, 0, 0, π/2, −π/2, 0)``.
From the shoulder point ``O1 = (0, 0, d1)`` the flange's origin is
``O6 = O1 + a2·x2 + a3·x3 + d4·z1 + d5·z4 + d6·z5``, where ``x2``, ``x3`` and ``z4`` lie in
the plane normal to the shoulder axis ``z1`` (joints 2-4 are parallel, joint 5 is normal to
them) and ``z5`` is a unit vector. So ``|O6 − O1| ≤ √((|a2| + |a3| + |d5|)² + d4²) + |d6|``
(for the UR5e 1.026 m, against its nominal 0.85 m reach to the wrist), and a TCP whose
offset from the flange is ``t`` m long is at most that plus ``t`` from ``O1``. Two TCP points
the arm reaches, the first with a TCP of length ``t1``, the second ``t2``, are at most
``2·flange_reach + t1 + t2`` apart: a displacement larger than that (plus
:data:`DRIFT_MARGIN`) from a point the arm stood at is out of reach for every start.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..runtime.values import Anchor, Relative

__all__ = ["DRIFT_MARGIN", "flange_reach", "widest_model", "Drift", "drift_error"]

DRIFT_MARGIN = 0.01
"""Slack (m) added to the bound: an arm's calibration moves its DH lengths by millimetres,
and at rest its actual TCP pose differs from the target pose by far less than this."""


def flange_reach(spec: Any) -> float:
    """An upper bound (m) of the distance from the shoulder point ``(0, 0, d1)`` to the
    flange's origin, over every joint position of the model ``spec`` (a
    :class:`urdsl.kinematics.models.ModelSpec`); see the module's docstring."""
    in_plane = abs(spec.a2) + abs(spec.a3) + abs(spec.d5)
    return math.hypot(in_plane, spec.d4) + abs(spec.d6)


def widest_model() -> Any:
    """The UR model whose flange reaches farthest from its shoulder (:func:`flange_reach`)."""
    from ..kinematics.models import MODELS

    return max(MODELS.values(), key=flange_reach)


@dataclass
class Drift:
    """Where the arm's TCP is while its position is unknown but followed: the point of the
    TCP ``tcp`` (position in the flange frame, m; None until the first read fixes it to the
    TCP then active) is ``anchor``'s point plus ``offset`` (m, Base frame).

    ``where`` describes the anchor until a read creates it; ``holder``: the only thread that
    may read it (the one whose move left the arm there: another thread may read while the
    move still runs), None for any thread (the arm has not moved since).
    """

    where: str
    anchor: Anchor | None = None
    tcp: np.ndarray | None = None
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    moves: int = 0
    statements: frozenset = frozenset()
    holder: Any = None

    def read(self, tcp: np.ndarray, holder: Any) -> Relative | None:
        """What a read of the pose of the TCP whose position in the flange frame is ``tcp``
        (m), by the thread ``holder``, knows: a :class:`Relative`, or None (plainly
        unknown: another TCP, or another thread)."""
        if self.holder is not None and holder is not self.holder:
            return None
        if self.anchor is None:
            self.anchor = Anchor(self.where, float(np.linalg.norm(tcp)))
            self.tcp = np.array(tcp, dtype=float)
        elif self.tcp is None or not np.allclose(self.tcp, tcp, rtol=0.0, atol=1e-9):
            return None
        return Relative(self.anchor, self.offset, self.moves, self.statements)

    @classmethod
    def after(cls, relative: Relative, tcp: np.ndarray, span: Any, holder: Any) -> Drift:
        """The arm after a move (by the thread ``holder``, at ``span``, with the TCP ``tcp``)
        that ended at ``relative``."""
        return cls(relative.anchor.where, relative.anchor, np.array(tcp, dtype=float),
                   relative.offset, relative.moves + 1, relative.statements | {span}, holder)


def drift_error(relative: Relative, tcp: np.ndarray, span: Any, spec: Any,
                any_model: bool) -> str | None:
    """Why a move (at ``span``, with a TCP at ``tcp`` in the flange frame, m) to
    ``relative`` is out of reach whatever the start, or None when some start may make it
    reachable. ``spec`` is the robot's model; ``any_model``: the model is only assumed, so
    the bound is that of the widest UR model (:func:`widest_model`)."""
    model = widest_model() if any_model else spec
    if model is None:
        return None
    reach = flange_reach(model)
    tcp_length = float(np.linalg.norm(tcp))
    bound = 2.0 * reach + relative.anchor.tcp_length + tcp_length + DRIFT_MARGIN
    distance = math.dist(relative.offset, (0.0, 0.0, 0.0))
    if distance <= bound:
        return None
    passes = relative.moves + 1
    if relative.statements <= {span}:
        after = f"after {passes} pass{'es' if passes != 1 else ''} of this move"
    else:
        after = f"after {passes} moves relative to it (this one and others)"
    farthest = (f"its TCP is at most {reach + max(tcp_length, relative.anchor.tcp_length):.2f}"
                f" m from the shoulder, so no two points it reaches are more than {bound:.2f} "
                "m apart")
    if any_model:
        keeps = (f"no start keeps it within the reach of any UR model (the robot is not "
                 f"known; on the widest, the {model.name}, {farthest})")
    else:
        keeps = f"no start within the {model.name}'s reach keeps it within reach ({farthest})"
    return f"the target is {distance:.2f} m from {relative.anchor.where}, {after}; {keeps}"
