"""Node variants learned from the ``tune4`` projects (the repositories fetched for the
real-world benchmark, PolyScope 3.12-5.17). Fixtures are written here; the expected forms
are PolyScope's."""

from __future__ import annotations

from test_polyscope_programs import EXPRESSION, WAYPOINT_UNTIL, lines_of, program
from test_polyscope_variants import DIRECTION, WAYPOINT_MOVE, compiled
from test_polyscope_variants import program as variants_program

from urdsl.polyscope.compile import compile_program
from urdsl.polyscope.installation import parse_installation
from urdsl.polyscope.urp import parse_urp
from urdsl.script import parse
from urdsl.script.printer import format as print_tree


def test_a_waypoint_with_only_an_expression_until_still_ends_with_its_move():
    # srs827/Robot-Cello-ResidualRL (5.17.3): a Waypoint whose only Until is an expression
    # waits for it or for the end of the move, which has no marker of its own
    lines = lines_of(program(WAYPOINT_UNTIL.format(untils=EXPRESSION)))
    loop = lines.index("move_thread_han_3 = run move_thread_3()") + 1
    assert lines[loop] == "while (True):"
    end = lines.index("break", loop) + 2  # the condition's break, then its ``end``
    assert lines[end:end + 7] == [
        "sleep(1e-10)", "if (move_thread_flag_3 > 1):", "join move_thread_han_3",
        "break", "end", "sync()", "end"]


def test_polyscope_3_12_and_3_14_write_flags_and_the_robot_program_marker():
    # kg398/kg_ursim kg_client (3.12.1), loryburgess/Regal-Rexnord Main (3.12.1) and
    # ldalepfi/UR-Simulation-Prod (3.14.1): '$ 1 "Robot Program"', '"breakAfter"' and a
    # subprogram's '"noBreak"', as 3.15 on; 3.8.0 writes neither
    for version in ("3.12.1.90940", "3.14.1.1031110"):
        markers = [line for line in compiled(WAYPOINT_MOVE, version=version)
                   if line.startswith("$")]
        assert markers == ['$ 1 "Robot Program"', '$ 2 "MoveJ"', '$ 3 "Start" "breakAfter"']


VARIABLE_BASE = """<Installation name="cell">
  <TCPSettings activePose="TCP"><tcp name="TCP" offset="0.0, 0.0, 0.1, 0.0, 0.0, 0.0"/>
  </TCPSettings>
  <Features>
    <BaseView><BaseView showAxes="true" joggable="true" isVariable="{variable}"/></BaseView>
    <ToolView><ToolView showAxes="true" joggable="true" isVariable="false"/></ToolView>
  </Features>
</Installation>"""

BASE_MOVES = """
        <Move motionType="MoveL" speed="0.5" acceleration="0.5" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <Waypoint type="Fixed" name="home" kinematicsFlags="3">
              <motionParameters/>
              <position joints="0.0, -1.5, 1.5, -1.5, -1.5, 0.0"
                        pose="0.3, -0.4, 0.5, 0.0, 3.14, 0.0"/>
            </Waypoint>
            <Waypoint type="Variable" name="approach" kinematicsFlags="-1">
              <motionParameters/>
              <variable name="APPROACH"/>
            </Waypoint>
          </children>
        </Move>
        <Move motionType="MoveJ" speed="1.05" acceleration="1.4" useActiveTCP="true">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>
            <Waypoint type="Variable" name="sp" kinematicsFlags="-1">
              <motionParameters/>
              <variable name="sp"/>
            </Waypoint>
          </children>
        </Move>"""


def base_lines(variable: str) -> list[str]:
    prog = parse_urp(variants_program(BASE_MOVES, version="3.14.1.1031110").encode(),
                     "prod.urp")
    inst = parse_installation(VARIABLE_BASE.format(variable=variable).encode(),
                              "cell.installation")
    text = compile_program(prog, inst).text
    assert print_tree(parse(text)) == text
    return [line.strip() for line in text.splitlines()]


def test_polyscope_3_moves_in_a_variable_base_go_relative_to_it():
    # ldalepfi/UR-Simulation-Prod (3.14.1): the installation's base is variable
    # (<BaseView isVariable="true">): ``global Base=p[0.0,…]`` in the preamble, a MoveL to
    # ``pose_trans(Base, p[…])`` and ``pose_trans(Base, APPROACH)``, a MoveJ to ``sp``
    lines = base_lines("true")
    assert "global Base = p[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]" in lines
    moves = [line for line in lines if line.startswith(("movel(", "movej("))]
    assert moves == ["movel(pose_trans(Base, p[0.3, -0.4, 0.5, 0.0, 3.14, 0.0]), a=0.5, v=0.5)",
                     "movel(pose_trans(Base, APPROACH), a=0.5, v=0.5)",
                     "movej(sp, a=1.4, v=1.05)"]


def test_polyscope_3_moves_in_a_fixed_base_are_unchanged():
    lines = base_lines("false")
    assert not any(line.startswith("global Base") for line in lines)
    assert "movel(p[0.3, -0.4, 0.5, 0.0, 3.14, 0.0], a=0.5, v=0.5)" in lines


def test_a_direction_under_a_movep_moves_with_movep():
    # Roma4286/UniversalRobots Robot1 (5.12): "Направление: Инструмент Z-" under a MoveP
    # writes ``movep(towardsPos, a=…, v=…)``; under a MoveL ``movel`` as before
    process = [line for line in compiled(DIRECTION.format(kind="BLEND").replace(
        'motionType="MoveL"', 'motionType="MoveP"')) if "(towardsPos" in line]
    assert process and all(line.startswith("movep(towardsPos") for line in process)
    linear = [line for line in compiled(DIRECTION.format(kind="BLEND"))
              if "(towardsPos" in line]
    assert linear and all(line.startswith("movel(towardsPos") for line in linear)


def test_a_program_named_with_a_keyword_is_prefixed_with_p():
    # Baxterminator/RoboTech-24 robot/run.urp (5.13.1): ``def Prun():``
    for name, expected in (("run", "def Prun():"), ("pick", "def pick():")):
        data = variants_program(WAYPOINT_MOVE).replace('name="variants"', f'name="{name}"')
        text = compile_program(parse_urp(data.encode(), f"{name}.urp")).text
        assert print_tree(parse(text)) == text
        assert text.splitlines()[0] == expected
