"""Every lint rule: a snippet that triggers it (code, line and column asserted) and one that
must not."""

from __future__ import annotations

from pathlib import Path

import pytest

from urdsl.lint import RULES, build_settings, lint_text

PROGRAMS = Path(__file__).resolve().parents[1] / "programs"


def places(text: str, code: str, **settings) -> list[tuple[int, int]]:
    found = lint_text(text, "t.script", build_settings(**settings))
    return [(d.line, d.column) for d in found if d.code == code]


def finding(text: str, code: str, **settings):
    found = [d for d in lint_text(text, "t.script", build_settings(**settings))
             if d.code == code]
    assert found, f"{code} not reported"
    return found[0]


# (code, triggering snippet, expected places, settings)
TRIGGERS = [
    ("URS001", "p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])\n", [(1, 45)], {}),
    ("URS100", "x = 1\n" + "if x:\n" * 3000 + "textmsg(x)\n" + "end\n" * 3000, [(1, 1)], {}),
    ("URS101", "thread blink():\n  on = True\nend\ndef show():\n  textmsg(on)\nend\n",
     [(5, 11)], {}),
    ("URS101", "def f():\n  run worker()\nend\n", [(2, 3)], {}),
    # no closures: a thread inside a function does not see the function's parameter
    ("URS101", "def f(speed):\n  thread t():\n    movel(p[0, 0, 0, 0, 0, 0], v=speed)\n"
     "  end\n  run t()\nend\nf(0.1)\n", [(3, 34)], {}),
    ("URS102", 'textmesg("hello")\n', [(1, 1)], {}),
    ("URS102", "thread t():\n  sync()\nend\nt()\n", [(4, 1)], {}),
    ("URS103", "l = make_list(3, 0, 10)\ntextmsg(l)\n", [(1, 5)], {"version": "3.15"}),
    ("URS104", "set_digital_out(2, True)\n", [(1, 1)], {}),
    ("URS105", "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0, 0)\n", [(1, 52)], {}),
    ("URS105", "def f(a, b=1):\n  return a + b\nend\nx = f(1, 2, 3)\ny = f(1, a=2)\n",
     [(4, 13), (5, 10)], {}),
    ("URS106", "q_home = [0, 0, 0, 0, 0, 0]\nmovej(q_home, speed=1.0)\n", [(2, 15)], {}),
    ("URS106", "def f(a):\n  return a\nend\nx = f(1, c=2)\n", [(4, 10)], {}),
    ("URS107", "set_standard_digital_out(3)\n", [(1, 1)], {}),
    ("URS107", "def f(a, b=1):\n  return a + b\nend\nx = f(b=2)\n", [(4, 5)], {}),
    ("URS108", "movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])\n", [(1, 7)], {}),
    ("URS108", "home = [0, -1.57, 0, -1.57, 0]\nmovej(home)\n", [(2, 7)], {}),
    ("URS108", "speedj([0.1, 0, 0], 0.5, 1)\n", [(1, 8)], {}),
    ("URS109", "movej([0, -90, 0, -90, 0, 0])\n", [(1, 7)], {}),
    ("URS109", "x = p[0.1, 0.2, 0.3, 180, 0, 0]\nmovel(x)\n", [(1, 5)], {}),
    ("URS110", "movej([0, 0, 0, 0, 0, 0], a=1.4, v=180)\n", [(1, 36)], {}),
    ("URS110", "movej([0, 0, 0, 0, 0, 0], v=3.5)\n", [(1, 29)], {"robot": "ur5e"}),
    ("URS110", "movel(p[0.1, 0.2, 0.3, 0, 0, 0], v=250)\n", [(1, 36)], {}),
    ("URS110", "speedj([0, 0, 0, 0, 0, 4], 1.0, 1)\n", [(1, 24)], {"robot": "ur10e"}),
    ("URS111", "a = p[0.1, 0.2, 0.3, 0, 0, 0]\nmovel(a, r=0.05)\nsleep(1.0)\nmovel(a)\n",
     [(2, 12)], {}),
    ("URS111", "def prog():\n  q = [0, 0, 0, 0, 0, 0]\n  movej(q, r=0.1)\nend\n", [(3, 14)],
     {}),
    ("URS111", "a = p[0.1, 0.2, 0.3, 0, 0, 0]\nmovel(a, r=0.05)\n"
     "while not get_standard_digital_in(0):\n  sync()\nend\nmovel(a)\n", [(2, 12)], {}),
    ("URS112", "def pick():\n  grip_force = 40\n  set_tool_digital_out(0, True)\nend\n",
     [(2, 3)], {}),
    ("URS112", "def prog():\n  unused = 1\n  textmsg(2)\nend\n", [(2, 3)], {}),
    ("URS113", "def approach(target, speed):\n  movel(target, v=0.25)\nend\n", [(1, 22)], {}),
    ("URS114", "def sleep(t):\n  textmsg(t)\nend\n", [(1, 5)], {}),
    ("URS114", "sleep = 0.5\nsync()\nsleep(sleep)\n", [(1, 1)], {}),
    ("URS115", "count = 1\ncount == 0\n", [(2, 1)], {}),
    ("URS115", "globl x = 1\n", [(1, 1)], {}),
    ("URS116", "def lift():\n  return None\n  textmsg(1)\nend\n", [(3, 3)], {}),
    ("URS116", "def f(x):\n  if x:\n    return 1\n  else:\n    halt\n  end\n  textmsg(2)\nend\n",
     [(7, 3)], {}),
    ("URS117", "sec light():\n  set_standard_digital_out(0, True)\n  sleep(0.5)\nend\n",
     [(3, 3)], {}),
    ("URS117", "def wait():\n  sleep(0.5)\nend\nsec s():\n  wait()\nend\n", [(5, 3)], {}),
    ("URS118", "thread watch():\n  while not get_standard_digital_in(0):\n  end\n"
     "  textmsg(\"pressed\")\nend\n", [(2, 3)], {}),
    ("URS118", "while True:\n  x = get_standard_digital_in(0)\nend\n", [(1, 1)], {}),
    ("URS119", 'print("done")\n', [(1, 1)], {}),
    ("URS119", 'b = 2\nx = f"a {b}"\n', [(2, 5)], {}),
    ("URS119", "import math\n", [(1, 1), (1, 8)], {}),
    ("URS120", "def main():\n  local count = 0\n  textmsg(count)\nend\n", [(2, 3)], {}),
    ("URS121", "def home():\n  textmsg(1)\nend\ndef home():\n  textmsg(2)\nend\n", [(4, 5)],
     {}),
    ("URS122", "def prog():\n  # begin: URCap Installation Node\n  unused = 1\n"
     "  # end: URCap Installation Node\nend\n", [(2, 3)], {}),
]

