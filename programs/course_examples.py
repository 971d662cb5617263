"""The course's URScript examples, written with the urdsl DSL.

Shows: the home position with Joints.deg (six joints, in degrees at the call, radians in
the URScript), the joint target p0 and the pose p1, pose_trans (move in the tool's frame)
and pose_add (add positions, compose rotations) computed in Python with Pose's @ and
pose_add as the course writes them, and a movel whose start is not singular (the slides' order would
start it from the stretched arm — see programs/mistakes/).

    urdsl compile programs/course_examples.py
    urdsl check programs/course_examples.py
"""

from urdsl.dsl import Joints, Pose, Program

program = Program("course_examples")
program.comment("Home position, as the course writes it (radians) ...")
program.movej(Joints(0, -1.57079632, 0, -1.57079632, 0, 0))
program.comment("... and in degrees, converted at the call.")
program.movej(Joints.deg(0, -90, 0, -90, 0, 0))

p0 = Joints.deg(90, -90, 0, -90, 0, 0)
p1 = Pose(0.200, -0.300, 0.300, 0.5, 0.0, -0.3)

program.comment("C = pose_trans(A, B): 0T_C = 0T_A * AT_B, 0.1 m along the tool's z axis.")
C = program.var("C", program.expr("pose_trans", p1, Pose(0, 0, 0.1)))
program.comment("C = pose_add(A, B): positions added in the base frame, rotations composed.")
D = program.var("D", program.expr("pose_add", p1, Pose(0, 0, 0.1)))
program.comment(f"The same pose_trans computed in Python, p1 @ offset: {p1 @ Pose(0, 0, 0.1)}")

program.movej(p0)
program.comment("p0 stretches the arm straight up; a straight line cannot start there.")
program.movej(p1)
program.movel(C, a=1.2, v=0.25)
program.movel(D, a=1.2, v=0.25)
