"""Values of DSL programs: joint vectors, poses, angle helpers, and URScript expressions.

Units are SI and radians: ``Joints`` in rad (``Joints.deg`` converts), ``Pose`` positions in m
and orientation as a rotation vector in rad. Python operators on an :class:`Expr` build
URScript expressions (``x + 1``, ``x < 3``); Python's ``and``/``or``/``not`` cannot be
overloaded, so ``&``, ``|``, ``^`` and ``~`` stand for URScript's ``and``, ``or``, ``xor`` and
``not`` (mind Python's precedence: write ``(a < 1) & (b > 2)``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np

from ..kinematics import pose as posemath
from ..script import build
from ..script import nodes as n
from .errors import DslError

__all__ = ["Joints", "Pose", "Expr", "deg", "rad", "to_node", "And", "Or", "Not"]


def deg(*degrees: float) -> float | tuple[float, ...]:
    """Degrees to radians: ``deg(90)`` → 1.5707…, ``deg(0, -90)`` → a tuple."""
    values = tuple(math.radians(float(d)) for d in degrees)
    return values[0] if len(values) == 1 else values


def rad(*radians: float) -> float | tuple[float, ...]:
    """Radians to degrees (for messages and printing)."""
    values = tuple(math.degrees(float(r)) for r in radians)
    return values[0] if len(values) == 1 else values


def _finite(values: Iterable, what: str, count: int) -> tuple[float, ...]:
    try:
        numbers = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise DslError(f"{what} must be {count} numbers") from None
    if len(numbers) != count:
        raise DslError(f"{what} needs {count} values, got {len(numbers)}",
                       "a joint vector is (base, shoulder, elbow, wrist1, wrist2, wrist3) in "
                       "rad" if count == 6 and what.startswith("Joints") else None)
    if not all(math.isfinite(v) for v in numbers):
        raise DslError(f"{what} contains a value that is not finite: {numbers}")
    return numbers


class Joints(tuple):
    """Six joint angles in rad: base, shoulder, elbow, wrist 1, wrist 2, wrist 3."""

    __slots__ = ()

    def __new__(cls, *values: float) -> Joints:
        if len(values) == 1 and isinstance(values[0], (Sequence, np.ndarray)):
            values = tuple(values[0])
        numbers = _finite(values, "Joints", 6)
        big = [v for v in numbers if abs(v) > 2 * math.pi + 1e-9]
        if big:
            raise DslError(f"Joints({', '.join(f'{v:g}' for v in numbers)}): {big[0]:g} rad is "
                           "more than a full turn — these look like degrees",
                           "write Joints.deg(...) for degrees")
        return tuple.__new__(cls, numbers)

    @classmethod
    def deg(cls, *degrees: float) -> Joints:
        """Six joint angles given in degrees."""
        if len(degrees) == 1 and isinstance(degrees[0], (Sequence, np.ndarray)):
            degrees = tuple(degrees[0])
        return cls(*(math.radians(v) for v in _finite(degrees, "Joints.deg", 6)))

    @property
    def degrees(self) -> tuple[float, ...]:
        return tuple(math.degrees(v) for v in self)

    def node(self) -> n.Expr:
        return build.list_of(_tidy(self))

    def __repr__(self) -> str:
        return f"Joints({', '.join(f'{v:.6g}' for v in self)})"


class Pose(tuple):
    """A pose ``p[x, y, z, rx, ry, rz]``: position in m, rotation vector in rad, in the
    robot's Base frame (or relative to another pose, for ``pose_trans``)."""

    __slots__ = ()

    def __new__(cls, x: float, y: float, z: float, rx: float = 0.0, ry: float = 0.0,
                rz: float = 0.0) -> Pose:
        return tuple.__new__(cls, _finite((x, y, z, rx, ry, rz), "Pose", 6))

    @classmethod
    def from_rpy(cls, x: float, y: float, z: float, roll: float, pitch: float,
                 yaw: float) -> Pose:
        """A pose from roll, pitch, yaw in rad (``R = Rz(yaw)·Ry(pitch)·Rx(roll)``, as
        URScript's ``rpy2rotvec``)."""
        return cls(x, y, z, *posemath.rpy2rotvec([roll, pitch, yaw]))

    @classmethod
    def from_matrix(cls, matrix) -> Pose:
        """A pose from a 4x4 homogeneous transform (m)."""
        matrix = np.asarray(matrix, dtype=float)
        if matrix.shape != (4, 4):
            raise DslError(f"Pose.from_matrix needs a 4x4 matrix, got shape {matrix.shape}")
        return cls(*posemath.from_matrix(matrix))

    @property
    def matrix(self) -> np.ndarray:
        """The 4x4 homogeneous transform (m)."""
        return posemath.to_matrix(np.array(self))

    @property
    def rpy(self) -> tuple[float, float, float]:
        return tuple(float(v) for v in posemath.rotvec2rpy(np.array(self[3:])))

    def __matmul__(self, other: Pose) -> Pose:
        """``a @ b`` is URScript's ``pose_trans(a, b)``."""
        if not isinstance(other, Pose):
            return NotImplemented
        return Pose(*posemath.pose_trans(np.array(self), np.array(other)))

    def inv(self) -> Pose:
        """URScript's ``pose_inv``."""
        return Pose(*posemath.pose_inv(np.array(self)))

    def node(self) -> n.Expr:
        return build.pose(_tidy(self))

    def __repr__(self) -> str:
        return f"Pose({', '.join(f'{v:.6g}' for v in self)})"


