"""The sampled trace of a real arm: knots with Hermite interpolation agree with solving every
sample by inverse kinematics."""

from __future__ import annotations

import numpy as np
import pytest

import urdsl.motion.trace as trace_module
from urdsl.verify.run import CheckOptions, check_text

PROGRAM = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
home = get_actual_tcp_pose()
movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.02)
movel(pose_add(home, p[0.1, 0.1, 0.05, 0.2, 0, 0]), r=0.02)
set_tcp(p[0, 0, 0.1, 0, 0, 0])
movel(pose_add(home, p[-0.1, 0.1, 0.15, 0, 0.3, 0]), v=0.5)
movep(pose_add(home, p[0, 0, 0.1, 0, 0, 0]))
"""


@pytest.mark.parametrize("robot", ["ur5e", "ur10"])
def test_interpolated_samples_match_solving_every_sample(robot, monkeypatch):
    options = CheckOptions(robot=robot, self_collision=False)
    interpolated = check_text(PROGRAM, "x.script", options=options).trace
    monkeypatch.setattr(trace_module, "KNOT_TIME", 0.0)
    dense = check_text(PROGRAM, "x.script", options=options).trace
    assert interpolated.q.shape == dense.q.shape
    assert np.abs(interpolated.q - dense.q).max() < 1e-6
    assert np.abs(interpolated.qd - dense.qd).max() < 1e-3
    assert np.abs(dense.qd).max() > 0.5  # the program moves fast enough to mean something


SLOW = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
home = get_actual_tcp_pose()
movel(pose_add(home, p[0.15, 0, 0, 0, 0, 0]), v=0.03, r=0.01)
movel(pose_add(home, p[0.15, 0.2, -0.1, 0.3, 0, 0]), v=0.06, r=0.01)
movel(pose_add(home, p[-0.1, 0.1, 0.1, 0, -0.2, 0.4]), a=0.5, v=0.1)
movel(home, v=0.02)
"""


@pytest.mark.parametrize("robot", ["ur5e", "ur10"])
def test_slow_moves_solved_every_few_millimetres_match_solving_every_sample(robot,
                                                                           monkeypatch):
    """A slow move cruises with knots every KNOT_PATH of path (here up to 400 ms apart);
    the joints still agree with solving every sample."""
    options = CheckOptions(robot=robot, self_collision=False)
    report = check_text(SLOW, "x.script", options=options)
    assert not report.has_errors, report.render_text()
    interpolated = report.trace
    monkeypatch.setattr(trace_module, "KNOT_TIME", 0.0)
    dense = check_text(SLOW, "x.script", options=options).trace
    assert np.abs(interpolated.q - dense.q).max() < 1e-6
    assert np.abs(interpolated.qd - dense.qd).max() < 1e-4
    assert interpolated.duration > 15.0  # slow indeed


@pytest.mark.parametrize("count", [0, 1, 2, 3, 7, 8, 9, 16, 17, 50])
def test_blocked_derivative_is_numpys_gradient(count):
    """The trace's speeds come from central differences computed in blocks on two threads;
    blocks of 8 rows put block edges everywhere in these short arrays."""
    from urdsl._threads import shared_pool

    values = np.random.default_rng(count).normal(size=(count, 6))
    derivative = trace_module._derivative(values, 0.002, shared_pool(), block=8)
    expected = np.gradient(values, 0.002, axis=0) if count > 1 else np.zeros_like(values)
    np.testing.assert_allclose(derivative, expected, rtol=1e-15, atol=0)
