"""The parser takes the language as real files write it and builds the right tree."""

from __future__ import annotations

import pytest

from urdsl import ScriptSyntaxError, format, parse
from urdsl.script.nodes import (
    Assign,
    Attribute,
    BinOp,
    Blank,
    Bool,
    Break,
    Call,
    Comment,
    Continue,
    Declare,
    EnterCritical,
    ExitCritical,
    ExprStmt,
    FunctionDef,
    Halt,
    If,
    Index,
    Join,
    Keyword,
    Kill,
    List,
    Marker,
    Name,
    NoneLit,
    Number,
    Paren,
    Pose,
    Return,
    Run,
    SecDef,
    String,
    ThreadDef,
    UnaryOp,
    While,
)


def expr(text: str):
    """The expression of ``x = <text>``."""
    return parse(f"x = {text}").body[0].value


def only(text: str):
    body = parse(text).body
    assert len(body) == 1, body
    return body[0]


# ---- definitions and blocks ---------------------------------------------------------------


def test_def_thread_sec_nested():
    tree = parse(
        "def prog():\n"
        "  def helper(a, b=2):\n    return a + b\n  end\n"
        "  thread worker():\n    sync()\n  end\n"
        "  sec side():\n  end\n"
        "end\n"
    )
    prog = tree.body[0]
    assert isinstance(prog, FunctionDef) and prog.name == "prog" and prog.params == ()
    helper, worker, side = prog.body
    assert isinstance(helper, FunctionDef)
    assert [p.name for p in helper.params] == ["a", "b"]
    assert helper.params[1].default == Number(2)
    assert helper.body == (Return(BinOp("+", Name("a"), Name("b"))),)
    assert isinstance(worker, ThreadDef) and worker.body == (ExprStmt(Call(Name("sync"))),)
    assert isinstance(side, SecDef) and side.body == ()


def test_if_elif_else_and_while():
    stmt = only("if a > 1:\n  x = 1\nelif a < 0:\n  x = 2\nelif b:\nelse:\n  x = 3\nend")
    assert isinstance(stmt, If)
    assert stmt.test == BinOp(">", Name("a"), Number(1))
    assert [e.test for e in stmt.elifs] == [BinOp("<", Name("a"), Number(0)), Name("b")]
    assert stmt.elifs[1].body == ()
    assert stmt.orelse == (Assign(Name("x"), Number(3)),)
    assert only("if a:\nend").orelse is None
    assert only("if a:\nelse:\nend").orelse == ()
    loop = only("while (True):\n  break\n  continue\nend")
    assert isinstance(loop, While) and loop.test == Paren(Bool(True))
    assert loop.body == (Break(), Continue())


def test_simple_statements():
    body = parse(
        "return\nreturn 5\nhalt\nenter_critical\nexit_critical\n"
        "global g\nglobal h = 1\nlocal l = [1, 2]\nlocal m\n"
        "t = run worker()\nrun worker()\njoin t\nkill t\n"
    ).body
    assert body == (
        Return(None), Return(Number(5)), Halt(), EnterCritical(), ExitCritical(),
        Declare("global", "g"), Declare("global", "h", Number(1)),
        Declare("local", "l", List((Number(1), Number(2)))), Declare("local", "m"),
        Assign(Name("t"), Run("worker")), ExprStmt(Run("worker")),
        Join(Name("t")), Kill(Name("t")),
    )


def test_statements_outside_def_and_several_on_one_line():
    body = parse("a = 1 b = 2 f(a) g() w = -w").body
    assert body == (
        Assign(Name("a"), Number(1)), Assign(Name("b"), Number(2)),
        ExprStmt(Call(Name("f"), (Name("a"),))), ExprStmt(Call(Name("g"))),
        Assign(Name("w"), UnaryOp("-", Name("w"))),
    )