# (code, snippet that must not trigger it, settings)
CLEAN = [
    ("URS001", "p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3]\n", {}),
    ("URS100", "x = 1\n" + "if x:\n" * 50 + "textmsg(x)\n" + "end\n" * 50, {}),
    ("URS101", "thread blink():\n  global on = True\nend\ndef show():\n  textmsg(on)\nend\n", {}),
    ("URS101", "def prog():\n  def f():\n    textmsg(x)\n  end\n  x = 1\n  f()\nend\n", {}),
    ("URS101", "x = pi / 2\ntextmsg(x)\n", {}),
    # a program's first-level variables are globals: its threads see them
    ("URS101", "def prog():\n  speed = 0.1\n  thread t():\n    textmsg(speed)\n  end\n"
     "  run t()\nend\n", {}),
    ("URS102", 'textmsg("hello")\ndef f():\n  return 1\nend\nx = f()\n', {}),
    ("URS103", "l = make_list(3, 0, 10)\ntextmsg(l)\n", {"version": "5.15"}),
    ("URS103", "l = make_list(3, 0, 10)\ntextmsg(l)\n", {}),
    ("URS104", "set_standard_digital_out(2, True)\n", {}),
    ("URS105", "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0)\n", {}),
    ("URS106", "q_home = [0, 0, 0, 0, 0, 0]\nmovej(q_home, v=1.0)\ns = struct(a=1, b=2)\n", {}),
    ("URS107", "set_standard_digital_out(3, True)\nmovej([0, 0, 0, 0, 0, 0])\n", {}),
    # two preambles define the name: a nested one-parameter helper and a top-level function
    ("URS107", "def setup():\n  def node(force):\n    return force\n  end\n  x = node(2)\nend\n"
     "def node(a, b, c):\n  return a + b + c\nend\nsetup()\ny = node(1, 2, 3)\n", {}),
    ("URS108", "movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0), d2r(0)])\n"
     "movel([0, -1.57, 0, -1.57, 0, 0])\nmovel(p[0.1, 0.2, 0.3, 0, 0, 0])\n", {}),
    ("URS109", "movej([0, d2r(-90), 0, d2r(-90), 0, 0])\nx = p[0.1, 0.2, 0.3, 0, 3.14, 0]\n"
     "movel(x)\n", {}),
    ("URS110", "movej([0, 0, 0, 0, 0, 0], a=1.4, v=d2r(180))\n", {}),
    ("URS110", "movej([0, 0, 0, 0, 0, 0], v=3.0)\n", {"robot": "ur5e"}),
    ("URS111", "a = p[0.1, 0.2, 0.3, 0, 0, 0]\nmovel(a, r=0.05)\n"
     "set_standard_digital_out(0, True)\nmovel(a)\n", {}),
    ("URS111", "a = p[0.1, 0.2, 0.3, 0, 0, 0]\nwhile True:\n  movel(a, r=0.05)\nend\n", {}),
    ("URS112", "def pick():\n  force_n = 40\n  textmsg(force_n)\nend\n", {}),
    ("URS112", "counter = 0\ndef bump():\n  counter = counter + 1\nend\nbump()\n", {}),
    ("URS112", "def prog():\n  global shared = 1\n  _scratch = 2\nend\n", {}),
    ("URS113", "def approach(target, speed):\n  movel(target, v=speed)\nend\n", {}),
    ("URS114", "time = 5\ntextmsg(time)\n", {}),
    ("URS115", "count = 0\nsync()\nrun_it = 1\n", {}),
    ("URS116", "def lift():\n  if True:\n    return None\n  end\n  textmsg(1)\nend\n", {}),
    ("URS117", "sec light():\n  set_standard_digital_out(0, True)\nend\n", {}),
    ("URS118", "thread watch():\n  while not get_standard_digital_in(0):\n    sync()\n  end\nend\n"
     "i = 0\nwhile i < 10:\n  i = i + 1\nend\n", {}),
    ("URS118", "def wait():\n  sleep(0.1)\nend\nwhile True:\n  wait()\nend\n", {}),
    # its first pass ends the program (a PolyScope Loop around a Halt)
    ("URS118", "mode = read_input_integer_register(0)\nwhile mode == 3:\n  halt\nend\n", {}),
    ("URS119", 'textmsg("done")\n', {}),
    ("URS119", "def print(s):\n  textmsg(s)\nend\nprint(1)\n", {}),
    ("URS120", "def main():\n  def f():\n    local c = 0\n    textmsg(c)\n  end\n  f()\nend\n",
     {}),
    ("URS121", "def home():\n  textmsg(1)\nend\ndef park():\n  textmsg(2)\nend\n", {}),
    ("URS122", "def prog():\n  # begin: URCap Installation Node\n  used = 1\n  textmsg(used)\n"
     "  # end: URCap Installation Node\nend\n", {}),
]


