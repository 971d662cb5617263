"""Installation variables (``*.variables``): ``name=value`` lines, bad lines reported with
file:line:col, never a traceback."""

from __future__ import annotations

import string

from hypothesis import given
from hypothesis import strategies as st

from urdsl.polyscope.variables import parse_variables, read_variables
from urdsl.script import nodes as n


def test_each_line_is_a_variable_with_its_value_and_place():
    result = parse_variables('count=0\n\nhome=p[0.1, -0.4, 0.3, 0, 3.14, 0]\n'
                             'label="cell 1"\n', "default.variables")
    assert [(v.name, v.line, v.span.column) for v in result.variables] == [
        ("count", 1, 1), ("home", 3, 1), ("label", 4, 1)]
    assert isinstance(result.variables[1].value, n.Pose)
    assert result.diagnostics == []
    assert result.names()["label"].value == n.String("cell 1")


def test_a_bad_line_is_a_diagnostic_and_the_others_are_kept():
    text = "a=1\nnot a variable\nb=[1, 2\nc = True\n"
    result = parse_variables(text, "cell.variables")
    assert [v.name for v in result.variables] == ["a", "c"]
    assert [(d.filename, d.line, d.code, d.severity) for d in result.diagnostics] == [
        ("cell.variables", 2, "URS001", "error"), ("cell.variables", 3, "URS001", "error")]
    rendered = result.diagnostics[1].render()
    assert rendered.startswith("cell.variables:3:")
    assert "b=[1, 2" in rendered  # the line is shown
    # the variable after a broken line keeps its own line and column
    assert result.names()["c"].span.line == 4


def test_an_unreadable_file_is_one_diagnostic(tmp_path):
    result = read_variables(tmp_path / "missing.variables")
    assert result.variables == []
    assert "cannot read" in result.diagnostics[0].message


@given(st.text(alphabet=string.printable, max_size=120))
def test_any_text_gives_variables_or_diagnostics_never_an_exception(text):
    result = parse_variables(text, "x.variables")
    for variable in result.variables:
        assert variable.span.source is not None
        assert variable.span.source.text[variable.span.start:variable.span.end] == \
            variable.name
    for diagnostic in result.diagnostics:
        assert diagnostic.line >= 1


def test_polyscope_writes_a_java_properties_file():
    text = '#\n#Mon May 11 15:45:38 CEST 2026\nheight=355\nlabel="a\\:b\\u00e9"\nok=True\n'
    result = parse_variables(text, "default.variables")
    assert result.diagnostics == []
    assert [(v.name, v.line) for v in result.variables] == [
        ("height", 3), ("label", 4), ("ok", 5)]
    assert result.names()["label"].value == n.String("a:bé")
