"""A straight-line move whose joints, followed continuously, run into a joint limit (issue
12): the controller stops the arm there, one URS303 at the move. Inverse kinematics keeps
every point inside the limits, so the trace jumps to another branch at that point; the
check had reported a URS302 for the jump, speeds and collisions for the motion drawn after
it, and a URS302 for the next move, where the trace came back (nedlecky ``start_nut.urp``,
bench/realworld project 135 ``program3.script``)."""

from __future__ import annotations

import numpy as np

from urdsl.kinematics import Robot
from urdsl.kinematics.pose import from_matrix
from urdsl.verify.run import CheckOptions, check_text

WOUND = np.array([0.2, -1.8, 1.9, -1.67, -1.5708, -6.1])
"""Wrist 3 at -349.5°, 10.5° from its limit."""
TURN = np.array([0.3, 0, 0, 0, 0, -0.5])
"""The base turns 0.3 rad and wrist 3 a further -0.5 rad: past -360° on the way."""


def _pose(q: np.ndarray) -> str:
    pose = from_matrix(Robot.model("ur5e").fk(q))
    return "p[" + ", ".join(f"{v:.9f}" for v in pose) + "]"


def _check(start: np.ndarray, **limits):
    text = (f"def wound():\n  movel({_pose(start + TURN)}, a=0.5, v=0.1)\n"
            f"  movel({_pose(start)}, a=0.5, v=0.1)\nend\n")
    options = CheckOptions(robot="ur5e", start_joints=tuple(start), timeout=None, **limits)
    report = check_text(text, "wound.script", options=options)
    return [f for f in report.findings if f.severity in ("error", "warning")]


def test_a_line_into_a_joint_limit_is_one_joint_limit_error():
    found = _check(WOUND, tcp_speed_limit=0.25)
    assert [(f.code, f.span.line) for f in found] == [("URS303", 2)], found
    (finding,) = found
    assert finding.severity == "error"
    assert "takes the wrist 3 joint to its limit of -360.0°" in finding.message
    assert "the controller stops the arm there" in finding.message


def test_the_same_line_further_from_the_limit_is_clean():
    assert _check(WOUND + np.array([0, 0, 0, 0, 0, 0.8]), tcp_speed_limit=0.25) == []
