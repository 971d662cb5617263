"""What `urdsl send` sends, and the way back from the controller's line to the user's line."""

from __future__ import annotations

from pathlib import Path

import pytest
from _corpus import corpus_available, corpus_files, fill_template

from urdsl.dsl import Joints, Program
from urdsl.robot.program import WRAPPER_NAME, needs_wrapping, prepare_text, prepare_tree
from urdsl.script import nodes as n
from urdsl.script.diagnostics import ScriptSyntaxError
from urdsl.script.parser import parse

PROGRAMS = Path(__file__).resolve().parents[1] / "programs"

BARE = """\
# wave
home = [0, -1.57, 0, -1.57, 0, 0]
movej(home, a=1.4)
if True:
  textmsg("x", 1 / 0)
end
"""


def test_bare_statements_are_wrapped_without_a_trailing_call():
    prepared = prepare_text(BARE, "wave.script")
    assert prepared.wrapped
    lines = prepared.text.splitlines()
    assert lines[0] == f"def {WRAPPER_NAME}():"
    assert lines[-1] == "end"  # the controller needs `end` in column 0 as the last line
    assert lines[2] == "  home = [0, -1.57, 0, -1.57, 0, 0]"
    assert prepared.text.endswith("end\n")
    assert prepared.name == WRAPPER_NAME


def test_a_single_def_is_sent_as_printed():
    text = "def pick():\n  movej([0,0,0,0,0,0])\nend\n"
    prepared = prepare_text(text, "pick.script")
    assert not prepared.wrapped
    assert prepared.text == "def pick():\n  movej([0, 0, 0, 0, 0, 0])\nend\n"
    assert prepared.name == "pick"


@pytest.mark.parametrize("text, wrap", [
    ("def a():\nend\n", False),
    ("def a(x):\nend\n", True),          # a def with parameters is not a program
    ("def a():\nend\na()\n", True),
    ("def a():\nend\ndef b():\nend\n", True),
    ("sec s():\n  set_digital_out(1, True)\nend\n", False),
    ("x = 1\n", True),
    ("# only a comment\n", True),
])
def test_when_to_wrap(text, wrap):
    assert needs_wrapping(parse(text)) is wrap


def test_controller_lines_map_back_through_the_wrapper():
    prepared = prepare_text(BARE, "wave.script")
    # the division by zero is on sent line 6 (user line 5), one level deeper
    sent = prepared.sent_line(6)
    assert sent == '    textmsg("x", 1 / 0)'
    column = sent.index("1 / 0") + 1
    location = prepared.locate(6, column)
    assert (location.filename, location.line, location.column) == ("wave.script", 5, 16)
    assert location.source_line == '  textmsg("x", 1 / 0)'
    # a column of 0 (unknown) gives the statement on the line
    assert prepared.locate(4, 0).line == 3 and prepared.locate(4, 0).column == 1
    # the wrapper's own lines are urdsl's, not the user's
    assert prepared.locate(1, 1) is None
    assert prepared.locate(99, 1) is None


def test_dsl_program_lines_map_to_the_python_file():
    program = Program("wave")
    program.movej(Joints(0, -1.57, 0, -1.57, 0, 0))
    marker_line = _line_of_next_statement()
    program.textmsg("done")
    prepared = prepare_tree(program.tree(), __file__)
    assert not prepared.wrapped
    location = prepared.locate(3, 0)  # def wave(): / movej / textmsg
    assert location.filename == __file__
    assert location.line == marker_line
    assert "program.textmsg" in location.source_line


def _line_of_next_statement() -> int:
    import inspect

    return inspect.currentframe().f_back.f_lineno + 1


def test_syntax_errors_are_raised_with_the_users_line():
    with pytest.raises(ScriptSyntaxError) as caught:
        prepare_text("movej([0,0,0,0,0,0]))\n", "bad.script")
    assert caught.value.line == 1


def _statements(module):
    return [node for node in n.walk(module) if isinstance(node, n.Stmt)
            and node.span.source is not None]


def _check_every_statement_maps_back(text: str, name: str) -> None:
    original = parse(text, name)
    prepared = prepare_tree(original, name)
    sent = parse(prepared.text, "sent")
    if prepared.wrapped:  # the wrapper's def is urdsl's own
        sent = n.Module(sent.body[0].body)
    for before, after in zip(_statements(original), _statements(sent), strict=True):
        location = prepared.locate(after.span.line, after.span.column)
        assert location is not None, (name, after.span)
        assert (location.line, location.column) == (before.span.line, before.span.column), \
            (name, before)


def test_every_statement_of_the_course_program_maps_back():
    path = PROGRAMS / "course_examples.script"
    _check_every_statement_maps_back(path.read_text(), str(path))


@pytest.mark.skipif(not corpus_available(), reason="corpus not available")
def test_every_statement_of_the_corpus_maps_back():
    checked = 0
    for item in corpus_files():
        text = item.text()
        if item.templated:
            text = fill_template(text, item.path)
        try:
            parse(text, item.name)
        except ScriptSyntaxError:
            continue
        _check_every_statement_maps_back(text, item.name)
        checked += 1
    assert checked >= 20
