"""Each problem the verifier knows, detected at the right line, in a small program of its own.

Programs start with a movej to known joints and build their poses from the pose reached
there, so they hold for the model under test without hand-computed coordinates.
"""

from __future__ import annotations

import math
import textwrap

import pytest

from urdsl.verify.run import CheckOptions, check_text

READY = "movej([0, -1.9, 1.9, -1.57, -1.57, 0])"  # tool down, in front of the robot


def check(body: str, robot: str = "ur5e", **options):
    text = textwrap.dedent(body).lstrip("\n")
    return check_text(text, "test.script", options=CheckOptions(robot=robot, **options))


def only(report, code):
    found = [f for f in report.findings if f.code == code]
    assert found, f"expected {code}, got:\n{report.render_text()}"
    return found


def test_a_clean_program_has_no_findings_and_a_cycle_time():
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.02)
        movel(pose_add(home, p[0.1, 0.1, 0, 0, 0, 0]), r=0.02)
        movel(home)
        """)
    assert [f for f in report.findings if f.severity != "info"] == [], report.render_text()
    assert len(report.moves) == 4
    assert report.cycle_time == pytest.approx(report.moves[-1].start
                                              + report.moves[-1].duration, abs=0.01)


def test_overlapping_blends_skip_the_move_with_a_warning():
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.05)
        movel(pose_add(home, p[0.1, 0.06, 0, 0, 0, 0]), r=0.05)
        movel(home)
        """)
    (finding,) = only(report, "URS309")
    assert finding.severity == "warning" and finding.span.line == 4
    assert "Overlapping Blends" in finding.message
    assert not report.has_errors
    assert [m.span.line for m in report.moves] == [1, 3, 5]


def test_unreachable_pose():
    report = check(f"""
        {READY}
        textmsg("going far")
        movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])
        """)
    (finding,) = only(report, "URS301")
    assert finding.severity == "error" and (finding.span.line, finding.span.column) == (3, 1)
    assert report.has_errors


def test_movel_through_an_unreachable_region_between_reachable_ends():
    # The straight line from one side of the base to the other passes the base's axis,
    # where no UR can put its wrist (the shoulder offset keeps it away).
    report = check("""
        movej(get_inverse_kin(p[0.35, -0.2, 0.3, 0, 3.1416, 0]))
        movel(p[-0.35, 0.2, 0.3, 0, 3.1416, 0])
        """)
    found = only(report, "URS302")
    assert found[0].span.line == 2
    assert "URS301" not in report.codes()


def test_joint_position_limit():
    report = check(f"""
        {READY}
        movej([0, -1.9, 1.9, -1.57, -1.57, 6.5])
        """)
    (finding,) = only(report, "URS303")
    assert finding.span.line == 2 and "wrist 3" in finding.message


def test_joint_speed_over_the_model_limit():
    report = check(f"""
        {READY}
        movej([3, -1.9, 1.9, -1.57, -1.57, 0], t=0.2)
        """)
    (finding,) = only(report, "URS304")
    assert finding.span.line == 2 and "base" in finding.message


def test_a_movej_asked_faster_than_its_joints_go_is_timed_at_their_top_speed():
    # PolyScope's MoveJ offers 180 deg/s on a UR10, whose base tops at 120 deg/s: the move
    # takes as long as the base needs, and nothing stops
    report = check(f"""
        {READY}
        movej([3, -1.9, 1.9, -1.57, -1.57, 0], a=20, v=5)
        """, robot="ur10")
    assert "URS304" not in report.codes(), report.render_text()
    move = report.moves[-1]
    assert 3.0 / math.radians(120) < move.duration < 3.0 / math.radians(120) + 0.2


def test_wrist_singularity_during_a_movel():
    report = check("""
        movej([0.3, -1.6, 1.6, -1.57, 0.25, 0])
        a = get_actual_tcp_pose()
        movej([0.3, -1.6, 1.6, -1.57, -0.25, 0])
        b = get_actual_tcp_pose()
        movej([0.3, -1.6, 1.6, -1.57, 0.25, 0])
        movel(b)
        """)
    found = [f for f in report.findings if f.code in ("URS307", "URS302")]
    assert found and found[0].span.line == 6, report.render_text()
    assert any(f.code == "URS307" and "wrist" in f.message for f in report.findings)


