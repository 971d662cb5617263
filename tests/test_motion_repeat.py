"""A loop that repeats a toolpath from the same place repeats its trajectory: the sampler
solves each distinct straight-line move once (``_Moves.knots``), with the same samples as
solving every move."""

from __future__ import annotations

import numpy as np

import urdsl.motion.trace as trace_module
from urdsl.verify.run import CheckOptions, check_text

LOOP = """movej([0, -1.9, 1.9, -1.57, -1.57, 0])
home = get_actual_tcp_pose()
i = 0
while i < 40:
  movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.01)
  movel(pose_add(home, p[0.1, 0.1, 0, 0, 0, 0.3]), r=0.01)
  movel(home)
  if i % 3 == 0:
    movel(pose_add(home, p[0, 0.1, 0.05, 0.2, 0, 0]))
  end
  i = i + 1
end
"""


def test_repeated_moves_give_the_samples_of_solving_each(monkeypatch):
    options = CheckOptions(self_collision=False)
    shared = check_text(LOOP, "loop.script", options=options)
    monkeypatch.setattr(trace_module._Moves, "knots", trace_module._Moves.solve_knots)
    each = check_text(LOOP, "loop.script", options=options)
    assert len(shared.trace.times) == len(each.trace.times) > 10000
    assert np.array_equal(shared.trace.q, each.trace.q)
    assert np.array_equal(shared.trace.qd, each.trace.qd)
    assert [f.message for f in shared.findings] == [f.message for f in each.findings]
