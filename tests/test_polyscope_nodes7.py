"""PolyScope compile: what the projects of round six (``tune6``) showed (urp11). Fixtures are
written here; the expected forms are what PolyScope wrote."""

from __future__ import annotations

import math

import pytest
from test_polyscope_variants import compiled

from urdsl.polyscope.compile import waypoint_pose
from urdsl.polyscope.urp import Kinematics

# a UR5e as PolyScope 5.9 stores an arm it has no calibration of (``NOT_INITIALIZED``): the
# nominal DH parameters, the twists rounded to 9 digits
UR5E_STORED = Kinematics((0.0,) * 6, (0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
                         (0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996),
                         (1.570796327, 0.0, 0.0, 1.570796327, -1.570796327, 0.0))


def test_set_increment_variable_adds_one():
    # manelpuig/Project_Assistive_Robotics 06_var_global_01 (5.9.1): a Set node of type
    # IncrementVariable on an installation variable
    body = """<Set type="IncrementVariable"><installationVariable name="i_count"/></Set>"""
    lines = compiled(body)
    at = lines.index('$ 2 "Set i_count=i_count+1"')
    assert lines[at + 1] == "i_count = i_count + 1"


@pytest.mark.parametrize(("q", "angle"), [
    # manelpuig/Project_Assistive_Robotics 02_Trajectory_01 (5.9.1): two waypoints taught
    # with the tool pointing straight down; PolyScope wrote ry 3.141592638689 for the first
    # (the trace of the rotation one rounding step above -1) and 3.14159265359 for the second
    ((-1.8654454372554232, -1.2346846680443821, -2.6457453354165446, -0.8319589767725013,
      1.5707963265733558, -0.29464911016810014), 3.141592638689),
    ((-2.228227919628095, -1.815187228347357, -2.1044164502436065, -0.792785301633181,
      1.5707963265553901, -0.6574315925407737), 3.14159265359),
])
def test_a_half_turn_pose_rounds_as_polyscope_computes_it(q, angle):
    pose = waypoint_pose(q, (0.0,) * 6, UR5E_STORED)
    assert math.hypot(*pose[3:]) == pytest.approx(angle, abs=1e-11)
    assert pose[4] == pytest.approx(angle, abs=1e-11)  # about y
