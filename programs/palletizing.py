"""Palletizing: a 3 x 4 pallet filled in a loop, with a counter, a function computing each
place from the counter, and the robot's own arithmetic (no Python loop unrolling).

Shows: variables and arithmetic on expressions, while loops, integer division with floor,
p[...] poses built from expressions, a function with a return value, if/else, and a popup
at the end.

    urdsl compile programs/palletizing.py
    urdsl check programs/palletizing.py --robot ur10e
"""

from urdsl.dsl import Joints, Pose, Program

ROWS, COLUMNS, PITCH = 3, 4, 0.08  # parts, parts, m

program = Program("palletizing")
program.set_tcp(Pose(0, 0, 0.10))
program.movej(Joints.deg(150, -100, 110, -100, -90, 0))
origin = program.var("origin", Pose(0.35, -0.15, 0.10, 0, 3.1416, 0))

with program.function("place_of", "k") as place_of:
    row = program.var("row", program.expr("floor", place_of.k / COLUMNS))
    column = program.var("column", place_of.k - row * COLUMNS)
    program.return_(program.expr("pose_add", origin, program.pose(
        row * PITCH, column * PITCH, 0, 0, 0, 0)))

count = program.var("count", 0)
with program.while_(count < ROWS * COLUMNS):
    target = program.var("target", place_of(count))
    above = program.var("above", program.expr("pose_add", target, Pose(0, 0, 0.05)))
    program.movel(above, a=1.2, v=0.25, r=0.01)
    program.movel(target, a=0.5, v=0.1)
    program.set_digital_out(0, False)
    program.sleep(0.2)
    program.movel(above, a=1.2, v=0.25)
    program.set(count, count + 1)
    with program.if_(count % COLUMNS == 0):
        program.textmsg("row done: ", count / COLUMNS)
program.popup("Pallet full", title="Palletizing")
