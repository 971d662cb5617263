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
still checked; a stoppable move to a waypoint just out of reach is still an error. "Until
distance" moves stop at a real, reachable destination and keep being checked to it. [U] The
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
    in a thread that the program kills inside an ``if`` (see the module docstring)."""
    threads: dict[str, n.ThreadDef] = {}
    handles: dict[str, set[str]] = {}  # handle variable -> threads run into it
    killed: set[str] = set()  # handle variables killed under a condition
    for node in n.walk(module):
        if isinstance(node, n.ThreadDef):
            threads[node.name] = node
        elif isinstance(node, (n.Assign, n.Declare)):
            value = node.value
            target = node.target if isinstance(node, n.Assign) else n.Name(node.name)
            if isinstance(value, n.Run) and isinstance(target, n.Name):
                handles.setdefault(target.id, set()).add(value.thread)
        elif isinstance(node, (n.If, n.Elif)):
            for inner in _blocks(node):
                for item in inner:
                    for below in n.walk(item):
                        if isinstance(below, n.Kill) and isinstance(below.thread, n.Name):
                            killed.add(below.thread.id)
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


def _blocks(node: n.If | n.Elif):
    """The statement blocks an ``if`` (or ``elif``) runs when its test holds."""
    yield node.body
    if isinstance(node, n.If):
        yield from (elif_.body for elif_ in node.elifs)
        if node.orelse is not None:
            yield node.orelse