def test_collision_with_the_floor(tmp_path):
    cell = tmp_path / "cell.toml"
    cell.write_text("[floor]\nheight = 0.0\n")
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0, 0, -0.2, 0, 0, 0]))
        movel(pose_add(home, p[0, 0, -1.0, 0, 0, 0]))
        """, cell=str(cell))
    (finding,) = only(report, "URS308")
    assert finding.span.line == 4 and finding.severity == "error"


def test_undefined_variable_at_runtime():
    report = check(f"""
        {READY}
        movel(target)
        """)
    (finding,) = only(report, "URS201")
    assert (finding.span.line, finding.span.column) == (2, 7)


def test_index_out_of_range():
    report = check("""
        q = [0, -1.9, 1.9, -1.57, -1.57, 0]
        movej(q)
        x = q[6]
        """)
    (finding,) = only(report, "URS202")
    assert finding.span.line == 3


def test_a_thread_busy_looping_without_sync():
    report = check(f"""
        thread watch():
          while True:
            x = 1
          end
        end
        {READY}
        t = run watch()
        sleep(1)
        """)
    (finding,) = only(report, "URS207")
    assert finding.span.line == 2


def test_a_loop_of_one_waypoint_is_not_a_loop_without_time():
    # PolyScope's looping Robot Program with a single MoveJ: after the first pass the arm is
    # at its target, and each move still takes the planner a controller frame
    report = check(f"""
        {READY}
        while True:
          movej([0, -1.9, 1.9, -1.57, -1.57, 0])
        end
        """, max_time=2.0)
    assert not [f for f in report.findings if f.code == "URS207"], report.render_text()
    assert any(f.code == "URS312" for f in report.findings)  # it ran to --max-time


def test_threads_left_running_and_time_limit():
    report = check(f"""
        thread beat():
          while True:
            sleep(0.5)
          end
        end
        {READY}
        t = run beat()
        """)
    assert "URS311" in report.codes()
    forever = check("""
        while True:
          sleep(1)
        end
        """, max_time=20)
    assert "URS312" in forever.codes() and not forever.has_errors


def test_tcp_speed_limit():
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0.2, 0, 0, 0, 0, 0]), v=0.5)
        movel(home, v=0.2)
        """, tcp_speed_limit=0.25, start_joints=(0, -1.9, 1.9, -1.57, -1.57, 0))
    (finding,) = only(report, "URS306")
    assert finding.span.line == 3


@pytest.mark.parametrize("distance,v,a", [(0.2, 0.25, 1.2), (0.02, 0.25, 1.2)])
def test_single_movel_lasts_the_closed_form_time(distance, v, a):
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[{distance}, 0, 0, 0, 0, 0]), a={a}, v={v})
        """)
    expected = distance / v + v / a if distance >= v * v / a else 2 * math.sqrt(distance / a)
    assert report.moves[1].duration == pytest.approx(expected, rel=1e-9)


def test_single_movej_lasts_the_closed_form_time_of_the_leading_axis():
    report = check("""
        movej([0, -1.9, 1.9, -1.57, -1.57, 0])
        movej([1.0, -1.5, 1.9, -1.57, -1.57, 0], a=1.4, v=1.05)
        """, start_joints=(0, -1.9, 1.9, -1.57, -1.57, 0))
    expected = 1.0 / 1.05 + 1.05 / 1.4
    assert report.moves[1].duration == pytest.approx(expected, rel=1e-9)
    assert report.cycle_time == pytest.approx(expected, abs=0.003)


def test_the_robot_stops_at_an_unreachable_target_even_when_solved_later():
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]))
        movel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])
        textmsg("after")
        movel(home)
        q = get_actual_joint_positions()
        """)
    (finding,) = only(report, "URS301")
    assert finding.span.line == 4 and "out of reach by" in finding.message
    assert [m.span.line for m in report.moves] == [1, 3]
    assert all(e.message != "after" for e in report.events)
    assert report.cycle_time == pytest.approx(report.moves[-1].start
                                              + report.moves[-1].duration)


