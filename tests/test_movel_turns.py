"""A straight-line move on which a joint turns more than half a turn (issue 12): its end is
where the joints get by following the path, not the whole turn nearest the start. A movel
that turned the tool 174° (o2ac ``flip_endcap.script``) turned wrist 3 by 183°; the check
had ended it 177° the other way, and its trace jumped a full turn at the end (a false URS302
and URS304)."""

from __future__ import annotations

import numpy as np
from _one_move import one_movel

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


def _turn_in_place(args: str):
    """A movel that only turns the tool 2.5 rad about its own axis, with ``args``."""
    robot = Robot.model("ur5e")
    here = from_matrix(robot.fk(START))
    from urdsl.kinematics import pose as posemath

    there = posemath.pose_trans(here, [0, 0, 0, 0, 0, 2.5])
    return [f for f in one_movel("ur5e", START, there, args) if f.code == "URS304"]


def test_a_wrist_over_its_limit_only_by_the_undocumented_turn_rate_is_a_warning():
    """At v = 1 m/s a movel that only turns the tool is timed at 4 rad/s (the rate a user
    measured, which UR does not document): wrist 3 over 3.14 rad/s by that rate is a
    warning that says so, not an error."""
    found = _turn_in_place("a=1.2, v=1.0")
    assert [f.severity for f in found] == ["warning"]
    assert "UR does not document" in found[0].message


def test_a_time_the_program_asks_for_is_judged_at_its_own_a_and_v():
    """The same turn in t = 0.8 s: shorter than the turn rate gives it, a warning that names
    the time the program gives (the controller stretches it, [U])."""
    found = _turn_in_place("a=1.2, v=1.0, t=0.8")
    assert [f.severity for f in found] == ["warning"]
    assert "t=0.8 s the program gives it" in found[0].message


def test_a_speed_on_a_move_whose_path_fails_stays_an_error():
    """On a move whose path leaves the workspace or jumps (URS302), a speed over the limit is
    that failure's, not the turn rate's: it stays an error even when the move is timed by its
    tool turn."""
    from types import SimpleNamespace

    from urdsl.script.nodes import Source, Span
    from urdsl.verify.checks import joint_speeds

    limits = np.full(6, 3.14)
    qd = np.zeros((6, 6))
    qd[1:5, 2] = 4.2  # the elbow over its limit, by less than 2x
    source = Source("movel(a)\n", "t.script")
    segments = [SimpleNamespace(kind="movel", span=Span(source, 0, 8),
                                params={"turn_timed": True})]
    trace = SimpleNamespace(qd=qd, times=np.arange(6) * 0.002, segments=segments,
                            segment=np.zeros(6, dtype=int))
    assert [f.severity for f in joint_speeds(trace, limits)] == ["warning"]
    failed = np.zeros(6, dtype=bool)
    failed[4:] = True  # URS302 reported the path's failure at the move's end
    assert [f.severity for f in joint_speeds(trace, limits, exclude=failed)] == ["error"]
