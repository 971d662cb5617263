"""Forward kinematics of the fourteen UR models against three independent references.

* DH test vectors computed from the nominal DH tables (docs/controller-facts.md §1) with
  40-digit arithmetic, to 12 decimals, for the nine CB3/e-Series/UR20/UR30 models, and the
  closed forms at q = 0 and q = upright for all fourteen;
* the example-robot-data URDF chain ``base`` → ``tool0`` (UR3, UR5, UR10);
* ur-analytic-ik's compiled forward kinematics (all fourteen models);

each over 1,000 random joint vectors in [−2π, 2π]. Positions in m, rotations compared as
matrices.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

from urdsl.kinematics import MODELS, KinematicsError, Robot, pose

Q_NAMED = {
    "q_zero": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    "q_upright": (0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0),
    "q_a": (0.1, -1.2, 1.3, -1.7, -1.5, 0.4),
    "q_b": (1.0, -0.5, -1.0, 0.7, 2.0, -3.0),
}

# 40-digit DH test vectors: TCP positions [m] per model at q_zero, q_upright, q_a, q_b.
POSITIONS = {
    "ur3": [(-0.4569, -0.19425, 0.06655), (0.0, -0.19425, 0.69415),
            (-0.374438261499, -0.156305705255, 0.278534021453),
            (-0.118933657501, -0.330087053219, 0.475386475628)],
    "ur5": [(-0.81725, -0.19145, -0.005491), (0.0, -0.19145, 1.001059),
            (-0.626617332374, -0.178420379646, 0.366820855807),
            (-0.218338109749, -0.478669620276, 0.671922443278)],
    "ur10": [(-1.1843, -0.256141, 0.0116), (0.0, -0.256141, 1.4273),
             (-0.887978135413, -0.260413845692, 0.552021818548),
             (-0.282796535801, -0.672840624966, 0.971106986574)],
    "ur3e": [(-0.45675, -0.22315, 0.0665), (0.0, -0.22315, 0.69395),
             (-0.372709393282, -0.175651273151, 0.268225698705),
             (-0.110211959565, -0.343257914121, 0.48189201681)],
    "ur5e": [(-0.8172, -0.2329, 0.0628), (0.0, -0.2329, 1.0794),
             (-0.629558679674, -0.204216651898, 0.423064999986),
             (-0.211951633077, -0.500095819622, 0.752979817469)],
    "ur10e": [(-1.18425, -0.2907, 0.06085), (0.0, -0.2907, 1.4848),
              (-0.891130026853, -0.272721447388, 0.581991652822),
              (-0.292979207895, -0.688839534376, 1.037086393026)],
    "ur16e": [(-0.8384, -0.2907, 0.06085), (0.0, -0.2907, 1.13895),
              (-0.633266958686, -0.246848841001, 0.477938562868),
              (-0.221214206223, -0.577072166411, 0.761679478775)],
    "ur20": [(-1.5907, -0.3553, 0.077), (0.0, -0.3553, 1.9863),
             (-1.173981333099, -0.330769788977, 0.817772717101),
             (-0.436030882136, -0.932248249633, 1.366102386557)],
    "ur30": [(-1.1407, -0.3553, 0.077), (0.0, -0.3553, 1.5363),
             (-0.870100661211, -0.30028002141, 0.630526441504),
             (-0.320745527272, -0.752701947428, 1.033795268385)],
}

# 40-digit DH test vectors: rotation matrices (rows), the same for every model.
ROTATIONS = {
    "q_zero": [(1, 0, 0), (0, 0, -1), (0, 1, 0)],
    "q_upright": [(-1, 0, 0), (0, 0, -1), (0, -1, 0)],
    "q_a": [(0.293692391793, 0.955648648568, -0.021918930014),
            (0.952834241177, -0.294508490185, -0.073291596041),
            (-0.076496325693, 0.000640077092, -0.997069657776)],
    "q_b": [(-0.657103369768, -0.297839345466, -0.692464357012),
            (0.642722058160, -0.701354081651, -0.308238232713),
            (-0.393857229709, -0.647606498148, 0.652290047573)],
}

ALL = list(MODELS)


@pytest.fixture(scope="module")
def robots() -> dict[str, Robot]:
    return {name: Robot.model(name) for name in ALL}


def random_q(n: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-2 * np.pi, 2 * np.pi, (n, 6))


@pytest.mark.parametrize("name", list(POSITIONS))
def test_fk_matches_the_dh_test_vectors(robots, name):
    robot = robots[name]
    for (label, q), position in zip(Q_NAMED.items(), POSITIONS[name], strict=True):
        for T in (robot.fk(q), robot.fk_many(np.array([q]))[0]):
            assert np.allclose(T[:3, 3], position, atol=1e-9, rtol=0), (name, label)
            assert np.allclose(T[:3, :3], ROTATIONS[label], atol=1e-9, rtol=0), (name, label)
            assert np.array_equal(T[3], [0, 0, 0, 1])


@pytest.mark.parametrize("name", ALL)
def test_closed_forms_at_zero_and_upright(robots, name):
    spec = MODELS[name]
    d1, a2, a3, d4, d5, d6 = spec.d1, spec.a2, spec.a3, spec.d4, spec.d5, spec.d6
    zero = robots[name].fk(Q_NAMED["q_zero"])[:3, 3]
    upright = robots[name].fk(Q_NAMED["q_upright"])[:3, 3]
    assert np.allclose(zero, (a2 + a3, -(d4 + d6), d1 - d5), atol=1e-12)
    assert np.allclose(upright, (0.0, -(d4 + d6), d1 - a2 - a3 + d5), atol=1e-12)


@pytest.mark.parametrize("name", ALL)
def test_pinocchio_and_vectorised_fk_agree(robots, name):
    robot = robots[name]
    Q = random_q(1000, 1)
    batched = robot.fk_many(Q)
    single = np.array([robot.fk(q) for q in Q])
    assert batched.shape == (1000, 4, 4)
    assert np.max(np.abs(batched - single)) < 1e-12


@pytest.mark.parametrize("name", ALL)
def test_fk_matches_ur_analytic_ik(robots, name):
    uaik = pytest.importorskip("ur_analytic_ik")
    module = getattr(uaik, name)
    Q = random_q(1000, 2)
    reference = np.array([module.forward_kinematics(*q) for q in Q])
    assert np.max(np.abs(robots[name].fk_many(Q) - reference)) < 1e-9


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10"])
def test_fk_matches_the_example_robot_data_urdf(robots, name):
    robot = robots[name]
    model = robot.urdf_model()
    data = model.createData()
    base, tool0 = model.getFrameId("base"), model.getFrameId("tool0")
    Q = random_q(1000, 3)
    worst = 0.0
    for q in Q:
        pin.framesForwardKinematics(model, data, q)
        urdf = (data.oMf[base].inverse() * data.oMf[tool0]).homogeneous
        worst = max(worst, float(np.max(np.abs(urdf - robot.fk(q)))))
    assert worst < 1e-6


def test_ros_base_link_is_the_base_turned_by_pi(robots):
    """A controller pose (x, y, z) appears in ROS base_link as (−x, −y, z)."""
    robot = robots["ur5"]
    model = robot.urdf_model()
    data = model.createData()
    q = np.array(Q_NAMED["q_a"])
    pin.framesForwardKinematics(model, data, q)
    in_base_link = data.oMf[model.getFrameId("tool0")].translation
    x, y, z = robot.fk(q)[:3, 3]
    assert np.allclose(in_base_link, (-x, -y, z), atol=1e-9)


def test_urdf_model_only_for_the_described_arms(robots):
    with pytest.raises(KinematicsError, match="ur3, ur5, ur10"):
        robots["ur5e"].urdf_model()


def test_tcp_offset_is_applied_in_the_flange_frame(robots):
    robot = robots["ur10e"]
    tcp = [0.0, 0.0, 0.15, 0.0, 0.0, np.pi / 4]
    Q = random_q(20, 4)
    flange = robot.fk_many(Q)
    with_tcp = robot.fk_many(Q, tcp=tcp)
    for q, f, t in zip(Q, flange, with_tcp, strict=True):
        assert np.allclose(t, f @ pose.to_matrix(tcp), atol=1e-12)
        assert np.allclose(robot.fk(q, tcp=tcp), t, atol=1e-12)
        # 15 cm out along the flange's Z axis
        assert np.allclose(t[:3, 3] - f[:3, 3], 0.15 * f[:3, 2], atol=1e-12)
    assert np.allclose(robot.fk_pose(Q[0], tcp), pose.pose_trans(robot.fk_pose(Q[0]), tcp))


def test_bad_joint_input_is_rejected(robots):
    robot = robots["ur5e"]
    with pytest.raises(KinematicsError, match="6 joint angles"):
        robot.fk([0, 0, 0, 0, 0])
    with pytest.raises(KinematicsError, match="finite"):
        robot.fk([0, 0, np.nan, 0, 0, 0])
    with pytest.raises(KinematicsError, match=r"\(N, 6\)"):
        robot.fk_many(np.zeros((3, 5)))


def test_course_pose_as_matrix():
    """The course notes' p1 = p[0.2, -0.3, 0.3, 0.5, 0.0, -0.3] as a 4x4 matrix."""
    expected = [[0.95626064, 0.28328667, -0.07289894, 0.2],
                [-0.28328667, 0.83476241, -0.47214445, -0.3],
                [-0.07289894, 0.47214445, 0.87850177, 0.3],
                [0, 0, 0, 1]]
    assert np.allclose(pose.to_matrix([0.2, -0.3, 0.3, 0.5, 0.0, -0.3]), expected, atol=1e-8)