def test_blend_radius_over_half_a_neighbouring_segment():
    """URS310 at the move whose radius is too large for the short segment after it (the
    spheres do not overlap, so the robot does not skip it: a warning of the house rule)."""
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        movel(pose_add(home, p[0.2, 0, 0, 0, 0, 0]), r=0.03)
        movel(pose_add(home, p[0.2, 0.05, 0, 0, 0, 0]), r=0.01)
        movel(home)
        """)
    (finding,) = only(report, "URS310")
    assert finding.span.line == 3 and "0.03 m" in finding.message
    assert [f.code for f in report.findings if f.code == "URS309"] == []


@pytest.mark.parametrize("at", [1, 32767, 32768, 32769, 40000 - 1])
def test_a_jump_is_found_wherever_it_lies_in_a_long_trace(at):
    """path_continuity works in blocks of samples: a jump on a block boundary counts too. The
    move after the jump is not the arm's motion (the controller stops there): the other
    checks leave it out, but keep what comes before the knot interval that draws the jump."""
    from types import SimpleNamespace

    import numpy as np

    from urdsl.motion.trace import Trace
    from urdsl.script.nodes import NO_SPAN
    from urdsl.verify.checks import path_continuity

    count, dt = 40000, 0.002
    q = np.zeros((count, 6))
    q[at:, 3] = math.pi  # wrist 1 flips half a turn between two samples
    move = SimpleNamespace(kind="movel", span=NO_SPAN, start=0.0, duration=count * dt)
    trace = Trace(np.arange(count) * dt, q, np.zeros_like(q), np.zeros_like(q),
                  np.zeros(count, dtype=np.int64), dt, [move], np.zeros(count, dtype=bool))
    found = path_continuity(trace, np.full(6, 3.14))
    (finding,) = found.findings
    assert f"t={at * dt:.3f} s" in finding.message and "wrist 1" in finding.message
    assert found.samples[at:].all() and not found.samples[:max(at - 20, 0)].any()


# ---- issue 12, item 5: motion semantics found wrong on real programs -------------------------


def test_a_short_movel_that_mostly_turns_the_tool_is_timed_on_its_rotation():
    # 1 cm along the tool's x and 120° about its z: at the defaults (v = 0.25 m/s,
    # a = 1.2 m/s²) the path alone would take 0.18 s and spin wrist 3 at over 20 rad/s
    report = check(f"""
        {READY}
        movel(pose_trans(get_target_tcp_pose(), p[0.01, 0, 0, 0, 0, {math.radians(120)}]))
        """)
    assert "URS304" not in report.codes(), report.render_text()
    assert not report.has_errors
    turn = report.moves[1]
    # rotation trapezoid: 2.094 rad at 1 rad/s with 4.8 rad/s²: 2.094 + 1/4.8 s
    assert turn.duration == pytest.approx(math.radians(120) / 1.0 + 1.0 / 4.8, rel=1e-6)


def test_a_move_that_mostly_translates_keeps_the_time_of_its_path():
    report = check(f"""
        {READY}
        movel(pose_trans(get_target_tcp_pose(), p[0.3, 0, 0, 0, 0, 0.2]), a=1.2, v=0.25)
        """)
    # 0.3 m at 0.25 m/s with 1.2 m/s²: 0.3/0.25 + 0.25/1.2; 0.2 rad takes far less
    assert report.moves[1].duration == pytest.approx(0.3 / 0.25 + 0.25 / 1.2, rel=1e-6)


def test_a_bug_in_a_loop_is_reported_once_with_how_often_and_when_first():
    report = check(f"""
        {READY}
        i = 0
        while i < 12:
          movej([0, -1.9, 1.9, -1.57, -1.57, 0])
          movej([0, -1.9, 1.9, -1.57, -1.57, 3.0], t=0.5)
          i = i + 1
        end
        """)
    (finding,) = only(report, "URS304")
    assert finding.span.line == 5 and finding.count == 12
    assert "wrist 3" in finding.message
    assert finding.message.endswith(f"(12 times, first at t={finding.time:.3f} s)")
    first_pass = [m for m in report.moves if m.span.line == 5][0]
    assert first_pass.start <= finding.time <= first_pass.start + first_pass.duration
    assert report.to_dict()["findings"][0]["count"] == 12


def test_a_controller_warning_in_a_loop_is_reported_once():
    report = check(f"""
        {READY}
        home = get_actual_tcp_pose()
        i = 0
        while i < 3:
          movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.05)
          movel(pose_add(home, p[0.1, 0.06, 0, 0, 0, 0]), r=0.05)
          movel(home)
          i = i + 1
        end
        """)
    (finding,) = only(report, "URS309")
    assert finding.count == 3 and "(3 times, first at t=" in finding.message


def test_findings_differing_only_in_numbers_merge_but_not_across_joints_or_lines():
    from urdsl.script.nodes import Source, Span
    from urdsl.verify.findings import Finding
    from urdsl.verify.report import Report

    source = Source("a = 1\nb = 2\n", "t.script")
    here, there = Span(source, 0, 5), Span(source, 6, 11)
    report = Report("t.script", "ur5e", findings=[
        Finding("URS205", "warning", "socket read 12 timed out after 0.5 s", here, 2.0),
        Finding("URS205", "warning", "socket read 7 timed out after 0.25 s", here, 1.0),
        Finding.of("URS304", "wrist 1 joint turns at 4.00 rad/s", here, 1.5),
        Finding.of("URS304", "wrist 2 joint turns at 4.00 rad/s", here, 1.6),
        Finding("URS205", "warning", "socket read 3 timed out after 0.5 s", there, 0.1),
    ])
    report.sort()
    messages = [f.message for f in report.findings]
    assert messages == ["socket read 7 timed out after 0.25 s (2 times, first at t=1.000 s)",
                        "wrist 1 joint turns at 4.00 rad/s", "wrist 2 joint turns at 4.00 rad/s",
                        "socket read 3 timed out after 0.5 s"]
    report.sort()  # sorting again changes nothing
    assert [f.message for f in report.findings] == messages


def _line_past_the_base(x: float) -> str:
    """A movel, tool down, along y at ``x`` (m) in front of the base: the wrist centre passes
    the base axis at about |x|, and the shoulder singularity lies on the cylinder of radius
    d4 (0.1333 m on a UR5e) around it, the workspace's inner boundary."""
    return f"""
        {READY}
        start = get_actual_tcp_pose()
        movej(p[{x}, -0.35, 0.25, start[3], start[4], start[5]])
        movel(p[{x}, 0.35, 0.25, start[3], start[4], start[5]], a=0.5, v=0.1)
        """


