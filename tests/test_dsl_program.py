"""The Python DSL: the fixed API shape, values, validation at the user's line, control flow,
functions, threads, catalog checks, and output identical to the printer's."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl import format, parse
from urdsl.dsl import And, DslError, Joints, Not, Or, Pose, Program, deg

THIS_FILE = __file__


def line_of(marker: str) -> int:
    """The line of this file that holds ``marker`` (to check error locations)."""
    with open(THIS_FILE, encoding="utf-8") as handle:
        for number, line in enumerate(handle, 1):
            if marker in line and "line_of(" not in line:
                return number
    raise AssertionError(marker)


def roundtrip(program: Program) -> str:
    text = program.script()
    assert format(parse(text, "dsl.script")) == text
    return text


def test_the_fixed_api_shape():
    program = Program("pick")
    program.movej(Joints(0, -1.57079632, 0, -1.57079632, 0, 0))
    program.movel(Pose(0.2, -0.3, 0.3, 0.5, 0.0, -0.3), a=1.2, v=0.25, r=0.01)
    assert roundtrip(program) == (
        "def pick():\n"
        "  movej([0, -1.57079632, 0, -1.57079632, 0, 0])\n"
        "  movel(p[0.2, -0.3, 0.3, 0.5, 0, -0.3], a=1.2, v=0.25, r=0.01)\n"
        "end\n")


def test_joints_and_poses():
    assert Joints.deg(0, -90, 0, -90, 0, 0)[1] == pytest.approx(-math.pi / 2)
    assert deg(180) == pytest.approx(math.pi)
    p = Pose(0.2, -0.3, 0.3, 0.5, 0.0, -0.3)
    assert p.matrix[0] == pytest.approx([0.95626064, 0.28328667, -0.07289894, 0.2], abs=1e-8)
    assert Pose.from_matrix(p.matrix) == pytest.approx(p)
    assert (p @ p.inv()) == pytest.approx((0, 0, 0, 0, 0, 0), abs=1e-12)
    shifted = p @ Pose(0, 0, 0.1)
    assert np.allclose(shifted.matrix, p.matrix @ Pose(0, 0, 0.1).matrix)
    rpy = Pose.from_rpy(0, 0, 0, 0.1, 0.2, 0.3).rpy
    assert rpy == pytest.approx((0.1, 0.2, 0.3))


def test_five_joints_are_refused_at_the_users_line():
    program = Program()
    with pytest.raises(DslError) as caught:
        program.movej([0, -1.57, 0, -1.57, 0])  # five-joints-here
    error = caught.value
    assert "6 joint angles, got 5" in str(error)
    assert error.location.filename == THIS_FILE
    assert error.location.line == line_of("# five-joints-here")
    assert "program.movej([0, -1.57, 0, -1.57, 0])" in str(error)


@pytest.mark.parametrize("call,message", [
    (lambda p: p.movej(Joints(0, 0, 0, 0, 0, 0), v=-1), "must not be negative"),
    (lambda p: p.movel(Pose(0.3, 0, 0.3), r=5), "r is in metres"),
    (lambda p: p.movel([0.3, 0, 0.3, 0, 0, 0]), "needs a Pose"),
    (lambda p: p.movej(Joints(0, -90, 0, -90, 0, 0)), "look like degrees"),
    (lambda p: Pose(0.1, float("nan"), 0), "not finite"),
    (lambda p: p.servoj(Joints(0, 0, 0, 0, 0, 0), lookahead_time=0.5), "lookahead_time"),
    (lambda p: p.set_digital_out(9, True), "does not exist"),
    (lambda p: p.call("movej", [0] * 6, speed=3), "no parameter 'speed'"),
    (lambda p: p.call("movj", [0] * 6), "not a URScript builtin"),
    (lambda p: p.call("textmsg", "a", "b", "c"), "at most 2 arguments"),
    (lambda p: p.call("set_tcp"), "set_tcp() is missing the argument 'pose'"),
    (lambda p: p.var("sleep", 1), "name of a builtin"),
])
def test_mistakes_are_refused(call, message):
    with pytest.raises(DslError) as caught:
        call(Program())
    # the message and hint, not the rendered error (which quotes this file's line)
    assert message in f"{caught.value.message} {caught.value.hint}"


def test_expressions_and_control_flow():
    program = Program("loop")
    count = program.var("count", 0)
    limit = program.var("limit", 5, scope="global")
    with program.while_((count < limit) & Not(count == 3)):
        program.set(count, count + 1)
        with program.if_(Or(count % 2 == 0, count > 4)):
            program.textmsg("even or big: ", count)
        with program.elif_(count == 1):
            program.sleep(0.5)
        with program.else_():
            program.sync()
    with program.if_(And(count >= 1, count <= 5)):
        program.halt()
    text = roundtrip(program)
    assert "while count < limit and not count == 3:" in text
    assert "if count % 2 == 0 or count > 4:" in text
    assert "elif count == 1:" in text and "else:" in text
    assert "global limit = 5" in text


def test_python_truth_of_an_expression_is_an_error():
    program = Program()
    x = program.var("x", 1)
    with pytest.raises(DslError, match="no Python truth value"):
        if x > 0:
            pass


def test_else_needs_an_if():
    with pytest.raises(DslError, match="must follow an if_"):
        with Program().else_():
            pass


def test_functions_and_threads():
    program = Program("cell")
    with program.function("approach", "target", height=0.1) as approach:
        above = program.var("above", program.expr("pose_trans", approach.target,
                                                   program.pose(0, 0, -approach.height,
                                                                0, 0, 0)))
        program.movel(above, v=0.25, r=0.02)
        program.return_(above)
    with program.thread("blink") as blink:
        with program.while_(True):
            program.set_tool_digital_out(0, ~program.tool_digital_in(0))
            program.sleep(0.5)
    handle = program.run(blink, "blinker")
    approach.call(Pose(0.4, 0, 0.2, 0, math.pi, 0))
    target = program.var("reached", approach(Pose(0.4, 0.1, 0.2, 0, math.pi, 0), height=0.05))
    program.movel(target)
    program.kill(handle)
    text = roundtrip(program)
    assert "def approach(target, height=0.1):" in text
    assert "blinker = run blink()" in text and "kill blinker" in text
    assert "approach(p[0.4, 0, 0.2, 0, 3.141592653589793, 0])" in text


def test_markers_and_comments_survive():
    program = Program("labelled")
    program.comment("first line\nsecond line")
    program.marker(1, "Robot Program")
    program.marker(2, "Waypoint_1", "breakAfter")
    program.blank()
    program.movej(Joints(0, -1.57, 1.57, -1.57, -1.57, 0))
    text = roundtrip(program)
    assert '$ 2 "Waypoint_1" "breakAfter"' in text and "# second line" in text


def test_statements_carry_the_python_line():
    program = Program("spans")
    program.movej(Joints(0, -1.57, 1.57, -1.57, -1.57, 0))  # span-marker
    statement = program.tree().body[0].body[0]
    assert statement.span.filename == THIS_FILE
    assert statement.span.line == line_of("# span-marker")
    assert statement.expr.span.line == statement.span.line  # the call too, for the verifier


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(
    st.sampled_from(["movej", "movel", "sleep", "var", "if"]),
    st.floats(-1, 1, allow_nan=False), st.floats(0, 0.5, allow_nan=False)),
    min_size=1, max_size=12))
def test_random_programs_print_as_the_printer_does(steps):
    program = Program("random")
    x = program.var("x", 0)
    for kind, value, positive in steps:
        if kind == "movej":
            program.movej(Joints(value, -1.5, 1.5, value, -1.5, 0), v=positive or None)
        elif kind == "movel":
            program.movel(Pose(0.3 + value / 10, value / 10, 0.3, 0, math.pi, 0), r=positive / 100)
        elif kind == "sleep":
            program.sleep(positive)
        elif kind == "var":
            program.set(x, (x + value) * 2 - -value)
        else:
            with program.if_(x > value):
                program.textmsg("x ", x / 3)
    tree = program.tree()
    text = format(tree)
    assert parse(text, "random.script") == tree  # the DSL's tree is the parser's tree
    assert format(parse(text, "random.script")) == text


def test_an_unclosed_block_is_reported():
    program = Program()
    manager = program.while_(True)
    manager.__enter__()
    with pytest.raises(DslError, match="still open"):
        program.tree()


def test_a_pose_where_joints_are_required():
    program = Program()
    program.movej(Pose(0.3, 0.1, 0.3, 0, 3.14, 0))  # movej solves a pose: allowed
    with pytest.raises(DslError, match="servoj needs joint angles, not a Pose"):
        program.servoj(Pose(0.3, 0.1, 0.3, 0, 3.14, 0))
