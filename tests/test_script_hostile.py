"""Hostile and unusual input to the language tools: deep trees, huge numbers, odd line ends,
byte-order marks. Every case ends with a result or a message, never a traceback."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

import urdsl
from urdsl._deep import FOLLOWED_DEPTH
from urdsl.cli import main
from urdsl.script.nodes import dump_json, to_dict

DEEP = FOLLOWED_DEPTH


def _long_sum(terms: int) -> str:
    return "x = " + " + ".join(["1"] * terms) + "\n"


def _nested_blocks(levels: int) -> str:
    head = "".join("  " * (i % 40) + "while True:\n" for i in range(levels))
    return head + "sync()\n" + "end\n" * levels


def test_deep_trees_print_without_recursion():
    # the printer, to_dict and the JSON writer walk with explicit stacks at any depth
    tree = urdsl.parse(_long_sum(20_000), filename="sum.script")
    text = urdsl.format(tree)
    assert text == "x = " + " + ".join(["1"] * 20_000) + "\n"
    document = dump_json(to_dict(tree))
    assert document.count('"BinOp"') == 19_999
    nested = urdsl.parse(_nested_blocks(3_000), filename="nest.script")
    lines = urdsl.format(nested).splitlines()
    assert lines[2_999] == "  " * 2_999 + "while True:"
    assert lines[3_000] == "  " * 3_000 + "sync()"
    assert lines[-1] == "end"


@pytest.mark.parametrize("command", [
    ["parse", "--json"], ["fmt"], ["lint"], ["check", "--max-time", "1"],
    ["send", "--dry-run", "--host", "127.0.0.1"],
])
@pytest.mark.parametrize("program", ["sum", "blocks"])
def test_commands_follow_deep_programs(tmp_path, capsys, command, program):
    path = tmp_path / "deep.script"
    path.write_text(_long_sum(DEEP) if program == "sum" else _nested_blocks(2_000))
    status = main([*command, str(path)])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "RecursionError" not in err
    assert status == 0, err[-500:]


def test_too_deep_is_a_message_not_a_traceback(tmp_path, capsys):
    path = tmp_path / "deeper.script"
    path.write_text(_long_sum(150_000))
    status = main(["check", "--max-time", "1", str(path)])
    err = capsys.readouterr().err
    assert status == 1
    assert "nests too deeply for urdsl to follow" in err and "Traceback" not in err


@given(st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=5), children, max_size=4),
    max_leaves=30))
def test_dump_json_is_json(value):
    assert dump_json(value) == json.dumps(value)
    assert json.loads(dump_json(value, indent=1)) == json.loads(json.dumps(value, indent=1))
    assert dump_json(value, indent=1) == json.dumps(value, indent=1)


def test_number_beyond_float_range_is_a_syntax_error():
    with pytest.raises(urdsl.ScriptSyntaxError) as caught:
        urdsl.parse("x = 1e309\n", filename="big.script")
    diagnostic = caught.value.diagnostic
    assert (diagnostic.line, diagnostic.column) == (1, 5)
    assert "largest number" in diagnostic.message
    assert urdsl.format(urdsl.parse("x = 1.7e308\n")) == "x = 1.7e308\n"


def test_attribute_of_a_number_keeps_its_meaning():
    tree = urdsl.parse("x = 1 .a\n")
    text = urdsl.format(tree)
    assert text == "x = 1 .a\n"
    assert urdsl.parse(text) == tree


@pytest.mark.parametrize("newline", ["\r", "\r\n", "\n"])
def test_line_ends_of_any_kind_give_the_right_line(newline):
    text = newline.join(["x = 1", "y = 2", "", "z = (", ""])
    with pytest.raises(urdsl.ScriptSyntaxError) as caught:
        urdsl.parse(text, filename="ends.script")
    assert (caught.value.diagnostic.line, caught.value.diagnostic.column) == (4, 5)
    tree = urdsl.parse(newline.join(["a = 1", "", "b = 2"]))
    assert urdsl.format(tree) == "a = 1\n\nb = 2\n"  # the blank line is kept


def test_byte_order_mark_is_no_character():
    tree = urdsl.parse("\ufeffx = 1\ny = x\n", filename="bom.script")
    assert urdsl.format(tree) == "x = 1\ny = x\n"
    with pytest.raises(urdsl.ScriptSyntaxError) as caught:
        urdsl.parse("\ufeffx = )\n", filename="bom.script")
    diagnostic = caught.value.diagnostic
    assert (diagnostic.line, diagnostic.column) == (1, 5)  # the mark is no column
    assert "\ufeff" not in diagnostic.render()


def _lint_work(monkeypatch, text: str) -> int:
    """Nodes the linter's tree walks visit while linting ``text`` (a measure of its work
    that does not depend on the machine's speed)."""
    from urdsl.lint import linter
    from urdsl.script import nodes

    visited = 0
    walk = nodes.walk

    def counting_walk(node):
        nonlocal visited
        for inner in walk(node):
            visited += 1
            yield inner

    monkeypatch.setattr(nodes, "walk", counting_walk)
    linter.lint_text(text, "nest.script")
    return visited