@pytest.mark.parametrize("x", [0.16, 0.145])
def test_a_movel_near_the_shoulder_singularity_follows_one_solution(x):
    # the base turns by about 130° while the tool passes the base: the IK solution closest
    # to the straight joint-space line between the ends is another branch mid-way, which
    # gave a jump and joint speeds of 20-100 rad/s; the arm follows its branch smoothly
    report = check(_line_past_the_base(x))
    assert not {"URS302", "URS304"} & set(report.codes()), report.render_text()
    base_speed = abs(report.trace.qd[:, 0]).max()
    assert base_speed < 3.0
    # the move ends where its branch leads, turning the base the long way round
    line = report.trace.segment == 2
    turned = report.trace.q[line, 0].max() - report.trace.q[line, 0].min()
    assert turned > math.radians(100)


def test_a_movel_through_the_shoulder_singularity_is_still_reported():
    report = check(_line_past_the_base(0.13))
    (finding,) = only(report, "URS302")
    assert finding.span.line == 4 and "workspace" in finding.message


def test_the_course_movel_from_a_singular_pose_is_still_found():
    from pathlib import Path

    mistakes = Path(__file__).parent.parent / "programs" / "mistakes"
    path = mistakes / "course_movel_from_singular.script"
    report = check(path.read_text(encoding="utf-8"))
    # the arm stops where the path fails: no joint speed is reported for the trace after it,
    # the singularities that make it fail are
    assert {"URS302", "URS307"} <= set(report.codes())
    assert {f.span.line for f in report.findings if f.severity == "error"} == {20}


