"""Reading PolyScope programs (.urp): the typed, named tree; references; bad files.

The fixture tests/data/polyscope/cell.urp is written here after the layout PolyScope 5.x saves
(no real program is copied)."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from urdsl.polyscope.urp import UrpError, parse_urp, read_urp

DATA = Path(__file__).parent / "data" / "polyscope"
CELL = DATA / "cell.urp"


@pytest.fixture(scope="module")
def program():
    return read_urp(CELL)


def kinds(program):
    return [node.kind for root in program.top for node in root.walk()]


def test_top_level_nodes_in_file_order(program):
    assert [node.kind for node in program.top] == [
        "InitVariablesNode", "SpecialSequence", "MainProgram", "Thread", "SubProgram"]
    assert program.name == "cell test.1"
    assert program.installation == "cell"
    assert program.major_version == 5
    assert program.before_start is program.top[1]
    assert [thread.name for thread in program.threads] == ["Thread_1"]


def test_every_node_type_is_read_with_its_fields(program):
    found = set(kinds(program))
    assert {"Move", "Waypoint", "Loop", "If", "Wait", "Set", "Assignment", "Script", "Popup",
            "Halt", "Comment", "Folder", "CallSubProgram", "Switch", "Case", "Timer",
            "Contributed", "FancyNewNode"} <= found
    main = program.main
    movej = main.children[0]
    assert movej.fields["motion_type"] == "MoveJ"
    assert movej.fields["speed"] == pytest.approx(1.0471975511965976)
    first, second = movej.children
    assert first.name == "Waypoint_1" and first.fields["type"] == "Fixed"
    assert second.fields["q"] == (0.1, -1.2, 1.1, -1.4, -1.6, 0.2)
    assert second.fields["tcp_offset"][2] == 0.1
    assert second.fields["params"] == {"nextMotionTime": 2.5}
    loop = main.children[2]
    assert (loop.fields["type"], loop.fields["count"], loop.fields["variable"]) == \
        ("Counting", 3, "Loop_1")
    assert program.kinematics is not None and program.kinematics.a[1] == -0.425


def test_references_are_resolved(program):
    movel = program.main.children[1]
    variable = movel.children[0]
    assert variable.fields["type"] == "Variable"
    assert variable.fields["variable"] == "count"  # a reference back into BeforeStart
    condition = program.main.children[3].fields["expression"]
    assert condition.label == "count≟1"
    assert condition.script == "count==1"
    sub = program.subprograms[0]
    assert sub.kind == "SubProgram" and sub.name == "Home"
    assert sub.fields["file"] == "/programs/Home.urp"
    assert [child.kind for child in sub.children] == ["Assignment"]
    assert sub.children[0].name == "count"


def test_expressions_are_joined_character_by_character(program):
    script = program.main.children[7].children[0]
    assert script.fields["type"] == "Line"
    assert script.fields["expression"].script == 'textmsg("hi")'


def test_suppressed_urcap_and_unknown_nodes_are_kept_by_name(program):
    folder = program.main.children[7]
    suppressed = folder.children[1]
    assert suppressed.kind == "Wait" and suppressed.suppressed
    assert suppressed.fields["seconds"] == 9.0
    urcap = program.before_start.children[1]
    assert urcap.kind == "Contributed" and urcap.title == "Grip"
    assert urcap.attrs["strategyURCapName"] == "Example_Gripper"
    unknown = program.main.children[-1]
    assert unknown.kind == "FancyNewNode" and unknown.attrs == {"colour": "blue"}


def test_node_path_names_the_tree(program):
    waypoint = program.main.children[0].children[1]
    assert waypoint.path == "Robot Program > MoveJ > Waypoint_2"


def test_gzip_and_plain_xml_read_the_same():
    plain = CELL.read_bytes()
    a, b = parse_urp(plain, "a.urp"), parse_urp(gzip.compress(plain), "b.urp")
    assert kinds(a) == kinds(b)


@pytest.mark.parametrize("data, message", [
    (gzip.compress(CELL.read_bytes())[:200], "the gzip data is truncated"),
    (CELL.read_bytes()[:1500], "truncated"),
    (b"<Installation/>", "not a PolyScope program"),
    (b"\x00\x01binary", "not well-formed"),
    (b"<gui.program.ProgramRootNode/>", "PolyScope 1.x"),
    (b"<URProgram name='x'/>", "without <children>"),
    (b"<URProgram><children/></URProgram>", "no <MainProgram>"),
    (b"<URProgram><children><MainProgram><children><Move><feature reference='../../../x'/>"
     b"</Move></children></MainProgram></children></URProgram>", "broken reference"),
])
def test_bad_files_give_one_clear_error_naming_the_file(data, message):
    with pytest.raises(UrpError) as error:
        parse_urp(data, "usb/bad.urp")
    assert str(error.value).startswith("usb/bad.urp: error: ")
    assert message in str(error.value)


def test_missing_file():
    with pytest.raises(UrpError, match="cannot read"):
        read_urp(DATA / "no such.urp")


@settings(max_examples=60, deadline=None)
@given(st.integers(min_value=0, max_value=len(CELL.read_bytes()) - 1))
def test_any_truncation_is_an_error_or_a_program(cut):
    data = CELL.read_bytes()[:cut]
    try:
        parse_urp(data, "cut.urp")
    except UrpError:
        pass
