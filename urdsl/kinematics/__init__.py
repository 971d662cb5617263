"""Kinematics of the UR family: models, forward/inverse kinematics and URScript pose math.

>>> from urdsl.kinematics import Robot, MODELS, pose
>>> robot = Robot.model("ur5e")
>>> T = robot.fk([0, -1.57, 1.57, -1.57, -1.57, 0])    # 4x4 flange pose in Base, m
>>> q = robot.ik(T, q_near=[0, -1.5, 1.5, -1.5, -1.5, 0])

``MODELS``, :mod:`.pose`, :class:`Calibration` and :class:`KinematicsError` need NumPy only;
:class:`Robot` (and everything that computes with a model) loads Pinocchio on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import pose
from .calibration import Calibration
from .errors import KinematicsError
from .models import MODELS, ModelSpec, model_spec

if TYPE_CHECKING:  # pragma: no cover
    from .robot import Robot
    from .urscript import get_forward_kin, get_inverse_kin, get_inverse_kin_has_solution

__all__ = [
    "Robot", "KinematicsError", "MODELS", "ModelSpec", "model_spec", "pose", "Calibration",
    "get_forward_kin", "get_inverse_kin", "get_inverse_kin_has_solution",
]

_LAZY = {
    "Robot": "robot",
    "get_forward_kin": "urscript",
    "get_inverse_kin": "urscript",
    "get_inverse_kin_has_solution": "urscript",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        module = importlib.import_module(f"{__name__}.{_LAZY[name]}")
        value = getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
