"""Every phase of ``urdsl check`` keeps to the wall-clock bound (issue 12): the run, sampling
the trajectory, the trace checks, and phases that never look at the clock; a check that
stops early says how far it got (URS313), and what it reports is what a longer bound also
reports (findings do not depend on the machine's speed)."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import numpy as np

import urdsl.verify.infer as infer_module
from urdsl.cli import main
from urdsl.kinematics import Robot
from urdsl.motion import trace as trace_module
from urdsl.motion.planner import MotionPlanner
from urdsl.motion.trace import WINDOW_SAMPLES, sample
from urdsl.script.nodes import NO_SPAN
from urdsl.verify.run import CheckOptions, check_text

#: A toolpath that runs for ever: four straight lines blended into a square, then again.
SQUARE = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
home = get_actual_tcp_pose()
n = 0
while True:
  movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.01)
  movel(pose_add(home, p[0.1, 0.1, 0, 0, 0, 0.3]), r=0.01)
  movel(pose_add(home, p[0, 0.1, 0, 0, 0, 0]), r=0.01)
  movel(home, r=0.01)
  n = n + 1
  if n < 0:
    halt
  end
end
"""  # n decides a branch: no pass begins as an earlier one did (that would end the check)


def identities(report) -> set:
    """What a finding is (rule, statement, cause), without its times and counts."""
    return {(code, span.line, span.column, cause) for code, span, cause
            in (f.identity() for f in report.findings if f.code != "URS313")}


def long_planner(moves: int) -> MotionPlanner:
    """A planner with ``moves`` joint moves back and forth (about 1 s each)."""
    planner = MotionPlanner(Robot.model("ur5e"), [0, -1.9, 1.9, -1.57, -1.57, 0])
    for index in range(moves):
        q = np.array([0.5 * (index % 2), -1.9, 1.9, -1.57, -1.57, 0])
        planner.movej(q, 1.4, 1.05, 0.0, 0.0, NO_SPAN, planner.free_at)
    planner.finish(planner.free_at)
    return planner


def test_sampling_stops_at_its_deadline_with_an_exact_prefix_of_the_trace():
    planner = long_planner(300)  # 300 s of robot time: five windows at 2 ms
    whole = sample(planner)
    assert whole.cut is None
    cut = sample(planner, deadline=time.monotonic() - 1.0)  # passed: one window only
    assert cut.cut is not None and len(cut.times) == WINDOW_SAMPLES - 2
    assert cut.cut == cut.times[-1] + cut.dt
    n = len(cut.times)
    assert np.array_equal(cut.q, whole.q[:n])
    assert np.array_equal(cut.qd, whole.qd[:n])  # central differences, as in the whole
    assert np.array_equal(cut.segment, whole.segment[:n])


def test_windowed_sampling_equals_one_pass(monkeypatch):
    planner = long_planner(12)
    windowed = sample(planner)
    monkeypatch.setattr(trace_module, "WINDOW_SAMPLES", 10**9)
    single = sample(planner)
    assert np.allclose(windowed.q, single.q, atol=1e-12, rtol=0)
    assert np.array_equal(windowed.segment, single.segment)


def test_a_long_toolpath_stops_at_a_small_bound_and_says_so():
    report = check_text(SQUARE, "square.script",
                        options=CheckOptions(timeout=1.0, max_time=1e9, self_collision=False))
    stops = [f for f in report.findings if f.code == "URS313"]
    assert stops and all("wall-clock bound of 1 s" in f.message for f in stops)
    assert all(f.span.line > 0 for f in stops)  # each names the statement where it stopped
    assert not report.has_errors
    if report.trace.cut is not None:  # the trace ends where sampling stopped, said so
        assert any(f"robot time {report.trace.cut:.3f} s" in f.message for f in stops)


def test_findings_of_a_stopped_check_are_a_prefix_of_the_whole_check():
    # a joint-speed error first, then a toolpath repeated for 3000 s of robot time
    text = ("movej([0, -1.5, 1.5, -1.5, -1.5, 0])\n"
            "movej([3, -1.5, 1.5, -1.5, -1.5, 0], t=0.3)\n" + SQUARE)
    whole = check_text(text, "p.script", options=CheckOptions(timeout=None, max_time=3000,
                                                             self_collision=False))
    short = check_text(text, "p.script", options=CheckOptions(timeout=0.5, max_time=3000,
                                                             self_collision=False))
    assert "URS313" not in whole.codes() and "URS304" in whole.codes()
    assert "URS313" in short.codes()
    assert identities(short) <= identities(whole)


def test_a_phase_that_never_looks_at_the_clock_is_abandoned_at_the_bound(tmp_path, capsys,
                                                                         monkeypatch):
    path = tmp_path / "slow.script"
    path.write_text("movej([0, -1.5, 1.5, -1.5, -1.5, 0])\n")
    slow = infer_module.infer

    def infer(*args, **kwargs):  # a phase stuck far past the bound
        time.sleep(6.0)
        return slow(*args, **kwargs)

    monkeypatch.setattr(infer_module, "infer", infer)
    status = main(["check", str(path), "--timeout", "1", "--no-project", "--json"])
    report = json.loads(capsys.readouterr().out)
    assert status == 0
    (finding,) = report["findings"]
    assert finding["code"] == "URS313" and "while inferring the robot" in finding["message"]
    assert finding["line"] == 1


def test_the_command_ends_with_its_report_at_a_small_timeout(tmp_path):
    path = tmp_path / "square.script"
    path.write_text(SQUARE)
    done = subprocess.run([sys.executable, "-m", "urdsl", "check", str(path), "--timeout", "5",
                           "--max-time", "1e9", "--no-project", "--json"],
                          capture_output=True, text=True,
                          timeout=120)  # a guard against a hang, not a measured duration
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    assert any(f["code"] == "URS313" for f in report["findings"])
    assert report["moves"]


def test_the_collision_sweep_stops_at_its_deadline_and_says_where():
    from urdsl.verify.checks import collisions

    trace = sample(long_planner(5))
    partial: dict[str, float] = {}
    findings = collisions(trace, Robot.model("ur5e"), None, deadline=time.monotonic() - 1.0,
                          partial=partial)
    assert findings == [] and partial == {"collisions": 0.0}
    assert collisions(trace, Robot.model("ur5e"), None, partial=partial) == []
