"""``urdsl check`` of a fragment: it runs with the definitions it takes from its host
program, sibling files and installation variables, and the report says so."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from urdsl.cli import main
from urdsl.lint import lint_text
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


# ---- files that neither include each other: what their run leaves in a global is unknown ----

READY = "movej([0, -1.9, 1.9, -1.57, -1.57, 0])"


def test_a_global_another_file_sets_again_is_unknown_not_its_first_value(tmp_path, capsys):
    # a hand-written copy of an export borrows the gripper's globals: the export gives the
    # mass 0.0 and sets it later (its preamble runs a setup this file does not run)
    (tmp_path / "export.script").write_text(
        "global tool_mass = 0.0\ndef setup():\n  tool_mass = 1.45\nend\n")
    (tmp_path / "mine.script").write_text("share = 2.0 / tool_mass\ntextmsg(share)\n")
    status, report = check(capsys, str(tmp_path / "mine.script"))
    assert status == 0, report["findings"]
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "tool_mass" in report["context"]


def test_a_global_whose_elements_another_file_sets_is_unknown(tmp_path, capsys):
    # an OnRobot-style preamble: a data thread fills the grip flags the grip function reads;
    # checked from a file that borrows the function, the flags are not their first value
    # (which would halt the program as if the grip had failed)
    (tmp_path / "export.script").write_text(
        "global grip_detected = [False, False]\n"
        "thread data_thread():\n  while True:\n    grip_detected[0] = True\n    sync()\n"
        "  end\nend\n"
        "def grip(index):\n  if not grip_detected[index]:\n"
        '    popup("did not grip", error=True)\n    halt\n  end\nend\n'
        "run data_thread()\n")
    (tmp_path / "mine.script").write_text("grip(0)\ntextmsg(\"gripped\")\n")
    status, report = check(capsys, str(tmp_path / "mine.script"))
    assert status == 0, report["findings"]
    assert "did not grip" not in [e["message"] for e in report["events"]]
    assert "gripped" in [e["message"] for e in report["events"]]
    assert "grip_detected" in report["context"]


def test_a_function_borrowed_from_another_file_writes_that_files_global(tmp_path, capsys):
    # ur_rtde's header and control loop: the header's function toggles the header's global
    # (assigned, not declared, in the function: the controller binds it to the global);
    # taken alone, the function read its own unassigned local: "not defined"
    (tmp_path / "header.script").write_text(
        "global finished = -2\n"
        "def signal_finished():\n  if finished == -1:\n    finished = -2\n  else:\n"
        "    finished = -1\n  end\n  write_output_integer_register(2, finished)\nend\n"
        "def scratch():\n  scratch_value = 3\n  return scratch_value\nend\n")
    (tmp_path / "loop.script").write_text("signal_finished()\nx = scratch()\nsync()\n")
    status, report = check(capsys, str(tmp_path / "loop.script"))
    assert status == 0, report["findings"]
    assert not [f for f in report["findings"] if f["severity"] == "error"]
    assert "finished" in report["context"] and "scratch_value" not in report["context"]


def test_a_fragment_takes_definitions_from_the_program_version_that_inlined_it(
        tmp_path, capsys):
    # two saved versions of a welding program inline the same script file; the older one
    # inlined an older version of it and defines weld(index, table); the newer weld(index,
    # table, kind), which this version of the file calls
    body = ["n = 1", "table = 2", "kind = 3", "textmsg(n)", "textmsg(table)", "textmsg(kind)",
            "weld(n, table, kind)", "sleep(0.1)", "textmsg(\"done\")", "sync()"]
    (tmp_path / "weld_steps.script").write_text("\n".join(body) + "\n")

    def program(name: str, params: str, lines: list[str]) -> str:
        inlined = "".join(f"  {line}\n" for line in lines)
        return (f"def {name}():\n  def weld({params}):\n    textmsg(index)\n  end\n"
                f'  $ 1 "Robot Program"\n{inlined}end\n')

    older = [line.replace("weld(n, table, kind)", "weld(n, table)") for line in body]
    (tmp_path / "a_cell_v1.script").write_text(program("cell_v1", "index, table", older))
    (tmp_path / "b_cell_v2.script").write_text(program("cell_v2", "index, table, kind", body))
    status, report = check(capsys, str(tmp_path / "weld_steps.script"))
    assert status == 0, report["findings"]
    assert "b_cell_v2.script, " in report["context"]  # the exact one first
    assert main(["lint", str(tmp_path / "weld_steps.script")]) == 0


def test_a_constant_another_file_gives_once_keeps_its_value(tmp_path, capsys):
    (tmp_path / "setup.script").write_text(
        "def init():\n  global dist = 3.0\nend\n")
    (tmp_path / "use.script").write_text(
        f"{READY}\nmovel(pose_add(get_actual_tcp_pose(), p[0, 0, -dist, 0, 0, 0]))\n")
    status, report = check(capsys, str(tmp_path / "use.script"))
    assert status == 1  # 3 m down: the constant is known, and the move out of reach
    assert [f["code"] for f in report["findings"] if f["severity"] == "error"] == ["URS301"]


def test_a_pose_the_operator_set_in_another_file_is_unknown(tmp_path, capsys):
    # init.script asks the operator to place the arm in freedrive and records the pose; a
    # routine in another file that moves there is not checked from the default start
    (tmp_path / "init.script").write_text(
        "def save_start():\n  freedrive_mode()\n"
        '  popup("Move the tool to the first cube", blocking=True)\n'
        "  end_freedrive_mode()\n  global start_p = get_actual_tcp_pose()\nend\n")
    (tmp_path / "routine.script").write_text(
        f"{READY}\nmovel(pose_trans(start_p, p[0, 0, -2.0, 0, 0, 0]), a=1.2, v=0.25)\n")
    status, report = check(capsys, str(tmp_path / "routine.script"))
    assert status == 0, report["findings"]
    (warning,) = [f for f in report["findings"] if f["code"] == "URS210"]
    assert "start_p" in warning["message"] and "init.script" in warning["message"]


def test_check_of_a_file_sees_its_folders_subfolders(tmp_path, capsys):
    # as `urdsl lint` of the folder does: a function of an export kept in a subfolder
    (tmp_path / "material").mkdir()
    (tmp_path / "material" / "export.script").write_text(
        'def export():\n  $ 1 "Robot Program"\n  def gripper_open(width):\n'
        "    textmsg(width)\n  end\n  gripper_open(50)\nend\n")
    (tmp_path / "routine.script").write_text("gripper_open(20)\n")
    status, report = check(capsys, str(tmp_path / "routine.script"))
    assert status == 0, report["findings"]
    assert "material/export.script" in report["context"]


def test_a_program_above_that_includes_the_neighbours_joins_the_project(tmp_path, capsys):
    # MAIN includes CONTROL/move.script but not CONTROL/log.script (its Script node is
    # disabled); log.script still reads MAIN's globals
    (tmp_path / "CONTROL").mkdir()
    (tmp_path / "CONTROL" / "move.script").write_text("textmsg(count)\ncount = count + 1\n")
    (tmp_path / "CONTROL" / "log.script").write_text("textmsg(cell_name)\n")
    (tmp_path / "MAIN.script").write_text(
        'def MAIN():\n  $ 1 "Robot Program"\n  global count = 0\n  global cell_name = "A"\n'
        '  $ 2 "Script: move.script"\n  textmsg(count)\n  count = count + 1\nend\n')
    status, report = check(capsys, str(tmp_path / "CONTROL" / "log.script"))
    assert status == 0, report["findings"]
    assert "MAIN.script" in report["context"]


def test_a_few_common_lines_spread_over_a_program_do_not_make_it_a_host(tmp_path, capsys):
    from urdsl.project.model import Project

    (tmp_path / "endless.script").write_text("i = 0\nwhile True:\n  i = i + 1\n  sync()\nend\n")
    (tmp_path / "other.script").write_text(
        'def other():\n  $ 1 "Robot Program"\n  i = 0\n  textmsg("a")\n  textmsg("b")\n'
        '  textmsg("c")\n  textmsg("d")\n  while True:\n    textmsg("e")\n    textmsg("f")\n'
        '    textmsg("g")\n    textmsg("h")\n    i = i + 1\n    textmsg("i")\n'
        '    textmsg("j")\n    textmsg("k")\n    textmsg("l")\n    sync()\n  end\nend\n')
    project = Project.discover(tmp_path / "endless.script")
    text = (tmp_path / "endless.script").read_text()
    assert project.context(tmp_path / "endless.script", text, "endless.script").hosts == []
    # the same lines inlined as one block do
    (tmp_path / "other.script").write_text(
        'def other():\n  $ 1 "Robot Program"\n  textmsg("a")\n  i = 0\n  while True:\n'
        "    i = i + 1\n    sync()\n  end\nend\n")
    project = Project.discover(tmp_path / "endless.script")
    assert [h.filename for h in project.context(
        tmp_path / "endless.script", text, "endless.script").hosts] != []


def test_a_fragment_that_reads_a_host_variable_before_it_sets_it_takes_the_hosts(
        tmp_path, capsys):
    # the fragment tests the host's flag first and clears it later: its first read is the
    # host's value, not an undefined name
    (tmp_path / "host.script").write_text(
        'def host():\n  $ 1 "Robot Program"\n  run_program = True\n'
        '  $ 2 "Script: step.script"\n  if run_program:\n    textmsg("step")\n  end\n'
        "  run_program = False\nend\n")
    (tmp_path / "step.script").write_text(
        'if run_program:\n  textmsg("step")\nend\nrun_program = False\n')
    status, report = check(capsys, str(tmp_path / "step.script"))
    assert status == 0, report["findings"]
    assert "run_program" in report["context"]


def test_a_program_def_sent_with_its_call_is_the_program(tmp_path, capsys):
    # a RoboDK station sends Robotiq's driver as `def gripper(): ... end` and `gripper()`:
    # the def's first-level names are the program's globals, which its nested functions see
    text = ("def gripper():\n  ACT = 1\n  def rq_get():\n    return ACT\n  end\n"
            "  textmsg(rq_get())\nend\ngripper()\n")
    (tmp_path / "GripperClose.script").write_text(text)
    status, report = check(capsys, str(tmp_path / "GripperClose.script"))
    assert status == 0, report["findings"]
    assert [e["message"] for e in report["events"]] == ["1"]
    assert not [d for d in lint_text(text, "GripperClose.script") if d.severity == "error"]
    # a def called with other statements around it stays an ordinary function: its
    # first-level names are its locals
    (tmp_path / "GripperClose.script").write_text(text + "textmsg(ACT)\n")
    status, report = check(capsys, str(tmp_path / "GripperClose.script"))
    assert status == 1
    assert [f["line"] for f in report["findings"] if f["code"] == "URS201"] == [4]


# ---- a fragment whose definitions are in another folder of its repository --------------------

GRIPPER = """def gripper_prog():
  global opened = False
  def open_gripper(width):
    opened = True
    textmsg(width)
  end
  open_gripper(0.08)
