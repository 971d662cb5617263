"""Distances to the shoulder, elbow and wrist singularities, and the manipulability."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from urdsl.kinematics import MODELS, Robot


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.model("ur5e")


def shoulder_singular_q(spec, theta3: float = 0.2) -> np.ndarray:
    """A configuration with the wrist centre in the plane through the base axis parallel to
    the shoulder axis: a2·c2 + a3·c23 + d5·sin θ234 = 0."""
    theta2 = -math.pi / 2
    u = spec.a2 * math.cos(theta2) + spec.a3 * math.cos(theta2 + theta3)
    theta234 = math.asin(-u / spec.d5)
    return np.array([0.4, theta2, theta3, theta234 - theta2 - theta3, 0.9, 0.1])


def test_each_measure_vanishes_at_its_singularity(robot):
    spec = robot.spec
    Q = np.array([
        [0.3, -1.0, 0.0, -0.8, 1.1, 0.2],            # elbow stretched (θ3 = 0)
        [0.3, -1.0, math.pi, -0.8, 1.1, 0.2],        # elbow folded (θ3 = π)
        [0.3, -1.0, 1.2, -0.8, 0.0, 0.2],            # wrist (θ5 = 0)
        [0.3, -1.0, 1.2, -0.8, math.pi, 0.2],        # wrist (θ5 = π)
        shoulder_singular_q(spec),
        [0.3, -1.2, 1.4, -1.6, -1.4, 0.2],           # a regular configuration
    ])
    measures = robot.singularity(Q)
    assert set(measures) == {"shoulder", "elbow", "wrist", "manipulability"}
    for values in measures.values():
        assert values.shape == (6,) and np.all(values >= 0)
    assert measures["elbow"][0] < 1e-12 and measures["elbow"][1] < 1e-12
    assert measures["wrist"][2] < 1e-12 and measures["wrist"][3] < 1e-12
    assert measures["shoulder"][4] < 1e-9
    assert np.all(measures["manipulability"][:5] < 1e-9)
    regular = {key: values[5] for key, values in measures.items()}
    assert regular["shoulder"] > 0.05 and regular["elbow"] > 0.05
    assert regular["wrist"] == pytest.approx(1.4)
    assert regular["manipulability"] > 1e-3


def test_measures_in_metres_and_radians(robot):
    spec = robot.spec
    q = np.array([0.0, -math.pi / 2, math.pi / 2, 0.0, 0.5, 0.0])
    measures = robot.singularity(q[None])
    # elbow at 90°: shoulder-to-wrist-1 distance sqrt(a2² + a3²)
    length = math.hypot(spec.a2, spec.a3)
    assert measures["elbow"][0] == pytest.approx(min(abs(spec.a2) + abs(spec.a3) - length,
                                                     length - abs(abs(spec.a2) - abs(spec.a3))))
    assert measures["wrist"][0] == pytest.approx(0.5)
    # the wrist centre lies at sqrt(r² − d4²) from the singular plane
    wrist = robot.frames_many(q[None])[0, 5, :3, 3]
    assert measures["shoulder"][0] == pytest.approx(
        math.sqrt(wrist[0] ** 2 + wrist[1] ** 2 - spec.d4 ** 2))


@pytest.mark.parametrize("name", ["ur3", "ur10e", "ur20", "ur8long"])
def test_manipulability_is_the_jacobian_determinant(name):
    robot = Robot.model(name)
    Q = np.random.default_rng(2).uniform(-math.pi, math.pi, (30, 6))
    measures = robot.singularity(Q)
    for q, value in zip(Q, measures["manipulability"], strict=True):
        jacobian = pin.computeFrameJacobian(robot.pin_model, robot.pin_data, q,
                                            robot.pin_model.getFrameId("tool0"),
                                            pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        assert value == pytest.approx(abs(np.linalg.det(jacobian)), rel=1e-9, abs=1e-15)
        assert np.allclose(robot.jacobian(q), jacobian)


@pytest.mark.parametrize("name", list(MODELS))
def test_shoulder_singularity_for_every_model(name):
    robot = Robot.model(name)
    q = shoulder_singular_q(robot.spec, theta3=0.1)
    assert robot.singularity(q[None])["shoulder"][0] < 1e-9


def test_a_linearized_factory_table_measures_as_the_arm_it_describes():
    # PolyScope's "linearized" tables move the three parallel axes' frames metres along the
    # axes, offsets that cancel (d2 + d3 + d4 is the arm's d4): the same arm, so the same
    # distances; measured on the frames' own offsets, every move of an e-Series export passed
    # "within 0 m" of the shoulder and elbow singularities
    from urdsl.kinematics import Calibration

    nominal = Robot.model("ur5e")
    linearized = Robot.model("ur5e", Calibration(delta_d=[0.0, 79.4, -95.5, 16.1, 0.0, 0.0]))
    Q = np.random.default_rng(7).uniform(-math.pi, math.pi, (40, 6))
    assert np.allclose(linearized.fk_many(Q), nominal.fk_many(Q), atol=1e-9)
    expected, measured = nominal.singularity(Q), linearized.singularity(Q)
    for kind in ("shoulder", "elbow", "wrist", "manipulability"):
        assert np.allclose(measured[kind], expected[kind], atol=1e-9), kind
