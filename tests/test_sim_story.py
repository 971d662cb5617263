"""The demo story end to end: check, send to the virtual controller, record RTDE, write the
report, the UR-style CSV and the plot."""

from __future__ import annotations

import numpy as np

from urdsl.sim import demo_story


def test_demo_story_records_the_program_it_sent(tmp_path):
    result = demo_story(tmp_path, speed=4.0)
    assert result.sent and all(path.exists() for path in result.paths())
    header, *rows = result.csv.read_text().splitlines()
    assert header.split()[:2] == ["timestamp", "actual_q_0"]
    data = np.array([[float(v) for v in row.split()] for row in rows])
    assert len(data) == result.samples > 50
    assert 2 in data[:, -1] and data[-1, -1] == 1  # PLAYING during the run, STOPPED after
    # the recording follows the checker's plan: the same joints, and the same cycle time in
    # controller time, however loaded the machine is (the sim's controller time advances in
    # lockstep with its interpreter; a slow machine only makes it slower in wall time). The
    # checker and the sim run the same interpreter and motion planner, so the sim ends the
    # program at the first controller step (8 ms at speed 4) at or after the planned cycle
    # time; the recording sees each end of the run only at its samples, one every
    # speed / frequency = 32 ms of controller time (125 Hz), up to 32 - 8 ms after the step
    # it shows. So observed - planned lies in [-24 ms, 32 ms). (Only a step whose work took
    # the sim more than OVERRUN = 0.25 s of wall time would hold the program and lengthen
    # it: this program's steps take milliseconds, also on a loaded machine.)
    period, step = 4.0 / 125.0, 4.0 * 0.002
    error = result.observed_time - result.planned_time
    assert -(period - step) - 1e-9 <= error < period + 1e-9
    assert result.max_deviation < 0.1
    assert "observed PLAYING" in result.report.read_text()
    assert result.plot.stat().st_size > 10_000


def test_demo_story_does_not_send_a_program_with_errors(tmp_path):
    programs = tmp_path / "programs"
    programs.mkdir()
    (programs / "course_examples.script").write_text(
        "def bad():\n  movej([0, 0, 0, 0, 0, 9])\nend\n")
    result = demo_story(tmp_path / "out", programs=programs)
    assert not result.sent and result.csv is None
    assert "not sent" in result.report.read_text()
