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


def test_thread_count_comes_from_the_machine_or_the_environment(capsys):
    import os

    from urdsl._threads import MAX_WORKERS, thread_count

    cores = max(1, min(os.cpu_count() or 1, MAX_WORKERS))
    assert thread_count({}) == cores
    assert thread_count({"URDSL_THREADS": "3"}) == 3
    assert thread_count({"URDSL_THREADS": " 1 "}) == 1
    assert capsys.readouterr().err == ""
    for bad in ("0", "-2", "two", "1.5"):
        assert thread_count({"URDSL_THREADS": bad}) == cores
        assert f"URDSL_THREADS={bad!r} is not a positive whole number" in capsys.readouterr().err


def test_the_pool_uses_the_setting(tmp_path):
    import os
    import subprocess
    import sys

    code = ("from urdsl._threads import WORKERS, shared_pool; "
            "print(WORKERS, shared_pool()._max_workers)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "URDSL_THREADS": "5"}).stdout
    assert out.split() == ["5", "5"]


def test_comments_cite_notes_that_live_in_the_repository():
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    facts = (root / "docs" / "controller-facts.md").read_text(encoding="utf-8")
    sections = set(re.findall(r"^## (§\d+)", facts, flags=re.M))
    items = {f"{section}.{number}" for section in sections for number in range(1, 10)}
    later = ("urdsl/sim/", "urdsl/protocol/", "urdsl/robot/sender.py")  # the sim/protocol work
    for path in sorted((root / "urdsl").rglob("*.py")):
        name = path.relative_to(root).as_posix()
        text = path.read_text(encoding="utf-8")
        if not name.startswith(later):
            assert not re.search(r"shared/reference|UR_FACTS|URSCRIPT_LANGUAGE|BUILTINS\.md",
                                 text), name
        for cited in re.findall(r"controller-facts\.md`{0,2},? (§[\d.]+\d)", text):
            assert cited in sections or cited in items, f"{name} cites {cited}"
