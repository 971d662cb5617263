"""The one exception of the kinematics layer."""

from __future__ import annotations

__all__ = ["KinematicsError"]


class KinematicsError(ValueError):
    """A kinematics request that cannot be met: unknown model, unreachable pose, bad input.

    ``distance`` is set for an unreachable pose: how far (m) the pose lies outside the arm's
    reach (see :meth:`urdsl.kinematics.Robot.ik`); ``None`` for other failures.
    ``position`` (x, y, z in m, Base) is set only for a pose beyond the arm's reach (not for
    one reachable only outside the joint limits): where the target lies.
    """

    def __init__(self, message: str, distance: float | None = None,
                 position: tuple[float, float, float] | None = None) -> None:
        super().__init__(message)
        self.distance = distance
        self.position = position
