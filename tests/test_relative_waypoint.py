"""PolyScope's relative waypoint, ``movel(pose_add(get_target_tcp_pose(), pose_sub(to, from)))``,
turns the tool the way its ``from`` and ``to`` poses were taught (issue 12): a tool turned
-90 degrees about its own axis turns wrist 3 by -90 degrees, not +90. With the rotations of
``pose_sub`` in the other order, a real program (o2ac ``bearing_orient_totb.script``) had its
wrist 3 a full turn away from the joints PolyScope stored for the waypoints taught after two
such moves, and got joint-limit, speed and collision errors its arm never met."""

from __future__ import annotations

import math

import numpy as np

from urdsl.kinematics import Robot, pose
from urdsl.verify.run import CheckOptions, check_text

START = (0.0, -math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, 0.0)


def program(turn: float) -> str:
    """A program at START that teaches ``from`` where the arm is and ``to`` turned ``turn``
    rad about the tool's own z axis, then runs the relative waypoint once."""
    here = Robot.model("ur5e").fk(np.array(START))
    from_p = pose.from_matrix(here)
    to_p = pose.pose_trans(from_p, [0, 0, 0, 0, 0, turn])

    def text(p) -> str:
        return "p[" + ", ".join(f"{v:.9f}" for v in p) + "]"

    return f"""def relative():
  global turn_from_p={text(from_p)}
  global turn_to_p={text(to_p)}
  $ 1 "Robot Program"
  $ 2 "MoveL"
  $ 3 "turn" "breakAfter"
  movel(pose_add(get_target_tcp_pose(), pose_sub(turn_to_p, turn_from_p)), a=1.2, v=0.25)
end
"""


def check(turn: float, wrist_3_max: float):
    limits_min = (-2 * math.pi,) * 5 + (-2.0,)
    limits_max = (2 * math.pi,) * 5 + (wrist_3_max,)
    options = CheckOptions(robot="ur5e", start_joints=START, q_min=limits_min, q_max=limits_max,
                           self_collision=False, timeout=None)
    return check_text(program(turn), "relative.script", options=options)


def test_a_relative_turn_goes_the_way_it_was_taught():
    """Taught as a -90 degree turn of the tool, it ends with wrist 3 at -90 degrees, inside a
    cell limit of +1 rad: no joint-limit error."""
    report = check(-math.pi / 2, 1.0)
    assert [f.code for f in report.findings if f.severity == "error"] == []


def test_the_same_turn_the_other_way_meets_the_limit():
    """The check still sees the limit: taught as a +90 degree turn, wrist 3 ends at +90
    degrees, beyond +1 rad."""
    report = check(math.pi / 2, 1.0)
    assert "URS303" in [f.code for f in report.findings if f.severity == "error"]