def test_manual_one_line_def():
    stmt = only('def myFun(): mystring = "Hello Interpreter" textmsg(mystring) end')
    assert isinstance(stmt, FunctionDef) and len(stmt.body) == 2


def test_empty_blocks_and_empty_file():
    assert parse("").body == ()
    assert parse("   \n\n  # only a comment\n").body == (Comment(" only a comment"),)
    assert only("def f():\nend").body == ()
    assert only("while x:\nend").body == ()


# ---- layout: newlines, comments, markers, line endings ------------------------------------


def test_newlines_inside_brackets_and_space_before_paren():
    stmt = only("movel(\n  p[0.1,\n    0.2, 0.3, 0, 0, 0],\n  a = 1.2,\n  v=0.25)")
    assert stmt.expr.keywords == (Keyword("a", Number(1.2)), Keyword("v", Number(0.25)))
    assert only("textmsg (\"hi\")") == ExprStmt(Call(Name("textmsg"), (String("hi"),)))


def test_comments_everywhere_are_kept():
    tree = parse(
        "# head\n"
        "def f(): # after header\n"
        "  x = 1#c\n"
        "  foo(1, # inside a call\n"
        "      2)\n"
        "  # before end\n"
        "end # after end\n"
    )
    f = tree.body[1]
    assert tree.body[0] == Comment(" head")
    assert f.body[0] == Comment(" after header", trailing=True)
    assert f.body[1] == Assign(Name("x"), Number(1))
    assert f.body[2] == Comment("c", trailing=True)
    assert f.body[3] == Comment(" inside a call")  # set in front of its statement
    assert f.body[4] == ExprStmt(Call(Name("foo"), (Number(1), Number(2))))
    assert f.body[5] == Comment(" before end")
    assert tree.body[2] == Comment(" after end", trailing=True)


def test_comment_inside_condition_goes_before_the_statement():
    tree = parse("while (a and # why\n b):\n  sync()\nend\n")
    assert tree.body[0] == Comment(" why")
    assert isinstance(tree.body[1], While)


def test_blank_lines_kept_between_statements_only():
    tree = parse("\n\na = 1\n\n\n\nb = 2\n\ndef f():\n\n  c = 3\n\nend\n\n\n")
    assert tree.body == (
        Assign(Name("a"), Number(1)), Blank(), Assign(Name("b"), Number(2)), Blank(),
        FunctionDef("f", (), (Assign(Name("c"), Number(3)),)),
    )


def test_polyscope_markers():
    body = parse(
        '$ 4 "Waypoint_1" "breakAfter"\n'
        '  $ 2 "Gripper Move30% (1)"\n'
        "$ 1 机器人程序\n"
        '$ 7 "Füge ein #1"\n'
    ).body
    assert body == (
        Marker(4, "Waypoint_1", "breakAfter"),
        Marker(2, "Gripper Move30% (1)"),
        Marker(1, "机器人程序", None, quoted=False),
        Marker(7, "Füge ein #1"),
    )


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r\n\t", "\n \t"])
def test_line_endings_tabs_mixed_indentation_no_final_newline(newline):
    text = newline.join(["def f():", "\tx = 1", "    \ty = 2", "end"])
    stmt = only(text)
    assert stmt.body == (Assign(Name("x"), Number(1)), Assign(Name("y"), Number(2)))


# ---- literals and expressions -------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "value"),
    [("42", 42), ("1.5", 1.5), (".5", 0.5), ("5.", 5.0), ("1.0E-10", 1e-10), ("2.5e5", 2.5e5),
     ("0", 0), ("-.143", None)],
)
def test_numbers(text, value):
    node = expr(text)
    if value is None:
        assert node == UnaryOp("-", Number(0.143))
    else:
        assert node == Number(value) and type(node.value) is type(value)


def test_strings_have_no_escapes():
    assert expr('"\\"') == String("\\")
    assert expr('"a\\nb"') == String("a\\nb")
    assert expr("'single'") == String("single")
    assert expr('"ünïcödé"') == String("ünïcödé")


