"""When a ``while True`` loop repeats itself: the state a pass begins in.

A cell program loops forever. The checker used to run such a loop until ``--max-time``
(3600 s of robot time) or its wall-clock bound, checking the same passes over and over. A
program is deterministic offline (a device read is an unknown value followed as a working
device answers, always the same way), so when a pass of the main thread's forever loop
begins in exactly the state the pass before it began in, every later pass does what that
pass did: the check has seen them all and may stop (:attr:`RuntimeConfig.stop_repeating`).

The state compared (:func:`pass_state`): the variables that can change what the program
does (those of the loop's frame and the globals, less the *inert* ones, see
:func:`inert_names`), the arm (where everything planned so far ends, the move still
blending, the TCP and payload, what is unknown of its position), the I/O and registers, and
the threads that run with their wake times relative to now. Numbers compare exactly: a
value that creeps by rounding keeps the loop running as before, never the reverse.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from typing import Any

import numpy as np

from ..script import nodes as n
from ..script.builtins import MOTION_CALLS, lookup
from .environment import SocketModel
from .values import (
    Anchor,
    ListValue,
    PoseValue,
    Relative,
    StructValue,
    ThreadHandle,
    Unknown,
)

__all__ = ["LOGGING_CALLS", "detached_threads", "freeze", "inert_names", "pass_state"]

LOGGING_CALLS = frozenset({"textmsg", "varmsg"})
"""Builtins whose arguments only end up in the log: a variable read there alone does not
change what the program does."""

_FLOWS = frozenset({n.Paren, n.UnaryOp, n.List, n.Pose, n.Number, n.Bool, n.String,
                    n.NoneLit})
_FLOW_OPS = frozenset({"+", "-", "*", "and", "or", "xor", "==", "!=", "<", ">", "<=", ">="})
"""Expressions through which a value flows into an assignment without a way to fail that a
later value could open (a division by what becomes zero, an index past the end, a builtin's
domain): only through these is the assigned name's inertness passed on to what it reads."""

_TIME_DIGITS = 6
"""Times relative to now (s) are compared rounded to a microsecond: the same pass begun at a
later robot time gives the same differences up to rounding."""

FRAME = 0.002
"""The controller's frame in s (500 Hz)."""


def inert_names(module: n.Module) -> frozenset[str]:
    """Names whose value cannot change what the program does: every read of them is in the
    value assigned to an inert name, through arithmetic that cannot fail (``count = count +
    1``, see :data:`_FLOWS`), or in a logging call (:data:`LOGGING_CALLS`). A name read in
    any other call, a division or an index matters. Names are taken by spelling, whatever
    their scope, which errs towards reading a name as one that matters."""
    flows: dict[str, set[str]] = {}  # target name -> names its assigned values read
    matters: set[str] = set()
    assigned: set[str] = set()
    stack: list[tuple[n.Node, str | None]] = [(module, None)]
    while stack:
        node, into = stack.pop()  # into: the name a value being read flows into, if any
        kind = type(node)
        if kind is n.Name:
            if into is None:
                matters.add(node.id)
            elif into != "":
                flows.setdefault(into, set()).add(node.id)
            continue
        if kind is n.Assign:
            target = node.target
            if type(target) is n.Name:
                assigned.add(target.id)
                stack.append((node.value, target.id))
            else:  # a[i] = v, s.m = v: everything read there matters
                stack.append((target, None))
                stack.append((node.value, None))
            continue
        if kind is n.Declare:
            assigned.add(node.name)
            if node.value is not None:
                stack.append((node.value, node.name))
            continue
        if kind is n.Call:
            func = node.func
            if type(func) is n.Name:  # a function's name is not a variable's
                # a logging call's arguments change nothing; any other call may fail on
                # what it is given (a square root, an index) or act on it
                into_args = "" if func.id in LOGGING_CALLS else None
                stack.extend((child, into_args) for child in (*node.args, *node.keywords))
                continue
            into = None
        elif into and not (kind in _FLOWS or (kind is n.BinOp and node.op in _FLOW_OPS)):
            into = None  # a division, an index...: it may fail on a later value
        for name in node.__dataclass_fields__:  # type: ignore[attr-defined]
            if name == "span":
                continue
            value = getattr(node, name)
            if isinstance(value, n.Node):
                stack.append((value, into))
            elif isinstance(value, tuple):
                stack.extend((v, into) for v in value if isinstance(v, n.Node))
    # a name matters when it is read where it matters, or flows into one that does
    todo = list(matters)
    while todo:
        for source in flows.get(todo.pop(), ()):
            if source not in matters:
                matters.add(source)
                todo.append(source)
    return frozenset(assigned - matters)


_IO_PREFIXES = ("set_", "write_", "get_", "read_")

_STOPPING_CALLS = frozenset({"popup", "protective_stop", "powerdown", "halt"})
"""Builtins that stop or pause the whole program: a thread that calls one steers it."""