def _across_the_base_twice(back: str) -> str:
    down = "0, 3.1416, 0"
    return textwrap.dedent(f"""\
        movej(get_inverse_kin(p[0.4, 0.1, 0.3, {down}]), a=1.4, v=1.0)
        i = 0
        while i < 2:
          movel(p[0.4, 0.1, 0.3, {down}], a=1.2, v=0.25)
          movel(p[-0.4, 0.1, 0.3, {down}], a=1.2, v=0.25)
          {back}
          i = i + 1
        end
        """)


def test_a_later_pass_after_a_failed_path_is_a_warning_unless_joints_are_given_again():
    # line 5 crosses the cylinder over the base (URS302, where the controller stops the
    # program); the check goes on, and the second pass's line 4 starts from line 6's end,
    # across the base again. Line 4 ran cleanly before the failure: what it meets now
    # follows from where the check went on after the failure (San28 Program1's wound
    # wrist), a warning; after a movej to given joints the joints are the program's again
    report = check(_across_the_base_twice("movel(p[-0.4, -0.1, 0.3, 0, 3.1416, 0], a=1.2, "
                                          "v=0.25)"))
    errors = {(f.code, f.span.line) for f in report.findings if f.severity == "error"}
    assert ("URS302", 5) in errors and not any(line == 4 for _, line in errors), errors
    (later,) = [f for f in report.findings if f.code == "URS302" and f.span.line == 4]
    assert later.severity == "warning" and "after the path at line 5 failed" in later.message
    from urdsl.kinematics import Robot

    far = Robot.model("ur5e").ik([-0.4, -0.1, 0.3, 0, 3.1416, 0], [1.5, -1.2, 1.2, -1.5, -1.5, 0])
    joints = ", ".join(f"{v:.6f}" for v in far)
    report = check(_across_the_base_twice(f"movej([{joints}], a=1.4, v=1.0)"))
    assert any(f.code == "URS302" and f.span.line == 4 and f.severity == "error"
               for f in report.findings), report.render_text()


# PolyScope's Direction node "until tool contact", as the e-Series writes it (shortened): a
# thread moves toward a point 1000 m away; the main loop kills it and stops the arm when the
# condition fires
DIRECTION = f"""
    def calculate_point_to_move_towards(feature, direction, position_distance):
      local posDir=[direction[0], direction[1], direction[2]]
      local unit=normalize(posDir)
      local d=position_distance
      local displacement=p[unit[0] * d, unit[1] * d, unit[2] * d, 0, 0, 0]
      local wanted=pose_sub(pose_trans(feature, displacement), feature)
      return pose_add(get_target_tcp_pose(), wanted)
    end
    {READY}
    global move_thread_flag_3=0
    thread move_thread_3():
      enter_critical
      move_thread_flag_3 = 1
      local towardsPos=calculate_point_to_move_towards(p[0,0,0,0,0,0], [0.0,0.0,-1.0], 1000.0)
      movel(towardsPos, a=1.2, v=0.1)
      move_thread_flag_3 = 2
      exit_critical
    end
    move_thread_han_3 = run move_thread_3()
    while (True):
      local stepsToRetract=tool_contact(direction=get_target_tcp_speed())
      if (stepsToRetract > 0):
        kill move_thread_han_3
        stopl(3.0)
        break
      end
      if (move_thread_flag_3 > 1):
        break
      end
      sync()
    end
    """


def test_a_direction_move_until_contact_is_not_a_move_to_its_far_target():
    report = check(DIRECTION)
    assert not {"URS301", "URS302"} & set(report.codes()), report.render_text()
    (move,) = [m for m in report.moves if m.kind == "movel"]
    assert move.span.line == 15
    # checked down to where the arm could still follow the line: about a metre at 0.1 m/s
    assert 5.0 < move.duration < 20.0
    assert not report.trace.unreachable.any()


