"""``urdsl check`` as a user runs it: text and JSON reports, exit status, plot, options."""

from __future__ import annotations

import json

import pytest

from urdsl.cli import main

GOOD = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
home = get_actual_tcp_pose()
movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.02)
movel(pose_add(home, p[0.1, 0.1, 0, 0, 0, 0]))
textmsg("done")
"""

BAD = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])
"""


@pytest.fixture
def files(tmp_path):
    (tmp_path / "good.script").write_text(GOOD)
    (tmp_path / "bad.script").write_text(BAD)
    return tmp_path


def test_a_good_program_exits_0_and_lists_its_moves(files, capsys):
    assert main(["check", str(files / "good.script"), "--no-self-collision"]) == 0
    out = capsys.readouterr().out
    assert "ok on ur5e" in out and "cycle time" in out and "movel" in out


def test_errors_exit_1_and_show_the_line(files, capsys):
    assert main(["check", str(files / "bad.script"), "--no-self-collision",
                 "--robot", "ur5e"]) == 1
    out = capsys.readouterr().out
    assert "bad.script:2:1" in out and "URS301" in out
    assert "movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])" in out


def test_json_report_is_one_document_even_on_failure(files, capsys):
    assert main(["check", str(files / "bad.script"), "--json", "--no-self-collision",
                 "--robot", "ur5e"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] is False and report["robot"] == "ur5e"
    (finding,) = report["findings"]
    assert {k: finding[k] for k in ("code", "severity", "line", "column")} == {
        "code": "URS301", "severity": "error", "line": 2, "column": 1}
    assert report["moves"][0]["line"] == 1 and report["moves"][0]["duration"] > 0
    assert report["cycle_time"] >= report["moves"][0]["duration"]


def test_json_moves_and_events(files, capsys):
    assert main(["check", str(files / "good.script"), "--json", "--no-self-collision",
                 "--start-joints", "0,-1.9,1.9,-1.57,-1.57,0"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert [m["line"] for m in report["moves"]] == [1, 3, 4]
    assert report["events"][-1]["message"] == "done"
    assert report["moves"][0]["duration"] == 0  # the arm already stands there


def test_start_joints_in_degrees():
    from urdsl.verify.command import parse_vector

    assert parse_vector("0,-90,90,-90,-90,180", 6, "q", degrees=True) == pytest.approx(
        (0, -1.5707963267948966, 1.5707963267948966, -1.5707963267948966,
         -1.5707963267948966, 3.141592653589793))


def test_plot_is_written(files, tmp_path, capsys):
    out = tmp_path / "plot.png"
    assert main(["check", str(files / "good.script"), "--plot", str(out),
                 "--no-self-collision"]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("argv,message", [
    (["--robot", "ur6"], "unknown robot model"),
    (["--start-joints", "0,1,2"], "6 finite numbers"),
])
def test_usage_errors_exit_2(files, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_info:
        status = main(["check", str(files / "good.script"), *argv])
        raise SystemExit(status)
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


def test_a_missing_file_exits_2(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nope.script")]) == 2
    assert "cannot read" in capsys.readouterr().err


def test_a_bad_cell_file_is_a_usage_error(files, tmp_path, capsys):
    cell = tmp_path / "cell.toml"
    cell.write_text("[[box]]\nsize = [1, 1]\n")
    assert main(["check", str(files / "good.script"), "--cell", str(cell)]) == 2
    assert "bad cell description" in capsys.readouterr().err


def test_a_cell_with_a_table_in_reach_finds_the_collision(files, tmp_path, capsys):
    cell = tmp_path / "cell.toml"
    cell.write_text('[[box]]\nname = "fixture"\nsize = [0.3, 0.3, 0.3]\n'
                    'pose = [-0.3, -0.08, 0.35, 0, 0, 0]\n')
    assert main(["check", str(files / "good.script"), "--cell", str(cell), "--json",
                 "--robot", "ur5e"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert any(f["code"] == "URS308" and "fixture" in f["message"]
               for f in report["findings"])


def test_user_joint_limits(files, capsys):
    assert main(["check", str(files / "good.script"), "--json", "--no-self-collision",
                 "--robot", "ur5e", "--q-max", "6.28,6.28,6.28,6.28,6.28,-0.5"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert {f["code"] for f in report["findings"]} == {"URS303"}  # one per move
    assert [f["line"] for f in report["findings"]] == [1, 3, 4]
    assert "wrist 3" in report["findings"][0]["message"]


def test_a_program_that_starts_where_the_arm_was_left(tmp_path, capsys):
    # no start pose given or inferred (no taught waypoints): the arm stands wherever it was
    # left, so a circle drawn around where it stands is not checked against the default
    # start; given a start, it is
    path = tmp_path / "around.script"
    path.write_text("centre = get_target_tcp_pose()\n"
                    "movel(pose_add(centre, p[0, 0, -1.5, 0, 0, 0]), a=1.2, v=0.25)\n")
    status = main(["check", str(path), "--json", "--no-project"])
    report = json.loads(capsys.readouterr().out)
    assert status == 0, report["findings"]
    (note,) = [f for f in report["findings"] if f["code"] == "URS210"]
    assert "the program starts" in note["message"]
    status = main(["check", str(path), "--json", "--no-project", "--robot", "ur5e",
                   "--start-joints", "0,-1.9,1.9,-1.57,-1.57,0"])
    report = json.loads(capsys.readouterr().out)
    assert status == 1
    assert [f["code"] for f in report["findings"] if f["severity"] == "error"] == ["URS301"]


def test_a_torque_loop_on_unknown_values_still_takes_a_frame_per_turn(tmp_path, capsys):
    path = tmp_path / "torque.script"
    path.write_text("while True:\n"
                    "  torques = [read_input_float_register(0), 0, 0, 0, 0, 0]\n"
                    "  direct_torque(torques)\nend\n")
    status = main(["check", str(path), "--json", "--no-project", "--max-time", "2"])
    report = json.loads(capsys.readouterr().out)
    assert status == 0, report["findings"]
    assert "URS207" not in [f["code"] for f in report["findings"]]
