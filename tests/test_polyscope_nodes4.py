"""Node variants learned from the ``tune4`` projects (the repositories fetched for the
real-world benchmark, PolyScope 3.12-5.17). Fixtures are written here; the expected forms
are PolyScope's."""

from __future__ import annotations

from test_polyscope_programs import EXPRESSION, WAYPOINT_UNTIL, lines_of, program


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