end
"""
PIECE = "open_gripper(0.05)\nmovej([0.0, -1.57, 1.57, -1.57, -1.57, 0.0], a=1.0, v=0.5)\n"


def _repository(root: Path, depth: int = 1) -> Path:
    """A repository (tmp_path is one, see conftest.py) with a program in ``objects/`` and a
    generated piece ``depth`` folders down from its top that calls the program's function."""
    (root / "objects").mkdir()
    (root / "objects" / "gripper.script").write_text(GRIPPER)
    folder = root.joinpath(*[f"gen{i}" for i in range(depth)])
    folder.mkdir(parents=True)
    (folder / "piece.script").write_text(PIECE)
    return folder / "piece.script"


def test_a_fragment_sees_the_definitions_of_its_repository(tmp_path, capsys):
    piece = _repository(tmp_path)
    status, report = check(capsys, str(piece))
    assert status == 0 and not [f for f in report["findings"] if f["severity"] == "error"]
    assert "gripper.script" in report["context"]
    status = main(["lint", "--format", "json", str(piece)])
    found = json.loads(capsys.readouterr()[0])
    assert status == 0
    assert [(f["code"], f["severity"]) for f in found] == [("URS102", "warning")]
    assert "objects/gripper.script:3" in found[0]["message"]


def test_a_name_the_repository_does_not_define_stays_an_error(tmp_path, capsys):
    piece = _repository(tmp_path)
    piece.write_text("close_gripper()\n")
    assert check(capsys, str(piece))[0] == 1
    assert main(["lint", str(piece)]) == 1


