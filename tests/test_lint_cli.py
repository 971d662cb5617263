"""``urdsl lint`` and ``urdsl rules`` as a user runs them: formats, exit status, settings."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from urdsl.cli import main
from urdsl.lint.command import load_rules

SCHEMA = Path(__file__).parent / "data" / "sarif-schema-2.1.0.json"

BAD = "def prog():\n  movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])\n  x = 1\nend\n"
WARN_ONLY = "def prog():\n  x = 1\nend\n"
GOOD = "def prog():\n  movej([0, -1.57, 0, -1.57, 0, 0])\nend\n"


@pytest.fixture
def files(tmp_path):
    (tmp_path / "bad.script").write_text(BAD)
    (tmp_path / "warn.script").write_text(WARN_ONLY)
    (tmp_path / "good.script").write_text(GOOD)
    return tmp_path


def run(capsys, *argv) -> tuple[int, str, str]:
    status = main(["lint", "--no-config", *argv])
    out, err = capsys.readouterr()
    return status, out, err


def test_text_is_ruff_style_with_the_line_a_caret_and_the_hint(files, capsys):
    status, out, _ = run(capsys, str(files / "bad.script"))
    assert status == 1
    lines = out.splitlines()
    assert lines[0] == f"{files / 'bad.script'}:2:9: URS108 movej() needs 6 joint values, " \
        "this list has 5"
    assert lines[1].strip() == "movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])"
    assert lines[2].index("^") == lines[1].index("[")
    assert lines[3].startswith("  hint: ")
    assert out.rstrip().endswith("Found 1 error, 1 warning in 1 file.")


def test_exit_status_zero_for_warnings_and_clean_files(files, capsys):
    assert run(capsys, str(files / "warn.script"))[0] == 0
    status, out, _ = run(capsys, str(files / "good.script"))
    assert status == 0 and "All checks passed" in out


def test_json_is_one_document_with_the_fields(files, capsys):
    status, out, _ = run(capsys, "--format", "json", str(files / "bad.script"),
                         str(files / "warn.script"))
    assert status == 1
    findings = json.loads(out)
    assert [(f["code"], f["severity"], f["line"], f["column"]) for f in findings] == [
        ("URS108", "error", 2, 9), ("URS112", "warning", 3, 3), ("URS112", "warning", 2, 3)]
    for finding in findings:
        assert {"file", "line", "column", "code", "severity", "message"} <= set(finding)


def test_sarif_validates_against_the_official_schema(files, capsys):
    stray = files / "stray.script"
    stray.write_text("p1 = p[0.2, -0.3, 0.3, 0.5, 0.0, -0.3])\n")
    status, out, _ = run(capsys, "--format", "sarif", str(files / "bad.script"),
                         str(files / "warn.script"), str(stray), str(files / "good.script"))
    assert status == 1
    log = json.loads(out)
    jsonschema.validate(log, json.loads(SCHEMA.read_text()))
    run_ = log["runs"][0]
    results = run_["results"]
    assert [r["ruleId"] for r in results] == ["URS108", "URS112", "URS112", "URS001"]
    rules = run_["tool"]["driver"]["rules"]
    assert rules[results[0]["ruleIndex"]]["id"] == "URS108"
    region = results[0]["locations"][0]["physicalLocation"]["region"]
    assert (region["startLine"], region["startColumn"]) == (2, 9)
    assert results[1]["level"] == "warning" and results[0]["level"] == "error"


def test_sarif_of_a_clean_run_validates_too(files, capsys):
    status, out, _ = run(capsys, "--format", "sarif", str(files / "good.script"))
    assert status == 0
    jsonschema.validate(json.loads(out), json.loads(SCHEMA.read_text()))


def test_github_annotations(files, capsys):
    status, out, _ = run(capsys, "--format", "github", str(files / "bad.script"))
    assert status == 1
    first, second = out.splitlines()
    assert first.startswith(f"::error file={files / 'bad.script'},line=2,col=9,title=URS108::"
                            "movej() needs 6 joint values")
    assert "%0Ahint: " in first
    assert second.startswith("::warning ") and "title=URS112" in second


def test_select_ignore_and_usage_errors(files, capsys):
    assert run(capsys, "--ignore", "URS108", str(files / "bad.script"))[0] == 0
    status, out, _ = run(capsys, "--select", "URS112", "--format", "json",
                         str(files / "bad.script"))
    assert status == 0 and {f["code"] for f in json.loads(out)} == {"URS112"}
    status, _, err = run(capsys, "--select", "URS999", str(files / "bad.script"))
    assert status == 2 and "URS999" in err and "Traceback" not in err
    status, _, err = run(capsys, "--robot", "ur99", str(files / "bad.script"))
    assert status == 2 and "ur99" in err
    status, _, err = run(capsys, "--version", "five", str(files / "bad.script"))
    assert status == 2 and "five" in err
    status, _, err = run(capsys, str(files / "missing.script"))
    assert status == 2 and "missing.script" in err


def test_folders_are_searched(files, capsys):
    status, out, _ = run(capsys, "--format", "json", str(files))
    assert status == 1
    assert {Path(f["file"]).name for f in json.loads(out)} == {"bad.script", "warn.script"}


def test_pyproject_settings_are_found_by_walking_up(tmp_path, capsys, monkeypatch):
    (tmp_path / "pyproject.toml").write_text(
        '[project]\nname = "cell"\n\n[tool.urdsl.lint]\nignore = ["URS112"]\n'
        'version = "3.15"\nrobot = "ur5e"\n')
    sub = tmp_path / "programs" / "deep"
    sub.mkdir(parents=True)
    script = sub / "p.script"
    script.write_text("def prog():\n  x = 1\n  l = make_list(3, 0, 10)\n  textmsg(l)\n"
                      "  movej([0, 0, 0, 0, 0, 0], v=3.5)\nend\n")
    monkeypatch.chdir(tmp_path.parent)
    status = main(["lint", "--format", "json", str(script)])
    codes = [f["code"] for f in json.loads(capsys.readouterr().out)]
    assert status == 1
    assert codes == ["URS103", "URS110"]  # URS112 ignored; 3.15 and ur5e from the file
    status = main(["lint", "--format", "json", "--version", "5.15", str(script)])
    assert [f["code"] for f in json.loads(capsys.readouterr().out)] == ["URS110"]
    assert status == 0
    # standard input: the configuration is looked for from the working directory
    monkeypatch.chdir(sub)
    monkeypatch.setattr("sys.stdin", _Stdin(script.read_bytes()))
    main(["lint", "--format", "json", "-"])
    assert [f["code"] for f in json.loads(capsys.readouterr().out)] == ["URS103", "URS110"]


def test_bad_pyproject_setting_is_a_usage_error(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text('[tool.urdsl.lint]\nselct = ["URS1"]\n')
    (tmp_path / "p.script").write_text(GOOD)
    status = main(["lint", str(tmp_path / "p.script")])
    err = capsys.readouterr().err
    assert status == 2 and "selct" in err and "pyproject.toml" in err


class _Stdin:
    def __init__(self, data: bytes) -> None:
        import io

        self.buffer = io.BytesIO(data)


def test_rules_lists_every_rule_and_explains_one(capsys):
    every = load_rules()  # every stage's rules: lint, runtime and check
    assert main(["rules"]) == 0
    out = capsys.readouterr().out
    for code, rule in every.items():
        assert f"{code} {rule.name} ({rule.severity})" in out
    assert out.count("Example:") == len(every) and out.count("Write instead:") == len(every)
    assert main(["rules", "--short"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == len(every) + 2
    assert main(["rules", "URS105"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("URS105 too-many-arguments (error)")
    assert "Example:" in out and "Write instead:" in out
    assert main(["rules", "busy-loop"]) == 0
    assert "sync()" in capsys.readouterr().out
    assert main(["rules", "URS999"]) == 2
    assert main(["rules", "--json"]) == 0
    assert len(json.loads(capsys.readouterr().out)) == len(every)


def test_help_teaches(capsys):
    with pytest.raises(SystemExit):
        main(["lint", "--help"])
    out = capsys.readouterr().out
    assert "[tool.urdsl.lint]" in out and "--format" in out and "Exit status" in out


@pytest.mark.parametrize("command", ["check", "send", "compile"])
def test_help_says_a_python_file_is_run(command, capsys):
    # check/send/compile of a .py file run it as Python: the help says so (issue 14)
    with pytest.raises(SystemExit):
        main([command, "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "run as Python" in out


def test_a_urp_that_is_urscript_text_is_linted_as_a_script_when_named(tmp_path, capsys):
    # projects keep script templates as .urp (a PolyScope program is XML): named, such a
    # file is read as URScript with a note; found in a folder it is named in a warning only
    text = "def main():\n  textmsg(undefined_name)\nend\nmain()\n"
    (tmp_path / "driver.urp").write_text(text)
    status, out, _ = run(capsys, str(tmp_path / "driver.urp"), "--format", "json")
    found = {(d["code"], d["severity"], d["line"]) for d in json.loads(out)}
    assert status == 1
    assert found == {("URS001", "info", 1), ("URS101", "error", 2)}
    status, out, _ = run(capsys, str(tmp_path), "--format", "json")
    (only,) = json.loads(out)
    assert status == 0 and only["severity"] == "warning" and "not linted" in only["message"]
    # a real program's .urp is still read as one: truncated XML is an error
    (tmp_path / "driver.urp").write_text('<URProgram name="x"><children>')
    status, out, _ = run(capsys, str(tmp_path / "driver.urp"), "--format", "json")
    assert status == 1 and "truncated" in json.loads(out)[0]["message"]
