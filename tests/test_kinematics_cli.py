"""`urdsl models`, `urdsl fk` and `urdsl ik` as a user runs them."""

from __future__ import annotations

import math

import numpy as np

from urdsl.cli import main
from urdsl.kinematics import Robot


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def numbers(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.strip().lstrip("p[").rstrip("]").split(",")])


def test_models_lists_all_fourteen(capsys):
    status, out, _ = run(capsys, "models")
    assert status == 0
    for name in ("ur3", "ur5e", "ur20", "ur8long"):
        assert f"\n{name} " in out
    assert "0.1625" in out   # UR5e d1


def test_fk_prints_the_pose(capsys):
    q = [0.1, -1.2, 1.3, -1.7, -1.5, 0.4]
    status, out, _ = run(capsys, "fk", "ur5e", *q)
    assert status == 0
    assert np.allclose(numbers(out), Robot.model("ur5e").fk_pose(q), atol=1e-6)
    status, out, _ = run(capsys, "fk", "ur5e", "--deg", *np.degrees(q), "--tcp", 0, 0, 0.1,
                         0, 0, 0)
    assert np.allclose(numbers(out), Robot.model("ur5e").fk_pose(q, [0, 0, 0.1, 0, 0, 0]),
                       atol=1e-6)
    status, out, _ = run(capsys, "fk", "ur5e", "--matrix", 0, 0, 0, 0, 0, 0)
    assert status == 0 and len(out.splitlines()) == 4


def test_ik_round_trip_and_all(capsys):
    q = [0.1, -1.2, 1.3, -1.7, -1.5, 0.4]
    pose = Robot.model("ur10e").fk_pose(q)
    status, out, _ = run(capsys, "ik", "ur10e", *pose, "--near", *q)
    assert status == 0
    assert np.allclose(numbers(out), q, atol=1e-5)
    status, out, _ = run(capsys, "ik", "ur10e", "--all", *pose)
    assert status == 0 and 2 <= len(out.splitlines()) <= 8
    status, out, _ = run(capsys, "ik", "ur10e", "--deg", *pose, "--near",
                         *np.degrees(q))
    assert np.allclose(numbers(out), np.degrees(q), atol=1e-3)


def test_ik_out_of_reach_exits_1_with_the_distance(capsys):
    status, out, err = run(capsys, "ik", "ur5e", 2, 0, 0, 0, math.pi, 0)
    assert status == 1 and out == ""
    assert "out of reach of the ur5e by" in err and "mm" in err and "Traceback" not in err


def test_usage_errors_exit_2(capsys, tmp_path):
    status, _, err = run(capsys, "fk", "ur6", 0, 0, 0, 0, 0, 0)
    assert status == 2 and "known models: ur3" in err
    status, _, err = run(capsys, "fk", "ur5e", 0, 0, "x", 0, 0, 0)
    assert status == 2 and "could not convert" in err
    bad = tmp_path / "cal.toml"
    bad.write_text("[delta]\nd = [1, 2]\n")
    status, _, err = run(capsys, "fk", "ur5e", "--calibration", bad, 0, 0, 0, 0, 0, 0)
    assert status == 2 and "6 finite numbers" in err


def test_calibration_file_changes_fk(capsys, tmp_path):
    cal = tmp_path / "cal.toml"
    cal.write_text('model = "ur5e"\n[delta]\nd = [0.002, 0, 0, 0, 0, 0]\n')
    _, plain, _ = run(capsys, "fk", "ur5e", 0, 0, 0, 0, 0, 0)
    _, lifted, _ = run(capsys, "fk", "ur5e", "--calibration", cal, 0, 0, 0, 0, 0, 0)
    assert abs(numbers(lifted)[2] - numbers(plain)[2] - 0.002) < 1e-6
