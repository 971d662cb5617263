"""Inverse kinematics: laws, the controller's choice of solution, reach errors, and a cross-check
against ur-analytic-ik."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.kinematics import MODELS, KinematicsError, Robot, pose
from urdsl.kinematics.ik import wrap

ROBOTS = {name: Robot.model(name) for name in MODELS}

joint = st.floats(-2 * math.pi, 2 * math.pi, allow_nan=False)
joints = st.tuples(*[joint] * 6).map(np.array)
models = st.sampled_from(list(MODELS))


def regular(robot: Robot, q: np.ndarray, margin: float = 1e-3) -> bool:
    """Away from the three singularities (where IK(FK(q)) cannot recover q exactly)."""
    measures = robot.singularity(q[None])
    return bool(measures["shoulder"][0] > margin and measures["elbow"][0] > margin
                and measures["wrist"][0] > margin)


@settings(max_examples=300, deadline=None)
@given(models, joints)
def test_fk_of_every_solution_is_the_pose(name, q):
    robot = ROBOTS[name]
    T = robot.fk(q)
    solutions = robot.ik_all(T)
    assert 1 <= len(solutions) <= 8
    assert np.all((solutions > -math.pi) & (solutions <= math.pi))
    for solution in solutions:
        assert np.allclose(robot.fk(solution), T, atol=1e-9, rtol=0)


@settings(max_examples=300, deadline=None)
@given(models, joints)
def test_ik_of_fk_contains_q(name, q):
    robot = ROBOTS[name]
    if not regular(robot, q):
        return
    solutions = robot.ik_all(robot.fk(q))
    closest = np.min(np.max(np.abs(wrap(solutions - q)), axis=1))
    assert closest < 1e-7


@settings(max_examples=200, deadline=None)
@given(models, joints, joints)
def test_ik_returns_the_closest_solution_within_limits(name, q, q_near):
    robot = ROBOTS[name]
    T = robot.fk(q)
    chosen = robot.ik(T, q_near)
    assert np.allclose(robot.fk(chosen), T, atol=1e-9)
    assert np.all((chosen >= robot.q_min) & (chosen <= robot.q_max))
    cost = np.sum((chosen - q_near) ** 2)
    # no solution, moved by any multiple of 2π within the limits, is closer
    for solution in robot.ik_all(T, q6_hint=q_near[5]):
        for shifts in np.ndindex(*(3,) * 6):
            candidate = solution + (np.array(shifts) - 1) * 2 * math.pi
            if np.all((candidate >= robot.q_min) & (candidate <= robot.q_max)):
                assert np.sum((candidate - q_near) ** 2) >= cost - 1e-9


def test_a_joint_is_moved_by_2pi_to_come_closer():
    robot = ROBOTS["ur5e"]
    q = np.array([-3.1, -1.2, 1.3, -1.7, -1.5, 0.4])
    q_near = np.array([3.0, -1.2, 1.3, -1.7, -1.5, 0.4])
    chosen = robot.ik(robot.fk(q), q_near)
    assert np.isclose(chosen[0], -3.1 + 2 * math.pi)
    assert np.allclose(chosen[1:], q[1:])
    # but never beyond the ±2π limit: 0.2 + 2π is out of range, so joint 1 cannot follow
    q = np.array([0.2, -1.2, 1.3, -1.7, -1.5, 0.4])
    q_near = q.copy()
    q_near[0] = 6.2
    chosen = robot.ik(robot.fk(q), q_near)
    assert chosen[0] <= 2 * math.pi
    assert not np.isclose(chosen[0], 0.2 + 2 * math.pi)
    assert np.allclose(robot.fk(chosen), robot.fk(q), atol=1e-9)
    q[0] = -0.3   # 2π − 0.3 lies within the limit and is next to 6.2
    assert np.allclose(robot.ik(robot.fk(q), q_near), q + [2 * math.pi, 0, 0, 0, 0, 0])


def test_unlimited_wrist_3_follows_q_near_over_many_turns():
    robot = ROBOTS["ur3e"]
    q = np.array([0.3, -1.2, 1.3, -1.7, -1.5, 0.4])
    q_near = q.copy()
    q_near[5] = 0.4 + 6 * math.pi + 0.1
    chosen = robot.ik(robot.fk(q), q_near)
    assert np.isclose(chosen[5], 0.4 + 6 * math.pi)
    # a limited wrist 3 (UR5e) cannot go there: it takes the nearest value within ±2π
    assert robot.q_max[5] == math.inf
    assert ROBOTS["ur5e"].ik(ROBOTS["ur5e"].fk(q), q_near)[5] <= 2 * math.pi


def test_wrist_singularity_keeps_wrist_3_of_q_near():
    robot = ROBOTS["ur10e"]
    q = np.array([0.5, -1.0, 1.2, -0.7, 0.0, 0.9])     # θ5 = 0: θ4 and θ6 are coupled
    T = robot.fk(q)
    chosen = robot.ik(T, q)
    assert np.allclose(chosen, q, atol=1e-9)
    for solution in robot.ik_all(T):
        assert np.allclose(robot.fk(solution), T, atol=1e-9)


@pytest.mark.parametrize("theta5", [0.0, math.pi, -math.pi])
@pytest.mark.parametrize("hint", [0.0, 1.0, -2.5])
def test_stretched_arm_at_the_wrist_singularity(theta5, hint):
    """Upright and stretched (θ3 = 0) with θ5 = 0 or π: the wrist-3 hint alone would put the
    wrist-1 point out of reach; the solver moves θ6 just enough."""
    robot = ROBOTS["ur5e"]
    q = np.array([0.3, -math.pi / 2, 0.0, -math.pi / 2, theta5, 1.0])
    T = robot.fk(q)
    solutions = robot.ik_all(T, q6_hint=hint)
    assert len(solutions) >= 1
    for solution in solutions:
        assert np.allclose(robot.fk(solution), T, atol=1e-9)
    # at θ3 = 0, θ3 itself is only determined to √ε (arccos near 1)
    assert np.allclose(robot.ik(T, q), q, atol=1e-7)


def test_ik_with_a_tcp():
    robot = ROBOTS["ur5e"]
    tcp = [0.01, -0.02, 0.2, 0.1, 0.0, math.pi / 2]
    q = np.array([0.4, -1.4, 1.6, -1.9, -1.6, 0.2])
    target = robot.fk(q, tcp)
    assert np.allclose(robot.ik(target, q, tcp=tcp), q, atol=1e-9)
    assert np.allclose(robot.ik(pose.from_matrix(target), q, tcp=tcp), q, atol=1e-9)
    # without the TCP the same target is a different joint vector
    assert not np.allclose(robot.ik(target, q), q, atol=1e-3)


def test_unreachable_pose_reports_the_distance():
    robot = ROBOTS["ur5e"]
    q = np.array([0.3, -0.4, 0.0, -0.8, 1.2, 0.5])     # θ3 = 0: arm fully stretched
    T = robot.fk(q)
    frames = robot.frames_many(q[None])[0]
    outward = frames[3, :3, 3] - frames[1, :3, 3]
    outward /= np.linalg.norm(outward)
    for gap in (0.001, 0.1, 0.5):
        target = T.copy()
        target[:3, 3] += gap * outward
        with pytest.raises(KinematicsError, match="out of reach") as info:
            robot.ik(target, q)
        assert info.value.distance == pytest.approx(gap, abs=1e-6)
        assert robot.out_of_reach(target[None])[0] == pytest.approx(gap, abs=1e-6)
    assert robot.out_of_reach(T[None])[0] == 0.0


def test_pose_inside_the_shoulder_cylinder_is_unreachable():
    robot = ROBOTS["ur5"]
    # tool pointing down with the wrist centre on the base axis
    target = pose.to_matrix([0.0, 0.0, 0.3 + robot.spec.d6, math.pi, 0.0, 0.0])
    with pytest.raises(KinematicsError) as info:
        robot.ik(target, np.zeros(6))
    assert info.value.distance == pytest.approx(abs(robot.spec.d4), abs=1e-9)


def test_ik_many_matches_ik_row_by_row():
    robot = ROBOTS["ur16e"]
    rng = np.random.default_rng(5)
    Q = rng.uniform(-math.pi, math.pi, (50, 6))
    near = Q + rng.normal(0, 0.3, Q.shape)
    T = robot.fk_many(Q)
    far = T[7].copy()
    far[:3, 3] = [3.0, 0.0, 0.0]
    T[7] = far
    batched = robot.ik_many(T, near)
    assert batched.shape == (50, 6)
    assert np.all(np.isnan(batched[7]))
    for i in range(50):
        if i == 7:
            continue
        assert np.allclose(batched[i], robot.ik(T[i], near[i]), atol=1e-9)
    # one q_near for every row, and poses given as 6-vectors
    shared = robot.ik_many(pose.from_matrix(T[:10]), near[0])
    for i in range(10):
        if i != 7:
            assert np.allclose(shared[i], robot.ik(T[i], near[0]), atol=1e-9)
    with pytest.raises(KinematicsError, match="q_near"):
        robot.ik_many(T, np.zeros((3, 6)))


@pytest.mark.parametrize("name", list(MODELS))
def test_same_solutions_as_ur_analytic_ik(name):
    uaik = pytest.importorskip("ur_analytic_ik")
    module = getattr(uaik, name)
    robot = ROBOTS[name]
    rng = np.random.default_rng(11)
    for q in rng.uniform(-math.pi, math.pi, (100, 6)):
        if not regular(robot, q, margin=1e-2):
            continue
        T = robot.fk(q)
        ours = robot.ik_all(T)
        theirs = np.array(module.inverse_kinematics(np.ascontiguousarray(T))).reshape(-1, 6)
        assert len(ours) == len(theirs), q
        for solution in theirs:
            assert np.min(np.max(np.abs(wrap(ours - solution)), axis=1)) < 1e-7


def _choose_one_by_one(solutions, q_first, q_min, q_max):
    from urdsl.kinematics.ik import choose_nearest

    chosen = np.full((len(solutions), 6), np.nan)
    found = np.zeros(len(solutions), dtype=bool)
    near = np.asarray(q_first, dtype=float)
    for row in range(len(solutions)):
        q, ok = choose_nearest(solutions[row:row + 1], near[None], q_min, q_max)
        if not ok[0]:
            break
        chosen[row], found[row], near = q[0], True, q[0]
    return chosen, found


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.floats(0.0, 0.3),
       st.integers(1, 8))
def test_choose_sequence_is_the_row_by_row_choice(seed, count, missing, rounds):
    """Batched rounds give exactly the controller's move-by-move choice, also when branches
    are missing, a target has no solution at all, or the rounds run out."""
    from urdsl.kinematics.ik import choose_sequence

    rng = np.random.default_rng(seed)
    robot = Robot.model("ur5e")
    # a wandering path of nearby solutions: every branch stays close to its neighbours,
    # and other branches lie about π away, so the choice can change branch
    walk = np.cumsum(rng.normal(0.0, 0.4, (count, 1, 6)), axis=0)
    solutions = walk + rng.choice([0.0, np.pi, -np.pi], (count, 8, 6)) \
        + rng.normal(0.0, 0.3, (count, 8, 6))
    scattered = rng.random(count) < rng.random()  # or anywhere: every choice depends on near
    solutions[scattered] = rng.uniform(-np.pi, np.pi, (int(scattered.sum()), 8, 6))
    solutions[rng.random((count, 8)) < missing] = np.nan
    if rng.random() < 0.3:
        solutions[rng.integers(count)] = np.nan  # a target out of reach
    q_first = rng.uniform(-3.0, 3.0, 6)
    expected, expected_found = _choose_one_by_one(solutions, q_first, robot.q_min,
                                                  robot.q_max)
    chosen, found = choose_sequence(solutions, q_first, robot.q_min, robot.q_max,
                                    rounds=rounds)
    np.testing.assert_array_equal(found, expected_found)
    np.testing.assert_array_equal(chosen, expected)
