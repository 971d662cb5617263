"""The one rule registry: every code URS0xx–URS3xx explained by ``urdsl rules``, and each
checker rule's example finds what it says (its fix does not)."""

from __future__ import annotations

import pytest

from urdsl.cli import main
from urdsl.lint.command import load_rules
from urdsl.runtime import Environment
from urdsl.verify.run import CheckOptions, check_text

RULES = load_rules()

# options a checker example needs (its first comment line says the same to a reader)
OPTIONS = {
    "URS305": {"joint_acceleration_limit": 5.0},
    "URS306": {"tcp_speed_limit": 0.25, "start_joints": (0, -1.9, 1.9, -1.57, -1.57, 0)},
    "URS312": {"max_time": 20.0},
    "URS313": {"max_time": 20.0},
}
NOT_RUN = {"URS204": "a move to an unreachable pose is URS301 in urdsl check",
           "URS214": "a .urp's URCap node: tests/test_polyscope_check.py checks one"}


def test_every_stage_has_its_codes_once():
    stages = {code: rule.stage for code, rule in RULES.items()}
    assert stages["URS001"] == "parse"
    assert {c for c, s in stages.items() if s == "runtime"} == {f"URS20{i}" for i in range(1, 10)}
    assert {c for c, s in stages.items() if s == "check"} == (
        {f"URS3{i:02d}" for i in range(1, 15)} | {"URS210", "URS214"})
    assert all(s == "lint" for c, s in stages.items() if c.startswith("URS1") and c != "URS100"
               ) and len({rule.name for rule in RULES.values()}) == len(RULES)
    # the severities on main are kept
    assert [RULES[c].severity for c in ("URS304", "URS305", "URS312", "URS313", "URS210")] == [
        "error", "warning", "info", "warning", "warning"]


def test_rules_explains_the_joint_speed_check_and_lists_the_checker(capsys):
    assert main(["rules", "URS304"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("URS304 joint-speed-limit (error)") and "urdsl check" in out
    assert "Example:" in out and "Write instead:" in out
    assert main(["rules", "URS3", "--short"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line[:6] for line in lines[:13]] == [f"URS3{i:02d}" for i in range(1, 14)]
    assert main(["rules", "URS39"]) == 2


def test_check_help_lists_the_registered_checks(capsys):
    with pytest.raises(SystemExit):
        main(["check", "--help"])
    out = capsys.readouterr().out
    for code, rule in RULES.items():
        if rule.stage == "check":
            assert f"{code}  {rule.severity}" in out


def _codes(text: str, code: str, tmp_path) -> dict[str, set[str]]:
    """The codes ``urdsl check`` reports for ``text``, each with its severities."""
    options = dict(OPTIONS.get(code, {}))
    if code == "URS209":  # the setting that makes an unsimulated builtin an error
        options["environment"] = Environment(devices="unknown", unsupported="error")
    if "cell.toml" in text:
        cell = tmp_path / "cell.toml"
        cell.write_text("[floor]\nheight = 0.0\n")
        options["cell"] = str(cell)
    report = check_text(text, "example.script", options=CheckOptions(timeout=None, **options))
    found: dict[str, set[str]] = {}
    for finding in report.findings:
        found.setdefault(finding.code, set()).add(finding.severity)
    return found


@pytest.mark.parametrize("code", sorted(c for c, r in RULES.items()
                                        if r.stage in ("runtime", "check")))
def test_each_checker_example_triggers_its_rule_and_the_fix_does_not(code, tmp_path):
    """``urdsl rules CODE`` heads its text with the rule's severity: the example shows a
    finding of that severity (a rule that is a warning in milder cases shows its error)."""
    if code in NOT_RUN:
        pytest.skip(NOT_RUN[code])
    rule = RULES[code]
    assert rule.severity in _codes(rule.example, code, tmp_path).get(code, set()), rule.example
    assert code not in _codes(rule.fixed, code, tmp_path), rule.fixed
