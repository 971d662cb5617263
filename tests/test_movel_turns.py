"""A straight-line move on which a joint turns more than half a turn (issue 12): its end is
where the joints get by following the path, not the whole turn nearest the start. A movel
that turned the tool 174° (o2ac ``flip_endcap.script``) turned wrist 3 by 183°; the check
had ended it 177° the other way, and its trace jumped a full turn at the end (a false URS302
and URS304)."""

from __future__ import annotations

import numpy as np

from urdsl.kinematics import Robot
from urdsl.kinematics.pose import from_matrix
from urdsl.motion.planner import MotionPlanner
from urdsl.verify.run import CheckOptions, check_text

START = np.array([0.0, -1.8, 1.9, -1.67, -1.5708, 0.55])
TURN = np.array([-0.6, 0, 0, 0, 0, -3.3])
"""The base turns -0.6 rad and wrist 3 -3.3 rad (189°): the tool turns 155° about the
vertical, the short way, the way wrist 3 goes."""


def target() -> str:
    pose = from_matrix(Robot.model("ur5e").fk(START + TURN))
    return "p[" + ", ".join(f"{v:.9f}" for v in pose) + "]"


def test_a_long_wrist_turn_on_a_movel_is_no_jump():
    text = f"def turn():\n  movel({target()}, a=0.5, v=0.05)\nend\n"
    options = CheckOptions(robot="ur5e", start_joints=tuple(START), timeout=None)
    report = check_text(text, "turn.script", options=options)
    assert [f.code for f in report.findings if f.severity in ("error", "warning")] == []


def test_the_move_ends_where_the_joints_get_along_the_path():
    robot = Robot.model("ur5e")
    for lazy in (True, False):
        planner = MotionPlanner(robot, START, lazy_ik=lazy)
        planner.movel(robot.fk(START + TURN), 0.5, 0.05, 0.0, 0.0, None, 0.0)
        planner.resolve()
        assert np.allclose(planner.segments[-1].q_end, START + TURN, atol=1e-6)
