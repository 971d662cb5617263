"""Values from the outside world that an offline check cannot know, and how they are followed.

When the environment's ``devices`` is ``"unknown"`` (``urdsl check``), everything a program
reads from outside the controller is an :class:`~urdsl.runtime.values.Unknown`:

* socket reads (``socket_read_*``, ``socket_get_var``) and XML-RPC calls (``rpc_factory``
  handles), Modbus signals, fieldbus (Euromap, ``read_port_*``), tool communication,
  conveyor ticks;
* digital and analog inputs (standard, configurable, tool) and the RTDE input registers
  (``read_input_*_register``);
* what the arm's sensors measure of the world: forces (``force``, ``get_tcp_force``), joint
  torques, tool current, temperatures;
* the operator's answers (``request_*_from_primary_client``).

What stays known: the program's own variables, outputs and output registers it wrote itself,
flags, the arm's own state (``get_actual_joint_positions`` and the like come from the
simulated arm), socket replies a caller queued in the environment.

An unknown value flows through expressions (arithmetic, comparisons, ``not``, indexing, string
and list builtins give an unknown value). Where the program decides on one, the checker
follows the path of a *working* device and says so once per statement (a URS210 warning that
names the read and its line), never with an error:

* ``if``/``elif`` on an unknown condition takes the branch unless the branch ends the program
  (``halt``, a ``popup``, a protective stop): an error branch is what a failing device causes;
  in a loop that polls (:func:`polls_devices`: it takes time only in such branches) the
  device reports something for :data:`IDLE_AFTER_PASSES` passes and is then idle, its reads
  at rest (``False``, 0: :func:`idle_truth`), so that a loop that spins while nothing happens
  is found, and one that waits while nothing happens (``if not ready: sleep(1)``) is not;
* ``while`` on an unknown condition runs at most :data:`UNKNOWN_LOOP_PASSES` passes and then
  leaves the loop, as a wait loop does when the device answers;
* a move or a builtin with an unknown argument is not checked (noted once); an unchecked move
  takes :data:`UNCHECKED_MOVE_TIME` of robot time (a servo or speed command one controller
  frame) and leaves the arm where it was; string and maths builtins give an unknown result.

Robot time of device replies (chosen, not measured; a real device may be faster or slower):
:data:`DEVICE_REPLY_TIME` for a reply over a link (a socket read, also with timeout 0, which
waits for the reply; an XML-RPC call; ``socket_get_var``), :data:`OPERATOR_REPLY_TIME` for an
operator's answer to a prompt or a blocking popup.
"""

from __future__ import annotations

import functools
import math
from typing import Any

from ..script import nodes as n
from .values import ListValue, PoseValue, StructValue, Unknown, has_unknown

__all__ = [
    "DEVICE_REPLY_TIME", "IDLE_AFTER_PASSES", "OPERATOR_REPLY_TIME", "UNCHECKED_MOVE_TIME",
    "UNKNOWN_LOOP_PASSES", "polls_devices", "idle_truth",
    "DEVICE_READS", "OPERATOR_PROMPTS", "ends_program", "stops_motion", "unknown_from",
    "describe",
]

DEVICE_REPLY_TIME = 0.1
"""Robot time (s) a device takes to answer a read over a link (socket, XML-RPC)."""

OPERATOR_REPLY_TIME = 10.0
"""Robot time (s) an operator takes to answer a prompt or close a blocking popup."""

UNCHECKED_MOVE_TIME = 1.0
"""Robot time (s) a move to an unknown target is assumed to take (it is not planned)."""

UNKNOWN_LOOP_PASSES = 3
"""Passes a ``while`` loop makes while its condition is unknown before the check leaves it."""

IDLE_AFTER_PASSES = 3
"""Passes of a polling loop (:func:`polls_devices`) during which the check takes the branches
that depend on a device; from the next pass on, the device is idle and they are skipped."""

DEVICE_READS = frozenset({
    "get_standard_digital_in", "get_digital_in", "get_configurable_digital_in",
    "get_tool_digital_in", "get_standard_analog_in", "get_analog_in", "get_tool_analog_in",
    "read_input_integer_register", "read_input_float_register",
    "read_input_boolean_register",
    "socket_read_string", "socket_read_line", "socket_read_ascii_float",
    "socket_read_binary_integer", "socket_read_byte_list", "socket_get_var",
    "modbus_get_signal_status", "modbus_get_error", "modbus_get_time_since_signal_invalid",
    "read_port_bit", "read_port_register", "get_euromap_input",
    "get_conveyor_tick_count", "tool_contact",
    # what the arm's sensors measure of the world: contact forces and what follows from them
    "force", "get_tcp_force", "get_joint_torques", "get_tool_current",
    "get_controller_temp", "get_joint_temp", "get_tool_temp",
})
"""Builtins whose result comes from outside the controller (unknown offline)."""

