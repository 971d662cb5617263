"""The one exception of the kinematics layer."""

from __future__ import annotations

__all__ = ["KinematicsError"]


class KinematicsError(ValueError):
    """A kinematics request that cannot be met: unknown model, unreachable pose, bad input.

    ``distance`` is set for an unreachable pose: how far (m) the pose lies outside the arm's
    reach (see :meth:`urdsl.kinematics.Robot.ik`); ``None`` for other failures.
    """

    def __init__(self, message: str, distance: float | None = None) -> None:
        super().__init__(message)
        self.distance = distance
