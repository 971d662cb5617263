"""Calls of a URCap's functions without its preamble: the error stays, the hint says whose
function it is and how to give urdsl its definitions."""

from __future__ import annotations

import re

from urdsl.lint import lint_text
from urdsl.script.urcaps import _table, urcap_hint, urcap_of
from urdsl.verify.run import check_text

GRIPPER = "def grip():\n  rq_activate_and_wait()\n  rq_close_and_wait()\nend\ngrip()\n"


def test_every_row_names_a_urcap_and_a_public_export():
    table = _table()
    assert len(table) > 500
    assert "rq_close_and_wait" in table and "textmsg" not in table
    assert all(re.fullmatch(r"[A-Za-z_]\w*", name) for name in table)


def test_a_robotiq_call_without_the_preamble_stays_an_error_with_a_hint():
    findings = [d for d in lint_text(GRIPPER, "grip.script") if d.code == "URS102"]
    assert [(d.line, d.severity) for d in findings] == [(2, "error"), (3, "error")]
    assert all("Robotiq_Grippers" in d.hint and "--include" in d.hint for d in findings)
    report = check_text(GRIPPER, "grip.script")
    errors = [f for f in report.findings if f.code == "URS201"]
    assert [f.span.line for f in errors] == [2, 3]
    assert all("Robotiq_Grippers" in f.hint for f in errors)


def test_a_typo_of_a_builtin_is_no_urcap_function():
    assert urcap_of("textmesg") is None and urcap_hint("textmesg") is None
    (finding,) = [d for d in lint_text('textmesg("x")\n', "t.script") if d.code == "URS102"]
    assert finding.hint == "did you mean `textmsg`?"
