"""Moves that a condition stops: PolyScope's Direction node and other "move until" patterns.

PolyScope's Direction node moves the tool along a direction *until* something happens (tool
contact, an expression such as a digital input, or a distance). For the conditions it cannot
know in advance it commands a straight line toward a point far away and stops the arm when
the condition holds. The script PolyScope writes for it (e-Series 5.x, "Until tool contact"
or "Until expression"; seen in public exports) has this shape::

    thread move_thread_3():
      enter_critical
      move_thread_flag_3 = 1
      local towardsPos=calculate_point_to_move_towards(feature, direction, 1000.0)
      movel(towardsPos, a=1.2, v=0.02)
      move_thread_flag_3 = 2
      exit_critical
    end
    move_thread_han_3 = run move_thread_3()
    while (True):
      local stepsToRetract=tool_contact(direction=get_target_tcp_speed())
      if (stepsToRetract > 0):        # or the Until expression
        kill move_thread_han_3
        stopl(3.0)
        ...                          # retract, break
      end
      sync()
    end

``calculate_point_to_move_towards`` returns ``pose_add(get_target_waypoint(), ...)``: the
current target plus the direction times 1000 m. That point is no destination: the arm stops
where the condition fires, and at the latest where the straight line leaves the arm's reach.

:func:`stoppable_moves` finds such moves by their structure, whatever the target expression:
a ``movel``/``movep`` inside a thread that the program kills inside an ``if`` (the Until
test; PolyScope follows the kill with ``stopl``). When such a move aims far beyond the arm's
reach (1.5 times it, :data:`urdsl.motion.planner.FAR_TARGET`) the planner checks it only up
to where it could stop (:meth:`urdsl.motion.planner.MotionPlanner.movel`): the far target is
not reported as URS301/URS302, while everything on the path up to the workspace's edge is
still checked. A stoppable move to a nearer target out of reach (a search past a box wall,
an "Until" on a waypoint) is checked the same way, and its target is a URS210 warning rather
than URS301: whether the arm gets to the workspace's edge depends on the condition
(:meth:`urdsl.motion.planner.MotionPlanner._beyond_reach`). "Until
distance" moves stop at a real, reachable destination and keep being checked to it, unless
the straight line there cannot be followed (it passes a singularity, or the cylinder over
the base that no wrist enters): such a move is cut as a far one is, and a URS210 warning says
how far the arm can follow it (seen: nedlecky/UR ``nut_table_handle``, a Direction of 25 mm
"until distance" or tool contact from a nearly stretched arm). [U] The
exact scripts of other PolyScope versions may differ; any thread killed under a condition
counts. A move stopped by a ``stopl`` from a watcher thread, with no kill, is not recognised
(whether such a ``stopl`` stops another thread's move is not documented).
"""

from __future__ import annotations

from ..script import nodes as n

__all__ = ["stoppable_moves", "STOPPABLE_KINDS"]

STOPPABLE_KINDS = frozenset({"movel", "movep"})
"""Moves that a condition may stop before their target (straight tool lines)."""


def stoppable_moves(module: n.Node) -> frozenset:
    """Spans of the ``movel``/``movep`` calls in ``module`` that a condition may stop: those
    in a thread that the program kills inside an ``if`` (see the module docstring).

    Only statements are visited (kills, thread definitions and ``run`` assignments are
    statements), so that a long toolpath costs one pass over its lines."""
    threads: dict[str, n.ThreadDef] = {}
    handles: dict[str, set[str]] = {}  # handle variable -> threads run into it
    killed: set[str] = set()  # handle variables killed under a condition
    for statement, conditional in _statements(module.body, False):
        if isinstance(statement, n.ThreadDef):
            threads[statement.name] = statement
        elif isinstance(statement, n.Assign):
            if isinstance(statement.value, n.Run) and isinstance(statement.target, n.Name):
                handles.setdefault(statement.target.id, set()).add(statement.value.thread)
        elif isinstance(statement, n.Declare):
            if isinstance(statement.value, n.Run):
                handles.setdefault(statement.name, set()).add(statement.value.thread)
        elif (isinstance(statement, n.Kill) and conditional
              and isinstance(statement.thread, n.Name)):
            killed.add(statement.thread.id)
    stopped = {thread for handle in killed for thread in handles.get(handle, ())}
    spans = set()
    for name in stopped:
        thread = threads.get(name)
        if thread is None:
            continue
        for node in n.walk(thread):
            if (isinstance(node, n.Call) and isinstance(node.func, n.Name)
                    and node.func.id in STOPPABLE_KINDS):
                spans.add(node.span)
    return frozenset(spans)


def _statements(block, conditional: bool):
    """Every statement in ``block`` and the blocks inside it, depth first, each with whether
    it runs only when an ``if`` (or ``elif``/``else``) test holds."""
    for item in block:
        yield item, conditional
        if isinstance(item, n.If):
            yield from _statements(item.body, True)
            for elif_ in item.elifs:
                yield from _statements(elif_.body, True)
            if item.orelse is not None:
                yield from _statements(item.orelse, True)
        elif isinstance(item, (n.While, n.FunctionDef, n.ThreadDef, n.SecDef)):
            yield from _statements(item.body, conditional)
