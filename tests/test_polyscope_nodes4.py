"""Node variants learned from the ``tune4`` projects (the repositories fetched for the
real-world benchmark, PolyScope 3.12-5.17). Fixtures are written here; the expected forms
are PolyScope's."""

from __future__ import annotations

from test_polyscope_programs import EXPRESSION, WAYPOINT_UNTIL, lines_of, program
from test_polyscope_variants import WAYPOINT_MOVE, compiled


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
