"""URScript's binary operators on runtime values.

Numbers follow the usual rules (an int and a float give a float); ``+`` also joins two
strings (real programs do this though only ``str_cat`` is documented). Lists combine
element-wise with an equal-length list or with a number; ``matrix * matrix`` and
``matrix * list`` are matrix products (docs/controller-facts.md §8.4).

Each operation raises TypeError (or ValueError) for values it cannot combine (or a string
longer than :data:`STRING_LIMIT` bytes) and
ZeroDivisionError for a division by zero; the interpreter turns these into messages that name
the line. ``int / int`` gives a float (true division) and ``%`` takes the sign of the
divisor, as in Python: the controller does not document either [U].
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from typing import Any

from .values import ListValue, is_number

__all__ = ["binary", "STRING_LIMIT"]

STRING_LIMIT = 1023
"""Bytes a string may hold: the controller's limit for ``str_cat``/``to_str`` results
(docs/controller-facts.md §8.1), applied to ``+`` of strings as well [U]."""


def _is_matrix(value: Any) -> bool:
    return type(value) is ListValue and bool(value) and type(value[0]) is ListValue


def _elementwise(function: Callable[[Any, Any], Any], a: Any, b: Any) -> ListValue:
    list_a, list_b = type(a) is ListValue, type(b) is ListValue
    if list_a and list_b:
        if len(a) != len(b):
            raise ValueError(f"lengths {len(a)} and {len(b)} differ")
        return ListValue([_combine(function, x, y) for x, y in zip(a, b, strict=True)])
    if list_a and is_number(b):
        return ListValue([_combine(function, x, b) for x in a])
    if list_b and is_number(a):
        return ListValue([_combine(function, a, y) for y in b])
    raise TypeError("")


def _combine(function: Callable[[Any, Any], Any], a: Any, b: Any) -> Any:
    if is_number(a) and is_number(b):
        return function(a, b)
    return _elementwise(function, a, b)


def _arithmetic(function: Callable[[Any, Any], Any], strings: bool = False):
    def apply(a: Any, b: Any) -> Any:
        kind_a, kind_b = type(a), type(b)
        if (kind_a is int or kind_a is float) and (kind_b is int or kind_b is float):
            return function(a, b)
        if strings and kind_a is str and kind_b is str:
            joined = a + b
            if len(joined) > 255 and len(joined.encode("utf-8")) > STRING_LIMIT:
                raise ValueError(f"the string would be longer than {STRING_LIMIT} bytes")
            return joined
        return _elementwise(function, a, b)

    return apply


def _matmul(a: ListValue, b: ListValue) -> ListValue:
    columns = len(a[0])
    if _is_matrix(b):
        if len(b) != columns:
            raise ValueError(f"a {len(a)}x{columns} and a {len(b)}x{len(b[0])} matrix")
        return ListValue([
            ListValue([sum(row[k] * b[k][j] for k in range(columns)) for j in range(len(b[0]))])
            for row in a
        ])
    if len(b) != columns:
        raise ValueError(f"a {len(a)}x{columns} matrix and a list of {len(b)}")
    return ListValue([sum(x * y for x, y in zip(row, b, strict=True)) for row in a])


_multiply_elements = _arithmetic(operator.mul)


def _multiply(a: Any, b: Any) -> Any:
    if _is_matrix(a) and type(b) is ListValue:
        return _matmul(a, b)
    return _multiply_elements(a, b)


def _compare(function: Callable[[Any, Any], bool]):
    def apply(a: Any, b: Any) -> bool:
        if is_number(a) and is_number(b):
            return function(a, b)
        if type(a) is str and type(b) is str:
            return function(a, b)
        raise TypeError("")

    return apply


def _equal(a: Any, b: Any) -> bool:
    if (type(a) is bool) != (type(b) is bool):
        return False
    return a == b


def _xor(a: Any, b: Any) -> bool:
    if type(a) is bool and type(b) is bool:
        return a != b
    raise TypeError("")


_OPERATIONS: dict[str, Callable[[Any, Any], Any]] = {
    "+": _arithmetic(operator.add, strings=True),
    "-": _arithmetic(operator.sub),
    "*": _multiply,
    "/": _arithmetic(operator.truediv),
    "%": _arithmetic(operator.mod),
    "<": _compare(operator.lt),
    ">": _compare(operator.gt),
    "<=": _compare(operator.le),
    ">=": _compare(operator.ge),
    "==": _equal,
    "!=": lambda a, b: not _equal(a, b),
    "xor": _xor,
}


def binary(op: str) -> Callable[[Any, Any], Any]:
    """The function for a binary operator (``and``/``or`` short-circuit in the
    interpreter and are not here)."""
    return _OPERATIONS[op]
