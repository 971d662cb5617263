"""A program of one ``movel`` checked from given joints: what several tests of issue 12's
motion rules run."""

from __future__ import annotations

import numpy as np

from urdsl.verify.findings import Finding
from urdsl.verify.run import CheckOptions, check_text


def one_movel(model: str, start: np.ndarray, pose, args: str) -> list[Finding]:
    """The findings of ``movel(p[pose], args)`` (``pose``: 6 values, m and rad) checked on
    ``model`` from the joints ``start`` (rad)."""
    text = ("def move():\n  movel(p[" + ", ".join(f"{x:.9f}" for x in pose) + f"], {args})\n"
            "end\n")
    options = CheckOptions(robot=model, start_joints=tuple(start), timeout=None)
    return check_text(text, "move.script", options=options).findings