def test_a_direction_move_is_still_checked_up_to_where_it_could_stop(tmp_path):
    cell = tmp_path / "cell.toml"
    cell.write_text("[floor]\nheight = 0.0\n")
    report = check(DIRECTION, cell=str(cell))
    (finding,) = only(report, "URS308")  # the floor is on its way down
    assert finding.span.line == 15 and "URS301" not in report.codes()
    # a warning: a move until tool contact is made to stop at what it touches first
    assert finding.severity == "warning" and "on a move its condition stops" in \
        finding.message
    plain = DIRECTION.replace("movel(towardsPos, a=1.2, v=0.1)",
                              "movel(pose_add(get_target_tcp_pose(), p[0, 0, -0.8, 0, 0, 0]), "
                              "a=1.2, v=0.1)").replace("kill move_thread_han_3", "sync()")
    (floor,) = only(check(plain, cell=str(cell)), "URS308")  # no condition stops it
    assert floor.severity == "error"


def test_the_same_far_target_without_a_condition_is_unreachable():
    report = check(f"""
        {READY}
        movel(pose_add(get_target_tcp_pose(), p[0, 0, -1000.0, 0, 0, 0]), a=1.2, v=0.1)
        """)
    (finding,) = only(report, "URS301")
    assert finding.span.line == 2


def test_stoppable_moves_are_those_in_a_thread_killed_under_a_condition():
    from urdsl.motion.direction import stoppable_moves
    from urdsl.script.parser import parse

    module = parse(textwrap.dedent("""
        thread until():
          movel(p[0, 0, -1000, 0, 0, 0])
        end
        thread plain():
          movel(p[0, 0, -1000, 0, 0, 0])
        end
        handle = run until()
        other = run plain()
        movel(p[0, 0, -1000, 0, 0, 0])
        while True:
          if get_digital_in(0):
            kill handle
            stopl(2)
          end
          sync()
        end
        join other
        """).lstrip("\n"), filename="t.script")
    assert sorted(span.line for span in stoppable_moves(module)) == [2]


def _killed_under(condition: str, move: str) -> str:
    """A move in a thread that the program kills when ``condition`` holds (the shape of
    PolyScope's "Until" on a waypoint or Direction); the move is the block's fifth line."""
    return textwrap.dedent(f"""\
        global move_thread_flag_7=0
        thread move_thread_7():
          enter_critical
          move_thread_flag_7 = 1
          {move}
          move_thread_flag_7 = 2
          exit_critical
        end
        move_thread_han_7 = run move_thread_7()
        while (True):
          if ({condition}):
            kill move_thread_han_7
            stopl(1.2)
            break
          end
          if (move_thread_flag_7 > 1):
            join move_thread_han_7
            break
          end
          sync()
        end
        """)


def test_a_stoppable_move_to_a_target_out_of_reach_is_a_warning_not_an_error():
    # "Until" on a waypoint, or a search move toward a point past a box wall, killed when an
    # input or tool contact fires: its target is 20 cm beyond the reach of a UR5e. Whether
    # the arm gets to the edge of its workspace depends on the outside world (the input),
    # unknown offline: a warning that says so, and the line is checked up to that edge
    report = check(_killed_under("get_digital_in(0)",
                                 "movel(p[0.95, 0.2, 0.3, 0, 3.1416, 0], a=1.2, v=0.25)"))
    assert not {"URS301", "URS302"} & set(report.codes()), report.render_text()
    (finding,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 5]
    assert finding.severity == "warning"
    assert "out of reach by" in finding.message and "condition" in finding.message
    (move,) = [m for m in report.moves if m.span.line == 5]
    assert move.duration > 0.5  # the line up to the edge of the workspace is still checked


SEARCH_ACROSS_THE_BASE = (
    "movej(get_inverse_kin(p[0.4, 0.0, 0.3, 0, 3.1416, 0]), a=1.4, v=1.0)\n"
    + _killed_under("tool_contact(direction=get_target_tcp_speed()) > 0",
                    "movel(p[-0.4, 0.0, 0.3, 0, 3.1416, 0], a=1.2, v=0.1)")
    + "movel(p[-0.4, 0.05, 0.3, 0, 3.1416, 0], a=1.2, v=0.25)\n")


