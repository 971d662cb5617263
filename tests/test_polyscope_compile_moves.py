"""Compiling PolyScope's motion nodes as PolyScope writes them: process moves and circles,
relative waypoints, Direction/Until, Force, conditions checked continuously, and PolyScope 3
waypoints written in place. Fixtures written here (tests/data/polyscope/moves.urp,
legacy3.urp)."""

from __future__ import annotations

from pathlib import Path

import pytest

from urdsl.polyscope.compile import compile_program
from urdsl.polyscope.urp import read_urp
from urdsl.script import parse
from urdsl.script.printer import format as print_tree

DATA = Path(__file__).parent / "data" / "polyscope"


@pytest.fixture(scope="module")
def lines():
    text = compile_program(read_urp(DATA / "moves.urp")).text
    assert print_tree(parse(text)) == text
    return [line.strip() for line in text.splitlines()]


def test_process_move_blends_but_stops_at_its_end(lines):
    assert "movep(Start_p, a=1.2, v=0.1, r=0.025)" in lines
    # a circle: via and end in one movec, fixed orientation is mode 1
    at = lines.index('$ 4 "CircleMove"')
    assert lines[at + 1:at + 4] == ['$ 5 "Via" "noBreak"', '$ 6 "End" "breakAfter"',
                                    "movec(Via_p, End_p, a=1.2, v=0.1, r=0.025, mode=1)"]
    # the last motion of a process move followed by no other process move does not blend
    assert "movep(Last_p, a=1.2, v=0.1, r=0.0)" in lines


def test_relative_waypoint(lines):
    assert any(line.startswith("global Up_from_p = p[") for line in lines)
    assert any(line.startswith("global Up_to_p = p[") for line in lines)
    assert "movel(pose_add(get_target_tcp_pose(), pose_sub(Up_to_p, Up_from_p)), " \
           "a=1.2, v=0.25)" in lines


def test_direction_runs_a_move_thread_and_waits_for_its_untils(lines):
    assert "def calculate_point_to_move_towards(feature, direction, position_distance):" \
        in lines
    assert "local towardsPos = calculate_point_to_move_towards(get_forward_kin(), " \
           "[0.0, 0.0, -1.0], 0.05)" in lines
    assert "movel(towardsPos, a=1.2, v=0.02)" in lines  # the node's own speed, acceleration
    # tool contact is checked first, then the distance
    contact = lines.index('$ 13 "Until (tool_contact_detection)"')
    distance = lines.index('$ 11 "Until (distance)"')
    assert contact < distance
    assert "stopl(3.0)" in lines and "movel(retractTo, a=3.0, v=0.1)" in lines
    assert lines[distance + 1] == '$ 12 "Popup: no part"'


def test_force_mode_around_the_children(lines):
    at = lines.index('$ 14 "Force"')
    assert lines[at + 1:at + 4] == [
        "sleep(0.02)", "zero_ftsensor()",
        "force_mode(tool_pose(), [0, 0, 1, 0, 0, 0], [0.0, 0.0, 5.0, 0.0, 0.0, 0.0], 2, "
        "[0.1, 0.1, 0.05, 0.3, 0.3, 0.3])"]
    assert lines[at + 4] == '$ 15 "Wait: 2.0" "noBreak"'
    assert lines[at + 6:at + 8] == ["end_force_mode()", "stopl(5.0)"]


def test_conditions_checked_continuously_run_in_threads(lines):
    assert "thread Thread_while_16():" in lines
    assert "global thread_handler_16 = run Thread_while_16()" in lines
    assert "kill thread_handler_16" in lines
    assert "thread Thread_if_17():" in lines
    assert "if not (y > 1):" in lines
    assert "if (thread_flag_17 == 2):" in lines  # the Else runs when the If did not
    assert "while (not (y == 0)):" in lines


def test_polyscope3_waypoints_are_written_in_place():
    text = compile_program(read_urp(DATA / "legacy3.urp")).text
    assert "global" not in text
    assert "movej(get_inverse_kin(p[0.1, 0.2, 0.3, 0.0, 3.14, 0.0], " \
           "qnear=[0.0, -1.5, 1.5, -1.5, -1.5, 0.0]), a=1.3962634015954636, " \
           "v=1.0471975511965976)" in text
    assert "movel(p[0.1, 0.2, 0.3, 0.0, 3.14, 0.0], a=1.2, v=0.25)" in text  # shared position
