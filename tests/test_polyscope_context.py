"""What a `.urp` is checked with, from real programs of issue 12's fourth development set:
the TCP a PolyScope 3 program's waypoints were taught with, the installation the program
names in a folder above it, the model when nothing says which arm it is, and where the arm
starts when the installation's TCP is not the one the waypoints were taught with."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
from _urp import program as _program
from _urp import script_line as _script_line

from urdsl.cli import main
from urdsl.kinematics import Robot
from urdsl.kinematics.pose import from_matrix

DATA = Path(__file__).parent / "data" / "polyscope"
UP = np.array([0.0, -1.5707963, 0.0, -1.5707963, 0.0, 0.0])  # stretched straight up
BENT = np.array([0.3, -1.2, 1.2, -1.5, -1.5, 0.0])
GRIPPER = np.array([0.0, 0.0, 0.19, 0.0, 0.0, 0.0])


UR5E_KINEMATICS = ('<kinematics><deltaTheta value="0, 0, 0, 0, 0, 0"/>'
                   '<a value="0.0, -0.425, -0.3922, 0.0, 0.0, 0.0"/>'
                   '<d value="0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996"/>'
                   '<alpha value="1.5707963267948966, 0, 0, 1.5707963267948966, '
                   '-1.5707963267948966, 0"/></kinematics>')
"""A nominal UR5e's calibration, as PolyScope 5 writes one into every program."""


def _values(values) -> str:
    return ", ".join(f"{v:.12g}" for v in values)


def _polyscope3_waypoint(name: str, q: np.ndarray) -> str:
    """A waypoint as PolyScope 3 saves it: joints and TCP pose as attributes, the flange
    pose beside them, no TCP offset."""
    robot = Robot.model("ur5e")
    tcp_pose = from_matrix(robot.fk(q, tcp=GRIPPER))
    flange = from_matrix(robot.fk(q))
    return (f'<Waypoint type="Fixed" name="{name}" kinematicsFlags="4"><motionParameters/>'
            f'<position joints="{_values(q)}" pose="{_values(tcp_pose)}"/>'
            f'<outputFlangePose pose="{_values(flange)}"/></Waypoint>')


def _movej(waypoints: str) -> str:
    return ('<Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">'
            f'<children>{waypoints}</children></Move>')


def _check(capsys, path: Path, *flags: str) -> tuple[dict, str]:
    main(["check", "--json", str(path), *flags])
    out = capsys.readouterr()
    return json.loads(out.out), out.err


def test_a_polyscope_3_waypoint_gives_its_tcp_by_its_flange_pose(tmp_path, capsys):
    # josepquintana/UR5-Motion-Planning test.urp: no installation, the TCP only in the
    # difference between a waypoint's pose and its flange pose; straight up with a 0.19 m
    # gripper the pose lies out of the flange's reach
    program = tmp_path / "up.urp"
    program.write_text(_program(_movej(_polyscope3_waypoint("Home", BENT)
                                       + _polyscope3_waypoint("Up", UP)), version="3.8.0"))
    report, _ = _check(capsys, program, "--robot", "ur5e")
    assert "TCP p[0, 0, 0.19, 0, 0, 0] the waypoints were taught with" in report["context"]
    assert [f["code"] for f in report["findings"] if f["severity"] == "error"] == []


def test_the_installation_a_program_names_may_be_in_a_folder_above(tmp_path, capsys,
                                                                   monkeypatch):
    # nedlecky/UR programs/g01_nut_handle/g01_home.urp names "default", which is
    # programs/default.installation: PolyScope saved the program in /programs
    (tmp_path / ".git").mkdir(exist_ok=True)
    programs = tmp_path / "programs"
    (programs / "sub").mkdir(parents=True)
    shutil.copy(DATA / "cell.installation", programs / "default.installation")
    program = programs / "sub" / "home.urp"
    program.write_text(_program('<Wait type="Sleep"><waitTime>0.1</waitTime></Wait>'))
    report, err = _check(capsys, program)
    assert "no installation" not in report["context"] and "a folder above" in err
    monkeypatch.chdir(program.parent)  # `urdsl check home.urp` in the program's folder
    report, err = _check(capsys, Path(program.name))
    assert "no installation" not in report["context"] and "a folder above" in err
    # another name, or above the repository's top, is not the program's
    (programs / "default.installation").rename(programs / "other.installation")
    report, _ = _check(capsys, program)
    assert "no installation default.installation beside the program" in report["context"]


def test_on_a_model_nothing_names_a_urps_model_findings_are_warnings(tmp_path, capsys):
    # Usaakm/UR10-Conveyor-Belt: a UR10 program with no <kinematics> and no taught pairs,
    # checked on the assumed UR5e: a pose 1.1 m out, which a UR10 reaches, is a warning
    # that says so, as for a script; with --robot it is an error
    program = tmp_path / "far.urp"
    program.write_text(_program(_script_line(
        "movel(p[-1.1, -0.1, 0.3, 0, 3.14, 0], a=1.2, v=0.25)")))
    report, _ = _check(capsys, program)
    (reach,) = [f for f in report["findings"] if f["code"] == "URS301"]
    assert reach["severity"] == "warning" and "on the assumed ur5e" in reach["message"]
    report, _ = _check(capsys, program, "--robot", "ur5e")
    assert [f["severity"] for f in report["findings"] if f["code"] == "URS301"] == ["error"]


