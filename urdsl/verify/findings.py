"""Findings of the verifier: what would go wrong on the robot, and where in the program.

Every code is a rule of the one registry (:data:`urdsl.rules.RULES`; ``urdsl rules`` explains
each): URS2xx runtime errors (:mod:`urdsl.runtime.errors`), the trace checks URS302–URS308
and URS310 (:mod:`urdsl.verify.checks`), and here the findings of the run itself: URS301
(unreachable pose), URS309 (Overlapping Blends), URS311 (threads still running), URS312
(time limit), URS313 (stopped early), URS314 (defines functions but runs none) and URS210
(depends on a value unknown offline).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

from ..rules import RULES, Rule, register
from ..script import nodes as n
from ..script.diagnostics import Diagnostic
from ..script.nodes import NO_SPAN, Span

__all__ = ["Finding", "nothing_runs"]

_NUMBER = re.compile(r"(?<![\w.])(?<!wrist )[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")
"""Numbers in a message (not inside names such as ``Waypoint_1``, nor a wrist's number)."""

_REPEATED = re.compile(r" \(\d+ times(?:, first at t=[-\d.]+ s)?\)$")

@dataclass(frozen=True)
class Finding:
    """One problem, at the statement that caused it. ``time`` is robot time in s.

    ``cause`` tells findings of one rule at one statement apart (the joint, the singularity,
    the colliding pair); None: the message without its numbers does (:meth:`identity`).
    ``count`` is how many times the program ran into it (a statement in a loop); the
    finding is the first of them. ``beyond``: for a target beyond the arm's reach (URS301),
    where it lies and how far out, ``((x, y, z), distance)`` in m. ``slowed``: for a speed
    the controller slows rather than stop (a URS304 or URS306 warning), the factor by which
    the move's fastest joint or TCP exceeds its limit: slowed evenly, the move takes that many
    times as long.
    """

    code: str
    severity: str
    message: str
    span: Span = NO_SPAN
    time: float | None = None
    hint: str | None = None
    cause: str | None = field(default=None, compare=False)
    count: int = field(default=1, compare=False)
    beyond: tuple[tuple[float, float, float], float] | None = field(default=None,
                                                                    compare=False)
    slowed: float | None = field(default=None, compare=False)

    @classmethod
    def of(cls, code: str, message: str, span: Span = NO_SPAN, time: float | None = None,
           hint: str | None = None, cause: str | None = None) -> Finding:
        return cls(code, RULES[code].severity, message, span, time, hint, cause)

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


# ---- the rules of the run itself ----------------------------------------------------------------

_READY = "movej([0, -1.9, 1.9, -1.57, -1.57, 0])"


def _rule(code: str, name: str, severity: str, summary: str, explanation: str, example: str,
          fixed: str) -> None:
    register(Rule(code, name, severity, summary, explanation, example, fixed, stage="check"))


_rule("URS210", "unknown-dependency", "warning",
      "What follows depends on a value from outside that is unknown offline.",
      """
A device's reply (a socket, an XML-RPC call, a gripper), an input or register, an operator's
answer: offline these values are unknown. The check goes on where it can (both ways of an
if, a move to an unknown pose is noted and not checked) and says once, at the statement,
what depends on such a value; the rest of the program is still checked.""",
      'rq = rpc_factory("xmlrpc", "http://127.0.0.1:4242/RPC2")\n'
      "if not rq.activated():\n  halt\nend",
      "# a program that does not depend on the reply: nothing to note\n"
      'rq = rpc_factory("xmlrpc", "http://127.0.0.1:4242/RPC2")')
_rule("URS301", "unreachable-pose", "error",
      "A target pose is out of reach: inverse kinematics find no solution.",
      """
The robot cannot put its TCP (with the active TCP offset) at the pose: it is further than
the arm reaches, too close to the base, or the orientation is impossible there. The
controller stops the program at the move; nothing after it runs. Where the arm started is
unknown (no taught start), a loop of moves relative to it (pose_add of the TCP pose) is
reported once its target is farther from every possible start than the arm reaches.""",
      f"{_READY}\nmovel(p[1.5, 0.2, 0.3, 0, 3.1416, 0])",
      f"{_READY}\nmovel(p[0.5, 0.2, 0.3, 0, 3.1416, 0])")
_rule("URS309", "overlapping-blends", "warning",
      "Overlapping Blends: the blend spheres of two waypoints overlap and the robot skips "
      "the move.",
      """
A blend radius may be at most as large as the distance to the neighbouring waypoints minus
their own radii; when two blend spheres overlap, the controller skips the move in between
and shows "Overlapping Blends" (PolyScope warns, the program goes on). urdsl reports the move
that is skipped.""",
      f"{_READY}\nhome = get_actual_tcp_pose()\n"
      "movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.05)\n"
      "movel(pose_add(home, p[0.1, 0.06, 0, 0, 0, 0]), r=0.05)\nmovel(home)",
      f"{_READY}\nhome = get_actual_tcp_pose()\n"
      "movel(pose_add(home, p[0.1, 0, 0, 0, 0, 0]), r=0.02)\n"
      "movel(pose_add(home, p[0.1, 0.06, 0, 0, 0, 0]), r=0.02)\nmovel(home)")
_rule("URS214", "urcap-node", "info",
      "A URCap program node: only the URCap can generate its code.",
      """
A PolyScope program (.urp) may hold program nodes of URCaps (a gripper's Grip node, a
vision system's Locate node). What such a node runs, only the URCap can write: urdsl
compiles the program without it, says so once per node, and checks the rest with the node
taken as a device (it takes a device's reply time, its results are unknown). In an export
(.script) PolyScope wrote the URCap's code, and urdsl checks that.""",
      "# a .urp with a Robotiq Grip node: urdsl check pick.urp",
      "# export the program from PolyScope (it writes pick.script with the URCap's code)")
_rule("URS311", "threads-still-running", "warning",
      "The program ended while threads were still running.",
      """
When the main program ends the controller stops every thread it started, in whatever state
it is (a gripper half closed, an output still on). Join the threads, or kill them at a
moment of your choosing, before the end.""",
      f"thread beat():\n  while True:\n    sleep(0.5)\n  end\nend\n{_READY}\nt = run beat()",
      f"thread beat():\n  while True:\n    sleep(0.5)\n  end\nend\n{_READY}\nt = run beat()\n"
      "sleep(1)\nkill t")
_rule("URS312", "time-limit", "info",
      "The program was stopped at the time limit, or where its forever loop repeats itself.",
      """
Cell programs often loop forever. When a pass of the main program's forever loop begins in
the state an earlier pass began in (the variables that can change what it does, the arm,
I/O, threads), every later pass repeats those passes: the check has seen them all and stops
there. Otherwise urdsl runs a program for at most --max-time seconds of robot time (3600 by
default), checks what ran until then and says that it stopped it.""",
      "# urdsl check --max-time 20\nwhile True:\n  sleep(1)\nend",
      "# urdsl check --max-time 20\ni = 0\nwhile i < 10:\n  sleep(1)\n  i = i + 1\nend")
_rule("URS313", "check-stopped-early", "warning",
      "The check stopped early: the program waits for ever, or the wall-clock bound was "
      "reached.",
      """
A read with timeout 0 that nothing answers offline (a socket nobody opened, a register no
one writes) waits for ever; the check stops that thread there and says so. Every check also
ends within its wall-clock bound (urdsl check --timeout, 60 s by default): the run stops
where it got to, and the checks left undone are named.""",
      'while True:\n  socket_read_byte_list(1, "g", 0)\nend',
      'socket_open("127.0.0.1", 30000, "g")\nwhile True:\n  socket_read_byte_list(1, "g", 2)\n'
      "end")
_rule("URS314", "nothing-runs", "info",
      "The program defines functions or threads but runs none of them.",
      """
A file whose top level only defines things (functions, threads, globals with plain values)
does nothing when it runs: the check runs no move and finds nothing, which says nothing
about the functions. A file that is a single `def` without parameters (a PolyScope export's
`def Program(): ... end`) is a program: the controller runs that def, and so does the check.
Several defs, or a def that takes parameters, need a call at the top level. A file of
definitions that another program includes is checked with that program (urdsl check finds
it in the project, or name it with --include).""",
      f"def pick():\n  {_READY}\nend\ndef place():\n  {_READY}\nend",
      f"def pick():\n  {_READY}\nend\ndef place():\n  {_READY}\nend\npick()\nplace()")


def nothing_runs(module: n.Module) -> Finding | None:
    """URS314 when running ``module`` runs none of the functions and threads it defines: its
    top level only defines things (a ``global``/``local`` or assignment whose value calls
    nothing counts as a definition), and it is not one program ``def`` without parameters
    nor a ``sec`` alone, which the controller (and :class:`urdsl.runtime.Interpreter`) runs
    as the program."""
    body = [item for item in module.body if isinstance(item, n.Stmt)]
    functions = [item for item in body if isinstance(item, n.FunctionDef)]
    threads = [item for item in body if isinstance(item, n.ThreadDef)]
    secs = [item for item in body if isinstance(item, n.SecDef)]
    others = [item for item in body if not isinstance(item, (n.FunctionDef, n.ThreadDef,
                                                               n.SecDef))]
    if not functions and not threads:
        return None  # nothing defined to run (an empty file, or a sec alone)
    for item in others:
        if not isinstance(item, (n.Declare, n.Assign)) or any(
                isinstance(node, (n.Call, n.Run)) for node in n.walk(item)):
            return None  # something runs
    if not others and len(functions) == 1 and not functions[0].params:
        return None  # the program's def: it runs
    if not others and not functions and secs:
        return None  # the sec runs
    defined = [f"{item.name}()" for item in functions + threads]
    what = "functions" if functions else "threads"
    if functions and threads:
        what = "functions and threads"
    shown = ", ".join(defined[:5]) + (", ..." if len(defined) > 5 else "")
    first = (functions or threads)[0]
    return Finding.of(
        "URS314", f"the program defines {what} ({shown}) but runs none of them, so "
        "none of them was checked", first.span, 0.0,
        f"call the program's entry at the top level (e.g. {first.name}()), or check the "
        "program that includes this file")
