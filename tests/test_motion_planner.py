"""Motion planning and timing, on a gantry robot whose joints are the TCP pose itself
(x, y, z in m, then a rotation vector): the planner's timing rules are then visible in
closed form, without the kinematics of an arm."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.kinematics.pose import matrix_to_rotvec, rotvec_to_matrix
from urdsl.motion.planner import MotionPlanner
from urdsl.motion.profiles import Trapezoid
from urdsl.motion.trace import sample
from urdsl.script.nodes import NO_SPAN


class OutOfReach(Exception):
    pass


class Gantry:
    """q = (x, y, z, rx, ry, rz); reach: a 1 m box, with ``hole`` outside a column of 0.1 m
    around the z axis (like a UR's base)."""

    def __init__(self, hole: bool = False) -> None:
        self.hole = hole

    def reachable(self, position) -> bool:
        position = np.asarray(position)
        outside = not self.hole or np.hypot(*position[:2]) >= 0.1
        return bool(np.all(np.abs(position) <= 1.0) and outside)

    def fk(self, q, tcp=None):
        matrix = np.eye(4)
        matrix[:3, :3] = rotvec_to_matrix(q[3:])
        matrix[:3, 3] = q[:3]
        return matrix

    def ik(self, pose, q_near, tcp=None):
        if not self.reachable(pose[:3, 3]):
            raise OutOfReach(pose[:3, 3])
        return np.concatenate([pose[:3, 3], matrix_to_rotvec(pose[:3, :3])])

    def ik_many(self, poses, q_near, tcp=None):
        result = np.array([self.ik(p, None) if self.reachable(p[:3, 3]) else np.full(6, np.nan)
                           for p in poses])
        return result.reshape(len(poses), 6)


def pose(x, y, z):
    matrix = np.eye(4)
    matrix[:3, 3] = (x, y, z)
    return matrix


def closed_form(distance, v, a):
    if distance >= v * v / a:
        return distance / v + v / a
    return 2 * math.sqrt(distance / a)


def planner(step=0.002, start=(0, 0, 0, 0, 0, 0), hole=False):
    return MotionPlanner(Gantry(hole), np.array(start, dtype=float), step_time=step)


@pytest.mark.parametrize("distance,v,a", [(0.5, 0.25, 1.2), (0.01, 0.25, 1.2), (0.3, 1.0, 0.5)])
def test_movel_takes_the_closed_form_trapezoid_time(distance, v, a):
    arm = planner()
    end = arm.movel(pose(distance, 0, 0), a, v, 0, 0, NO_SPAN, 0.0)
    arm.finish(end)
    assert end == pytest.approx(closed_form(distance, v, a), rel=1e-12)
    trace = sample(arm)
    assert trace.duration == pytest.approx(end, abs=arm.step_time)
    assert np.abs(trace.qd[:, 0]).max() == pytest.approx(min(v, math.sqrt(a * distance)),
                                                         rel=0.02)


def test_movej_is_timed_by_the_leading_axis():
    arm = planner()
    target = np.array([0.1, -0.4, 0.2, 0.0, 0.0, 0.0])
    end = arm.movej(target, 1.4, 1.05, 0, 0, NO_SPAN, 0.0)
    assert end == pytest.approx(closed_form(0.4, 1.05, 1.4))
    arm.finish(end)
    trace = sample(arm)
    # all joints start and stop together: the others move proportionally slower
    ratio = trace.qd[:, 0] / np.where(trace.qd[:, 1] != 0, trace.qd[:, 1], np.nan)
    assert np.nanmax(np.abs(ratio + 0.25)) < 1e-6
    assert np.allclose(trace.q[-1], target)


def test_time_has_priority_over_speed_and_acceleration():
    arm = planner()
    assert arm.movej(np.array([0.2, 0, 0, 0, 0, 0]), 1.4, 1.05, 3.0, 0, NO_SPAN, 0.0) == \
        pytest.approx(3.0)
    assert arm.movel(pose(0.0, 0, 0), 1.2, 0.25, 2.0, 0, NO_SPAN, 3.0) == pytest.approx(5.0)


def test_a_blend_shortens_the_cycle_and_keeps_the_motion_smooth():
    stopped, blended = planner(), planner()
    for arm, radius in ((stopped, 0.0), (blended, 0.05)):
        now = arm.movel(pose(0.3, 0, 0), 1.2, 0.25, 0, radius, NO_SPAN, 0.0)
        now = arm.movel(pose(0.3, 0.3, 0), 1.2, 0.25, 0, 0, NO_SPAN, now)
        arm.finish(now)
    assert blended.end_time < stopped.end_time - 0.1
    trace = sample(blended)
    speed = np.linalg.norm(trace.qd[:, :3], axis=1)
    middle = (trace.times > 0.5) & (trace.times < blended.end_time - 0.5)
    assert speed[middle].min() > 0.1  # the TCP never stops at the waypoint
    corner = np.linalg.norm(trace.q[:, :3] - [0.3, 0, 0], axis=1)
    assert 0.0 < corner.min() < 0.05  # it passes inside the blend sphere, not through it
    assert np.abs(np.diff(trace.q, axis=0)).max() < 0.25 * blended.step_time * 2


def test_overlapping_blend_spheres_skip_the_move_with_a_warning():
    arm = planner()
    now = arm.movel(pose(0.2, 0, 0), 1.2, 0.25, 0, 0.05, NO_SPAN, 0.0)
    now = arm.movel(pose(0.2, 0.06, 0), 1.2, 0.25, 0, 0.05, NO_SPAN, now)  # 0.05 + 0.05 > 0.06
    arm.finish(now)
    assert len(arm.segments) == 1 and len(arm.skipped) == 1
    assert "Overlapping Blends" in arm.warnings[0].message


def test_the_start_point_counts_as_radius_zero():
    arm = planner()
    arm.movel(pose(0.04, 0, 0), 1.2, 0.25, 0, 0.05, NO_SPAN, 0.0)
    assert arm.skipped and not arm.segments


def test_blends_that_just_fit_are_kept():
    arm = planner()
    now = arm.movel(pose(0.2, 0, 0), 1.2, 0.25, 0, 0.03, NO_SPAN, 0.0)
    now = arm.movel(pose(0.2, 0.07, 0), 1.2, 0.25, 0, 0.03, NO_SPAN, now)
    now = arm.movel(pose(0.0, 0.07, 0), 1.2, 0.25, 0, 0.0, NO_SPAN, now)
    arm.finish(now)
    assert not arm.skipped and len(arm.segments) == 3


def test_servoj_moves_at_constant_speed_for_its_time():
    arm = planner()
    now = 0.0
    for k in range(1, 101):
        now = arm.servoj(np.array([0.001 * k, 0, 0, 0, 0, 0]), 0.002, NO_SPAN, now)
    arm.finish(now)
    assert now == pytest.approx(0.2)
    trace = sample(arm)
    assert np.allclose(trace.qd[2:-2, 0], 0.5, atol=1e-6)


def test_speedj_cruises_for_t_then_stops():
    arm = planner()
    resume = arm.speedj(np.array([0.2, 0, 0, 0, 0, 0]), 0.5, 1.0, NO_SPAN, 0.0)
    assert resume == pytest.approx(1.0)
    arm.finish(arm.stop(resume))
    assert arm.end_time == pytest.approx(1.0 + 0.2 / 0.5)
    assert arm.target_joints[0] == pytest.approx(0.2 * 1.0)


def test_a_speed_command_shorter_than_its_ramp_reaches_only_a_t():
    # the manual: with t "the function will return after time t, regardless of the target
    # speed has been reached": 0.1 s at 0.5 m/s² reaches 0.05 m/s, not the asked 0.2
    for command in ("speedj", "speedl"):
        arm = planner()
        resume = getattr(arm, command)(np.array([0.2, 0, 0, 0, 0, 0]), 0.5, 0.1, NO_SPAN, 0.0)
        assert resume == pytest.approx(0.1)
        arm.finish(arm.stop(resume))
        assert arm.end_time == pytest.approx(0.2)  # and as long to stop
        trace = sample(arm)
        assert np.abs(trace.qd[:, 0]).max() == pytest.approx(0.05, rel=0.05)
        assert arm.target_joints[0] == pytest.approx(0.5 * 0.1 ** 2)


@pytest.mark.parametrize("command", ["speedj", "speedl"])
def test_a_streamed_speed_goes_on_without_stopping_between_commands(command):
    # a loop giving the same speed every 8 ms (until a force or a distance stops it): the
    # arm ramps up once, cruises and stops once, as one command of 100 x 8 ms
    arm = planner()
    now = 0.0
    speed = np.array([0, 0, -0.1, 0, 0, 0])
    for _ in range(100):
        now = getattr(arm, command)(speed, 0.5, 0.008, NO_SPAN, now)
    assert now == pytest.approx(0.8)
    arm.finish(arm.stop(now))
    assert arm.end_time == pytest.approx(0.8 + 0.1 / 0.5)
    assert len(arm.segments) == 1
    assert arm.target_joints[2] == pytest.approx(-0.1 * 0.8)
    trace = sample(arm)
    assert np.abs(trace.qd[:, 2]).max() == pytest.approx(0.1, rel=0.01)
    # what a read in the loop sees is where the arm is then, not where the chain ends
    assert arm.joints_at(0.2)[2] == pytest.approx(-0.5 * 0.5 * 0.2 ** 2, abs=1e-9)


def test_a_speed_chain_breaks_at_a_pause_a_stop_or_another_speed():
    speed = np.array([0.1, 0, 0, 0, 0, 0])
    arm = planner()
    now = arm.speedj(speed, 0.5, 0.4, NO_SPAN, 0.0)
    now = arm.speedj(speed, 0.5, 0.4, NO_SPAN, now + 0.1)  # a sleep between: it stopped
    assert len(arm.segments) == 2
    now = arm.speedj(speed, 0.5, 0.4, NO_SPAN, arm.stop(now))
    assert len(arm.segments) == 3
    now = arm.speedj(2 * speed, 0.5, 0.4, NO_SPAN, now)
    assert len(arm.segments) == 4
    now = arm.speedj(2 * speed, 0.5, 0.4, NO_SPAN, now)  # the same again: goes on
    assert len(arm.segments) == 4 and arm.segments[-1].params["t"] == pytest.approx(0.8)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.floats(-0.8, 0.8), st.floats(-0.8, 0.8), st.floats(0, 0.01)),
                min_size=1, max_size=6),
       st.floats(0, 1))
