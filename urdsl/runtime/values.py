"""URScript values in Python.

========== =============================================================
URScript   Python
========== =============================================================
int        ``int`` (not bool)
float      ``float``
bool       ``bool``
string     ``str``
none       ``None``
pose       :class:`PoseValue` (a tuple of 6 floats: metres, rotation vector in rad)
list       :class:`ListValue` (a list with a capacity)
matrix     :class:`ListValue` of equal-length :class:`ListValue` rows
struct     :class:`StructValue`
thread     :class:`ThreadHandle`
(unknown)  :class:`Unknown`: a value read from the outside world that the
           checker cannot know (a device's reply, an input, an operator's
           answer); see :mod:`urdsl.runtime.unknown`
========== =============================================================

URScript passes and assigns values *by value*: :func:`copy_value` makes the copy that an
assignment or a call needs (lists and structs; other values are immutable).
"""

from __future__ import annotations

import math
from typing import Any

__all__ = [
    "PoseValue", "ListValue", "StructValue", "ThreadHandle", "copy_value", "type_name",
    "format_value", "is_number", "Unknown", "has_unknown", "exceeds", "LIST_LIMIT",
]

LIST_LIMIT = 1_000_000
"""Values (list items, matrix cells, struct members, counted through nesting) one value may
hold. The controller documents no maximum [U]; this bounds the checker's memory."""


class PoseValue(tuple):
    """A pose ``p[x, y, z, rx, ry, rz]``: position in metres, rotation vector in radians."""

    __slots__ = ()

    def __new__(cls, values) -> PoseValue:
        items = tuple(float(v) for v in values)
        if len(items) != 6:
            raise ValueError(f"a pose has 6 values, not {len(items)}")
        return tuple.__new__(cls, items)

    def replace(self, index: int, value: float) -> PoseValue:
        items = list(self)
        items[index] = float(value)
        return PoseValue(items)


class ListValue(list):
    """A URScript list (or matrix row list). ``capacity`` is how long it may grow."""

    __slots__ = ("capacity",)

    def __init__(self, items=(), capacity: int | None = None) -> None:
        super().__init__(items)
        self.capacity = len(self) if capacity is None else capacity

    def copy_value(self) -> ListValue:
        return ListValue([copy_value(v) for v in self], self.capacity)


class StructValue:
    """``struct(a=1, b=2)``: named members, fixed after creation; also indexable by position."""

    __slots__ = ("members",)

    def __init__(self, members: dict[str, Any]) -> None:
        self.members = dict(members)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, StructValue) and self.members == other.members

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={format_value(v)}" for k, v in self.members.items())
        return f"struct({inner})"


class ThreadHandle:
    """What ``run t()`` gives: a handle to join or kill the thread."""

    __slots__ = ("thread",)

    def __init__(self, thread: Any) -> None:
        self.thread = thread

    def __repr__(self) -> str:
        return f"<thread {self.thread.name}>"


class Unknown:
    """A value the program read from the outside world, which the checker cannot know.

    ``source`` says where it came from, for messages ("the reply of socket_read_byte_list()
    at line 12"); ``span`` is that read's place in the program. Operations on an unknown
    value give an unknown value (the first one's source is kept); immutable.

    ``lean``: for a condition, the truth a working device would give, when there is one: a
    reply compared with ``==`` to what the program expects is taken as equal (True), with
    ``!=`` as not different (False); ``not`` flips it; None: no lean.
    """

    __slots__ = ("source", "span", "lean")

    def __init__(self, source: str, span: Any = None, lean: bool | None = None) -> None:
        self.source = source
        self.span = span
        self.lean = lean

    def leaning(self, lean: bool | None) -> Unknown:
        """The same unknown value with another lean."""
        return self if lean is self.lean else Unknown(self.source, self.span, lean)

    def __repr__(self) -> str:
        return f"<unknown: {self.source}>"


def has_unknown(value: Any) -> Unknown | None:
    """The first :class:`Unknown` in ``value`` (itself, or inside a list, matrix or struct),
    or None."""
    kind = type(value)
    if kind is Unknown:
        return value
    if kind is ListValue:
        for item in value:
            item_kind = type(item)
            if item_kind is Unknown:
                return item
            if item_kind is ListValue or item_kind is StructValue:
                found = has_unknown(item)
                if found is not None:
                    return found
        return None
    if kind is StructValue:
        for item in value.members.values():
            found = has_unknown(item)
            if found is not None:
                return found
    return None


def exceeds(value: Any, limit: int) -> bool:
    """Whether ``value`` holds more than ``limit`` values, counted through nested lists and
    structs (stops counting once past the limit)."""
    count = 0
    stack = [value]
    while stack:
        item = stack.pop()
        kind = type(item)
        if kind is ListValue:
            count += len(item)
            stack.extend(v for v in item if type(v) is ListValue or type(v) is StructValue)
        elif kind is StructValue:
            count += len(item.members)
            stack.extend(item.members.values())
        if count > limit:
            return True
    return False


def is_number(value: Any) -> bool:
    kind = type(value)
    return kind is int or kind is float


def copy_value(value: Any) -> Any:
    """The copy an assignment or a call makes (URScript has value semantics)."""
    kind = type(value)
    if kind is ListValue:
        return value.copy_value()
    if kind is StructValue:
        return StructValue({k: copy_value(v) for k, v in value.members.items()})
    return value


def type_name(value: Any) -> str:
    """The URScript name of a value's type, for messages."""
    kind = type(value)
    if kind is bool:
        return "bool"
    if kind is int:
        return "int"
    if kind is float:
        return "float"
    if kind is str:
        return "string"
    if value is None:
        return "none"
    if kind is PoseValue:
        return "pose"
    if kind is ListValue:
        return "matrix" if value and type(value[0]) is ListValue else "list"
    if kind is StructValue:
        return "struct"
    if kind is ThreadHandle:
        return "thread"
    if kind is Unknown:
        return "unknown value"
    return kind.__name__


def _format_float(value: float) -> str:
    # The controller prints floats with 6 decimals, trailing zeros removed.
    if math.isinf(value) or math.isnan(value):
        return str(value)
    text = f"{value:.6f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def format_value(value: Any) -> str:
    """A value as ``to_str``/``textmsg`` show it."""
    kind = type(value)
    if kind is bool:
        return "True" if value else "False"
    if kind is float:
        return _format_float(value)
    if kind is str:
        return value
    if value is None:
        return "None"
    if kind is PoseValue:
        return "p[" + ", ".join(_format_float(v) for v in value) + "]"
    if kind is ListValue:
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    if kind is Unknown:
        return "?"
    return repr(value)