def test_a_stoppable_line_the_arm_cannot_follow_to_its_target_is_a_warning():
    # a Direction with "until distance" and "until tool contact": its target is reachable,
    # but the straight line to it passes over the base, through the cylinder no wrist can
    # enter. The arm gets there only if no contact stops it first (the move is made to
    # touch something): a warning that says how far the line can be followed, the line
    # checked up to before there, and the next move starts where the arm stopped (unknown)
    report = check(SEARCH_ACROSS_THE_BASE)
    assert not [f for f in report.findings if f.severity == "error"], report.render_text()
    (finding,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 6]
    assert "can follow this line only" in finding.message and "of its 800 mm" in \
        finding.message and "condition" in finding.message
    (move,) = [m for m in report.moves if m.span.line == 6]
    assert 0.0 < move.duration < 8.0  # not the whole 0.8 m at 0.1 m/s
    # the next line, drawn from where the check left the arm, would cross the base too
    (after,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 23]
    assert "after the move at line 6, which a condition stops" in after.message
    # the same line without a condition fails where the arm cannot follow it
    plain = check(SEARCH_ACROSS_THE_BASE.replace("kill move_thread_han_7", "sync()"))
    assert any(f.code == "URS302" and f.span.line == 6 and f.severity == "error"
               for f in plain.findings), plain.render_text()


def test_the_same_waypoint_out_of_reach_without_a_condition_is_an_error():
    report = check("""
        movel(p[0.95, 0.2, 0.3, 0, 3.1416, 0], a=1.2, v=0.25)
        """)
    (finding,) = only(report, "URS301")
    assert finding.span.line == 1


FREEDRIVE = f"""
    {READY}
    freedrive_mode()
    popup("Move the tool to the corner, then press Continue", blocking=True)
    end_freedrive_mode()
    corner = get_actual_tcp_pose()
    movel(pose_trans(corner, p[0, 0, -1.5, 0, 0, 0]), a=1.2, v=0.1)
    """


def test_where_the_operator_left_the_arm_in_freedrive_is_unknown():
    # the operator placed the tool by hand: a path computed from where it stands is not
    # checked against where the simulated arm happens to be (a warning says why)
    report = check(FREEDRIVE)
    assert "URS301" not in report.codes(), report.render_text()
    (warning,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 6]
    assert "freedrive at line 2" in warning.message and "by hand" in warning.message


def test_a_move_to_a_known_target_after_freedrive_is_checked_again():
    text = textwrap.dedent(FREEDRIVE).lstrip("\n") + textwrap.dedent(f"""\
        {READY}
        movel(pose_trans(get_actual_tcp_pose(), p[0, 0, -1.5, 0, 0, 0]), a=1.2, v=0.1)
        """)
    (finding,) = only(check(text), "URS301")
    assert finding.span.line == 8


def test_a_speed_move_from_an_unknown_position_leaves_it_unknown():
    # an edge search (Philippschwind/Projektarbeit_UR_Robot, blind batch 23): a move to a
    # taught point the project does not hold, then speedl until a force; two such searches
    # must not read the same "known" pose, or the program's distance check halts the run and
    # nothing after it is checked
    report = check("""
        def edge():
          speedl([0.01, 0, 0, 0, 0, 0], 0.1, 0.05)
          stopl(1)
          return get_actual_tcp_pose()
        end
        movel(first_point, a=1.2, v=0.2)
        p1 = edge()
        movel(second_point, a=1.2, v=0.2)
        p2 = edge()
        if norm(p2[0] - p1[0]) < 0.01:
          popup("too close", blocking=True)
          halt
        end
        textmsg(after_the_check)
        """)
    undefined = {f.span.line for f in report.findings if f.code == "URS201"}
    assert undefined == {6, 8, 14}, report.render_text()
    (condition,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 10]
    assert "after the move at line 8 to an unknown target" in condition.message