def test_a_program_does_not_take_names_from_its_repository(tmp_path, capsys):
    piece = _repository(tmp_path)
    piece.write_text("def job():\n  open_gripper(0.05)\nend\njob()\n")
    status, report = check(capsys, str(piece))
    assert status == 1 and report["findings"][0]["code"] == "URS201"


def test_a_repository_top_far_above_is_not_searched(tmp_path, capsys):
    piece = _repository(tmp_path, depth=4)  # four folders down: more than HOST_LEVELS
    assert check(capsys, str(piece))[0] == 1


def test_a_fragment_sees_the_installation_variables_its_repository_keeps_apart(tmp_path,
                                                                              capsys):
    # PolyScope programs in folders of their own, the installation's variables in another
    # (the robot's /programs holds both; a repository often splits them)
    (tmp_path / "UR_installation").mkdir()
    (tmp_path / "UR_installation" / "cell.variables").write_text(
        "contact_pose=p[0.4, -0.2, 0.2, 0.0, 3.1416, 0.0]\n")
    program = tmp_path / "path_1" / "init_par.script"
    program.parent.mkdir()
    program.write_text("approach = pose_trans(contact_pose, p[0, 0, -0.05, 0, 0, 0])\n"
                       "textmsg(approach)\n")
    status, report = check(capsys, str(program))
    assert status == 0 and not [f for f in report["findings"] if f["severity"] == "error"]
    program.write_text("textmsg(retract_pose)\n")  # defined nowhere: still an error
    assert check(capsys, str(program))[0] == 1


