"""`urdsl parse` and `urdsl fmt` as a user runs them."""

from __future__ import annotations

import io
import json
import subprocess
import sys

import pytest

from urdsl.cli import main

MESSY = "def prog():\r\n\tmovej([0,-1.57079632,0,-1.57079632,0,0],a=1.4)  # home\r\nend"
CLEAN = "def prog():\n  movej([0, -1.57079632, 0, -1.57079632, 0, 0], a=1.4)  # home\nend\n"
BROKEN = "p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])\n"


@pytest.fixture
def files(tmp_path):
    (tmp_path / "messy.script").write_bytes(MESSY.encode())
    (tmp_path / "clean.script").write_text(CLEAN)
    (tmp_path / "broken.script").write_text(BROKEN)
    return tmp_path


def run(capsys, *argv, stdin: str | None = None, monkeypatch=None):
    if stdin is not None:
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(stdin.encode())))
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_parse_ok_and_error(files, capsys):
    status, _, err = run(capsys, "parse", str(files / "clean.script"))
    assert status == 0 and "ok" in err
    status, _, err = run(capsys, "parse", str(files / "clean.script"), str(files / "broken.script"))
    assert status == 1
    assert f"{files / 'broken.script'}:1:45: error: unexpected ')'" in err
    assert "hint:" in err and "Traceback" not in err


def test_parse_json_tree(files, capsys):
    status, out, _ = run(capsys, "parse", "--json", str(files / "clean.script"))
    assert status == 0
    [entry] = json.loads(out)
    prog = entry["tree"]["body"][0]
    assert prog["type"] == "FunctionDef" and prog["name"] == "prog"
    call = prog["body"][0]["expr"]
    assert call["func"] == {"type": "Name", "span": {"line": 2, "column": 3, "end_line": 2,
                                                     "end_column": 8}, "id": "movej"}


def test_parse_missing_file_is_a_usage_error(tmp_path, capsys):
    status, _, err = run(capsys, "parse", str(tmp_path / "nope.script"))
    assert status == 2 and "cannot read" in err


def test_fmt_prints_canonical_text(files, capsys):
    status, out, _ = run(capsys, "fmt", str(files / "messy.script"))
    assert status == 0 and out == CLEAN


def test_fmt_check_and_diff(files, capsys):
    assert run(capsys, "fmt", "--check", str(files / "clean.script"))[0] == 0
    status, _, err = run(capsys, "fmt", "--check", str(files / "messy.script"))
    assert status == 1 and "would reformat" in err
    status, out, _ = run(capsys, "fmt", "--diff", str(files / "messy.script"))
    assert status == 1 and "+  movej([0, -1.57079632" in out and "No newline" in out
    assert (files / "messy.script").read_bytes() == MESSY.encode()  # untouched


def test_fmt_in_place(files, capsys):
    status, _, err = run(capsys, "fmt", "-i", str(files / "messy.script"))
    assert status == 0 and "reformatted" in err
    assert (files / "messy.script").read_text() == CLEAN
    assert run(capsys, "fmt", "--check", str(files / "messy.script"))[0] == 0


def test_fmt_syntax_error_leaves_file_alone(files, capsys):
    status, _, err = run(capsys, "fmt", "-i", str(files / "broken.script"))
    assert status == 1 and ":1:45:" in err
    assert (files / "broken.script").read_text() == BROKEN


def test_stdin(capsys, monkeypatch):
    status, out, _ = run(capsys, "fmt", "-", stdin=MESSY, monkeypatch=monkeypatch)
    assert status == 0 and out == CLEAN
    status, _, err = run(capsys, "parse", "-", stdin=BROKEN, monkeypatch=monkeypatch)
    assert status == 1 and "<stdin>:1:45" in err


def test_latin1_file_round_trips(tmp_path, capsys):
    path = tmp_path / "old.script"
    path.write_bytes('textmsg("Gr\xfc\xdfe")\n'.encode("latin-1"))
    assert run(capsys, "fmt", "--check", str(path))[0] == 0


def test_usage_errors_exit_2(files, capsys):
    with pytest.raises(SystemExit) as caught:
        main(["fmt", "--check", "--diff", str(files / "clean.script")])
    assert caught.value.code == 2
    with pytest.raises(SystemExit) as caught:
        main(["nonsense"])
    assert caught.value.code == 2


def test_console_script_help_teaches():
    result = subprocess.run([sys.executable, "-m", "urdsl.cli", "--help"],
                            capture_output=True, text=True, check=True)
    assert "urdsl fmt --check" in result.stdout and "parse" in result.stdout
    result = subprocess.run([sys.executable, "-m", "urdsl.cli", "fmt", "--help"],
                            capture_output=True, text=True, check=True)
    assert "--check" in result.stdout and "example" in result.stdout
