"""PolyScope compile: what the versions of programs saved beside their ``.script`` in the
history of the studied projects showed (urp10; not benchmark pairs). Fixtures are written
here; the expected forms are PolyScope's."""

from __future__ import annotations

from test_polyscope_variants import WAYPOINT, compiled


def _move(kind: str, name: str, blend: str = "") -> str:
    radius = f' blendRadius="{blend}"' if blend else ""
    return f"""<Move motionType="{kind}" speed="0.25" acceleration="1.2"{radius}
              useActiveTCP="true" positionType="CartesianPose">
          <feature class="GeomFeatureReference" referencedName="Joint_0_name"/>
          <children>{WAYPOINT.format(name=name)}</children>
        </Move>"""


FORCE = """<Force type="Frame">
      <feature referencedName="Joint_0_name"/>
      <selection value="1, 0, 0, 0, 0, 0"/>
      <wrench value="5.0, 0.0, 0.0, 0.0, 0.0, 0.0"/>
      <limitsForce value="0.005, 0.15, 0.15, 1.0, 1.0, 1.0"/>
      <limitsMotion value="0.1, 0.1, 0.1, 0.35, 0.35, 0.35"/>
      <children>{body}</children>
    </Force>"""


def test_a_movep_that_ends_a_force_at_the_end_of_the_program_keeps_its_blend():
    # o2ac/o2ac-ur b_bot/taskboard_pick_hook at 7b9c47d (PolyScope 5.7): a MoveP (its last
    # motion a CircleMove) is the last node of a Force, the last node of a program run once:
    # ``movec(…, r=0.001, mode=1)`` — nothing follows it in the program tree
    lines = compiled(FORCE.format(body=_move("MoveP", "Tophole", "0.001")))
    assert "movep(Tophole_p, a=1.2, v=0.25, r=0.001)" in lines
    assert lines.index("movep(Tophole_p, a=1.2, v=0.25, r=0.001)") < lines.index(
        "end_force_mode()")


def test_a_movep_at_the_end_of_a_program_run_once_keeps_its_blend():
    lines = compiled(_move("MoveL", "Start") + _move("MoveP", "Last", "0.02"))
    assert "movep(Last_p, a=1.2, v=0.25, r=0.02)" in lines


def test_a_movep_ending_a_container_blends_only_into_a_movep_after_it():
    # nedlecky/UR Lnn/L01_movejlp (5.9): a MoveP that ends a Loop followed by a MoveL writes
    # r=0 (what follows the Loop counts, not the Loop's first node again)
    loop = """<Loop type="Counting" count="3"><children>{body}</children></Loop>"""
    lines = compiled(loop.format(body=_move("MoveP", "Inner", "0.025")) +
                     _move("MoveL", "After"))
    assert "movep(Inner_p, a=1.2, v=0.25, r=0.0)" in lines
    # the same, followed by a MoveP: it blends into it
    lines = compiled(loop.format(body=_move("MoveP", "Inner", "0.025")) +
                     _move("MoveP", "Next", "0.01"))
    assert "movep(Inner_p, a=1.2, v=0.25, r=0.025)" in lines
    # a Force inside a Folder, followed by a MoveL: what follows the Folder counts
    folder = f"""<Folder name="Work"><children>{FORCE.format(body=_move("MoveP", "Deep", "0.01"))}
        </children></Folder>"""
    lines = compiled(folder + _move("MoveL", "After"))
    assert "movep(Deep_p, a=1.2, v=0.25, r=0.0)" in lines