OPERATOR_PROMPTS = frozenset({
    "request_boolean_from_primary_client", "request_float_from_primary_client",
    "request_integer_from_primary_client", "request_string_from_primary_client",
})
"""Builtins that wait for an operator's answer."""

_ENDING_CALLS = frozenset({"popup", "protective_stop", "powerdown", "halt"})


def describe(name: str, node: Any) -> str:
    """How a read is named in messages: ``"socket_read_byte_list() at line 12"``."""
    line = getattr(getattr(node, "span", None), "line", 0)
    return f"{name}() at line {line}" if line else f"{name}()"


_READS: dict[tuple[str, int], tuple[Any, Unknown]] = {}


def unknown_from(name: str, node: Any) -> Unknown:
    """The unknown result of the read ``name`` at ``node`` (one object per read site: it is
    immutable, and a loop reads the same site at every pass)."""
    key = (name, id(node))
    cached = _READS.get(key)
    if cached is not None and cached[0] is node:
        return cached[1]
    value = Unknown(describe(name, node), getattr(node, "span", None))
    if len(_READS) > 4096:
        _READS.clear()
    _READS[key] = (node, value)
    return value


def stops_motion(body: Any) -> bool:
    """Whether a block stops the arm's motion: it kills a thread or calls ``stopl``/``stopj``
    (outside nested definitions), as PolyScope's Until conditions of a Direction node do."""
    return _holds(body, (n.Kill,), frozenset(("stopl", "stopj")))


def ends_program(body: Any) -> bool:
    """Whether a block ends or stops the program in a way a failing device causes: it holds
    (outside nested definitions) a ``halt``, a ``popup`` or a protective stop."""
    return _holds(body, (n.Halt,), _ENDING_CALLS)


def _holds(body: Any, statements: tuple[type, ...], calls: frozenset[str]) -> bool:
    """Whether a block holds (in its branches and loops, not in nested definitions) one of
    ``statements`` or a call statement of one of ``calls``."""
    stack = list(body or ())
    while stack:
        item = stack.pop()
        if isinstance(item, statements):
            return True
        if isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef)):
            continue
        if isinstance(item, n.ExprStmt):
            call = item.expr
            if (isinstance(call, n.Call) and isinstance(call.func, n.Name)
                    and call.func.id in calls):
                return True
        elif isinstance(item, n.If):
            stack.extend(item.body)
            for branch in item.elifs:
                stack.extend(branch.body)
            stack.extend(item.orelse or ())
        elif isinstance(item, n.While):
            stack.extend(item.body)
    return False


def polls_devices(body: Any) -> bool:
    """Whether a loop body takes physical time only inside the branches of its ``if``
    statements (or in inner loops, which may make no pass): a loop that polls and acts only
    when something is reported. When its tests depend on a device, an idle device (nothing
    to report, the usual state between two events) leaves such a loop running without
    physical time; the check follows a working device for :data:`IDLE_AFTER_PASSES` passes,
    then an idle one, so that such a loop spins and is reported (URS207) as on the robot.
    A call that may take time (a blocking builtin, a function the program defines, a method
    call) outside the branches makes the loop not a polling one."""
    from ..script.builtins import BLOCKING_CALLS, lookup

    branches = False
    for item in body or ():
        if isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef)):
            continue
        if isinstance(item, n.Join):
            return False
        if isinstance(item, n.If):
            branches = True
            tested: list[Any] = [item.test, *(branch.test for branch in item.elifs)]
        elif isinstance(item, n.While):
            tested = [item.test]
        else:
            tested = [item]
        for node in tested:
            for inner in n.walk(node):
                if not isinstance(inner, n.Call):
                    continue
                if not isinstance(inner.func, n.Name):
                    return False  # a method call (XML-RPC) may wait for its reply
                name = inner.func.id
                if name in BLOCKING_CALLS or lookup(name) is None:
                    return False
    return branches