@pytest.mark.parametrize(("code", "text", "expected", "settings"), TRIGGERS,
                         ids=[f"{t[0]}-{i}" for i, t in enumerate(TRIGGERS)])
def test_rule_triggers(code, text, expected, settings):
    assert places(text, code, **settings) == expected


@pytest.mark.parametrize(("code", "text", "settings"), CLEAN,
                         ids=[f"{t[0]}-{i}" for i, t in enumerate(CLEAN)])
def test_rule_stays_quiet(code, text, settings):
    assert places(text, code, **settings) == []


def test_every_rule_has_a_trigger_and_a_clean_case():
    assert {t[0] for t in TRIGGERS} == set(RULES)
    assert {c[0] for c in CLEAN} == set(RULES)


def test_every_rule_example_triggers_it_and_its_fix_does_not():
    # `urdsl rules CODE` shows these; they must be true.
    for code, rule in RULES.items():
        if code == "URS100":
            continue  # its example is a sketch (thousands of levels)
        settings = {"version": "3.15"} if code == "URS103" else {}
        example = rule.example
        fixed = rule.fixed.replace("# urdsl lint --version 5.15\n", "")
        assert places(example, code, **settings), code
        # the severity `urdsl rules` heads its text with is what the example shows
        assert rule.severity in {d.severity for d in lint_text(example, "t.script",
                                                               build_settings(**settings))
                                 if d.code == code}, code
        fixed_settings = {"version": "5.15"} if code == "URS103" else {}
        assert not places(fixed, code, **fixed_settings), code


