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
    "format_value", "is_number", "Unknown", "Anchor", "Relative", "has_unknown", "exceeds",
    "LIST_LIMIT",
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


class Anchor:
    """A place the arm stood still at while the checker did not know where: the TCP point
    (with the TCP then active) at that moment, unknown offline but fixed.

    ``where`` says which moment, for messages ("where the arm stood when the program
    started"); ``tcp_length`` (m) is the length of the TCP offset the point was read with
    (the point lies at most that far from the flange's origin). Compared by identity.
    """

    __slots__ = ("where", "tcp_length")

    def __init__(self, where: str, tcp_length: float) -> None:
        self.where = where
        self.tcp_length = tcp_length

    def __repr__(self) -> str:
        return f"<anchor: {self.where}>"


class Relative:
    """What is known of a pose whose position is an :class:`Anchor`'s point plus a known
    displacement, its rotation unknown: ``pose_add(get_target_tcp_pose(), d)`` while the
    arm stands where the checker does not know.

    ``offset``: the displacement (x, y, z) in m, in the Base frame; ``moves``: how many moves
    to such poses took the arm from the anchor to where this pose was read (0: it was read at
    the anchor); ``statements``: the spans of those moves. Immutable.
    """

    __slots__ = ("anchor", "offset", "moves", "statements")

    def __init__(self, anchor: Anchor, offset: tuple[float, float, float], moves: int = 0,
                 statements: frozenset = frozenset()) -> None:
        self.anchor = anchor
        self.offset = (float(offset[0]), float(offset[1]), float(offset[2]))
        self.moves = moves
        self.statements = statements

    def shifted(self, by: Any, sign: float = 1.0) -> Relative:
        """This pose moved by ``sign`` times the position (first three numbers) of ``by``."""
        return Relative(self.anchor, tuple(o + sign * float(b) for o, b in
                                           zip(self.offset, by[:3], strict=True)),
                        self.moves, self.statements)

    def __repr__(self) -> str:
        x, y, z = self.offset
        return f"<{self.anchor.where} + [{x:.4g}, {y:.4g}, {z:.4g}] m>"


class Unknown:
    """A value the program read from the outside world, which the checker cannot know.

    ``source`` says where it came from, for messages ("the reply of socket_read_byte_list()
    at line 12"); ``span`` is that read's place in the program. Operations on an unknown
    value give an unknown value (the first one's source is kept); immutable.

    ``lean``: for a condition, the truth a working device would give, when there is one: a
    reply compared with ``==`` to what the program expects is taken as equal (True), with
    ``!=`` as not different (False); ``not`` flips it; None: no lean.

    ``likely``: for a number, what a working device gives (the count of values a socket
    read asked for): a comparison of it with a number leans the way that value compares;
    a loop on it still ends after a few passes (a device's buffer runs dry).

    ``relative``: for a pose read of the arm while its position is unknown, what is known of
    it (a :class:`Relative`: an unknown start plus a known displacement), else None. Only
    ``pose_add``/``pose_sub`` and the moves read it; every other operation gives
    :meth:`plain` (an element of such a pose, a pose made from its elements, ... is simply
    unknown).
    """

    __slots__ = ("source", "span", "lean", "relative", "likely")

    def __init__(self, source: str, span: Any = None, lean: bool | None = None,
                 relative: Relative | None = None, likely: float | None = None) -> None:
        self.source = source
        self.span = span
        self.lean = lean
        self.relative = relative
        self.likely = likely

    def leaning(self, lean: bool | None) -> Unknown:
        """The same unknown value with another lean (and no :attr:`relative`, no
        :attr:`likely`)."""
        if lean is self.lean and self.relative is None and self.likely is None:
            return self
        return Unknown(self.source, self.span, lean)

    def plain(self) -> Unknown:
        """This value without :attr:`relative` and :attr:`likely`: what an operation on it
        gives."""
        if self.relative is None and self.likely is None:
            return self
        return Unknown(self.source, self.span, self.lean)

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
