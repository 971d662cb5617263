"""``urdsl check`` of a fragment: it runs with the definitions it takes from its host
program, sibling files and installation variables, and the report says so."""

from __future__ import annotations

import json
from pathlib import Path

from urdsl.cli import main
from urdsl.project.check import in_context, needed_names
from urdsl.script.parser import parse

DATA = Path(__file__).parent / "data" / "projects"

HOST = """def cell():
  $ 1 "Robot Program"
  global far = p[2.0, 0.0, 0.3, 0.0, 3.1416, 0.0]
  def reach_far():
    movel(far, a=1.0, v=0.1)
  end
  $ 2 "Script: task.script"
  textmsg("task")
  reach_far()
end
"""


def check(capsys, *argv) -> tuple[int, dict]:
    status = main(["check", "--json", *argv])
    out, _ = capsys.readouterr()
    return status, json.loads(out)


def test_a_fragment_runs_in_its_hosts_context(capsys):
    status, report = check(capsys, str(DATA / "cell" / "pick.script"))
    assert status == 0
    assert report["findings"] == []
    assert report["context"].startswith("checked in the context of ")
    assert "main.script" in report["context"]
    assert [m["kind"] for m in report["moves"]] == ["movej", "movel"]


def test_alone_the_fragment_fails_on_the_hosts_names(capsys):
    status, report = check(capsys, "--no-project", str(DATA / "cell" / "pick.script"))
    assert status == 1
    assert report["context"] is None
    assert report["findings"][0]["message"] == "name 'home_q' is not defined"


def test_a_subprogram_file_runs_with_its_callers_globals(capsys):
    status, report = check(capsys, str(DATA / "subprogram" / "SubProgram_1.script"))
    assert status == 0 and len(report["moves"]) == 1


def test_a_message_about_a_host_definition_names_the_host_file(tmp_path, capsys):
    (tmp_path / "cell.script").write_text(HOST)
    (tmp_path / "task.script").write_text('textmsg("task")\nreach_far()\n')
    status, report = check(capsys, str(tmp_path / "task.script"))
    assert status == 1
    finding = report["findings"][0]
    assert finding["code"] == "URS301"
    assert (Path(finding["file"]).name, finding["line"]) == ("cell.script", 5)
    assert "cell.script" in report["context"]


def test_text_report_says_which_host(capsys):
    status = main(["check", str(DATA / "cell" / "pick.script")])
    out, _ = capsys.readouterr()
    assert status == 0
    assert "checked in the context of" in out and "main.script" in out


def test_installation_variables_reach_a_complete_program(capsys):
    status, report = check(capsys, str(DATA / "cell" / "main.script"))
    assert status == 0
    assert "default.variables" in report["context"]
    assert [e["message"] for e in report["events"] if e["kind"] == "textmsg"] == ["0"]


def test_definitions_come_before_what_uses_them():
    path = DATA / "cell" / "pick.script"
    text = path.read_text()
    context = in_context(path, text, parse(text, str(path)), use_config=False)
    order = [d.name for d in context.definitions]
    assert order.index("rq_speed") < order.index("rq_open")
    assert set(order) == {"home_q", "pick_p", "part_count", "rq_speed", "rq_open", "rq_close"}
    assert needed_names(context.module) == (set(), set(), set())


def test_a_file_that_needs_nothing_is_left_alone(tmp_path):
    (tmp_path / "a.script").write_text("textmsg(1)\n")
    text = "textmsg(1)\n"
    assert in_context(tmp_path / "a.script", text, parse(text), use_config=False) is None


def test_include_gives_a_fragment_the_definitions_it_needs(capsys):
    target = str(DATA / "included" / "prog" / "run.script")
    assert check(capsys, target)[0] == 1  # clamp() is defined nowhere it can see
    status, report = check(capsys, target, "--include", str(DATA / "included" / "lib"))
    assert status == 0
    assert "math.script" in report["context"]
    assert main(["check", target, "--include", "no/such/file.script"]) == 2


def test_a_fragment_in_a_subfolder_is_checked_with_the_program_above(capsys):
    status, report = check(capsys, str(DATA / "nested" / "scripts" / "start_seam.script"))
    assert status == 0
    assert "weld.script" in report["context"]
    assert [e["message"] for e in report["events"] if e["kind"] == "textmsg"] == ["0.01"]


LOOP_HOST = """def loop_cell():
  $ 1 "Robot Program"
  def measure():
    offset = 0.1
    global shifted = offset * 2
  end
  while True:
    $ 2 "Script: use.script"
    global here = get_actual_tcp_pose()
    textmsg(here)
    textmsg(shifted)
    measure()
  end
end
"""


def test_a_global_given_a_value_in_a_loop_is_run_first_when_it_can_be(tmp_path, capsys):
    (tmp_path / "cell.script").write_text(LOOP_HOST)
    (tmp_path / "use.script").write_text("textmsg(here)\n")
    status, report = check(capsys, str(tmp_path / "use.script"))
    assert status == 0 and "here" in report["context"]
    # a value that needs a local of its function cannot be computed first: the name stays
    # undefined, as an honest runtime error
    (tmp_path / "use.script").write_text("textmsg(shifted)\n")
    status, report = check(capsys, str(tmp_path / "use.script"))
    assert status == 1
    assert report["findings"][0]["message"] == "name 'shifted' is not defined"
    assert "gives shifted a value only inside a function or loop" in report["context"]


def test_a_name_the_controller_may_define_is_taken_from_the_project(tmp_path, capsys):
    """``pi`` may be a controller variable [U]; a project that assigns it in a sibling file
    gives the globals that use it their value (a hand-written library of globals)."""
    (tmp_path / "globals.script").write_text(
        "global pi = 3.14159265359\nglobal down = [pi, 0, -pi/2]\n")
    (tmp_path / "main.script").write_text("textmsg(down)\n")
    status, report = check(capsys, str(tmp_path / "main.script"))
    assert status == 0, report["findings"]
    assert report["findings"] == []
    assert "pi" in report["context"] and "down" in report["context"]