def test_hints_say_what_to_write():
    assert finding("globl x = 1\n", "URS115").hint == "did you mean `global`?"
    assert finding("globl x = 1\n", "URS101").hint == "did you mean `global`?"
    blink = "thread blink():\n  on = True\nend\ndef show():\n  textmsg(on)\nend\n"
    assert "`global on`" in finding(blink, "URS101").hint
    assert "textmsg" in finding('print("x")\n', "URS119").hint
    assert "str_cat" in finding('b = 1\nx = f"{b}"\n', "URS119").hint
    assignment = finding("a = 0\nif a = 1:\nend\n", "URS001")
    assert (assignment.line, assignment.column) == (2, 6)
    assert "'=' in a condition" in assignment.message and "'=='" in assignment.hint
    assert "set_standard_digital_out" in finding("set_digital_out(2, True)\n", "URS104").hint
    assert "`v`" in finding("movej([0, 0, 0, 0, 0, 0], vel=1)\n", "URS106").hint
    assert "5.15" in finding("l = make_list(3, 0, 10)\n", "URS103", version="3.15").message


@pytest.mark.parametrize(("text", "hint"), [
    ("for i in range(3):\nend\n", "while"),
    ("x = 1\nx += 1\n", "x = x +"),
    ("x = 2 ** 3\n", "pow("),
    ("x = 1\nif x is None:\nend\n", "'=='"),
    ('textmsg(f"x {y}")\n', "str_cat"),
    ("if x == 1:\nelse if x == 2:\nend\n", "elif"),
    ("while x = 1:\nend\n", "'=='"),
])
def test_python_habits_that_are_syntax_errors_carry_urs001_and_the_urscript_way(text, hint):
    (diagnostic,) = lint_text(text, "t.script")
    assert diagnostic.code == "URS001"
    assert hint in diagnostic.hint


def test_course_five_joint_movej_and_stray_parenthesis():
    five = (PROGRAMS / "mistakes" / "course_five_joint_movej.script").read_text()
    (d,) = [d for d in lint_text(five, "five.script") if d.severity == "error"]
    assert (d.code, d.line, d.column) == ("URS108", 5, 9)
    stray = (PROGRAMS / "mistakes" / "course_stray_parenthesis.script").read_text()
    (d,) = lint_text(stray, "stray.script")
    assert (d.code, d.line, d.column) == ("URS001", 6, 47)
    assert "6:8" in d.message
    fixed = (PROGRAMS / "course_examples.script").read_text()
    assert not [d for d in lint_text(fixed, "c.script") if d.severity == "error"]


def test_course_notes_lines_as_written():
    notes = Path(__file__).resolve().parents[2] / "shared" / "reference" / \
        "course-notes-ur-programming.txt"
    if not notes.exists():
        pytest.skip("course notes not found")
    lines = notes.read_text(encoding="utf-8").splitlines()
    five = next(line for line in lines if line.startswith("movej([d2r(0)"))
    (d,) = lint_text(five + "\n", "notes")
    assert (d.code, d.line, d.column) == ("URS108", 1, 7)
    stray = next(line for line in lines if "p1 = p[0.200" in line)
    stray = stray.strip().strip("$").strip()  # the notes wrap code in LaTeX $...$
    (d,) = lint_text(stray + "\n", "notes")
    assert (d.code, d.line, d.column) == ("URS001", 1, 45)


def test_noqa_silences_a_line_or_some_codes():
    text = "def f(a):\n  x = 1 # noqa\n  y = 2 # noqa: URS113\nend\n"
    found = {(d.code, d.line) for d in lint_text(text, "t.script")}
    assert ("URS112", 2) not in found
    assert ("URS112", 3) in found


