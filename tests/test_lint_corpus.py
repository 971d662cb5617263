"""The linter on real URScript (../shared/corpus) and on random text: it never crashes, and
the drivers' and UR's own scripts get no error-severity finding."""

from __future__ import annotations

from collections import Counter

import pytest
from _corpus import corpus_files, fill_template
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from urdsl.lint import lint_text

FILES = corpus_files()
TRUSTED = ("UniversalRobots__", "ros-industrial__", "medra-ai__")
# UR's example of a script with a mistake in it ("note pose vs pos"): the linter must find it.
DELIBERATELY_BAD = "UniversalRobots__Universal_Robots_Client_Library/examples/send_script.cpp" \
    "__bad_script_code"

# The warnings that remain on the trusted scripts, each defended in the lint note
# (../notes/issue-6.md): (file, code) -> count.
EXPECTED_WARNINGS = {
    ("UniversalRobots__Universal_Robots_Client_Library/examples/send_script.cpp"
     "__bad_script_code", "URS112"): 1,
    ("UniversalRobots__Universal_Robots_Client_Library/resources/external_control.urscript",
     "URS104"): 1,
    ("UniversalRobots__Universal_Robots_Client_Library/resources/external_control.urscript",
     "URS112"): 1,
    ("UniversalRobots__Universal_Robots_Client_Library/resources/external_control.urscript",
     "URS113"): 1,
    ("UniversalRobots__Universal_Robots_ROS_as_a_Service_URCap/src/main/resources/"
     "json_parser.script", "URS112"): 1,
    ("UniversalRobots__URScript_Examples/admittance-control/admittance_control.script",
     "URS112"): 1,
    ("medra-ai__ur_rtde/doc/_static/robotiq_preamble.py__ROBOTIQ_PREAMBLE", "URS112"): 9,
    ("medra-ai__ur_rtde/scripts/rtde_control.script", "URS104"): 5,
    ("medra-ai__ur_rtde/scripts/rtde_control.script", "URS113"): 1,
    ("ros-industrial__universal_robot/ur_driver/prog", "URS104"): 4,
    ("ros-industrial__universal_robot/ur_driver/prog", "URS112"): 7,
    ("ros-industrial__ur_modern_driver/src/ros/lowbandwidth_trajectory_follower.cpp"
     "__POSITION_PROGRAM", "URS112"): 3,
}


def _text(corpus_file) -> str:
    text = corpus_file.text()
    return fill_template(text, corpus_file.path) if corpus_file.templated else text


@pytest.mark.parametrize("corpus_file", FILES, ids=[f.name for f in FILES])
def test_lint_never_crashes_on_the_corpus(corpus_file):
    found = lint_text(_text(corpus_file), corpus_file.name)
    for diagnostic in found:
        assert diagnostic.line >= 1 and diagnostic.column >= 1
        assert diagnostic.severity in ("error", "warning", "info")


def test_trusted_scripts_have_no_errors_and_only_the_defended_warnings():
    warnings: Counter = Counter()
    for corpus_file in FILES:
        if not corpus_file.name.startswith(TRUSTED):
            continue
        found = lint_text(_text(corpus_file), corpus_file.name)
        errors = [(d.line, d.column, d.code) for d in found if d.severity == "error"]
        if corpus_file.name == DELIBERATELY_BAD:
            assert errors == [(3, 9, "URS101")]  # movel(current_pos) after current_pose = ...
        else:
            assert errors == [], corpus_file.name
        warnings.update((corpus_file.name, d.code) for d in found if d.severity == "warning")
    assert dict(warnings) == EXPECTED_WARNINGS


@pytest.mark.parametrize("corpus_file", FILES[::3], ids=[f.name for f in FILES[::3]])
def test_truncated_corpus_files_never_crash(corpus_file):
    text = _text(corpus_file)
    for cut in range(0, len(text), max(1, len(text) // 25)):
        lint_text(text[:cut], "cut.script")


_TOKENS = [
    "def", "f", "(", ")", ":", "end", "thread", "t", "sec", "s", "if", "elif", "else", "while",
    "True", "False", "None", "return", "halt", "break", "continue", "run", "join", "kill",
    "global", "local", "x", "y", "=", "==", "+", "-", "*", "/", "%", "not", "and", "or", "[",
    "]", "p[", ",", ".", "1", "-90", "0.5", '"s"', "movej", "movel", "sleep", "sync",
    "textmsg", "a=", "v=", "r=", "\n", " ", "# c\n", "$ 1 \"L\"\n", "print", "globl", "f\"x\"",
    "enter_critical", "exit_critical", "d2r", "speedj", "struct", "make_list",
]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.sampled_from(_TOKENS), max_size=60))
def test_random_token_soup_never_crashes(tokens):
    lint_text(" ".join(tokens), "fuzz.script")


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=200))
def test_random_text_never_crashes(text):
    lint_text(text, "fuzz.script")


_STATEMENTS = st.sampled_from([
    "x = 1", "global g = 2", "local l = 3", "movej([0, 0, 0, 0, 0, 0], r=0.1)",
    "movel(p[0.1, 0.2, 0.3, 0, 0, 0], v=9)", "sleep(0.1)", "sync()", "return None", "halt",
    "textmsg(x)", "x == 1", "while True:\nend", "if x:\n  return 1\nelse:\n  halt\nend",
    "run t()", "h = run t()", "join h", "kill h", "speedj([0, 0, 0], 1)", "f(1, 2, c=3)",
    "break", "continue", "enter_critical", "exit_critical", "y", "def g(a):\nend",
    "thread t():\n  while True:\n  end\nend", "sec s():\n  sleep(1)\nend",
])


@settings(max_examples=200, deadline=None)
@given(st.lists(_STATEMENTS, max_size=12), st.booleans())
def test_random_valid_programs_never_crash(statements, wrap):
    body = "\n".join(statements)
    if wrap:
        body = "def prog():\n" + body + "\nend"
    lint_text(body + "\n", "fuzz.script")