def _urp_including(*files: str) -> bytes:
    """A PolyScope 5 program whose Robot Program runs the script ``files`` in order."""
    nodes = "".join(f'<Script type="File"><cachedContents></cachedContents>'
                    f"<file>/programs/cell/{name}</file></Script>" for name in files)
    return (f'<URProgram name="cell" installation="default" directory="/programs/cell" '
            f'createdIn="5.11.0" lastSavedIn="5.11.0"><children><MainProgram '
            f'runOnlyOnce="true"><children>{nodes}</children></MainProgram></children>'
            f"</URProgram>").encode()


INIT = ("def cell_init():\n  global angle = 0\n  global last = read_input_integer_register(43)\n"
        "end\n\ncell_init()\n")
WAIT = ("def cell_wait():\n  command = read_input_integer_register(43)\n"
        "  while command == last:\n    sync()\n    command = read_input_integer_register(43)\n"
        "  end\n  global angle = angle + 5\n  global last = command\nend\n\ncell_wait()\n")


def test_a_polyscope_program_hosts_the_script_files_its_script_nodes_run(tmp_path, capsys):
    # each file a complete program of its own (def + call), run by the .urp one after another:
    # what the first sets, the next reads
    (tmp_path / "cell_init.script").write_text(INIT)
    (tmp_path / "cell_wait.script").write_text(WAIT)
    (tmp_path / "cell.urp").write_bytes(_urp_including("cell_init.script", "cell_wait.script"))
    status, report = check(capsys, str(tmp_path / "cell_wait.script"))
    assert status == 0, report["findings"]
    assert "cell.urp" in report["context"]
    assert main(["lint", str(tmp_path)]) == 0
    capsys.readouterr()
    # without the program, the names the file reads before it sets them are not defined
    (tmp_path / "cell.urp").unlink()
    assert check(capsys, str(tmp_path / "cell_wait.script"))[0] == 1


def test_only_the_first_level_reading_a_global_before_setting_it_asks_the_program():
    wrapped = parse("def step():\n  if busy:\n    sync()\n  end\n  global busy = False\nend\n"
                    "step()\n")
    assert needed_names(wrapped)[0] == {"busy"}  # the program def a file wraps itself in
    library = parse("def weave():\n  a = gap[0]\n  global gap = [1, 2]\nend\n"
                    "def start():\n  global gap = [0, 0]\nend\n")
    assert needed_names(library)[0] == set()  # start() may run first: the file has it


def test_a_fragment_sees_the_features_of_the_installation_beside_it(tmp_path, capsys):
    # a script file a Script node includes may use the installation's features as
    # variables (PolyScope writes them into every program's preamble): with no program
    # beside it, the installation itself defines them, for lint and check
    from test_polyscope_preamble import _installation5

    (tmp_path / "default.installation").write_bytes(_installation5())
    fragment = tmp_path / "approach.script"
    fragment.write_text("above = pose_trans(pick, p[0, 0, -0.05, 0, 0, 0])\n"
                        "textmsg(above)\ntextmsg(Table)\n")
    status, report = check(capsys, str(fragment))
    assert status == 0 and not [f for f in report["findings"] if f["severity"] == "error"]
    assert main(["lint", "--format", "json", str(fragment)]) == 0
    assert json.loads(capsys.readouterr().out) == []
    # a feature named in PolyScope's own language is written as PolyScope writes it
    (tmp_path / "default.installation").write_bytes(_installation5().replace(
        b'name="pick"', 'name="点_1"'.encode()))
    fragment.write_text("textmsg(u28857_1)\n")
    assert main(["lint", "--format", "json", str(tmp_path)]) == 0
    assert json.loads(capsys.readouterr().out) == []
    fragment.write_text("textmsg(hidden)\n")  # a feature that is not variable: not there
    assert main(["lint", "--format", "json", str(fragment)]) == 1
    assert "'hidden'" in json.loads(capsys.readouterr().out)[0]["message"]


