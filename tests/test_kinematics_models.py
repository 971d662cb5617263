"""The model table: fourteen arms, their names, limits and units."""

from __future__ import annotations

import math

import numpy as np
import pytest

from urdsl.kinematics import MODELS, KinematicsError, Robot, model_spec

EXPECTED = ["ur3", "ur5", "ur10", "ur3e", "ur5e", "ur10e", "ur16e", "ur20", "ur30", "ur7e",
            "ur12e", "ur15", "ur18", "ur8long"]


def test_all_fourteen_models_are_there():
    assert list(MODELS) == EXPECTED


@pytest.mark.parametrize("name", EXPECTED)
def test_spec_shapes_units_and_structure(name):
    spec = MODELS[name]
    assert spec.name == name
    for array in (spec.dh_a, spec.dh_d, spec.dh_alpha, spec.q_min, spec.q_max, spec.qd_max):
        assert array.shape == (6,)
        assert not array.flags.writeable
    # the UR structure: only d1, a2, a3, d4, d5, d6 are non-zero; a2, a3 negative
    assert spec.a2 < 0 and spec.a3 < 0
    assert np.count_nonzero(spec.dh_a) == 2 and np.count_nonzero(spec.dh_d) == 4
    assert np.allclose(spec.dh_alpha, [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0])
    assert np.all(spec.q_min == -spec.q_max)
    assert np.all(spec.q_max[:5] == 2 * math.pi)
    # joint speeds between 120 and 360 deg/s
    assert np.all((spec.qd_max >= math.radians(119)) & (spec.qd_max <= math.radians(361)))
    assert spec.generation in ("cb3", "e-series", "ur-series")
    assert 0.4 < spec.reach < 2.0 and 2.0 <= spec.payload <= 35.0
    # the arm's own length never exceeds its reach by more than the wrist
    assert abs(spec.a2) + abs(spec.a3) < spec.reach


def test_wrist_3_of_the_small_arms_is_unlimited():
    assert MODELS["ur3"].q_max[5] == math.inf and MODELS["ur3e"].q_min[5] == -math.inf
    assert MODELS["ur5e"].q_max[5] == 2 * math.pi


def test_renamed_arms_share_their_kinematics():
    for new, old in (("ur7e", "ur5e"), ("ur12e", "ur10e")):
        assert np.array_equal(MODELS[new].dh_a, MODELS[old].dh_a)
        assert np.array_equal(MODELS[new].dh_d, MODELS[old].dh_d)


def test_joint_speeds_in_rad_per_s():
    assert np.allclose(MODELS["ur10e"].qd_max, np.radians([120, 120, 180, 180, 180, 180]))
    assert np.allclose(MODELS["ur3"].qd_max, np.radians([180, 180, 180, 360, 360, 360]))


@pytest.mark.parametrize("spelling", ["UR5e", "ur5e", " UR5E ", "ur-5e"])
def test_names_are_case_insensitive(spelling):
    assert model_spec(spelling).name == "ur5e"
    assert Robot.model(spelling).name == "ur5e"


def test_ur8_long_spellings():
    assert model_spec("UR8 Long").name == "ur8long"
    assert model_spec("ur8_long").name == "ur8long"


def test_unknown_model_lists_the_known_ones():
    with pytest.raises(KinematicsError) as info:
        Robot.model("ur6")
    message = str(info.value)
    assert "'ur6'" in message
    for name in EXPECTED:
        assert name in message
