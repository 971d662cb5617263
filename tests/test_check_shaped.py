"""What the check computes on a path it chose for a device is not a certain error (issue 12).

Modelled on a camera program (SICK PLOC2D URCap, lukasfalk/34764-Pharma
``programs/pickPlace_v2_grp6.script``): the check's reply had no fields, the parser left the
part data at zeros, a reachability test on a pick pose made of those zeros failed, and the
program kept the arm's last pose as its pick pose, so a move relative to it was "out of
reach". See :mod:`urdsl.runtime.shaped`.
"""

from __future__ import annotations

from test_project_check import check

CAMERA = """def cam():
  socket_open("127.0.0.1", 2000, "cam")
  reply = socket_read_string("cam")
  data = [0, 0.0, 0.0]
  if reply == "ok":
    data[0] = 1
  end
  found = data[0]
  table = p[1.2, 0.0, 0.0, 0, 0, 0]
  pick = p[0.4, -0.2, 0.25, 0, 3.1416, 0]
  seen = pose_trans(table, p[data[1], data[2], 0, 0, 3.1416, 0])
  if found == 1 and get_inverse_kin_has_solution(seen):
    pick = seen
  end
  movej(get_inverse_kin(p[0.4, -0.2, 0.25, 0, 3.1416, 0]))
  movel(pose_trans(pick, p[0, -0.8, 0, 0, 0, 0]))
  movel(p[0.4, -0.2, 0.25, 0, 3.1416, 0])
end
"""


def _errors(report) -> list[tuple[int, str]]:
    return [(f["line"], f["code"]) for f in report["findings"] if f["severity"] == "error"]


def _warnings(report, code: str) -> list[dict]:
    return [f for f in report["findings"] if f["severity"] == "warning" and f["code"] == code]


def test_a_target_left_as_it_was_because_of_the_devices_reply_is_a_warning(tmp_path, capsys):
    program = tmp_path / "cam.script"
    program.write_text(CAMERA)
    status, report = check(capsys, "--no-project", "--robot", "ur5e", str(program))
    assert status == 0, _errors(report)
    (unreachable,) = _warnings(report, "URS301")
    assert unreachable["line"] == 16
    assert "socket_read_string()" in unreachable["message"]
    assert "the check stopped at this move" in unreachable["message"]


def test_the_same_move_from_values_no_device_decided_stays_an_error(tmp_path, capsys):
    # the pick pose is not touched by the decision: the move is out of reach whatever the
    # camera says
    program = tmp_path / "cam.script"
    program.write_text(CAMERA.replace("    pick = seen\n", "    textmsg(seen)\n"))
    status, report = check(capsys, "--no-project", "--robot", "ur5e", str(program))
    assert status == 1 and _errors(report) == [(16, "URS301")]


def test_a_constant_target_set_on_the_devices_path_stays_an_error(tmp_path, capsys):
    # wherever the device leads to this branch, the target is this constant
    program = tmp_path / "cam.script"
    program.write_text(CAMERA.replace("    data[0] = 1\n", "    data[0] = 1\n"
                                      "    pick = p[0.4, -0.5, 0.25, 0, 3.1416, 0]\n")
                       .replace("    pick = seen\n", "    textmsg(seen)\n"))
    status, report = check(capsys, "--no-project", "--robot", "ur5e", str(program))
    assert status == 1 and _errors(report) == [(17, "URS301")]


def test_a_shaped_value_passed_to_a_function_and_returned_is_still_shaped(tmp_path, capsys):
    program = tmp_path / "cam.script"
    program.write_text(CAMERA.replace(
        "def cam():\n", "def cam():\n  def above(pose, dz):\n    return pose_trans(pose, "
        "p[0, -0.8, dz, 0, 0, 0])\n  end\n").replace(
        "  movel(pose_trans(pick, p[0, -0.8, 0, 0, 0, 0]))\n", "  target = above(pick, 0)\n"
        "  movel(target)\n"))
    status, report = check(capsys, "--no-project", "--robot", "ur5e", str(program))
    assert status == 0, _errors(report)
    assert [f["line"] for f in _warnings(report, "URS301")] == [20]
    # a plain argument makes the parameter plain again
    program.write_text(program.read_text().replace("above(pick, 0)",
                                                   "above(p[0.4, -0.2, 0.25, 0, 3.1416, 0], 0)"))
    status, report = check(capsys, "--no-project", "--robot", "ur5e", str(program))
    assert status == 1 and _errors(report) == [(20, "URS301")]


LOOP = """def count():
  socket_open("127.0.0.1", 2000, "s")
  n = 0
  while socket_read_string("s") != "done":
    n = n + 1
  end
  step = 0.1 * n
  movel(pose_trans(p[0.4, -0.2, 0.25, 0, 3.1416, 0], p[0, step, 0, 0, 0, 0]))
  movel(p[0.4, -0.2, 0.25, 0, 3.1416, 0])
  n = 2
  movel(pose_trans(p[0.4, -0.2, 0.25, 0, 3.1416, 0], p[0, 0.1 * n, 0, 0, 0, 0]))
end
"""


def test_what_a_loop_waiting_on_a_reply_counts_is_shaped_until_set_plainly():
    from urdsl import parse
    from urdsl.kinematics import Robot
    from urdsl.motion.planner import MotionPlanner
    from urdsl.runtime import Environment, Interpreter, RuntimeConfig

    planner = MotionPlanner(Robot.model("ur5e"), [0, -1.9, 1.9, -1.57, -1.57, 0])
    result = Interpreter(parse(LOOP, "count.script"), robot=planner,
                         environment=Environment(devices="unknown"),
                         config=RuntimeConfig()).run()
    assert result.error is None
    shaped = {span.line: source for span, source in result.shaped_moves.items()}
    assert list(shaped) == [8]  # not the constant move, not the move after n = 2
    assert "socket_read_string()" in shaped[8]