def _tidy(values: tuple[float, ...]) -> list[float | int]:
    """Whole numbers print as integers (``0`` rather than ``0.0``); the value is the same."""
    return [int(v) if v.is_integer() and abs(v) < 1e15 else v for v in values]


def to_node(value: object) -> n.Expr:
    """A tree expression for a DSL value, a Python literal or an :class:`Expr`."""
    if isinstance(value, Expr):
        return value.node
    if isinstance(value, (Joints, Pose)):
        return value.node()
    if isinstance(value, (list, tuple)) and any(isinstance(v, Expr) for v in value):
        return n.List(tuple(to_node(v) for v in value))
    try:
        return build.literal(value)
    except (TypeError, ValueError) as error:
        raise DslError(f"cannot write {value!r} in URScript: {error}") from None


def _wrap(node: n.Expr) -> Expr:
    return Expr(node)


class Expr:
    """A URScript expression. Arithmetic, comparisons, ``&``/``|``/``^``/``~`` (and, or, xor,
    not), indexing ``e[i]`` and ``e.field("name")`` build bigger expressions."""

    __slots__ = ("node",)
    __hash__ = object.__hash__

    def __init__(self, node: n.Expr) -> None:
        self.node = node

    def _binary(self, op: str, other: object, reflected: bool = False) -> Expr:
        left, right = self.node, to_node(other)
        if reflected:
            left, right = right, left
        return _wrap(build.binop(op, left, right))

    def __add__(self, other): return self._binary("+", other)
    def __radd__(self, other): return self._binary("+", other, True)
    def __sub__(self, other): return self._binary("-", other)
    def __rsub__(self, other): return self._binary("-", other, True)
    def __mul__(self, other): return self._binary("*", other)
    def __rmul__(self, other): return self._binary("*", other, True)
    def __truediv__(self, other): return self._binary("/", other)
    def __rtruediv__(self, other): return self._binary("/", other, True)
    def __mod__(self, other): return self._binary("%", other)
    def __rmod__(self, other): return self._binary("%", other, True)
    def __eq__(self, other): return self._binary("==", other)  # type: ignore[override]
    def __ne__(self, other): return self._binary("!=", other)  # type: ignore[override]
    def __lt__(self, other): return self._binary("<", other)
    def __le__(self, other): return self._binary("<=", other)
    def __gt__(self, other): return self._binary(">", other)
    def __ge__(self, other): return self._binary(">=", other)
    def __and__(self, other): return self._binary("and", other)
    def __rand__(self, other): return self._binary("and", other, True)
    def __or__(self, other): return self._binary("or", other)
    def __ror__(self, other): return self._binary("or", other, True)
    def __xor__(self, other): return self._binary("xor", other)
    def __rxor__(self, other): return self._binary("xor", other, True)
    def __neg__(self): return _wrap(build.unary("-", self.node))
    def __pos__(self): return self
    def __invert__(self): return _wrap(build.unary("not", self.node))

    def __getitem__(self, index) -> Expr:
        indices = index if isinstance(index, tuple) else (index,)
        target = self.node
        if not isinstance(target, (n.Name, n.Index, n.Attribute, n.Call, n.Paren)):
            target = n.Paren(target)
        return _wrap(n.Index(target, tuple(to_node(i) for i in indices)))

    def field(self, name: str) -> Expr:
        """A struct's member ``e.name``."""
        return _wrap(n.Attribute(self.node, name))

    def __bool__(self) -> bool:
        raise DslError("a URScript expression has no Python truth value",
                       "use program.if_(condition) / program.while_(condition), and & | ~ "
                       "instead of and, or, not")

    def __repr__(self) -> str:
        from ..script.printer import format_expr

        return f"Expr({format_expr(self.node)})"


def And(*operands: object) -> Expr:  # noqa: N802 - reads like the operator it builds
    """``a and b and ...``."""
    return _fold("and", operands)


def Or(*operands: object) -> Expr:  # noqa: N802
    """``a or b or ...``."""
    return _fold("or", operands)


def Not(operand: object) -> Expr:  # noqa: N802
    """``not a``."""
    return _wrap(build.unary("not", to_node(operand)))


def _fold(op: str, operands: tuple) -> Expr:
    if not operands:
        raise DslError(f"{op} needs at least one operand")
    result = to_node(operands[0])
    for operand in operands[1:]:
        result = build.binop(op, result, to_node(operand))
    return _wrap(result)
