"""A joint over its speed limit on an ordinary move (issue 12): the controller slows a running
program so that no joint exceeds its limit, and stops it only when one does (CB3 user manual,
safety "Joint Limits"). Up to 2x over, the move takes longer: a URS304 warning that says so
(project 126's UR10 rack loop at v=1 m/s, CA-Giken TEST_SUB_106). A time ``t`` the program gives
is judged at the speeds the move's own a and v give when t is shorter (what t adds, the
controller stretches: project 26's 0.1 s lines). Faster — near a singularity, where the joints
speed up without bound — servo commands and a move whose path fails stay errors."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from _one_move import one_movel

from urdsl.kinematics import Robot
from urdsl.kinematics.pose import from_matrix
from urdsl.script.nodes import Source, Span
from urdsl.verify.checks import joint_speeds

START = np.array([0.0, -1.2, 1.6, -1.97, -1.5708, 0.0])


def _sweep(v: float, t: float = 0.0) -> list:
    """A UR10 movel that swings the base 1 rad on a chord at ``v`` m/s (``t`` s if given)."""
    pose = from_matrix(Robot.model("ur10").fk(START + np.array([1.0, 0, 0, 0, 0, 0])))
    args = f"a=10, v={v}" + (f", t={t}" if t else "")
    return [f for f in one_movel("ur10", START, pose, args) if f.code == "URS304"]


def test_a_fast_movel_a_little_over_a_joint_limit_is_a_warning_that_it_takes_longer():
    found = _sweep(2.0)
    assert [(f.severity, f.message.split(" joint")[0]) for f in found] == [("warning", "base")]
    assert "takes longer than planned" in found[0].message


def test_a_time_too_short_for_the_joints_is_a_warning_that_names_the_time():
    """The same sweep at v = 0.5 m/s keeps every joint within its limit; given t = 0.35 s it
    does not, by what the time adds: the controller stretches it (a warning naming t)."""
    assert _sweep(0.5) == []
    found = _sweep(0.5, t=0.35)
    assert [f.severity for f in found] == ["warning"]
    assert "longer than the t=0.35 s the program gives it" in found[0].message


def _speeds(kind: str, factor: float, **params) -> list[str]:
    limits = np.full(6, 3.14)
    qd = np.zeros((6, 6))
    qd[1:5, 0] = 3.14 * factor
    source = Source("movel(a)\n", "t.script")
    segments = [SimpleNamespace(kind=kind, span=Span(source, 0, 8), params=params)]
    trace = SimpleNamespace(qd=qd, times=np.arange(6) * 0.002, segments=segments,
                            segment=np.zeros(6, dtype=int))
    return [f.severity for f in joint_speeds(trace, limits)]


@pytest.mark.parametrize(("kind", "factor", "params", "severity"), [
    ("movel", 1.5, {}, "warning"),
    ("movej", 1.9, {"t": 0.0}, "warning"),
    ("movec", 1.2, {}, "warning"),
    ("movel", 2.5, {}, "error"),          # near a singularity: the arm stops
    ("movej", 1.5, {"t": 0.4}, "error"),  # a given time, the move's own timing unknown
    ("movej", 1.5, {"t": 0.4, "t_free": 1.0}, "warning"),  # what the too short t adds
    ("movel", 6.0, {"t": 0.4, "t_free": 1.2}, "warning"),  # 2x at its own a and v
    ("movel", 6.0, {"t": 0.4, "t_free": 0.8}, "error"),    # 3x at its own a and v: the path's
    ("movej", 2.5, {"t": 1.0, "t_free": 0.5}, "error"),    # t longer than a and v give
    ("movej", 1.5, {"t": 1.0, "t_free": 0.5}, "warning"),
    ("servoj", 1.5, {"t": 0.008}, "error"),
    ("speedj", 1.5, {}, "error"),
])
def test_which_speeds_the_controller_slows(kind, factor, params, severity):
    assert _speeds(kind, factor, **params) == [severity]


_HOME = "movej([0, -1.57, 1.57, -1.57, -1.57, 0], a=1.4, v=1.0)"
_LEFT = "movel(p[0.45, -0.3, 0.3, 0, 3.14, 0], a=10, v=0.25)"
_RIGHT = "movel(p[0.45, 0.3, 0.3, 0, 3.14, 0], a=10, v=1.0)"  # on a UR10: base 1.1x its limit


def _checked(*body: str, indent: str = "  "):
    from urdsl.verify.run import check_text

    text = "def prog():\n" + "".join(f"{indent}{line}\n" for line in body) + "end\n"
    return check_text(text, "slowed.script", robot="ur10")


def test_a_move_the_controller_slows_says_how_much_longer_the_cycle_may_take():
    """The cycle time is the program as planned; the moves the controller slows add up to
    their planned time times the factor their fastest joint exceeds its limit by."""
    report = _checked(_HOME, _LEFT, _RIGHT)
    [warning] = [f for f in report.findings if f.code == "URS304"]
    assert warning.severity == "warning" and 1.0 < warning.slowed < 2.0
    right = report.moves[-1]
    assert report.slowed is not None and report.slowed.moves == 1
    assert report.slowed.up_to == pytest.approx(right.duration * (warning.slowed - 1.0))
    assert report.to_dict()["slowed"] == {"moves": 1, "up_to": round(report.slowed.up_to, 6)}
    assert f"the controller slows 1 move: up to {report.slowed.up_to:.3f} s longer" \
        in report.summary()


def test_a_program_within_its_limits_is_not_slowed():
    report = _checked(_HOME, _LEFT)
    assert report.slowed is None and "slowed" not in report.to_dict()
    assert "slows" not in report.summary()


def test_a_loop_counts_what_its_slowed_moves_add_to_one_pass():
    """The loop's passes each slow the same move: one move, its extra time once per pass."""
    once = _checked(_HOME, _LEFT, _RIGHT).slowed
    report = _checked(_HOME, "while True:", f"  {_LEFT}", f"  {_RIGHT}", "end")
    assert report.loop is not None and report.loop.passes >= 2
    assert report.slowed is not None and report.slowed.moves == 1
    assert report.slowed.up_to == pytest.approx(once.up_to, rel=0.05)


def _tcp(move: str) -> list:
    """The URS306 findings of ``move`` from a UR5e's tool-down pose in a 0.25 m/s cell."""
    from urdsl.verify.run import CheckOptions, check_text

    text = ("movej([0, -1.9, 1.9, -1.57, -1.57, 0])\nhome = get_actual_tcp_pose()\n"
            f"{move}\n")
    report = check_text(text, "tcp.script", options=CheckOptions(
        tcp_speed_limit=0.25, start_joints=(0, -1.9, 1.9, -1.57, -1.57, 0)))
    return [f for f in report.findings if f.code == "URS306"]


def test_a_move_far_over_the_cells_tcp_speed_is_slowed_not_stopped():
    """A line asked at 1 m/s in a 0.25 m/s cell (4x) runs at the limit: the controller
    slows a program's moves to the safety limit (Reduced mode slows a running 1 m/s program
    to 0.25 m/s without stopping it); only the cycle takes longer."""
    [finding] = _tcp("movel(pose_add(home, p[0.3, 0, 0, 0, 0, 0]), a=10, v=1.0)")
    assert finding.severity == "warning" and "takes longer" in finding.message
    assert finding.slowed == pytest.approx(4.0, rel=0.02)


def test_a_speed_command_over_the_cells_tcp_speed_stays_an_error():
    [finding] = _tcp("speedl([0.5, 0, 0, 0, 0, 0], a=2, t=0.5)")
    assert finding.severity == "error" and finding.slowed is None
