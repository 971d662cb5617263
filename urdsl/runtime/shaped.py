"""Values the check computed on a path it chose for a device (implicit flow).

Where a condition depends on a device's reply that is unknown offline, ``urdsl check`` follows
a working device (:mod:`urdsl.runtime.unknown`): it takes one branch and goes on with known
values. Those values are a guess about the cell, not a fact about the program. Seen on a
camera program (SICK PLOC2D URCap, lukasfalk/34764-Pharma): the check's reply had no fields,
so the parser left the part data at the zeros it was initialised with; a reachability test
on a pick pose made of those zeros failed, so the program kept the arm's last pose as its
pick pose, and a move relative to it was "out of reach by 41.5 mm". A real camera sends the
part's place, and the move goes there.

Such values are **shaped** by the device. This module follows them by name (every scope
alike: a name is shaped wherever it is written, which errs towards more shaped values):

* at a decision on an unknown value, or on a condition that reads a shaped name, every name
  that any of the statement's branches assigns is shaped: the branch not taken shapes the
  values it would have changed (a pick pose left as it was) as much as the one taken does.
  In the branch taken, an assignment then goes by the rule below (a constant target set
  there is plain: wherever the device leads here, the target is that);
* an assignment whose value reads a shaped name, or calls a function that returned a shaped
  value, shapes its target; any other assignment of a whole variable, outside a shaped body,
  makes it plain again (an element assignment never does);
* a user function's parameter is shaped when its argument reads a shaped name;
* a motion call (or ``get_inverse_kin``) whose arguments read a shaped name is recorded in
  :attr:`Shaping.moves`: errors about where that move goes are warnings that say why
  (:func:`urdsl.verify.run.device_shaped`).
"""

from __future__ import annotations

from ..script import nodes as n

__all__ = ["MOTION_CALLS", "Shaping", "assigned_in", "reads", "root_name"]

MOTION_CALLS = frozenset({"movej", "movel", "movep", "movec", "servoj", "servoc",
                          "get_inverse_kin"})
"""Calls whose arguments say where the arm goes."""


class Shaping:
    """What the run shaped so far: ``names`` (name -> the device reply's source text),
    ``returned`` (the source of the value the last ``return`` gave, until an assignment or
    a motion call takes it), ``moves`` (span of a motion call -> source)."""

    __slots__ = ("names", "returned", "moves")

    def __init__(self) -> None:
        self.names: dict[str, str] = {}
        self.returned: str | None = None
        self.moves: dict[n.Span, str] = {}

    def source(self, names: frozenset[str]) -> str | None:
        """The source of the first shaped name among ``names``, or None."""
        shaped = self.names
        if not shaped:
            return None
        for name in names:
            found = shaped.get(name)
            if found is not None:
                return found
        return None

    def decide(self, names: frozenset[str], source: str) -> None:
        """A decision on ``source``: the ``names`` its branches assign are shaped."""
        for name in names:
            self.names.setdefault(name, source)

    def assigned(self, name: str | None, source: str | None, whole: bool) -> None:
        """``name`` was given a value shaped by ``source`` (None: a plain value; a ``whole``
        variable, not an element, is then plain again)."""
        if name is None:
            return
        if source is not None:
            self.names[name] = source
        elif whole:
            self.names.pop(name, None)


def reads(node: n.Node | None) -> frozenset[str]:
    """The names ``node`` reads (and the functions it calls, which are never shaped)."""
    if node is None:
        return frozenset()
    return frozenset(x.id for x in n.walk(node) if type(x) is n.Name)


def root_name(target: n.Expr) -> str | None:
    """The variable an assignment target writes: ``x`` for ``x``, ``x[i]`` and ``x.a``."""
    while type(target) in (n.Index, n.Attribute):
        target = target.value  # type: ignore[attr-defined]
    return target.id if type(target) is n.Name else None


def assigned_in(*bodies) -> frozenset[str]:
    """The names the statements of ``bodies`` assign, in nested blocks too (not in the
    functions and threads they define)."""
    found: set[str] = set()
    stack = [item for body in bodies if body for item in body]
    while stack:
        item = stack.pop()
        kind = type(item)
        if kind is n.Assign:
            name = root_name(item.target)
            if name is not None:
                found.add(name)
        elif kind is n.Declare:
            if item.value is not None:
                found.add(item.name)
        elif kind is n.If:
            stack.extend(item.body)
            for branch in item.elifs:
                stack.extend(branch.body)
            if item.orelse:
                stack.extend(item.orelse)
        elif kind is n.While:
            stack.extend(item.body)
    return frozenset(found)
