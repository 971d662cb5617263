"""Python DSL that builds URScript syntax trees.

>>> from urdsl.dsl import Program, Joints, Pose
>>> program = Program("pick")
>>> program.movej(Joints(0, -1.57079632, 0, -1.57079632, 0, 0))
>>> program.movel(Pose(0.2, -0.3, 0.3, 0.5, 0.0, -0.3), a=1.2, v=0.25, r=0.01)
>>> print(program.script())
def pick():
  movej([0, -1.57079632, 0, -1.57079632, 0, 0])
  movel(p[0.2, -0.3, 0.3, 0.5, 0, -0.3], a=1.2, v=0.25, r=0.01)
end
<BLANKLINE>
"""

from .errors import DslError
from .program import Function, Program, Thread
from .values import And, Expr, Joints, Not, Or, Pose, deg, rad

__all__ = ["Program", "Joints", "Pose", "Expr", "Function", "Thread", "DslError", "deg", "rad",
           "And", "Or", "Not"]