def test_models_are_readable_without_pinocchio():
    code = ("import sys; from urdsl.kinematics import MODELS, pose, Calibration; "
            "assert len(MODELS) == 14; pose.to_matrix([0, 0, 0, 0, 0, 1]); "
            "assert 'pinocchio' not in sys.modules, 'pinocchio was imported'")
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("name", ALL)
def test_closed_form_axes_and_origins_are_those_of_the_dh_chain(robots, name):
    robot = robots[name]
    Q = random_q(300, 11)
    frames = robot.frames_many(Q)
    axes, origins = robot.axes_many(Q)
    assert np.allclose(axes, frames[:, :6, :3, 2], atol=1e-12)
    assert np.allclose(origins, frames[:, :, :3, 3], atol=1e-12)


@pytest.mark.parametrize("name", ["ur5e", "ur10", "ur30"])
def test_batched_jacobians_match_pinocchio_at_the_flange_and_a_tcp(robots, name):
    """jacobian_many (closed form) against Pinocchio's frame Jacobian; at a TCP the linear
    rows gain ω × (p_tcp − p_flange)."""
    robot = robots[name]
    Q = random_q(40, 12)
    tcp = np.array([0.02, -0.03, 0.15, 0.1, 0.2, 0.3])
    at_flange = robot.jacobian_many(Q)
    at_tcp = robot.jacobian_many(Q, tcp=tcp)
    for q, flange, moved in zip(Q, at_flange, at_tcp, strict=True):
        reference = robot.jacobian(q)
        assert np.allclose(flange, reference, atol=1e-12)
        lever = robot.fk(q, tcp=tcp)[:3, 3] - robot.fk(q)[:3, 3]
        shifted = reference.copy()
        shifted[:3] -= np.cross(lever, reference[3:].T).T
        assert np.allclose(moved, shifted, atol=1e-12)