def _uses(nodes: Any, unknown_reads: frozenset[str] = frozenset()
          ) -> tuple[set[str], set[str], set, set, bool]:
    """What the statements ``nodes`` do with the world outside them: the names they read,
    the names they assign, the I/O they write and read, as (family, address) pairs
    (``("port_register", "128")`` for ``write_port_register(128, v)`` and
    ``read_port_register(128)``, ``("standard_digital_out", "*")`` for an address that is not
    a number), and whether they move the arm, stop the program, call a function of the
    program or start or stop a thread. A read named in ``unknown_reads`` (a device read whose
    value the run does not know, whatever was written) reads nothing the program wrote."""
    reads: set[str] = set()
    writes: set[str] = set()
    io_out: set[tuple[str, str]] = set()
    io_in: set[tuple[str, str]] = set()
    steers = False
    stack = list(nodes)
    while stack:
        node = stack.pop()
        kind = type(node)
        if kind is n.Name:
            reads.add(node.id)
        elif kind is n.Assign and type(node.target) is n.Name:
            writes.add(node.target.id)
            stack.append(node.value)
            continue
        elif kind is n.Declare:
            writes.add(node.name)
        elif kind is n.Call and type(node.func) is n.Name:
            name = node.func.id
            if name in MOTION_CALLS or name in _STOPPING_CALLS:
                steers = True
            elif lookup(name) is None:
                steers = True  # a function of the program: it may do anything
            for prefix in _IO_PREFIXES:
                if name.startswith(prefix) and name not in unknown_reads:
                    first = node.args[0] if node.args else None
                    where = repr(first.value) if type(first) is n.Number else "*"
                    (io_out if prefix in ("set_", "write_") else io_in).add(
                        (name[len(prefix):], where))
            stack.extend(node.args)
            stack.extend(k.value for k in node.keywords)
            continue
        elif kind in (n.Run, n.Kill, n.FunctionDef, n.ThreadDef, n.Halt):
            steers = True
        for name in getattr(node, "__dataclass_fields__", ()):
            if name == "span":
                continue
            value = getattr(node, name)
            if isinstance(value, n.Node):
                stack.append(value)
            elif isinstance(value, tuple):
                stack.extend(v for v in value if isinstance(v, n.Node))
    return reads, writes, io_out, io_in, steers


def detached_threads(module: n.Module,
                     unknown_reads: frozenset[str] = frozenset()) -> frozenset[str]:
    """Threads whose timing cannot change what the rest of the program does, nor the other
    way round: they neither move the arm nor stop the program nor call the program's
    functions nor start or stop threads; no other code reads a variable they assign or an
    I/O family they write, and they read no variable other code assigns (a heartbeat that
    counts to 499 and writes a register each second). When such a thread wakes relative to
    a pass of the main loop does not enter the pass's state; its variables do.
    ``unknown_reads``: device reads whose value the run takes as unknown, whatever the program
    wrote (see :func:`_uses`)."""
    threads = [node for node in n.walk(module) if type(node) is n.ThreadDef]
    if not threads:
        return frozenset()
    detached = set()
    for thread in threads:
        reads, writes, io_out, io_in, steers = _uses(thread.body)
        if steers:
            continue
        rest = _without(module, thread)
        other_reads, _writes, _other_out, other_in, _steers = _uses(rest, unknown_reads)
        # what the program sets once before anything runs (its first-level statements,
        # not those of its loops) is the thread's start value, not an interaction
        _reads, other_writes, _out, _in, _steers = _uses(_nested(rest))
        if (writes & other_reads) or (reads & other_writes) or _meets(io_out, other_in):
            continue
        detached.add(thread.name)
    return frozenset(detached)


def _meets(written: set[tuple[str, str]], read: set[tuple[str, str]]) -> bool:
    """Whether an I/O written may be one read: same family, and the same address or one
    that is not a number."""
    return any(family == other and "*" in (where, there) or (family, where) == (other, there)
               for family, where in written for other, there in read)


def _nested(items: list[n.Node]) -> list[n.Node]:
    """What of ``items`` (top-level statements) runs more than once or later: everything
    but the plain first-level statements of the program (a ``def`` that is the program is
    opened)."""
    out: list[n.Node] = []
    for item in items:
        if type(item) is n.FunctionDef and not item.params and len(items) == 1:
            out.extend(_nested(list(item.body)))
        elif type(item) in (n.Assign, n.Declare, n.ExprStmt):
            continue
        else:
            out.append(item)
    return out


def _without(module: n.Module, thread: n.ThreadDef) -> list[n.Node]:
    """The top-level statements of ``module`` with ``thread``'s definition left out (at any
    depth: the ``def`` that holds it is rebuilt without it)."""
    def strip(node: Any) -> Any:
        if node is thread:
            return None
        if type(node) in (n.FunctionDef, n.Module):
            body = tuple(s for s in (strip(item) for item in node.body) if s is not None)
            return dataclasses.replace(node, body=body)
        return node
    stripped = strip(module)
    return list(stripped.body)


