"""``urdsl compile`` and the example programs."""

from __future__ import annotations

from pathlib import Path

import pytest

from urdsl import format, parse
from urdsl.cli import main
from urdsl.dsl.command import load_program

PROGRAMS = sorted((Path(__file__).resolve().parents[1] / "programs").glob("*.py"))


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_every_example_program_compiles_to_formatted_urscript(path, capsys):
    assert main(["compile", str(path)]) == 0
    text = capsys.readouterr().out
    assert text.startswith("def ") and text.endswith("end\n")
    assert format(parse(text, path.name)) == text
    assert path.read_text().lstrip().startswith('"""')  # a header saying what it shows


@pytest.mark.parametrize("path", PROGRAMS, ids=lambda p: p.name)
def test_compiled_programs_parse_back_into_the_dsl_tree(path, tmp_path, capsys):
    program = load_program(path)
    assert parse(program.script(), path.name) == program.tree()
    script = tmp_path / "out.script"
    script.write_text(program.script())
    assert main(["fmt", "--check", str(script)]) == 0


def test_the_socket_example_checks_and_sends_to_the_simulator(monkeypatch, capsys):
    import runpy

    from urdsl.sim import VirtualController
    from urdsl.sim.servers import STANDARD_PORTS

    module = runpy.run_path(str(PROGRAMS[0].parent / "socket_send.py"), run_name="example")
    with VirtualController(robot="ur5e", speed=4.0) as sim, \
            sim.serve(ports={k: 0 for k in STANDARD_PORTS}) as servers:
        monkeypatch.setattr("sys.argv", ["socket_send.py", "--port",
                                         str(servers.ports["secondary"]), "--primary-port",
                                         str(servers.ports["primary"])])
        assert module["main"]() == 0
    assert "127.0.0.1" in capsys.readouterr().out


def test_course_examples_compile_to_what_the_course_shows(capsys):
    assert main(["compile", str(PROGRAMS[0].parent / "course_examples.py")]) == 0
    text = capsys.readouterr().out
    assert "  movej([0, -1.57079632, 0, -1.57079632, 0, 0])\n" in text
    assert "C = pose_trans(p[0.2, -0.3, 0.3, 0.5, 0, -0.3], p[0, 0, 0.1, 0, 0, 0])" in text
    assert "D = pose_add(p[0.2, -0.3, 0.3, 0.5, 0, -0.3], p[0, 0, 0.1, 0, 0, 0])" in text


def test_output_file(tmp_path, capsys):
    out = tmp_path / "pick.script"
    assert main(["compile", str(PROGRAMS[0]), "-o", str(out)]) == 0
    assert out.read_text().startswith("def ")
    assert "wrote" in capsys.readouterr().err


def test_main_function_is_used(tmp_path, capsys):
    source = tmp_path / "prog.py"
    source.write_text("from urdsl.dsl import Program, Joints\n"
                      "def main():\n"
                      "    p = Program('viamain')\n"
                      "    p.movej(Joints(0, -1.5, 1.5, -1.5, -1.5, 0))\n"
                      "    return p\n")
    assert main(["compile", str(source)]) == 0
    assert "def viamain():" in capsys.readouterr().out


def test_a_dsl_mistake_names_the_users_line(tmp_path, capsys):
    source = tmp_path / "bad.py"
    source.write_text("from urdsl.dsl import Program\n"
                      "program = Program('bad')\n"
                      "program.movej([0, -1.57, 0, -1.57, 0])\n")
    assert main(["compile", str(source)]) == 1
    err = capsys.readouterr().err
    assert f"{source}:3: error: movej needs 6 joint angles, got 5" in err
    assert "program.movej([0, -1.57, 0, -1.57, 0])" in err


def test_a_python_error_names_the_users_line(tmp_path, capsys):
    source = tmp_path / "crash.py"
    source.write_text("from urdsl.dsl import Program\nprogram = Program()\nx = 1 / 0\n")
    assert main(["compile", str(source)]) == 1
    err = capsys.readouterr().err
    assert f"{source}:3: error: ZeroDivisionError" in err and "Traceback" not in err


def test_a_file_without_a_program(tmp_path, capsys):
    source = tmp_path / "empty.py"
    source.write_text("x = 1\n")
    assert main(["compile", str(source)]) == 1
    assert "must define `program = Program(...)`" in capsys.readouterr().err


def test_a_missing_file_is_a_usage_error(tmp_path, capsys):
    assert main(["compile", str(tmp_path / "nope.py")]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_main_guard_does_not_run(tmp_path):
    source = tmp_path / "guarded.py"
    source.write_text("from urdsl.dsl import Program\nprogram = Program('g')\n"
                      "if __name__ == '__main__':\n    raise SystemExit('ran')\n")
    assert load_program(source).name == "g"


def test_verifier_reports_at_the_python_line(tmp_path, capsys):
    source = tmp_path / "far.py"
    source.write_text("from urdsl.dsl import Program, Pose, Joints\n"
                      "program = Program('far')\n"
                      "program.movej(Joints(0, -1.9, 1.9, -1.57, -1.57, 0))\n"
                      "program.movel(Pose(1.5, 0.2, 0.3, 0, 3.1416, 0))\n")
    assert main(["check", str(source), "--no-self-collision"]) == 1
    out = capsys.readouterr().out
    assert f"{source}:4:1: error" in out and "URS301" in out
    assert "program.movel(Pose(1.5, 0.2, 0.3, 0, 3.1416, 0))" in out


def test_check_reports_a_dsl_mistake_without_a_traceback(tmp_path, capsys):
    source = tmp_path / "bad.py"
    source.write_text("from urdsl.dsl import Program\nprogram = Program('bad')\n"
                      "program.sleep(-1)\n")
    assert main(["check", str(source)]) == 1
    err = capsys.readouterr().err
    assert f"{source}:3: error: sleep time must not be negative" in err