def test_lists_matrices_poses_structs():
    assert expr("[]") == List(())
    assert expr("[[1, 2], [3, 4]]") == List((List((Number(1), Number(2))),
                                             List((Number(3), Number(4)))))
    pose = expr("p[0.2, -0.3, 0.3, 0.5, 0.0, -0.3]")
    assert isinstance(pose, Pose) and len(pose.items) == 6
    assert expr("struct(a=1, b=2)") == Call(Name("struct"), (), (Keyword("a", Number(1)),
                                                                 Keyword("b", Number(2))))
    assert expr("None") == NoneLit() and expr("False") == Bool(False)


def test_p_as_a_name_and_pose_literal_side_by_side():
    stmt = only("def f(x, p, yaw):\n  pose = p[x, p, yaw, rv[0], rv[1], p]\n  p1 = p\n"
                "  p[0] = p[0] * 2\n  q = p [1]\nend")
    pose, alias, element, spaced = stmt.body
    assert isinstance(pose.value, Pose) and pose.value.items[1] == Name("p")
    assert alias.value == Name("p")
    assert element.target == Index(Name("p"), (Number(0),))
    assert spaced.value == Index(Name("p"), (Number(1),))


def test_indexing_fields_methods_and_assignment_targets():
    assert expr("m[i, j]") == Index(Name("m"), (Name("i"), Name("j")))
    assert expr("h.m()") == Call(Attribute(Name("h"), "m"))
    assert expr("f(1).p[2]") == Index(Attribute(Call(Name("f"), (Number(1),)), "p"),
                                      (Number(2),))
    body = parse("a[1] = 2 m[1, 2] = 3 s.f = 4 s.l[0] = 5").body
    assert [type(s.target) for s in body] == [Index, Index, Attribute, Index]


def test_calls_with_keywords():
    call = expr("movej(q, a=1.4, v=1.05, t=0, r=0)")
    assert call.args == (Name("q"),)
    assert [k.name for k in call.keywords] == ["a", "v", "t", "r"]


@pytest.mark.parametrize(
    ("text", "tree"),
    [
        ("a or b and c", BinOp("or", Name("a"), BinOp("and", Name("b"), Name("c")))),
        ("a xor b or c", BinOp("or", BinOp("xor", Name("a"), Name("b")), Name("c"))),
        ("not a == b", UnaryOp("not", BinOp("==", Name("a"), Name("b")))),
        ("not a and b", BinOp("and", UnaryOp("not", Name("a")), Name("b"))),
        ("! a", UnaryOp("!", Name("a"))),
        ("a + b * c", BinOp("+", Name("a"), BinOp("*", Name("b"), Name("c")))),
        ("a - b - c", BinOp("-", BinOp("-", Name("a"), Name("b")), Name("c"))),
        ("a / b % c", BinOp("%", BinOp("/", Name("a"), Name("b")), Name("c"))),
        ("-a * b", BinOp("*", UnaryOp("-", Name("a")), Name("b"))),
        ("a <= b != c", BinOp("!=", BinOp("<=", Name("a"), Name("b")), Name("c"))),
        ("1 > 2 or 3 != 4 xor 5 < -6", BinOp("xor", BinOp("or",
            BinOp(">", Number(1), Number(2)), BinOp("!=", Number(3), Number(4))),
            BinOp("<", Number(5), UnaryOp("-", Number(6))))),
        ("(a + b) * c", BinOp("*", Paren(BinOp("+", Name("a"), Name("b"))), Name("c"))),
    ],
)
def test_operator_precedence(text, tree):
    assert expr(text) == tree


# ---- spans --------------------------------------------------------------------------------


