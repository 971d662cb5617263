"""Moves relative to an unknown start (issue 12): a loop of ``movej(pose_add(get_target_tcp_pose(),
d))`` drifts by ``d`` a pass until no start keeps the target within reach (URS301); what
cannot be followed exactly stays unknown and is never an error."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.cli import main
from urdsl.kinematics import MODELS, Robot
from urdsl.motion.drift import Drift, drift_error, flange_reach, widest_model
from urdsl.runtime.values import Anchor, Relative
from urdsl.verify.run import CheckOptions, check_text

TCP = "p[0, 0, 0.1, 0, 0, 0]"


def export(loop: str, setup: str = "") -> str:
    """A PolyScope export without a taught start: its moves are relative to the arm's
    position, so the check starts with that position unknown."""
    return f"""def drift():
  set_tcp({TCP})
  global w_from_p=p[0.3, 0.4, 0.2, 0, 3.14, 0]
  global w_to_p=p[0.3, 0.3, 0.2, 0, 3.14, 0]
  global w_back_p=p[0.3, 0.5, 0.2, 0, 3.14, 0]
{setup}  while (True):
    $ 1 "MoveJ"
{loop}
  end
end
"""


STEP = "    movej(pose_add(get_target_tcp_pose(), pose_sub(w_to_p, w_from_p)), a=1.4, v=1.05)"
"""One relative move of 0.1 m (line 8 of :func:`export`)."""

BACK = "    movej(pose_add(get_target_tcp_pose(), pose_sub(w_back_p, w_from_p)), a=1.4, v=1.05)"
"""The same move back."""


def check(tmp_path, capsys, text: str, *flags: str) -> dict:
    path = tmp_path / "drift.script"
    path.write_text(text)
    main(["check", str(path), "--json", "--no-self-collision", "--max-time", "400", *flags])
    return json.loads(capsys.readouterr().out)


def errors(report: dict) -> list[dict]:
    return [f for f in report["findings"] if f["severity"] == "error"]


def test_a_loop_of_one_relative_move_drifts_out_of_every_models_reach(tmp_path, capsys):
    report = check(tmp_path, capsys, export(STEP))
    found = errors(report)
    assert [(f["code"], f["line"]) for f in found] == [("URS301", 8)]
    message = found[0]["message"]
    # the robot is not known: the widest UR model's reach decides (ur20: 2 x 1.92 m + TCPs)
    widest = widest_model()
    bound = 2 * flange_reach(widest) + 0.2 + 0.01
    passes = math.floor(bound / 0.1 + 1e-9) + 1
    assert f"after {passes} passes of this move" in message
    assert "any UR model" in message and widest.name in message
    assert "where the arm stood when the program started" in message


def test_with_the_robot_given_its_own_reach_decides(tmp_path, capsys):
    report = check(tmp_path, capsys, export(STEP), "--robot", "ur5e")
    found = errors(report)
    assert [(f["code"], f["line"]) for f in found] == [("URS301", 8)]
    bound = 2 * flange_reach(MODELS["ur5e"]) + 0.2 + 0.01  # 2.26 m
    passes = math.floor(bound / 0.1 + 1e-9) + 1
    assert f"after {passes} passes of this move" in found[0]["message"]
    assert "ur5e's reach" in found[0]["message"]


def test_back_and_forth_never_drifts(tmp_path, capsys):
    assert errors(check(tmp_path, capsys, export(f"{STEP}\n{BACK}"))) == []
    # the same loop with both moves the same way drifts out
    assert [f["line"] for f in errors(check(tmp_path, capsys, export(f"{STEP}\n{STEP}")))] == [8]


@pytest.mark.parametrize(("passes", "out"), [(20, False), (30, True)])
def test_a_drift_that_stays_under_the_bound_is_no_error(tmp_path, capsys, passes, out):
    # 20 passes on a ur5e: 2.0 m from the start, which some start reaches; 30 passes: 3.0 m
    loop = f"    if i < {passes}:\n  {STEP}\n    end\n    i = i + 1\n    sleep(0.1)"
    found = errors(check(tmp_path, capsys, export(loop, "  i = 0\n"), "--robot", "ur5e"))
    assert [f["line"] for f in found] == ([10] if out else [])


@pytest.mark.parametrize("move", [
    "    movej(pose_trans(get_target_tcp_pose(), p[0, -0.1, 0, 0, 0, 0]), a=1.4, v=1.05)",
    "    x = get_target_tcp_pose()\n"
    "    movej(p[x[0], x[1] - 0.1, x[2], x[3], x[4], x[5]], a=1.4, v=1.05)",
    "    x = get_target_tcp_pose()\n"
    "    movej(pose_add(pose_sub(x, x), pose_add(x, pose_sub(w_to_p, w_from_p))))",
])
def test_what_cannot_be_followed_exactly_stays_unknown(tmp_path, capsys, move):
    report = check(tmp_path, capsys, export(move), "--robot", "ur5e")
    assert errors(report) == []
    assert any(f["code"] == "URS210" for f in report["findings"])


def test_the_same_move_with_pose_add_is_followed(tmp_path, capsys):
    # the contrast of the cases above: what they do with pose_add is an error
    move = "    x = get_target_tcp_pose()\n    movej(pose_add(x, p[0, -0.1, 0, 0, 0, 0]))"
    assert [f["line"] for f in errors(check(tmp_path, capsys, export(move),
                                            "--robot", "ur5e"))] == [9]


def test_the_target_waypoint_at_an_unknown_start_is_as_unknown_as_the_tcp_pose(tmp_path,
                                                                              capsys):
    # get_target_waypoint() (what PolyScope's Direction node aims from) is where the arm
    # stands when it stands still: relative to the unknown start, not urdsl's default pose
    move = "    x = get_target_waypoint()\n    movej(pose_add(x, p[0, -0.1, 0, 0, 0, 0]))"
    found = errors(check(tmp_path, capsys, export(move), "--robot", "ur5e"))
    assert [f["line"] for f in found] == [9]
    assert "where the arm stood when the program started" in found[0]["message"]


def test_a_move_that_blends_leaves_the_position_unknown(tmp_path, capsys):
    # with a blend radius the thread goes on before the arm is there: what it reads next
    # is a point on the way, so nothing is followed
    blend = STEP.replace("v=1.05)", "v=1.05, r=0.01)")
    assert errors(check(tmp_path, capsys, export(blend), "--robot", "ur5e")) == []


def test_a_known_move_ends_the_drift(tmp_path, capsys):
    home = "    movej([0, -1.57, 1.57, -1.57, -1.57, 0])"
    assert errors(check(tmp_path, capsys, export(f"{STEP}\n{home}"), "--robot", "ur5e")) == []


def test_check_text_without_inference_uses_its_model():
    options = CheckOptions(robot="ur5e", start_unknown=True, timeout=None, max_time=400)
    report = check_text(export(STEP), "drift.script", options=options)
    found = [f for f in report.findings if f.severity == "error"]
    assert [(f.code, f.span.line) for f in found] == [("URS301", 8)]
    assert "ur5e's reach" in found[0].message


def test_a_read_by_another_thread_or_with_another_tcp_is_plainly_unknown():
    drift = Drift("where it stood", holder="main")
    tcp = np.array([0.0, 0.0, 0.1])
    assert drift.read(tcp, "other") is None
    first = drift.read(tcp, "main")
    assert first is not None and first.offset == (0.0, 0.0, 0.0)
    assert first.anchor.tcp_length == pytest.approx(0.1)
    assert drift.read(np.array([0.0, 0.0, 0.2]), "main") is None


# ---- the bound is sound: two points the arm reaches are never reported --------------------


@settings(max_examples=60, deadline=None)
@given(model=st.sampled_from(sorted(MODELS)),
       seed=st.integers(0, 2**32 - 1),
       tcp_a=st.tuples(*[st.floats(-0.3, 0.3)] * 3),
       tcp_b=st.tuples(*[st.floats(-0.3, 0.3)] * 3))
def test_law_no_displacement_between_two_reachable_points_is_reported(model, seed, tcp_a,
                                                                      tcp_b):
    rng = np.random.default_rng(seed)
    robot = Robot.model(model)
    q = rng.uniform(-2 * np.pi, 2 * np.pi, size=(2, 6))
    pose_a = np.array([*tcp_a, 0.0, 0.0, 0.0])
    pose_b = np.array([*tcp_b, 0.0, 0.0, 0.0])
    start = robot.fk(q[0], tcp=pose_a)[:3, 3]
    end = robot.fk(q[1], tcp=pose_b)[:3, 3]
    anchor = Anchor("the start", float(np.linalg.norm(tcp_a)))
    relative = Relative(anchor, tuple(end - start), moves=5)
    assert drift_error(relative, np.array(tcp_b), None, MODELS[model], False) is None
    assert drift_error(relative, np.array(tcp_b), None, MODELS["ur3"], True) is None


@settings(max_examples=40, deadline=None)
@given(model=st.sampled_from(sorted(MODELS)), seed=st.integers(0, 2**32 - 1))
def test_law_the_flange_stays_within_the_bound_of_the_shoulder(model, seed):
    spec = MODELS[model]
    q = np.random.default_rng(seed).uniform(-2 * np.pi, 2 * np.pi, size=(64, 6))
    robot = Robot.model(model)
    shoulder = np.array([0.0, 0.0, spec.d1])
    farthest = max(np.linalg.norm(robot.fk(row)[:3, 3] - shoulder) for row in q)
    assert farthest <= flange_reach(spec) + 1e-9


def test_a_direction_node_from_an_unknown_start_is_no_move_to_its_far_target(tmp_path, capsys):
    # PolyScope's Direction node aims 1000 m away from where the arm is and a condition stops
    # it: from an unknown start that target is relative to it, and no destination
    direction = """  thread move_thread_3():
    enter_critical
    movel(pose_add(get_target_tcp_pose(), p[0, 0, -1000, 0, 0, 0]), a=1.2, v=0.1)
    exit_critical
  end
  move_thread_han_3 = run move_thread_3()
  while (True):
    if (tool_contact(direction=get_target_tcp_speed()) > 0):
      kill move_thread_han_3
      stopl(3.0)
      break
    end
    sync()
  end
"""
    text = export("    sleep(1)", direction)
    report = check(tmp_path, capsys, text, "--robot", "ur5e")
    assert errors(report) == []
    # the same move without the condition is out of reach whatever the start
    plain = "    movel(pose_add(get_target_tcp_pose(), p[0, 0, -1000, 0, 0, 0]), a=1.2, v=0.1)"
    assert [f["line"] for f in errors(check(tmp_path, capsys, export(plain),
                                            "--robot", "ur5e"))] == [8]
