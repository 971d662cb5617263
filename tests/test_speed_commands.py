"""``speedj``/``speedl`` in ``urdsl check`` as the manual times them: a command returns after
its ``t`` whether or not the speed was reached, and a loop that streams one speed (the
"move down until contact" pattern of real programs) does not stop between its commands."""

from __future__ import annotations

import pytest

from urdsl.verify.run import CheckOptions, check_text

_START = (0, -1.9, 1.9, -1.57, -1.57, 0)  # a UR5e, tool down, 0.465 m above the base


def _check(text: str, **options):
    return check_text(text, "speed.script", options=CheckOptions(start_joints=_START,
                                                                 **options))


def test_a_loop_streaming_one_speed_until_a_distance_is_one_motion():
    """Down at 0.1 m/s in 8 ms commands until 5 cm are done: 0.2 s to reach the speed
    (1 cm), 0.4 s at it, 0.2 s to stop. Planned from rest each time, it took 5.2 s."""
    report = _check("""start = get_actual_tcp_pose()
travel = 0
while travel < 0.05:
  speedl([0, 0, -0.1, 0, 0, 0], 0.5, 0.008)
  travel = start[2] - get_actual_tcp_pose()[2]
end
stopl(0.5)
""")
    assert not report.findings
    assert len(report.moves) == 1
    assert report.cycle_time == pytest.approx(0.8, abs=0.02)


def test_a_short_speed_command_is_judged_at_the_speed_it_reaches():
    """0.5 m/s asked with a = 1 m/s² for 0.2 s reaches 0.2 m/s: within a 0.25 m/s cell
    (planned as 0.1 m at up to 0.5 m/s, it peaked at 0.32 m/s and was a URS306 error)."""
    report = _check("speedl([0, 0, -0.5, 0, 0, 0], a=1.0, t=0.2)\nstopl(1.0)\n",
                    tcp_speed_limit=0.25)
    assert not [f for f in report.findings if f.code == "URS306"]
    assert report.cycle_time == pytest.approx(0.4, abs=0.01)
    over = _check("speedl([0, 0, -0.5, 0, 0, 0], a=1.0, t=0.4)\nstopl(1.0)\n",
                  tcp_speed_limit=0.25)
    assert [f.severity for f in over.findings if f.code == "URS306"] == ["error"]