def test_spans_name_lines_and_columns():
    line2 = "  movel(p[1, 2, 3, 0, 0, 0], a=1.2)"
    tree = parse(f"def f():\n{line2}\nend\n", "t.script")
    call = tree.body[0].body[0].expr
    assert (call.span.line, call.span.column) == (2, 3)
    assert (call.span.end_line, call.span.end_column) == (2, len(line2) + 1)
    pose = call.args[0]
    assert pose.span.column == line2.index("p[") + 1
    assert pose.span.end_column == line2.index("]") + 2
    assert call.keywords[0].value.span.column == line2.index("1.2") + 1
    assert call.span.filename == "t.script"
    assert tree.body[0].span.end_line == 3


# ---- errors -------------------------------------------------------------------------------


def syntax_error(text: str) -> ScriptSyntaxError:
    with pytest.raises(ScriptSyntaxError) as caught:
        parse(text, "course.script")
    return caught.value


def test_course_stray_parenthesis():
    error = syntax_error("p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])")
    assert (error.line, error.column) == (1, 45)
    assert error.message == "unexpected ')': the pose opened at 1:6 is already closed"
    rendered = str(error)
    assert rendered.startswith("course.script:1:45: error:")
    assert "p1 = p[0.200" in rendered and "\n" + " " * 46 + "^" in rendered


def test_globl_is_two_statements_not_a_traceback():
    assert parse("globl x = 1").body == (ExprStmt(Name("globl")), Assign(Name("x"), Number(1)))


@pytest.mark.parametrize(
    ("text", "line", "column", "words"),
    [
        ("def f():\n  x = 1\n", 1, 1, "never closed by 'end'"),
        ("x += 1", 1, 3, "no '+='"),
        ("x = 2 ** 3", 1, 7, "'**'"),
        ("if x = 1:\nend", 1, 6, "'='"),
        ("for i in range(3):\nend", 1, 1, "no 'for' loop"),
        ("foo(1, 2]", 1, 9, "does not close the parenthesis opened at 1:4"),
        ("x = 1;", 1, 6, "';'"),
        ("end", 1, 1, "without a block"),
        ('x = "abc', 1, 5, "string not closed"),
        ("if a:\nelse if b:\nend\nend", 2, 1, "'elif'"),
        ("f(a=1, 2)", 1, 8, "positional argument after a keyword"),
        ("f(a=1, a=2)", 1, 8, "given twice"),
        ("x = (1 +", 1, 5, "never closed"),
        ("x = p[1, 2, 3]", 1, 5, "a pose has 6 values"),
        ("f() = 1", 1, 1, "cannot assign to a call"),
        ("x = a[1, 2, 3]", 1, 13, "too many indices"),
        ("thread t(a):\nend", 1, 10, "unexpected name a"),
        ("def f(a, a):\nend", 1, 10, "appears twice"),
        ("x = 1 @ 2", 1, 7, "'@'"),
    ],
)
def test_syntax_errors_say_where_and_why(text, line, column, words):
    error = syntax_error(text)
    assert (error.line, error.column) == (line, column), str(error)
    assert words in str(error)
    assert "Traceback" not in str(error) and "Lark" not in str(error)


def test_hint_for_threads_with_parameters():
    assert "take no parameters" in (syntax_error("thread t(a):\nend").hint or "")


def test_format_single_nodes():
    assert format(expr("a+b*(c)")) == "a + b * (c)"
    assert format(only("if a:\n x=1\nend")) == "if a:\n  x = 1\nend"


def test_a_lone_cr_inside_a_comment_of_an_lf_file_is_part_of_the_comment():
    # the OnRobot URCap's preamble comment, as PolyScope writes it into every program
    text = "x = 1\n#======    OnRobot FT Search Part\r    ======#\ny = x\n"
    tree = parse(text, filename="onrobot.script")
    assert format(tree) == text
    # in a file of CR-only lines, a CR still ends the comment
    classic = "x = 1\r# note\ry = x\r"
    assert [type(item).__name__ for item in parse(classic).body][-1] == "Assign"
