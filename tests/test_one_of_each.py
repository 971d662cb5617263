"""One home for each shared thing (issue 15): robot model names, controller versions, joint
names and the CLI helpers; and no module imports one that imports it back."""

from __future__ import annotations

import pytest

from urdsl.cli import main

NAMES = ["UR5e", "ur5e", "UR8 Long", "ur8-long", " UR10 "]


@pytest.mark.parametrize("name", NAMES)
def test_send_and_check_accept_the_same_robot_names(name, tmp_path, capsys):
    good = tmp_path / "good.script"
    good.write_text("textmsg(1)\n")
    bad = tmp_path / "bad.script"
    bad.write_text("x = (1\n")
    assert main(["check", str(good), "--robot", name]) == 0
    # send resolves the name before it reads the program: a syntax error, not a usage error
    assert main(["send", str(bad), "--host", "127.0.0.1", "--robot", name]) == 1
    assert "unknown robot model" not in capsys.readouterr().err


def test_an_unknown_model_is_refused_alike_by_every_command(tmp_path, capsys):
    good = tmp_path / "good.script"
    good.write_text("textmsg(1)\n")
    for command in (["check", str(good)], ["send", str(good), "--host", "127.0.0.1"]):
        assert main([*command, "--robot", "UR6"]) == 2
        err = capsys.readouterr().err
        assert "unknown robot model 'UR6'" in err and "ur5e" in err


def test_the_robot_api_names_models_as_the_commands_do():
    from urdsl.kinematics import KinematicsError
    from urdsl.robot import Robot

    assert Robot("127.0.0.1", robot="UR8 Long").robot == "ur8long"
    with pytest.raises(KinematicsError, match="unknown robot model"):
        Robot("127.0.0.1", robot="UR6")


def test_one_version_type_for_the_catalog_and_the_commands():
    from urdsl.script.builtins import parse_version
    from urdsl.versions import ControllerVersion

    version = ControllerVersion.parse(" 3.15.7.106331 ")
    assert (version.series, version.e_series, str(version)) == ("cb", False, "3.15.7.106331")
    assert parse_version("5.15.2") == ControllerVersion.parse("5.15").feature == (5, 15)
    assert ControllerVersion.parse("10.7").series == "x"
    for text in ("", "five", "5.x", "5..1", "-5.1"):
        with pytest.raises(ValueError, match="not a controller version"):
            ControllerVersion.parse(text)


def test_one_list_of_joint_names():
    from urdsl.kinematics.models import JOINT_NAMES
    from urdsl.verify import checks

    assert JOINT_NAMES == ("base", "shoulder", "elbow", "wrist 1", "wrist 2", "wrist 3")
    assert checks.JOINTS is JOINT_NAMES