def test_joints_at_agrees_with_the_sampled_trace(waypoints, where):
    arm = planner()
    now = 0.0
    for x, y, radius in waypoints:
        now = arm.movel(pose(x, y, 0.0), 1.2, 0.25, 0, radius, NO_SPAN, now)
    arm.finish(now)
    trace = sample(arm)
    index = int(where * (len(trace.times) - 1))
    assert np.allclose(arm.joints_at(float(trace.times[index])), trace.q[index], atol=1e-9)


def test_trapezoid_profile_is_consistent():
    profile = Trapezoid.plan(0.5, 0.25, 1.2)
    times = np.linspace(0, profile.duration, 1001)
    positions = profile.position(times)
    assert positions[0] == 0 and positions[-1] == pytest.approx(0.5)
    assert np.all(np.diff(positions) >= -1e-15)
    for s in (0.0, 0.01, 0.25, 0.49, 0.5):
        assert profile.position(profile.time_at(s)) == pytest.approx(s, abs=1e-12)


def test_samples_out_of_reach_are_marked_and_the_trace_stays_finite():
    arm = planner(start=(-0.5, 0.02, 0, 0, 0, 0), hole=True)
    arm.finish(arm.movel(pose(0.5, 0.02, 0), 1.2, 0.25, 0, 0, NO_SPAN, 0.0))
    trace = sample(arm)
    assert np.isfinite(trace.q).all()
    inside = trace.unreachable.nonzero()[0]
    assert len(inside) > 0
    x = 0.02
    crossing = np.abs(trace.q[inside[0] - 1, 0])
    assert crossing == pytest.approx(np.sqrt(0.1 ** 2 - x ** 2), abs=0.01)
    assert np.allclose(trace.q[-1, :3], (0.5, 0.02, 0))


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 0.5), st.floats(0.0, 3.0), st.floats(0.05, 1.0), st.floats(0.2, 3.0))
def test_a_line_takes_the_longer_of_its_path_and_rotation_profiles(length, angle, v, a):
    from urdsl.motion.planner import ROTATION_PER_METRE, line_profile

    start, end = pose(0, 0, 0), pose(length, 0, 0)
    end[:3, :3] = rotvec_to_matrix(np.array([0.0, 0.0, angle]))
    profile = line_profile(start, end, v, a, 0.0, ROTATION_PER_METRE * v,
                           ROTATION_PER_METRE * a)
    expected = max(closed_form(length, v, a) if length > 1e-9 else 0.0,
                   closed_form(angle, ROTATION_PER_METRE * v, ROTATION_PER_METRE * a)
                   if angle > 1e-9 else 0.0)
    assert profile.duration == pytest.approx(expected, rel=1e-9, abs=1e-12)
    if length > 1e-9:  # the path's distance, whatever profile leads
        assert profile.distance == pytest.approx(length)
        assert float(profile.position(profile.duration)) == pytest.approx(length)


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, -1, 0), (0.6, 0.8, 0)])
def test_a_move_that_a_condition_stops_goes_as_far_as_the_arm_can_follow_it(direction):
    arm = planner()
    arm.stoppable = frozenset({NO_SPAN})  # this move is in a thread killed under a condition
    target = pose(*(100.0 * np.array(direction)))
    end = arm.movel(target, 1.2, 0.25, 0, 0, NO_SPAN, 0.0)
    arm.finish(end)
    (move,) = arm.segments
    reached = move.pose_end[:3, 3]
    # the gantry's box ends at |x|, |y| = 1 m; the move stops 5 cm of path before its edge
    edge = 1.0 / max(abs(c) for c in direction)
    assert np.linalg.norm(reached) == pytest.approx(edge - 0.05, abs=0.002)
    assert move.params["until"] and arm.failure is None


