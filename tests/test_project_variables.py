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


XML = """<InstallationVariables timestamp="Mon Jan 05 10:00:00 CET 2026">
  <variable name="parts_done" value="12" favourite="false"/>
  <variable name="drop_pose" value="p[0.4, -0.2, 0.1, 0.0, 3.14, 0.0]" favourite="true"/>
  <variable name="label" value="&quot;line A&quot;" favourite="false"/>
  <variable name="broken" value="[1, 2" favourite="false"/>
</InstallationVariables>
"""


def test_the_xml_form_of_polyscope_5():
    result = parse_variables(XML, "default.variables")
    assert [(v.name, v.line, v.span.column) for v in result.variables] == [
        ("parts_done", 2, 19), ("drop_pose", 3, 19), ("label", 4, 19)]
    assert result.names()["label"].value == n.String("line A")
    assert isinstance(result.names()["drop_pose"].value, n.Pose)
    [problem] = result.diagnostics
    assert (problem.line, problem.code) == (5, "URS001")
    assert 'value="[1, 2"' in problem.source_line


def test_gzip_compressed_files_are_read_and_damaged_ones_reported(tmp_path):
    import gzip

    (tmp_path / "a.variables").write_bytes(gzip.compress(XML.encode()))
    (tmp_path / "b.variables").write_bytes(gzip.compress(b"#stamp\nspeed=0.25\n"))
    (tmp_path / "c.variables").write_bytes(gzip.compress(b"speed=0.25\n")[:12])
    assert [v.name for v in read_variables(tmp_path / "a.variables").variables] == [
        "parts_done", "drop_pose", "label"]
    assert [v.name for v in read_variables(tmp_path / "b.variables").variables] == ["speed"]
    damaged = read_variables(tmp_path / "c.variables")
    assert damaged.variables == []
    assert damaged.diagnostics[0].message.endswith("c.variables cannot be read: the gzip data "
                                                   "is truncated")