def test_select_and_ignore_take_prefixes_and_names():
    text = "def f(a):\n  x = 1\nend\nprint(1)\n"
    only = {d.code for d in lint_text(text, "t", build_settings(select=["URS11"]))}
    assert only == {"URS112", "URS113", "URS119"}
    assert not lint_text(text, "t", build_settings(select=["URS0"]))
    none = {d.code for d in lint_text(text, "t", build_settings(ignore=["unused-variable"]))}
    assert "URS112" not in none and "URS119" in none


# ---- the catalog of every controller generation ------------------------------------------

CB3_SPEEDJ = "speedj([0.1, 0, 0, 0, 0, 0], 0.5, t_min=0.008)\n"
CB_ERA = ("varmsg(\"x\", 1)\np = tool_pose()\nset_runstate_outputs([])\n"
          "set_runstate_standard_digital_outputs([])\n")


def _codes(text: str, **settings) -> list[str]:
    return [d.code for d in lint_text(text, "t.script", build_settings(**settings))]


@pytest.mark.parametrize("version", [None, "3.15", "3.2", "1.8"])
def test_cb3_speedj_signature_is_accepted_where_it_applies(version):
    settings = {"version": version} if version else {}
    assert _codes(CB3_SPEEDJ, **settings) == []


@pytest.mark.parametrize("version", ["5.15", "10.11"])
def test_cb3_speedj_signature_is_an_error_on_later_versions(version):
    found = finding(CB3_SPEEDJ, "URS106", version=version)
    assert found.message == "speedj() has no parameter 't_min'"
    assert "speedj(qd, a, [t_min]) is the signature on CB2/CB3" in found.hint
    assert _codes(CB3_SPEEDJ, version=version) == ["URS106"]


@pytest.mark.parametrize("version", [None, "1.8", "3.15", "5.15"])
def test_cb_era_builtins_are_not_errors(version):
    # valid on some controller: never an error without --version; on e-Series their fate
    # is not known, so they are not reported there either
    settings = {"version": version} if version else {}
    assert _codes(CB_ERA, **settings) == []


def test_a_builtin_the_version_lacks_is_still_an_error():
    text = "x = get_euromap_input(1)\n"
    assert _codes(text) == [] and _codes(text, version="3.15") == []
    assert "CB2/CB3" in finding(text, "URS103", version="5.15").message


def test_an_unknown_function_is_still_urs102():
    assert "varmsg" in finding("varmesg(\"x\", 1)\n", "URS102").hint
    assert _codes("tool_poses()\n", version="3.15") == ["URS102"]


@pytest.mark.parametrize("call", ['modbus_set_output_register("payload", 3)',
                                  'modbus_set_output_signal("BRUSH", True)'])
def test_modbus_outputs_set_from_the_main_program_need_not_say_so(call):
    # is_secondary_program left out: programs that ran on e-Series robots do it
    assert _codes(call + "\n") == []
    assert _codes(call.replace(")", ", False)") + "\n") == []


def test_warnings_in_code_a_urcap_wrote_are_counted_in_one_note_errors_stay():
    text = ("def prog():\n"
            "  # begin: URCap Installation Node\n"
            "  #   Source: Gripper, 1.0, Maker\n"
            "  grip_state = 0\n"
            "  grip_force = 0\n"
            "  undefined_call_here()\n"
            "  # end: URCap Installation Node\n"
            "  unused = 1\n"
            "end\n")
    found = lint_text(text, "export.script")
    assert [(d.code, d.severity, d.line) for d in found] == [
        ("URS122", "info", 2), ("URS102", "error", 6), ("URS112", "warning", 8)]
    assert found[0].column == 3
    assert "2 finding(s) (URS112) in the code Gripper wrote" in found[0].message
    quiet = lint_text(text, "export.script", build_settings(ignore=["URS122"]))
    assert [d.code for d in quiet] == ["URS102", "URS112"]


def test_polyscope_s_own_jump_to_label_is_not_an_unknown_name():
    """PolyScope writes ``jump_to_label(N)`` before the Robot Program (a 5.x export of o2ac):
    what PolyScope itself writes is no error."""
    text = ('def program():\n  jump_to_label(3)\n  $ 1 "Robot Program"\n  $ 2 "MoveJ"\n'
            '  $ 3 "home" "breakAfter"\n  movej([0, -1.57, 1.57, -1.57, -1.57, 0])\nend\n')
    assert _codes(text) == []