def _nested_loops(levels: int, innermost: str) -> str:
    return ("x = 0\n" + "while x < 5:\n" * levels + innermost + "\n" + "end\n" * levels)


_BLENDED = "movej([0, -1.57, 1.57, -1.57, -1.57, 0], r=0.01)\n"


@pytest.mark.parametrize("shape", [
    lambda levels: _nested_loops(levels, "sleep(0.1)"),
    # a blended move before each loop: URS111 asked each loop whether it only waits
    lambda levels: "x = 0\n" + (_BLENDED + "while x < 5:\n") * levels + "sync()\n"
    + "end\n" * levels,
    lambda levels: "x = 0\nif x > 0:\n  sync()\nend\n" + "while x < 5:\n" * levels
    + "sleep(1)\n" + "end\n" * levels,
], ids=["loops", "blended-moves", "after-if"])
def test_lint_work_grows_linearly_with_loop_nesting(monkeypatch, shape):
    # each loop used to walk everything nested in it: 3,000 levels took 9 s, 10,000 over 100 s
    small = _lint_work(monkeypatch, shape(500))
    large = _lint_work(monkeypatch, shape(2_000))
    assert large < 5 * small  # 4 times the depth: linear is 4x, quadratic 16x


def test_nested_loops_keep_their_findings():
    from urdsl.lint.linter import lint_text

    def busy(text: str) -> list[int]:
        return [d.line for d in lint_text(text, "nest.script") if d.code == "URS118"]

    levels = 3_000
    # the innermost loop changes x: every loop around it may end by itself
    assert busy(_nested_loops(levels, "x = x + 1")) == []
    # the innermost loop waits: every loop around it gives up its time slice
    assert busy(_nested_loops(levels, "sync()")) == []
    # nothing waits or changes x: every loop spins
    assert busy(_nested_loops(levels, "y = 1")) == list(range(2, levels + 2))
    # a wait after the inner loop's end belongs to the outer loop only
    text = "x = 0\nwhile x < 5:\n  while x < 5:\n    y = 1\n  end\n  sleep(1)\nend\n"
    assert busy(text) == [3]


def test_findings_on_a_long_line_show_a_window_of_it(tmp_path, capsys):
    # 5,000 nested calls of an unknown function: 5,000 findings on one 20,000-character
    # line used to print the whole line for each (100 MB)
    levels = 5_000
    path = tmp_path / "calls.script"
    path.write_text("x = " + "f(" * levels + "1" + ")" * levels + "\n")
    status = main(["lint", str(path)])
    out = capsys.readouterr().out
    assert status == 1
    assert out.count("unknown function 'f'") == levels
    assert max(len(line) for line in out.splitlines()) < 200
    assert len(out) < 2_000_000
    blocks = [block.splitlines() for block in out.split("\n\n") if "calls.script:1:" in block]
    for _head, text, caret in (block[:3] for block in blocks[::997]):
        assert text[caret.index("^")] == "f"  # the caret still points at the call


def test_long_names_and_lines_render_bounded():
    from urdsl.script.diagnostics import Diagnostic, excerpt

    line = "x = " + "y" * 10_000 + " + zz"
    diagnostic = Diagnostic("a.script", 1, 10_008, "error", "URS102", "unknown name '"
                            + "zz" * 5_000 + "'", "hint " * 5_000, line, 10_010)
    rendered = diagnostic.render().splitlines()
    assert all(len(text) < 500 for text in rendered)
    assert rendered[1].strip().endswith("y + zz") and rendered[2].strip() == "^^"
    assert rendered[1][rendered[2].index("^"):].startswith("zz")
    # a short line is shown whole, as before
    assert excerpt("movej(q)", 1, 6) == ("movej(q)", "^^^^^")