def freeze(value: Any) -> Any:
    """``value`` as a hashable key that two values the program cannot tell apart share."""
    kind = type(value)
    if kind in (float, int, bool, str) or value is None:
        return (kind.__name__, value)
    if kind is PoseValue:
        return ("p", *value)
    if kind is ListValue or kind is list or kind is tuple:
        return ("l", getattr(value, "capacity", None), *(freeze(v) for v in value))
    if kind is dict:
        return ("d", *sorted((str(k), freeze(v)) for k, v in value.items()))
    if kind is StructValue:
        return ("s", *((k, freeze(v)) for k, v in value.members.items()))
    if kind is Unknown:
        return ("?", value.source, value.span, value.lean, freeze(value.relative),
                value.likely)
    if kind is Relative:
        return ("r", id(value.anchor), value.offset, value.moves, value.statements)
    if kind is SocketModel:  # what it sent is a log: only what reads will return counts
        return ("socket", value.host, value.port, value.connected,
                tuple(freeze(v) for v in value.incoming))
    if kind is deque:
        return ("l", None, *(freeze(v) for v in value))
    if kind is ThreadHandle:  # a thread run anew each pass is the same thread
        return ("t", value.thread.name, value.thread.done)
    if kind is Anchor:
        return ("o", id(value))
    if isinstance(value, np.ndarray):
        return ("a", value.shape, value.tobytes())
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return (kind.__name__, value.item())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (kind.__name__, *(freeze(getattr(value, f.name))
                                 for f in dataclasses.fields(value)))
    return ("o", id(value))


def _ahead(when: float, now: float) -> float:
    """How far ``when`` (s of robot time) lies ahead of ``now``, rounded; 0 when past (an
    arm at rest since then is at rest, however long)."""
    return max(0.0, round(when - now, _TIME_DIGITS))


def _frames_ahead(when: float, now: float) -> int:
    """How many controller frames (:data:`FRAME`, 2 ms) ahead of ``now`` a thread wakes: the
    controller runs its threads on frames, so two passes whose threads wake within the same
    frame are the same to it (a ``sync()`` loop's offset inside a frame is urdsl's own)."""
    return max(0, math.ceil(round((when - now) / FRAME, _TIME_DIGITS)))


def _arm(robot: Any, now: float) -> Any:
    """What the planner will do from now on: where everything planned ends, the move still
    running or blending, TCP, payload, what is unknown of the position. None without a
    planner (nothing to compare: no stop)."""
    segments = getattr(robot, "segments", None)
    if segments is None:
        return None
    pending = getattr(robot, "_pending", None)
    unresolved = getattr(robot, "_unresolved", [])
    last = unresolved[-1] if unresolved else (pending if pending is not None else (
        segments[-1] if segments else None))
    end = None if last is None else (
        last.kind, last.pose_end.tobytes(), None if unresolved else last.q_end.tobytes(),
        _ahead(last.end, now), last.radius, freeze(last.params))
    unknown_at = getattr(robot, "unknown_at", None)
    return (end, freeze(robot.q_start) if last is None else None, freeze(robot.tcp),
            robot.payload_mass, freeze(robot.payload_cog),
            None if unknown_at is None else unknown_at[0], repr(getattr(robot, "drift", None)),
            _ahead(getattr(robot, "_free_at", 0.0), now))


_ENVIRONMENT_SKIPPED = frozenset({"messages"})


def _environment(env: Any) -> Any:
    if not dataclasses.is_dataclass(env):
        return ("o", id(env))
    return tuple(freeze(getattr(env, f.name)) for f in dataclasses.fields(env)
                 if f.name not in _ENVIRONMENT_SKIPPED)


def _compared(name: str, value: Any, inert: frozenset[str]) -> bool:
    """Whether a variable is part of the state: it is not inert, or its value is not a
    number (a list or string that grows by ``+`` fails when it outgrows its limit)."""
    return name not in inert or type(value) not in (int, float, bool)


def pass_state(rt: Any, frame: Any, inert: frozenset[str],
               detached: frozenset[str] = frozenset()) -> Any:
    """The state a pass of a loop run in ``frame`` of the interpreter ``rt`` begins in, as a
    hashable key (see the module's docstring); variables named in ``inert`` are left out, and
    when the threads named in ``detached`` (:func:`detached_threads`) wake."""
    arm = _arm(rt.robot, rt.time) if rt.robot is not None else ()
    if arm is None:
        return None
    variables = [] if frame.vars is rt.globals else [
        (k, freeze(v)) for k, v in frame.vars.items() if _compared(k, v, inert)]
    variables.extend((k, freeze(v)) for k, v in rt.globals.items() if _compared(k, v, inert))
    # in the order they were started (which decides ties), not by the count of threads
    # ever started: a thread run anew each pass is the same thread
    threads = tuple((t.name, None if t.name in detached else _frames_ahead(t.wake, rt.time))
                    for t in sorted(rt._threads, key=lambda t: t.order)
                    if not t.done and t is not rt.current)
    return (tuple(sorted(variables, key=lambda item: item[0])), arm,
            _environment(rt.env), threads)