def idle_truth(test: Any) -> bool:
    """Whether the condition ``test`` holds while the devices it reads are idle (a polling
    loop's device after :data:`IDLE_AFTER_PASSES` passes): an idle device reads as at rest,
    ``False`` or 0, so ``not ready`` holds and ``ready``, ``state == 1`` do not; a loop that
    tests ``if reg: ...`` and ``if not reg: sleep(...)`` takes the second while nothing
    happens, as on the controller, and does not spin. Judged from the test's form: ``not``,
    ``and``, ``or``, ``xor`` and parentheses, a comparison with 0 or ``False`` by ``==`` or
    ``!=``; anything else does not hold."""
    kind = type(test)
    if kind is n.Paren:
        return idle_truth(test.expr)
    if kind is n.UnaryOp and test.op in ("not", "!"):
        return not idle_truth(test.operand)
    if kind is n.BinOp:
        if test.op == "and":
            return idle_truth(test.left) and idle_truth(test.right)
        if test.op == "or":
            return idle_truth(test.left) or idle_truth(test.right)
        if test.op == "xor":
            return idle_truth(test.left) != idle_truth(test.right)
        if test.op in ("==", "!="):
            rest = [side for side in (test.left, test.right) if _at_rest(side)]
            if rest:
                return test.op == "=="
    return False


def _at_rest(node: Any) -> bool:
    """Whether ``node`` is the literal 0 or ``False`` (what an idle device reads)."""
    while type(node) is n.Paren:
        node = node.expr
    return (type(node) is n.Number and node.value == 0) or \
        (type(node) is n.Bool and node.value is False)


def first_unknown(values: Any, named: dict | None = None) -> Unknown | None:
    """The first unknown among call arguments (positional list and keyword dict)."""
    for value in values:
        kind = type(value)
        if kind is Unknown:
            return value
        if kind is ListValue or kind is StructValue:
            found = has_unknown(value)
            if found is not None:
                return found
    if named:
        return first_unknown(list(named.values()))
    return None


_PASS_THROUGH = frozenset({
    "textmsg", "popup", "socket_send_string", "socket_send_line", "socket_send_byte",
    "socket_send_int", "socket_set_var",
})
"""Builtins that take an unknown argument as it is (they print or send it)."""

_STORES = frozenset({
    "set_standard_digital_out", "set_digital_out", "set_configurable_digital_out",
    "set_tool_digital_out", "set_flag", "set_standard_analog_out", "set_analog_out",
    "write_output_integer_register", "write_output_float_register",
    "write_output_boolean_register",
})
"""Builtins that store an unknown value where the program reads it back unknown."""


_FRAME_COMMANDS = ("servo", "speed", "direct_torque")
"""Control commands that last one controller frame (a control loop's step)."""


def _is_motion(name: str) -> bool:
    return name.startswith(("move", *_FRAME_COMMANDS)) or name in ("stopj", "stopl")


def unknown_call(rt: Any, name: str, values: list, named: dict, found: Unknown, node: Any,
                 call: Any) -> Any:
    """Call the builtin ``name`` whose arguments hold the unknown value ``found``: a move is
    not planned (noted once, it takes :data:`UNCHECKED_MOVE_TIME`), a procedure is skipped
    (noted once), a function gives an unknown result.

    A pose relative to an unknown start (:class:`~urdsl.runtime.values.Relative`) is
    followed through ``pose_add``/``pose_sub`` with a known pose and checked as a move's
    target (:mod:`urdsl.motion.drift`); everywhere else it is plainly unknown."""
    kind = _kind(name, len(values), tuple(named))
    if kind == "function" and name in _POSE_MATHS:
        shifted = _relative_maths(name, values, named)
        if shifted is not None:
            return shifted
    target = _relative_target(name, values, named) if kind == "motion" else None
    values = [v.plain() if type(v) is Unknown else v for v in values]
    named = {k: v.plain() if type(v) is Unknown else v for k, v in named.items()}
    found = found.plain()
    if kind == "call":
        return call(values, named, node)
    if kind == "store":
        where = values[0] if values else next(iter(named.values()), None)
        if type(where) is not Unknown:
            return call(values, named, node)
        rt.warn_once(f"which output {name}() writes depends on {found.source}, which is "
                     "unknown offline; not checked", node, found)
        return None
    if kind == "motion":
        # a servo or speed command lasts a controller frame; a move is taken as
        # UNCHECKED_MOVE_TIME
        frame = name.startswith(_FRAME_COMMANDS)
        took = f"{rt.config.step_time:g}" if frame else f"{UNCHECKED_MOVE_TIME:g}"
        robot = rt.robot
        why = f"the move at line {node.span.line} to an unknown target"
        # the thread goes on when the move has ended, unless it blends
        settles = not frame and _settles(name, values, named)
        if target is not None and robot is not None:
            problem = robot.relative_move(target, why, node.span, settles, rt.current)
            if problem is not None:
                error = rt.error("ik", problem, node, _DRIFT_HINT)
                error.drift = True  # the verifier's URS301 says it holds whatever the start
                raise error
        rt.warn_once(f"this move depends on {found.source}, which is unknown offline; the "
                     f"move is not checked (taken as {took} s)", node, found)
        if robot is not None:
            robot.stop_blending(rt.time)
            if target is None:
                # where the arm went is unknown until a move to a known target
                still = f"where the move at line {node.span.line} left the arm"
                robot.unknown_position(why, node.span, still if settles else None,
                                       rt.current)
        if frame:
            rt.sync()
        else:
            rt.wait(UNCHECKED_MOVE_TIME)
        return None
    if kind == "sleep":
        rt.warn_once(f"this wait depends on {found.source}, which is unknown offline; taken "
                     "as one controller frame", node, found)
        rt.sync()
        return None
    if kind == "procedure":
        rt.warn_once(f"{name}() depends on {found.source}, which is unknown offline; not "
                     "checked", node, found)
        return None
    if kind == "read":
        # a socket read whose timeout (or socket, or count) is unknown still waits for the
        # device: at least one controller frame (UR's External Control script reads its
        # command socket with a timeout the driver sent, in a loop that has no other wait)
        rt.warn_once(f"{name}() depends on {found.source}, which is unknown offline; its "
                     "wait is taken as one controller frame and its reply is unknown", node, found)
        rt.sync()
        return unknown_from(name, node)
    return found


