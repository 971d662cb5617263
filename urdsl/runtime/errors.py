"""Runtime errors of URScript programs, as the controller would report them.

Each error names the node that caused it, so the message carries ``file:line:col`` and the
source line, and a stable code:

========  ====================================================================
URS201    a name is not defined (the controller: ``name 'x' is not defined``)
URS202    index out of range
URS203    wrong type for an operation or argument
URS204    inverse kinematics found no solution
URS205    arithmetic error (division by zero, sqrt of a negative, ...)
URS206    wrong arguments in a call (count, unknown keyword, missing argument)
URS207    a thread ran without using physical time (no sync/sleep/move): the
          controller stops the program
URS208    something that is not a function was called, or a thread misused
URS209    a builtin that urdsl does not simulate was called
========  ====================================================================

Not errors: ``urdsl check`` reports what depends on a value unknown offline (a device's
reply, an input; :mod:`urdsl.runtime.unknown`) as the warning URS210, and a run that stops
early without an error (it waits for ever, or the wall-clock bound) as URS313.
"""

from __future__ import annotations

from ..rules import Rule, register
from ..script.diagnostics import Diagnostic, ScriptError
from ..script.nodes import NO_SPAN, Span

__all__ = ["ScriptRuntimeError", "CODES", "beyond_reach"]

CODES = {
    "undefined": "URS201",
    "index": "URS202",
    "type": "URS203",
    "ik": "URS204",
    "arithmetic": "URS205",
    "arguments": "URS206",
    "runaway": "URS207",
    "call": "URS208",
    "unsupported": "URS209",
}


class ScriptRuntimeError(ScriptError):
    """A URScript program failed while running (the controller would stop it).

    ``beyond``: for a failed inverse kinematics (``kind`` ``"ik"``) of a pose beyond the
    arm's reach, where the pose lies and how far out, ``((x, y, z), distance)`` in m
    (:func:`beyond_reach`); None otherwise. ``name``: for a name or function that nothing
    defined (``kind`` ``"undefined"``), that name; None otherwise."""

    def __init__(self, kind: str, message: str, span: Span = NO_SPAN, hint: str | None = None,
                 time: float | None = None) -> None:
        super().__init__(Diagnostic.at(span, message, code=CODES[kind], hint=hint), span)
        self.kind = kind
        self.time = time
        self.beyond: tuple[tuple[float, float, float], float] | None = None
        self.name: str | None = None


def beyond_reach(error: Exception) -> tuple[tuple[float, float, float], float] | None:
    """Where a kinematics error's pose lies and how far (m) beyond the arm's reach, when it
    is one (a ``KinematicsError`` with a ``position``), else None."""
    position = getattr(error, "position", None)
    distance = getattr(error, "distance", None)
    if position is None or distance is None:
        return None
    return (tuple(float(v) for v in position), float(distance))  # type: ignore[return-value]


# ---- the rules (``urdsl rules URS2``) ----------------------------------------------------------

_RULES = (
    ("URS201", "name-not-defined", "A name is used before anything gave it a value.",
     """
The controller stops the program with "name 'x' is not defined" when it evaluates a name
that no assignment, global, parameter or definition has given a value yet on this run.""",
     "movej([0, -1.9, 1.9, -1.57, -1.57, 0])\nmovel(target)",
     "movej([0, -1.9, 1.9, -1.57, -1.57, 0])\ntarget = get_actual_tcp_pose()\nmovel(target)"),
    ("URS202", "index-out-of-range", "A list, pose or string is indexed past its end.",
     """
Indices count from 0: a list of six joints has the indices 0 to 5. The controller stops the
program at the first index outside.""",
     "q = [0, -1.9, 1.9, -1.57, -1.57, 0]\nx = q[6]",
     "q = [0, -1.9, 1.9, -1.57, -1.57, 0]\nx = q[5]"),
    ("URS203", "wrong-type", "A value of the wrong type for an operation or an argument.",
     """
URScript does not convert between types by itself: a string is not added to a number, a
pose is not a list of joints. Convert explicitly (to_str, str_cat, p[...], ...).""",
     'n = 3\nmsg = "parts: " + n',
     'n = 3\nmsg = str_cat("parts: ", n)'),
    ("URS204", "no-ik-solution", "Inverse kinematics found no solution for a pose.",
     """
get_inverse_kin (or a move to a pose) asked for joints that put the TCP at a pose the arm
cannot reach. In urdsl check a move to such a pose is reported as URS301.""",
     "q = get_inverse_kin(p[1.5, 0.2, 0.3, 0, 3.1416, 0])",
     "q = get_inverse_kin(p[0.5, 0.2, 0.3, 0, 3.1416, 0])"),
    ("URS205", "arithmetic-error", "Division by zero, the square root of a negative number, ...",
     """
The controller stops the program on an arithmetic operation without a result: x / 0,
sqrt(-1), acos(2), log(0).""",
     "n = 0\nx = 1 / n",
     "n = 0\nx = 0\nif n != 0:\n  x = 1 / n\nend"),
    ("URS206", "wrong-arguments", "A call with the wrong arguments: count, an unknown keyword "
     "or a missing one.",
     """
A call of one of the file's own functions (or a builtin) binds its arguments as the
controller does; a call that gives too many or too few, or names a parameter that does not
exist, stops the program. urdsl lint finds many of these before a run (URS105, URS106).""",
     "def twice(a):\n  return 2 * a\nend\nx = twice(1, 2)",
     "def twice(a):\n  return 2 * a\nend\nx = twice(1)"),
    ("URS207", "runaway-thread", "A thread ran without using physical time: the controller "
     "stops the program.",
     """
Every thread must give the controller time in each of its loop passes (sync(), sleep(),
a move, a blocking read). A loop that does not — even with sleep(0) — makes the controller
stop the program with "runaway thread".""",
     "while True:\n  x = 1\nend",
     "while True:\n  x = 1\n  sync()\nend"),
    ("URS208", "bad-call", "A call the controller cannot make: not a function, nested without "
     "end, or a thread misused.",
     """
A variable called like a function, a function that calls itself without end (the call
stack is bounded), a thread that joins itself, more threads at once than the controller
runs, threads that all wait for each other: the controller stops the program.""",
     "def countdown(n):\n  return countdown(n - 1)\nend\nx = countdown(3)",
     "def countdown(n):\n  if n <= 0:\n    return 0\n  end\n  return countdown(n - 1)\nend\n"
     "x = countdown(3)"),
    ("URS209", "not-simulated", "A builtin that urdsl does not simulate was called.",
     """
Builtins without an offline model (force control, conveyor tracking, some interfaces) do
nothing in a check, return a neutral value and are noted once; with the environment
setting unsupported = "error" such a call stops the run with this error instead.""",
     "force_mode(p[0, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 10, 0, 0, 0], 2, "
     "[0.1, 0.1, 0.15, 0.35, 0.35, 0.35])",
     "# check the force-controlled part on the robot or the URSim simulator"),
)
for _code, _name, _summary, _explanation, _example, _fixed in _RULES:
    register(Rule(_code, _name, "error", _summary, _explanation, _example, _fixed,
                  stage="runtime"))
