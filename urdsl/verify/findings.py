"""Findings of the verifier: what would go wrong on the robot, and where in the program.

Codes are stable (documented in ``urdsl check --help`` and the README):

=======  ========  =============================================================
code     severity  what
=======  ========  =============================================================
URS2xx   error     a runtime error stopped the program (see urdsl.runtime.errors)
URS301   error     a target pose is out of reach (inverse kinematics fails)
URS302   error     a movel/movec path leaves the workspace or needs an IK branch
                   flip (a jump in joint space), even though both ends are reachable
URS303   error     a joint position limit is exceeded
URS304   error     a joint speed limit is exceeded
URS305   warning   a joint acceleration limit is exceeded
URS306   error     the TCP speed limit set for the cell is exceeded
URS307   warning   the arm passes close to a singularity (shoulder, elbow, wrist)
URS308   error     collision with the cell (floor, boxes, cylinders) or itself
URS309   warning   Overlapping Blends: the robot skips the move
URS310   warning   a blend radius larger than half of a neighbouring segment
URS311   warning   the program ended while threads were still running
URS312   info      the program was stopped at the time limit (it loops forever)
URS313   warning   the check stopped early: the program waits for ever (a read with
                   timeout 0 nothing answers) or the wall-clock bound was reached
URS210   warning   what follows depends on a value from outside (a device's reply, an
                   input, an operator's answer) that is unknown offline
=======  ========  =============================================================
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

from ..script.diagnostics import Diagnostic
from ..script.nodes import NO_SPAN, Span

__all__ = ["Finding", "RULES"]

_NUMBER = re.compile(r"(?<![\w.])(?<!wrist )[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")
"""Numbers in a message (not inside names such as ``Waypoint_1``, nor a wrist's number)."""

_REPEATED = re.compile(r" \(\d+ times(?:, first at t=[-\d.]+ s)?\)$")

RULES: dict[str, tuple[str, str]] = {
    "URS301": ("error", "unreachable pose"),
    "URS302": ("error", "path leaves the workspace or flips IK branch"),
    "URS303": ("error", "joint position limit"),
    "URS304": ("error", "joint speed limit"),
    "URS305": ("warning", "joint acceleration limit"),
    "URS306": ("error", "TCP speed limit"),
    "URS307": ("warning", "near a singularity"),
    "URS308": ("error", "collision"),
    "URS309": ("warning", "overlapping blends (move skipped)"),
    "URS310": ("warning", "blend radius larger than half a segment"),
    "URS311": ("warning", "threads still running at program end"),
    "URS312": ("info", "stopped at the time limit"),
    "URS313": ("warning", "check stopped early (waits for ever, wall-clock bound)"),
    "URS210": ("warning", "depends on a device value unknown offline"),
}


@dataclass(frozen=True)
class Finding:
    """One problem, at the statement that caused it. ``time`` is robot time in s.

    ``cause`` tells findings of one rule at one statement apart (the joint, the singularity,
    the colliding pair); None: the message without its numbers does (:meth:`identity`).
    ``count`` is how many times the program ran into it (a statement in a loop); the
    finding is the first of them.
    """

    code: str
    severity: str
    message: str
    span: Span = NO_SPAN
    time: float | None = None
    hint: str | None = None
    cause: str | None = field(default=None, compare=False)
    count: int = field(default=1, compare=False)

    @classmethod
    def of(cls, code: str, message: str, span: Span = NO_SPAN, time: float | None = None,
           hint: str | None = None, cause: str | None = None) -> Finding:
        return cls(code, RULES[code][0], message, span, time, hint, cause)

    def identity(self) -> tuple:
        """What makes two findings the same problem: rule, statement and cause — not the
        times, speeds or poses of one loop pass (numbers in the message are ignored when no
        ``cause`` is given; joint names such as "wrist 2" are kept)."""
        cause = (self.cause if self.cause is not None
                 else _NUMBER.sub("#", _REPEATED.sub("", self.message)))
        return (self.code, self.span, cause)

    def repeated(self, count: int) -> Finding:
        """This finding as the first of ``count`` occurrences, saying so in its message."""
        if count == self.count:
            return self
        message = _REPEATED.sub("", self.message)
        if count > 1:
            when = f", first at t={self.time:.3f} s" if self.time is not None else ""
            message = f"{message} ({count} times{when})"
        return replace(self, message=message, count=count)

    def diagnostic(self) -> Diagnostic:
        return Diagnostic.at(self.span, self.message, code=self.code, severity=self.severity,
                             hint=self.hint)

    def to_dict(self) -> dict:
        result = self.diagnostic().to_dict()
        result["time"] = None if self.time is None else round(self.time, 6)
        result["count"] = self.count
        return result