_POSE_MATHS = {"pose_add": ("p_1", "p_2"), "pose_sub": ("p_to", "p_from")}
"""The pose maths followed for poses relative to an unknown start, with their parameters."""

_DRIFT_HINT = ("a move relative to where the arm is (pose_add(get_target_tcp_pose(), ...)) "
               "adds the same displacement at every pass of a loop; move to a taught waypoint "
               "in the loop, or end the loop")

_TARGETS = {"movej": "q", "movel": "pose", "movep": "pose"}
"""Moves whose target (first argument) may be a pose relative to an unknown start."""


def _arguments(values: list, named: dict, params: tuple[str, ...]) -> list | None:
    """The arguments ``params`` of a call, positional then by name, or None if missing."""
    arguments = list(values[:len(params)])
    for param in params[len(arguments):]:
        if param not in named:
            return None
        arguments.append(named[param])
    return arguments


def _relative_maths(name: str, values: list, named: dict) -> Unknown | None:
    """``pose_add``/``pose_sub`` of a pose relative to an unknown start and a known pose:
    the start plus the known displacement (position ``p_1 + p_2``, ``p_to − p_from``; the
    rotation stays unknown), or None (plainly unknown)."""
    arguments = _arguments(values, named, _POSE_MATHS[name])
    if arguments is None or len(values) + len(named) != 2:
        return None
    first, second = arguments
    if name == "pose_add" and type(first) is PoseValue:
        first, second = second, first  # the positions add up in either order
    if type(first) is not Unknown or first.relative is None or type(second) is not PoseValue:
        return None
    if not all(type(v) in (int, float) and math.isfinite(v) for v in second):
        return None
    shifted = first.relative.shifted(second, -1.0 if name == "pose_sub" else 1.0)
    return Unknown(first.source, first.span, relative=shifted)


def _relative_target(name: str, values: list, named: dict):
    """The :class:`~urdsl.runtime.values.Relative` target of a move, or None."""
    param = _TARGETS.get(name)
    if param is None:
        return None
    target = values[0] if values else named.get(param)
    return target.relative if type(target) is Unknown else None


def _settles(name: str, values: list, named: dict) -> bool:
    """Whether the thread goes on only once the arm has stopped at the move's end: a
    ``movej``/``movel``/``movep`` whose blend radius ``r`` (positional after q, a, v, t) is a
    known 0."""
    if name not in _TARGETS:
        return False
    radius = values[4] if len(values) > 4 else named.get("r", 0)
    return type(radius) in (int, float) and radius == 0


@functools.lru_cache(maxsize=1024)
def _kind(name: str, positional: int, keywords: tuple[str, ...]) -> str:
    """How :func:`unknown_call` treats a call shape: ``call`` (as usual: it takes unknown
    values, or the call is wrong and reports it), ``store``, ``motion``, ``sleep``,
    ``procedure`` (skipped), ``read`` (a socket read: one controller frame, an unknown
    reply) or ``function`` (an unknown result)."""
    from ..script.builtins import lookup

    row = lookup(name)
    if row is None or row.argument_problem(positional, keywords) is not None:
        return "call"  # reports the unknown name or the bad call
    if name in _PASS_THROUGH:
        return "call"
    if name in _STORES:
        return "store"
    if _is_motion(name):
        return "motion"
    if name == "sleep":
        return "sleep"
    if name.startswith("socket_read") or name == "socket_get_var":
        return "read"  # a read over a link waits for the device; an input read does not
    if not row.returns or row.returns[0] == "None":
        return "procedure"
    return "function"
