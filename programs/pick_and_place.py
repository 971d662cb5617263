"""Pick and place with blends: approach, pick, retreat and place, passing through the
approach points without stopping (blend radius r in metres) while the grip points are
exact stops. The gripper is a tool digital output.

Shows: Pose arithmetic with @ (offsets in the tool frame), blends, tool I/O, sleep,
textmsg, and a function with parameters called for every part.

    urdsl compile programs/pick_and_place.py
    urdsl check programs/pick_and_place.py --robot ur5e
"""

from urdsl.dsl import Joints, Pose, Program

DOWN = (0.0, 3.1416, 0.0)  # tool z pointing down
ABOVE = Pose(0, 0, -0.10)  # 10 cm above a point, along the tool's z axis

program = Program("pick_and_place")
program.set_tcp(Pose(0, 0, 0.12))
program.set_payload(1.2)
program.movej(Joints.deg(160, -100, 100, -90, -90, 0))

with program.function("transfer", "grip", "drop") as transfer:
    above_grip = program.var("above_grip", program.expr("pose_trans", transfer.grip, ABOVE))
    above_drop = program.var("above_drop", program.expr("pose_trans", transfer.drop, ABOVE))
    program.movej(above_grip, a=1.4, v=1.05, r=0.03)
    program.movel(transfer.grip, a=0.5, v=0.1)
    program.set_tool_digital_out(0, True)
    program.sleep(0.3)
    program.movel(above_grip, a=1.2, v=0.25, r=0.03)
    program.movej(above_drop, a=1.4, v=1.05, r=0.03)
    program.movel(transfer.drop, a=0.5, v=0.1)
    program.set_tool_digital_out(0, False)
    program.sleep(0.3)
    program.movel(above_drop, a=1.2, v=0.25)

for k, (x, y) in enumerate([(0.45, -0.20), (0.45, -0.10), (0.45, 0.0)]):
    program.comment(f"part {k + 1}")
    transfer.call(Pose(x, y, 0.05, *DOWN), Pose(0.30, round(0.35 + 0.05 * k, 3), 0.08, *DOWN))
program.textmsg("placed parts: ", 3)