def test_where_a_direction_move_stops_is_unknown_until_a_move_to_a_known_target():
    # after "until tool contact" the arm is wherever the part was: a move relative to that
    # is not checked against the end of reach (a warning says why); a taught move makes the
    # position known again
    text = textwrap.dedent(DIRECTION).lstrip("\n") + textwrap.dedent(f"""\
        movel(pose_trans(get_actual_tcp_pose(), p[0.355, 0, 0, 0, 0, 0]), a=1.2, v=0.1)
        {READY}
        movel(pose_trans(get_actual_tcp_pose(), p[0, 0, -2.0, 0, 0, 0]), a=1.2, v=0.1)
        """)
    report = check(text)
    relative = 1 + next(i for i, line in enumerate(text.splitlines()) if "0.355" in line)
    assert "URS301" in report.codes()  # the last move, from a known pose, is out of reach
    (unreachable,) = only(report, "URS301")
    assert unreachable.span.line == relative + 2
    (warning,) = [f for f in report.findings
                  if f.code == "URS210" and f.span.line == relative]
    assert "after the move at line 15" in warning.message


_MOVE = "  movej([0, -1.9, 1.9, -1.57, -1.57, 0])\n"


@pytest.mark.parametrize(("text", "names"), [
    (f"def a():\n{_MOVE}end\ndef b():\n  a()\nend\n", "(a(), b())"),
    (f"def go(speed):\n{_MOVE}end\n", "(go())"),  # a def with parameters is not the program
    (f"global home = [0, 0, 0, 0, 0, 0]\ndef Program():\n{_MOVE}end\n", "(Program())"),
    ("thread beat():\n  sleep(1)\nend\n", "(beat())"),
])
def test_a_file_that_only_defines_says_nothing_ran(text, names):
    report = check_text(text, "defs.script", options=CheckOptions(timeout=None))
    (finding,) = [f for f in report.findings if f.code == "URS314"]
    assert finding.severity == "info" and names in finding.message
    assert "runs none of them" in finding.message
    assert report.moves == []


@pytest.mark.parametrize("text", [
    f"def Program():\n{_MOVE}end\n",  # a PolyScope export: the controller runs the def
    f"def Program():\n{_MOVE}end\nthread t():\n  sleep(1)\nend\n",
    f"def a():\n{_MOVE}end\ndef b():\n  a()\nend\nb()\n",
    f"def a():\n{_MOVE}end\nglobal x = a()\n",  # a global whose value calls a()
    "sec s():\n  set_standard_digital_out(0, True)\nend\n",
    "x = 1\n",
    "",
])
def test_a_program_that_runs_is_not_told_nothing_ran(text):
    report = check_text(text, "prog.script", options=CheckOptions(timeout=None))
    assert "URS314" not in report.codes()


def test_the_path_of_a_move_from_where_an_unknown_move_left_the_arm_is_not_checked():
    fast = "movej([3.0, -1.9, 1.9, -1.57, -1.57, 0], t=0.2)"  # the base: 3 rad in 0.2 s
    (error,) = only(check(f"{READY}\n{fast}"), "URS304")
    assert error.span.line == 2
    report = check(f"""
        {READY}
        goal = read_input_integer_register(0)
        movej([goal, -1.9, 1.9, -1.57, -1.57, 0])
        {fast}
        """)
    assert "URS304" not in report.codes(), report.render_text()
    (note,) = [f for f in report.findings if f.code == "URS210" and f.span.line == 4]
    assert "after the move at line 3 to an unknown target" in note.message
    assert "path is not checked" in note.message


def test_a_builtin_that_is_not_simulated_gives_a_list_of_its_own_length():
    # set_payload(m, cog) takes three numbers: get_target_payload_cog() gives three
    report = check(f"""
        {READY}
        set_payload(1.2, get_target_payload_cog())
        """)
    assert not [f for f in report.findings if f.severity == "error"], report.render_text()


@pytest.mark.parametrize(("target", "reported"), [
    # the forearm folded back until upper arm and wrist 1 overlap by 2 mm: within what the
    # approximate link shapes can tell (arms taught on the robot pass such poses)
    ("[-0.7169, -0.0399, -2.886, -0.0877, 2.8188, -1.3079]", False),
    # ... and folded further, 20 mm deep: a self-collision
    ("[-0.7241, -0.0211, -2.9342, -0.0728, 2.863, -1.3211]", True),
])
def test_a_self_collision_is_one_deeper_than_the_link_shapes_can_tell(target, reported):
    report = check(f"""
        {READY}
        movej({target})
        """)
    assert ("URS308" in report.codes()) is reported, report.render_text()
