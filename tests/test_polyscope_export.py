"""PolyScope's export beside a ``.urp`` as evidence of the installation the program ran with
(issue 12, the stop-30 probe of the set's ``.urp`` programs against their exports): a
repository's ``default.installation`` that lacks a Modbus signal, a feature or a URCap
function the export defines is not the installation the program ran with (projects 213, 53
and 37 of bench/realworld). Such a name is an unknown value of that installation, not a
mistake of the program; a name neither defines stays an error."""

from __future__ import annotations

import shutil
from pathlib import Path

from _urp import program as urp_program
from _urp import script_line

from urdsl.cli import main
from urdsl.polyscope.export import exported_by

DATA = Path(__file__).parent / "data" / "polyscope"

READ_SIGNAL = ('<Assignment valueSource="Expression"><variable name="level"/><expression>'
               '<ExpressionIO><pin referencedName="MODBUS_1"/></ExpressionIO></expression>'
               '</Assignment><Wait type="Sleep"><waitTime>0.5</waitTime></Wait>')

EXPORT = """def t():
  modbus_add_signal("127.0.0.1", 255, 128, 2, "MODBUS_1", False)
  global cam_bin1=p[-0.22,-0.61,0.19,-3.14,0.0,0.0]
  def rq_grip():
    return True
  end
  $ 1 "Robot Program"
end
"""


def _project(tmp_path: Path, children: str, export: str | None) -> Path:
    program = tmp_path / "t.urp"
    program.write_text(urp_program(children), encoding="utf-8")
    shutil.copy(DATA / "cell.installation", tmp_path / "default.installation")
    if export is not None:
        (tmp_path / "t.script").write_text(export, encoding="utf-8")
    return program


def test_a_modbus_signal_the_export_adds_is_an_unknown_value(tmp_path, capsys):
    program = _project(tmp_path, READ_SIGNAL, None)
    assert main(["check", str(program)]) == 1
    assert "the I/O 'MODBUS_1' is not named in the installation" in capsys.readouterr().out
    (tmp_path / "t.script").write_text(EXPORT, encoding="utf-8")
    assert main(["check", str(program)]) == 0
    captured = capsys.readouterr()
    assert "URS001" not in captured.out
    assert ("names the default.installation beside the program lacks and t.script "
            "(PolyScope's export of it) defines, read as unknown values of the installation "
            "the program ran with: MODBUS_1") in captured.out
    assert "default.installation lacks MODBUS_1, which t.script beside the program adds" in \
        captured.err


def test_a_feature_and_a_function_the_export_defines_are_not_undefined(tmp_path, capsys):
    children = script_line("movej(cam_bin1)") + script_line("ok = rq_grip()")
    program = _project(tmp_path, children, None)
    assert main(["check", str(program)]) == 1
    out = capsys.readouterr().out
    assert "name 'cam_bin1' is not defined" in out
    (tmp_path / "t.script").write_text(EXPORT, encoding="utf-8")
    assert main(["check", str(program)]) == 0
    out = capsys.readouterr().out
    assert "URS201" not in out and "cam_bin1" in out
    # a name neither the installation nor the export defines stays the program's mistake
    program.write_text(urp_program(children + script_line("movej(nowhere)")), encoding="utf-8")
    assert main(["check", str(program)]) == 1
    out = capsys.readouterr().out
    assert "name 'nowhere' is not defined" in out and "'cam_bin1' is not defined" not in out


def test_lint_says_the_export_defines_what_the_installation_lacks(tmp_path, capsys):
    children = script_line("movej(cam_bin1)") + script_line("ok = rq_grip()")
    program = _project(tmp_path, children, None)
    assert main(["lint", str(program)]) == 1
    assert "URS101 name 'cam_bin1' is not defined [" in capsys.readouterr().out
    (tmp_path / "t.script").write_text(EXPORT, encoding="utf-8")
    assert main(["lint", str(program)]) == 0
    out = capsys.readouterr().out
    assert ("name 'cam_bin1' is not defined: a name of the installation t.script was exported "
            "with (the default.installation beside the program lacks it)") in out
    assert "unknown function 'rq_grip': a name of the installation t.script" in out


def test_what_an_export_defines(tmp_path):
    (tmp_path / "t.urp").write_text("", encoding="utf-8")
    assert exported_by(tmp_path / "t.urp") is None  # no export
    (tmp_path / "t.script").write_text(EXPORT, encoding="utf-8")
    export = exported_by(tmp_path / "t.urp")
    assert export is not None
    assert (export.signals, export.names, export.functions) == (
        {"MODBUS_1"}, {"cam_bin1"}, {"rq_grip"})
    # what the program tree's own nodes assign (after its first marker) is no installation's,
    # nor is a subprogram of the tree
    (tmp_path / "t.script").write_text(EXPORT.replace(
        '  $ 1 "Robot Program"\n',
        '  $ 1 "Robot Program"\n  global counter=0\n'
        '  modbus_add_signal("127.0.0.1", 255, 9, 1, "LATE", False)\n'
        '  def sub():\n    $ 2 "sub"\n  end\n'), encoding="utf-8")
    export = exported_by(tmp_path / "t.urp")
    assert (export.names, export.signals) == ({"cam_bin1"}, {"MODBUS_1"})
    text = EXPORT.replace("  def rq_grip", '  def sub():\n    $ 2 "sub"\n  end\n  def rq_grip')
    (tmp_path / "t.script").write_text(text, encoding="utf-8")
    assert exported_by(tmp_path / "t.urp").functions == {"rq_grip"}
    # not a program PolyScope wrote: no evidence
    for text in ("def t(:\n", "movej(cam_bin1)\n", EXPORT + EXPORT.replace("def t", "def u"),
                 ""):
        (tmp_path / "t.script").write_text(text, encoding="utf-8")
        assert exported_by(tmp_path / "t.urp") is None, text