def _urp_calling(subprogram: str, suppressed: bool) -> bytes:
    """A PolyScope 5 program whose Robot Program calls the subprogram saved as
    ``subprogram``.urp (kept synchronised with that file), the call suppressed or not."""
    inner = (f'<subprogram name="{subprogram}" keepHidden="true" '
             f'keepSynchronizedWithDisk="true"><programFile>/programs/cell/{subprogram}.urp'
             f'</programFile><children><Script type="Line"><expression>'
             + "".join(f'<ExpressionChar character="{c}"/>' for c in "lift()")
             + "</expression></Script></children></subprogram>")
    call = (f'<SuppressedNode><suppressedNode class="CallSubProgram">{inner}</suppressedNode>'
            "</SuppressedNode>" if suppressed else f"<CallSubProgram>{inner}</CallSubProgram>")
    return (f'<URProgram name="MAIN" installation="default" directory="/programs/cell" '
            f'createdIn="5.13.0" lastSavedIn="5.13.0"><children><MainProgram '
            f'runOnlyOnce="true"><children>{call}</children></MainProgram></children>'
            f"</URProgram>").encode()


SUBPROGRAM = ('def SUB_A():\n  $ 1 "Robot Program"\n  $ 2 "lift()"\n  lift()\n'
              '  $ 3 "Wait: 0.5"\n  sleep(0.5)\nend\n')


@pytest.mark.parametrize("suppressed", [False, True])
def test_a_subprogram_saved_as_its_own_program_is_checked_in_its_callers_context(
        tmp_path, capsys, suppressed):
    # PolyScope saves a subprogram as a program (SUB_A.urp, SUB_A.script) that its caller's
    # .urp names; its lines may call functions the caller defines. The caller's exported
    # .script can be older than its .urp and not inline the subprogram at all (seen:
    # CA-Giken/docker-noetic-capc, ursim/programs.UR10/GD/SUB_104.script, whose call in
    # MAIN.urp is suppressed and whose MAIN.script predates it)
    (tmp_path / "MAIN.urp").write_bytes(_urp_calling("SUB_A", suppressed))
    (tmp_path / "MAIN.script").write_text(
        'def MAIN():\n  $ 1 "BeforeStart"\n  def lift():\n    textmsg("lift")\n  end\n'
        '  $ 2 "Robot Program"\n  lift()\nend\n')
    (tmp_path / "SUB_A.script").write_text(SUBPROGRAM)
    status, report = check(capsys, str(tmp_path / "SUB_A.script"))
    assert status == 0, report["findings"]
    assert "MAIN.script" in report["context"]
    assert main(["lint", str(tmp_path)]) == 0
    capsys.readouterr()
    # a program that names no such subprogram is no caller: the name stays undefined
    (tmp_path / "MAIN.urp").write_bytes(_urp_calling("SUB_OTHER", suppressed))
    assert check(capsys, str(tmp_path / "SUB_A.script"))[0] == 1


def test_a_fragment_no_program_includes_keeps_its_error_with_a_hint(tmp_path, capsys):
    # a Script-node file whose PolyScope program is not in the repository (blind batch 23,
    # Philippschwind's taught positions): the name stays an error, and the hint says how to
    # check the file with the program that defines it
    (tmp_path / "frag").mkdir()
    job = tmp_path / "frag" / "job.script"
    job.write_text('movej(approach_q, a=1.0, v=0.2)\ntextmsg("done")\n')
    status, report = check(capsys, str(job))
    assert status == 1
    [finding] = report["findings"]
    assert (finding["code"], finding["severity"]) == ("URS201", "error")
    assert "`approach_q` is a waypoint, feature or variable of that program" in finding["hint"]
    assert "check it with them (--include PROGRAM.urp" in finding["hint"]
    assert report["context"].startswith("a fragment that no program of the project includes")
    # following the hint settles it
    (tmp_path / "prog").mkdir()
    variables = tmp_path / "prog" / "cell.variables"
    variables.write_text("approach_q=[0.0, -1.57, 1.57, -1.57, -1.57, 0.0]\n")
    status, report = check(capsys, "--include", str(variables), str(job))
    assert status == 0 and len(report["moves"]) == 1
    # a complete program lacking the name gets no such hint: nothing else runs it
    job.write_text("def job():\n  movej(approach_q, a=1.0, v=0.2)\nend\njob()\n")
    status, report = check(capsys, str(job))
    assert status == 1 and "PolyScope program" not in report["findings"][0]["hint"]
    assert report["context"] is None