def test_a_move_without_a_condition_to_the_same_target_is_not_cut():
    arm = planner()
    with pytest.raises(OutOfReach):
        arm.movel(pose(100.0, 0, 0), 1.2, 0.25, 0, 0, NO_SPAN, 0.0)


def test_movec_fixed_mode_turns_the_tool_with_the_arc():
    # mode 1 keeps the tool's orientation relative to the arc's tangent: half a circle in
    # the xy plane turns it by 180 degrees about z, whatever the target's orientation says;
    # mode 0 goes from the start's orientation to the target's
    start = (0.3, 0.0, 0.2, 0.0, 0.0, 0.0)
    target = pose(-0.3, 0.0, 0.2)
    target[:3, :3] = rotvec_to_matrix(np.array([0.0, 0.0, 1.0]))  # 57 degrees about z
    fixed = planner(start=start)
    fixed.movec(pose(0.0, 0.3, 0.2), target, a=1.2, v=0.25, r=0.0, mode=1, span=NO_SPAN,
                now=0.0)
    (segment,) = fixed.segments
    halfway = segment.path_poses(np.array([0.5]))[0]
    assert np.allclose(halfway[:3, 3], (0.0, 0.3, 0.2), atol=1e-9)
    assert np.allclose(matrix_to_rotvec(halfway[:3, :3]), (0, 0, math.pi / 2), atol=1e-9)
    assert abs(abs(matrix_to_rotvec(segment.pose_end[:3, :3])[2]) - math.pi) < 1e-9
    free = planner(start=start)
    free.movec(pose(0.0, 0.3, 0.2), target, a=1.2, v=0.25, r=0.0, mode=0, span=NO_SPAN,
               now=0.0)
    assert np.allclose(matrix_to_rotvec(free.segments[0].pose_end[:3, :3]), (0, 0, 1.0))
