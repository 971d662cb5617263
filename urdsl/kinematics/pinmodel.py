"""Pinocchio models of a UR arm: built from a DH table, or loaded from example-robot-data.

From DH
-------
Joint ``i`` turns about the z axis of DH frame ``i − 1``. Its placement in the previous
joint's frame is the fixed part of the previous link, ``Rz(δθ) · Tz(d) · Tx(a) · Rx(α)``
(Rz(θ) commutes with Rz(δθ), so a θ offset is part of the fixed placement). The model's
universe is the controller's Base frame; frame ``"tool0"`` (alias ``"flange"`` in urdsl
terms) is DH frame 6: the tool flange with Z out of it, the controller's TCP when no TCP
offset is set. Frames ``"dh1"`` … ``"dh5"`` are the intermediate DH frames. Joint names are
the ROS ones (``shoulder_pan_joint`` … ``wrist_3_joint``).

From URDF
---------
example-robot-data ships ROS-Industrial descriptions of the UR3, UR5 and UR10 with collision
meshes. Their root is ``base_link`` (REP-103, X forward), the controller's Base is the frame
``base`` (``base_link`` turned by π about z) and the zero-offset TCP is ``tool0``.
"""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from .errors import KinematicsError

__all__ = ["URDF_JOINT_NAMES", "build_dh_model", "example_robot_data_dir", "urdf_path",
           "load_urdf_model", "URDF_MODELS"]

URDF_JOINT_NAMES = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                    "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
LINK_NAMES = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
              "wrist_2_link", "wrist_3_link")

#: The models example-robot-data describes with meshes.
URDF_MODELS = ("ur3", "ur5", "ur10")


def dh_placement(theta_offset: float, a: float, d: float, alpha: float) -> pin.SE3:
    """``Rz(δθ)·Tz(d)·Tx(a)·Rx(α)`` as an SE3 (m, rad)."""
    ct, st, ca, sa = np.cos(theta_offset), np.sin(theta_offset), np.cos(alpha), np.sin(alpha)
    matrix = np.array([[ct, -st * ca, st * sa, a * ct],
                       [st, ct * ca, -ct * sa, a * st],
                       [0.0, sa, ca, d],
                       [0.0, 0.0, 0.0, 1.0]])
    return pin.SE3(matrix)


def build_dh_model(name: str, theta_offset, a, d, alpha, q_min, q_max, qd_max) -> pin.Model:
    """A Pinocchio model of the six-joint DH chain (m, rad; limits in rad and rad/s).

    Bodies carry no inertia: the model is for kinematics only.
    """
    model = pin.Model()
    model.name = name
    parent = 0
    placement = pin.SE3.Identity()
    parent_frame = 0
    for i in range(6):
        joint = model.addJoint(parent, pin.JointModelRZ(), placement, URDF_JOINT_NAMES[i],
                               np.array([1e3]), np.array([float(qd_max[i])]),
                               np.array([float(q_min[i])]), np.array([float(q_max[i])]))
        joint_frame = model.addJointFrame(joint, parent_frame)
        link = dh_placement(theta_offset[i], a[i], d[i], alpha[i])
        frame_name = "tool0" if i == 5 else f"dh{i + 1}"
        parent_frame = model.addFrame(
            pin.Frame(frame_name, joint, joint_frame, link, pin.FrameType.OP_FRAME), False)
        model.addFrame(pin.Frame(LINK_NAMES[i], joint, joint_frame, pin.SE3.Identity(),
                                 pin.FrameType.BODY), False)
        parent = joint
        placement = link
    return model


def example_robot_data_dir() -> Path:
    """The ``robots`` folder of the installed example-robot-data package."""
    candidates: list[Path] = []
    try:  # the Python loader is optional in the wheels
        import example_robot_data  # type: ignore[import-not-found]

        candidates.append(Path(example_robot_data.__file__).resolve().parent)
    except ImportError:
        pass
    roots = {Path(p) for p in sys.path if p} | {Path(sys.prefix)}
    roots |= set(Path(pin.__file__).resolve().parents)
    for root in roots:
        candidates.append(root / "cmeel.prefix" / "share" / "example-robot-data")
        candidates.append(root / "share" / "example-robot-data")
    for candidate in candidates:
        robots = candidate / "robots"
        if (robots / "ur_description").is_dir():
            return robots
    raise KinematicsError("example-robot-data is not installed (pip install example-robot-data)")


def urdf_path(name: str) -> Path:
    """The example-robot-data URDF of ``name`` (``ur3``, ``ur5``, ``ur10``)."""
    if name not in URDF_MODELS:
        raise KinematicsError(f"example-robot-data has no URDF for {name}; it has "
                              + ", ".join(URDF_MODELS))
    path = example_robot_data_dir() / "ur_description" / "urdf" / f"{name}_robot.urdf"
    if not path.is_file():
        raise KinematicsError(f"missing URDF {path}")
    return path


@cache
def _urdf_model(name: str) -> pin.Model:
    return pin.buildModelFromUrdf(str(urdf_path(name)))


def load_urdf_model(name: str) -> pin.Model:
    """The Pinocchio model of the example-robot-data URDF of ``name`` (a fresh copy)."""
    return pin.Model(_urdf_model(name))
