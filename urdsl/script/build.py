"""Building syntax trees from code: the constructors the DSL and tests use.

These add parentheses (:class:`~urdsl.script.nodes.Paren`) exactly where operator precedence
needs them and write negative numbers as a unary minus, as the parser would read the printed
text back. A tree built only with them satisfies ``parse(format(tree)) == tree``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from .nodes import (
    BINARY_PRECEDENCE,
    PREFIX_PRECEDENCE,
    BinOp,
    Bool,
    Expr,
    List,
    NoneLit,
    Number,
    Paren,
    Pose,
    String,
    UnaryOp,
    precedence,
)

__all__ = ["literal", "binop", "unary", "pose", "list_of"]


def literal(value: object) -> Expr:
    """A literal for a Python value: int, float (finite), bool, str, None, or a list/tuple of
    these (a list; nested lists make a matrix). Negative numbers become a unary minus."""
    if isinstance(value, Expr):
        return value
    if value is None:
        return NoneLit()
    if isinstance(value, bool):
        return Bool(value)
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            raise ValueError(f"URScript has no literal for {value!r}")
        if value < 0 or (value == 0 and math.copysign(1.0, value) < 0):
            return UnaryOp("-", Number(-value))
        return Number(value)
    if hasattr(value, "__float__") and not isinstance(value, str):
        return literal(float(value))  # NumPy scalars
    if isinstance(value, str):
        if '"' in value and "'" in value:
            raise ValueError("a URScript string cannot hold both kinds of quote")
        if "\n" in value or "\r" in value:
            raise ValueError("a URScript string cannot hold a line break")
        return String(value)
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        items = value.tolist() if hasattr(value, "tolist") else value
        return List(tuple(literal(item) for item in items))
    raise TypeError(f"no URScript literal for {type(value).__name__}")


def binop(op: str, left: Expr, right: Expr) -> BinOp:
    """``left op right``, parenthesising an operand that binds looser than ``op`` (and a
    right operand that binds equally, since all operators are left-associative)."""
    strength = BINARY_PRECEDENCE[op]
    if precedence(left) < strength:
        left = Paren(left)
    if precedence(right) <= strength:
        right = Paren(right)
    return BinOp(op, left, right)


def unary(op: str, operand: Expr) -> UnaryOp:
    """``op operand`` for ``-``, ``+``, ``not``, ``!``, parenthesising when needed."""
    if precedence(operand) < PREFIX_PRECEDENCE[op]:
        operand = Paren(operand)
    return UnaryOp(op, operand)


def pose(values: Iterable[object]) -> Pose:
    """A pose literal from six numbers or expressions (metres, radians)."""
    return Pose(tuple(literal(v) for v in values))


def list_of(values: Iterable[object]) -> List:
    """A list literal."""
    return List(tuple(literal(v) for v in values))