def test_with_another_tcp_than_the_taught_one_the_start_is_not_the_taught_joints(
        tmp_path, capsys):
    # nedlecky/UR fun2.urp, ryan_test.urp, demo01.urp: taught with a 0.174 m TCP, the
    # installation's is turned half a turn; the arm does not start at the first waypoint's
    # taught joints, and the first move from them (a wrist flip) is not the arm's
    shutil.copy(DATA / "cell.installation", tmp_path / "cell.installation")
    program = tmp_path / "flip.urp"
    taught = "".join(
        f'<Waypoint type="Fixed" name="{name}" kinematicsFlags="3"><motionParameters/>'
        f'<position><JointAngles angles="{_values(q)}"/>'
        f'<TCPOffset pose="{_values(GRIPPER)}"/></position></Waypoint>'
        for name, q in (("A", BENT), ("B", BENT + np.array([0.4, 0, 0, 0, 0, 0]))))
    program.write_text(_program(_movej(taught), installation="cell",
                                kinematics=UR5E_KINEMATICS))
    report, _ = _check(capsys, program)
    assert "the waypoints were taught with TCP p[0, 0, 0.19" in report["context"]
    assert "where the arm starts is not known" in report["context"]


def test_a_subprogram_another_program_calls_is_checked_as_one_call(tmp_path, capsys):
    # CA-Giken/docker-noetic-capc GD/SUB_7002.urp: a subprogram saved as a program ("Program
    # Loops Forever" on), which MAIN.urp calls. On its own PolyScope would loop it, and the
    # way back from its last move to its first crosses the base (URS302); called, it runs
    # once, from wherever the caller left the arm
    down = "0, 3.1416, 0"
    moves = [f"movel(p[0.4, 0.1, 0.3, {down}], a=1.2, v=0.25)",
             f"movel(p[0.4, -0.3, 0.3, {down}], a=1.2, v=0.25)",
             f"movel(p[-0.4, -0.3, 0.3, {down}], a=1.2, v=0.25)"]
    program = tmp_path / "SUB_7.urp"
    program.write_text(_program("".join(_script_line(move) for move in moves),
                                name="SUB_7", version="5.13.0", loops=True))
    report, _ = _check(capsys, program, "--robot", "ur5e")
    looped = [f for f in report["findings"] if f["severity"] == "error"]
    first = report["moves"][0]["line"]
    # the second pass's first move, from the last one's end
    assert "URS302" in {f["code"] for f in looped} and {f["line"] for f in looped} == {first}
    caller = tmp_path / "MAIN.urp"
    caller.write_text(_program(
        '<CallSubProgram><subprogram name="SUB_7" keepHidden="false" '
        'keepSynchronizedWithDisk="true"><programFile>/programs/SUB_7.urp</programFile>'
        '<children/></subprogram></CallSubProgram>'))
    report, _ = _check(capsys, program, "--robot", "ur5e")
    assert [f for f in report["findings"] if f["severity"] == "error"] == []
    assert "a subprogram that MAIN.urp calls" in report["context"]
    assert len(report["moves"]) == 3  # one pass
    # a program that only names another file is no caller
    caller.write_text(_program(_script_line('textmsg("SUB_7.urp")')))
    report, _ = _check(capsys, program, "--robot", "ur5e")
    assert "URS302" in {f["code"] for f in report["findings"] if f["severity"] == "error"}


def test_a_gzip_bomb_beside_a_program_is_read_only_so_far(tmp_path, monkeypatch):
    # calling_programs reads the .urp files beside the program, which the user did not name:
    # one that would decompress to more than CALLER_XML_LIMIT bytes is skipped, read no further
    import gzip

    from urdsl.polyscope import check

    program = tmp_path / "SUB_1.urp"
    program.write_text(_program(""))
    bomb = b"<URProgram>" + b" " * 2_000_000 + b"<programFile>/programs/SUB_1.urp</programFile>"
    (tmp_path / "big.urp").write_bytes(gzip.compress(bomb))
    (tmp_path / "caller.urp").write_bytes(gzip.compress(
        b"<URProgram><programFile>/programs/SUB_1.urp</programFile></URProgram>"))
    (tmp_path / "broken.urp").write_bytes(b"\x1f\x8b not gzip")
    assert check.calling_programs(program) == ["big.urp", "caller.urp"]
    monkeypatch.setattr(check, "CALLER_XML_LIMIT", 1_000_000)
    assert check.calling_programs(program) == ["caller.urp"]


def test_the_programs_beside_a_folder_of_subprograms_are_read_once(tmp_path, monkeypatch):
    # urdsl check of every program of a folder (CA-Giken keeps 80 in one): each file beside
    # them is read once, not once per program checked; a file saved again is read again
    from urdsl.polyscope import check, gz

    reads = []
    inflate = gz.inflate
    monkeypatch.setattr(gz, "inflate", lambda data, limit=None: reads.append(1) or
                        inflate(data, limit))
    for index in range(4):
        (tmp_path / f"SUB_{index}.urp").write_text(_program(""))
    caller = tmp_path / "main.urp"
    caller.write_text("<URProgram><programFile>/programs/SUB_1.urp</programFile></URProgram>")
    assert [check.calling_programs(tmp_path / f"SUB_{i}.urp") for i in range(4)] == [
        [], ["main.urp"], [], []]
    assert len(reads) == 5  # the five files, each once
    caller.write_text("<URProgram><programFile>/programs/SUB_2.urp</programFile>"
                      "<!-- saved again --></URProgram>")
    assert check.calling_programs(tmp_path / "SUB_2.urp") == ["main.urp"]
