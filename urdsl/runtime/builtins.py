"""Builtin functions bound to an interpreter: their Python implementations.

Arguments are bound by the builtin catalog (:mod:`urdsl.script.builtins`): its parameter
names, defaults and arity are the contract, so a call with a wrong keyword or too many
arguments fails with the catalog's signature in the message. Each implementation is a
function ``impl(rt, node, **arguments)``.

Motion goes to the interpreter's robot (:mod:`urdsl.motion`), pose maths to
:mod:`urdsl.kinematics`, I/O, registers, sockets and messages to the environment. A catalog
builtin without an implementation here is "not simulated": it returns a neutral value of its
return type and leaves an event (or stops the program, if the environment says so).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from typing import Any

from ..script.binder import Problem
from ..script.builtins import Builtin, lookup
from ..script.builtins import method as lookup_method
from ..script.nodes import Node
from . import motion_builtins  # noqa: F401 - registers motion, robot state and pose maths
from .environment import SocketModel
from .registry import IMPLEMENTATIONS, implements
from .unknown import (
    DEVICE_READS,
    DEVICE_REPLY_TIME,
    OPERATOR_PROMPTS,
    OPERATOR_REPLY_TIME,
    unknown_from,
)
from .values import (
    LIST_LIMIT,
    ListValue,
    PoseValue,
    StructValue,
    Unknown,
    copy_value,
    exceeds,
    format_value,
    is_number,
    type_name,
)

__all__ = ["BuiltinTable", "IMPLEMENTATIONS"]

_NEUTRAL = {"Int": 0, "Float": 0.0, "Number": 0, "Bool": False, "String": "",
            "Array": None, "Pose": None, "None": None}


class BuiltinTable:
    """Calls builtins for one interpreter."""

    def __init__(self, rt: Any) -> None:
        self.rt = rt
        self._prepared: dict[tuple, Any] = {}

    def call(self, name: str, args: list, named: dict, node: Node) -> Any:
        rt = self.rt
        row = lookup(name)
        implementation = IMPLEMENTATIONS.get(name)
        if row is None and implementation is None:
            return rt.not_defined(name, "name", node, _builtin_hint(name))
        if row is not None:
            bound = self.bind(row, args, named, node)
        else:
            bound = dict(named)
            if args:
                bound["__args__"] = args
        if implementation is None:
            return self.unsupported(row, node)
        try:
            return implementation(rt, node, **bound)
        except _PYTHON_FAILURES as error:
            raise _failed(rt, name, node, error) from error

    def prepare(self, name: str, positional: int, keywords: tuple[str, ...]):
        """A faster :meth:`call` for one call site — ``call(values, named, node)`` — when
        ``name`` is a simulated builtin and the site's shape (``positional`` arguments and
        the ``keywords`` names) fits its signature; None otherwise (:meth:`call` then
        reports the problem when the call runs)."""
        key = (name, positional, keywords)
        if key not in self._prepared:  # a long program has few distinct call shapes
            self._prepared[key] = self._prepare(name, positional, keywords)
        return self._prepared[key]

    def _prepare(self, name: str, positional: int, keywords: tuple[str, ...]):
        row = lookup(name)
        implementation = IMPLEMENTATIONS.get(name)
        if row is None or implementation is None or row.variadic_keywords or not row.callable:
            return None
        result = row.bind(positional, keywords)
        if isinstance(result, Problem) or result[0] is not row:
            return None  # call() reports the problem, or renames another row's parameters
        params = result[1].positional
        rt = self.rt

        def call(values: list, named: dict, node: Node) -> Any:
            bound = dict(zip(params, values, strict=True))
            if named:
                bound.update(named)
            try:
                return implementation(rt, node, **bound)
            except _PYTHON_FAILURES as error:
                raise _failed(rt, name, node, error) from error

        return call

    def bind(self, row: Builtin, args: list, named: dict, node: Node) -> dict[str, Any]:
        """The arguments of a call of ``row`` by parameter name, bound by the one call
        binder against every signature row of the builtin; raises the binder's message.
        A call that fits an older signature row (``speedj(qd, a, t_min=...)``) is given
        to the implementation under the current row's names, position by position."""
        rt = self.rt
        if not row.callable:
            raise rt.error("call", f"'{row.name}' is a command of the interpreter socket "
                           "(port 30020), not a function", node,
                           f"send `{row.name}` alone on a line to port 30020")
        result = row.bind(len(args), tuple(named))
        if isinstance(result, Problem):
            raise rt.error("arguments", result.message, node, result.hint)
        if row.variadic_keywords:
            return {"__members__": named}
        used, binding = result
        bound = dict(zip(binding.positional, args, strict=False))
        bound.update(named)
        if used is not row:
            current = [p.name for p in row.params]
            older = [p.name for p in used.params]
            bound = {current[older.index(key)]: value for key, value in bound.items()
                     if older.index(key) < len(current)}
        return bound

    def unsupported(self, row: Builtin, node: Node) -> Any:
        rt = self.rt
        if rt.unknown and (row.name in DEVICE_READS or row.name in OPERATOR_PROMPTS):
            if row.name in OPERATOR_PROMPTS:
                rt.wait(OPERATOR_REPLY_TIME)
            return unknown_from(row.name, node)
        if rt.env.unsupported == "error":
            raise rt.error("unsupported", f"{row.name}() is not simulated by urdsl", node)
        rt.event_once("unsupported", f"{row.name}() is not simulated; it did nothing here",
                      node.span)
        kind = row.returns[0] if row.returns else "None"
        if kind == "Object":  # a handle (an EtherNet/IP writer): its methods are device calls
            return _RemoteHandle(row.name, "")
        if rt.unknown and kind != "None":
            # checking offline: what the controller would return is not known here, and a
            # neutral value (zeros) would be taken for the arm's state or a device's reply
            return unknown_from(row.name, node)
        if kind == "Array":  # nearly all of them return a 6-vector (joints, wrench, speeds)
            return ListValue([0.0] * _ARRAY_LENGTHS.get(row.name, 6))
        if kind == "Pose":
            return PoseValue([0.0] * 6)
        if kind == "Matrix":  # the 6x6 ones: mass matrix, Jacobians
            return ListValue([ListValue([0.0] * 6) for _ in range(6)])
        return _NEUTRAL.get(kind)

    def call_method(self, receiver: Any, method: str, args: list, named: dict,
                    node: Node) -> Any:
        rt = self.rt
        if type(receiver) is ListValue:
            row = None
            if receiver and all(type(item) is ListValue for item in receiver):
                row = lookup_method("matrix", method)  # a matrix is a list of rows
                if row is not None:
                    bound = self.bind(row, args, named, node)
                    return _matrix_method(rt, node, receiver, method, bound)
            row = lookup_method("list", method)
            if row is None:
                raise rt.error("undefined", f"a list has no method '{method}'", node,
                               "lists have " + ", ".join(_LIST_METHODS))
            bound = self.bind(row, args, named, node)
            return _list_method(rt, node, receiver, method, bound)
        if type(receiver) is StructValue:
            row = lookup_method("struct", method)
            if row is None:
                raise rt.error("undefined", f"a struct has no method '{method}'", node,
                               "structs have length and to_string")
            self.bind(row, args, named, node)
            return len(receiver.members) if method == "length" else format_value(receiver)
        if type(receiver) is _RemoteHandle:
            method = receiver.prefix + method
            if rt.unknown:  # a blocking call: the server's reply is unknown offline
                rt.wait(DEVICE_REPLY_TIME)
                return Unknown(f"the {receiver.kind} reply of {method}() at line "
                               f"{node.span.line}", node.span)
            rt.event("rpc", f"{receiver.kind} call {method}() is not simulated; it did "
                     "nothing here", node.span)
            return None
        if type(receiver) is Unknown:
            return receiver.plain()
        raise rt.error("type", f"a {type_name(receiver)} has no method '{method}'", node)


_ARRAY_LENGTHS = {
    # the script manual: "the 3d coordinates of the COG (CoGx, CoGy, CoGz)" and "X, Y, and Z
    # composant of the measured acceleration"; the other array getters give six numbers
    "get_target_payload_cog": 3,
    "get_tool_accelerometer_reading": 3,
}
"""Length of the neutral list a builtin that is not simulated returns, where it is not 6."""


class _RemoteHandle:
    """What ``rpc_factory`` and URCap factories give: calls on it are recorded, not made.
    A member of it (``handle.ModbusServiceWrapper``) is a handle for the server's dotted
    methods (XML-RPC ``ModbusServiceWrapper.readRegisters``); ``prefix`` is that path."""

    __slots__ = ("kind", "url", "prefix")

    def __init__(self, kind: str, url: str, prefix: str = "") -> None:
        self.kind = kind
        self.url = url
        self.prefix = prefix

    def member(self, name: str) -> _RemoteHandle:
        """The handle of the server's methods under ``name.``."""
        return _RemoteHandle(self.kind, self.url, f"{self.prefix}{name}.")


_PYTHON_FAILURES = (TypeError, ValueError, AttributeError, LookupError, ArithmeticError)
"""What a builtin's Python model raises on arguments it was not written for."""


def _failed(rt: Any, name: str, node: Node, error: Exception) -> Exception:
    """The program error for a builtin whose model failed on its arguments (never a Python
    traceback): a URS203 at the call, saying so; an error of urdsl's kinematics passes."""
    from ..kinematics.errors import KinematicsError

    if isinstance(error, KinematicsError):
        return error
    return rt.error("type", f"{name}() cannot take these arguments "
                    f"({type(error).__name__}: {error})", node,
                    f"if they are valid URScript, urdsl's model of {name}() lacks this case: "
                    "please report it")


def _builtin_hint(name: str) -> str | None:
    import difflib

    from ..script.builtins import catalog
    from ..script.urcaps import urcap_hint

    hint = urcap_hint(name)
    if hint is not None:
        return hint
    close = difflib.get_close_matches(name, list(catalog()), n=1)
    return f"did you mean '{close[0]}'?" if close else None


_LIST_METHODS = ("append", "capacity", "clear", "excess_capacity", "extend", "insert",
                 "length", "pop", "remove", "slice", "to_string")
"""The list methods of the manual's "Methods on List" (5.15 and later)."""


def _index(rt: Any, node: Node, value: Any, size: int, what: str) -> int:
    """A whole-number ``value`` in ``0..size`` (a list position), else a program error."""
    whole = type(value) is int or (type(value) is float and value.is_integer())
    if not whole or not 0 <= value <= size:
        raise rt.error("index", f"{what}: index {format_value(value)} is outside 0..{size}",
                       node)
    return int(value)


def _matrix_method(rt: Any, node: Node, rows: ListValue, method: str, bound: dict) -> Any:
    if method == "shape":
        return ListValue([len(rows), len(rows[0])])
    if method == "to_string":
        return format_value(rows)
    if method == "get_row":
        return copy_value(rows[_index(rt, node, bound["index"], len(rows) - 1, "get_row")])
    column = _index(rt, node, bound["index"], len(rows[0]) - 1, "get_column")
    if any(len(row) <= column for row in rows):
        raise rt.error("index", f"get_column: a row has no column {column}", node)
    return ListValue([copy_value(row[column]) for row in rows])


def _list_method(rt: Any, node: Node, items: ListValue, method: str, bound: dict) -> Any:
    if method == "excess_capacity":
        return items.capacity - len(items)
    if method == "extend":
        more = bound["elements"]
        if type(more) is not ListValue:
            raise rt.error("type", f"extend needs a list, not a {type_name(more)}", node)
        if len(items) + len(more) > items.capacity:
            raise rt.error("index", f"extend: the list is full (capacity {items.capacity})",
                           node, "check l.excess_capacity() >= other.length() first")
        items.extend(copy_value(v) for v in more)
        return None
    if method == "remove":
        if not items:
            raise rt.error("index", "remove from an empty list", node)
        del items[_index(rt, node, bound["index"], len(items) - 1, "remove")]
        return None
    if method == "slice":
        end = _index(rt, node, bound["end"], len(items), "slice")
        begin = _index(rt, node, bound["begin"], end, "slice")
        return ListValue([copy_value(v) for v in items[begin:end]])
    if method == "to_string":
        return format_value(items)
    if method == "append":
        if len(items) >= items.capacity:
            raise rt.error("index", f"append: the list is full (capacity {items.capacity})",
                           node, "make a longer list with make_list(length, value, capacity)")
        items.append(bound["value"])
        return None
    if method == "insert":
        if len(items) >= items.capacity:
            raise rt.error("index", f"insert: the list is full (capacity {items.capacity})",
                           node)
        items.insert(int(bound["index"]), bound["value"])
        return None
    if method == "pop":
        if not items:
            raise rt.error("index", "pop from an empty list", node)
        return items.pop()
    if method == "clear":
        items.clear()
        return None
    if method == "length":
        return len(items)
    return items.capacity


# ---- numbers ------------------------------------------------------------------------------


def _number(rt: Any, node: Node, value: Any, what: str = "argument") -> float:
    if is_number(value):
        return value
    raise rt.error("type", f"{what} must be a number, not a {type_name(value)}", node)


def _math1(function: Callable[[float], float], name: str, domain=None):
    def apply(rt, node, **kw):
        value = _number(rt, node, next(iter(kw.values())))
        if domain is not None and not domain(value):
            raise rt.error("arithmetic", f"{name}({format_value(value)}) is undefined", node)
        return function(value)

    return apply


for _name, _function, _domain in [
    ("sin", math.sin, None), ("cos", math.cos, None), ("tan", math.tan, None),
    ("asin", math.asin, lambda x: -1 <= x <= 1), ("acos", math.acos, lambda x: -1 <= x <= 1),
    ("atan", math.atan, None), ("sqrt", math.sqrt, lambda x: x >= 0),
    ("d2r", math.radians, None), ("r2d", math.degrees, None),
]:
    IMPLEMENTATIONS[_name] = _math1(_function, _name, _domain)


@implements("floor")
def _floor(rt, node, f):
    return math.floor(_number(rt, node, f))


@implements("ceil")
def _ceil(rt, node, f):
    return math.ceil(_number(rt, node, f))


@implements("atan2")
def _atan2(rt, node, x, y):
    # UR names the numerator x: atan2(x, y) is the angle of x/y (builtins.tsv remarks).
    return math.atan2(_number(rt, node, x), _number(rt, node, y))


@implements("pow")
def _pow(rt, node, base, exponent):
    base, exponent = _number(rt, node, base), _number(rt, node, exponent)
    try:
        result = math.pow(base, exponent)
    except (ValueError, OverflowError):
        raise rt.error("arithmetic", f"pow({base}, {exponent}) is undefined", node) from None
    return result


@implements("log")
def _log(rt, node, b, f):
    b, f = _number(rt, node, b), _number(rt, node, f)
    if b <= 0 or f <= 0 or b == 1:
        raise rt.error("arithmetic", f"log({b}, {f}) is undefined", node)
    return math.log(f, b)


@implements("norm")
def _norm(rt, node, a):
    if is_number(a):
        return abs(a)
    if type(a) in (ListValue, PoseValue):
        return math.sqrt(sum(_number(rt, node, v) ** 2 for v in a))
    raise rt.error("type", f"norm() needs a number or a list, not a {type_name(a)}", node)


@implements("normalize")
def _normalize(rt, node, v):
    length = _norm(rt, node, v)
    if length == 0:
        raise rt.error("arithmetic", "normalize() of a zero vector", node)
    return ListValue([x / length for x in v])


@implements("random")
def _random(rt, node):
    return random.random()


@implements("to_num")
def _to_num(rt, node, str):  # noqa: A002 - the catalog's parameter name
    text = str.strip()
    try:
        return int(text, 0) if text.lower().startswith(("0x", "0b", "0o")) else int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            raise rt.error("type", f"to_num({text!r}): not a number", node) from None


# ---- strings ------------------------------------------------------------------------------

# str_cat/to_str results are limited to 1023 characters (docs/controller-facts.md §8.1)
_STRING_LIMIT = 1023


def _limited(rt, node, text: str) -> str:
    if len(text.encode("utf-8")) > _STRING_LIMIT:
        raise rt.error("arithmetic", f"string longer than {_STRING_LIMIT} bytes", node)
    return text


@implements("to_str")
def _to_str(rt, node, val):
    return _limited(rt, node, format_value(val))


@implements("str_cat")
def _str_cat(rt, node, op1, op2):
    return _limited(rt, node, format_value(op1) + format_value(op2))


@implements("str_len")
def _str_len(rt, node, str):  # noqa: A002
    return len(str.encode("utf-8"))


@implements("str_empty")
def _str_empty(rt, node, str):  # noqa: A002
    return len(str) == 0


@implements("str_at")
def _str_at(rt, node, src, index):
    if not 0 <= index < len(src):
        raise rt.error("index", f"str_at: index {index} is out of range", node)
    return src[index]


@implements("str_sub")
def _str_sub(rt, node, src, index, len=None):  # noqa: A002
    if not 0 <= index <= builtins_len(src):
        raise rt.error("index", f"str_sub: index {index} is out of range", node)
    return src[index:] if len is None else src[index:index + len]


builtins_len = len


@implements("str_find")
def _str_find(rt, node, src, target, start_from=0):
    return src.find(target, start_from)


# ---- lists and matrices --------------------------------------------------------------------


@implements("get_list_length", "length")
def _length(rt, node, **kw):
    """Elements of a list, characters of a string, members of a struct.

    The manual documents lists and strings. A struct is read by position like a list
    (``s[1]``) and assigns to a list; real programs on 5.14 call ``length(s)`` on one (its
    member count) in production, so urdsl accepts it [U: not in UR's documentation].
    """
    value = next(iter(kw.values()))
    if type(value) in (ListValue, str):
        return len(value)
    if type(value) is StructValue:
        return len(value.members)
    raise rt.error("type", f"length of a {type_name(value)}", node)


@implements("size")
def _size(rt, node, v):
    if type(v) is ListValue and v and type(v[0]) is ListValue:
        return ListValue([len(v), len(v[0])])
    if type(v) in (ListValue, str, PoseValue):
        return len(v)
    raise rt.error("type", f"size of a {type_name(v)}", node)


@implements("make_list")
def _make_list(rt, node, length, initial_value, capacity=None):
    capacity = length if capacity is None else capacity
    for name, value in (("length", length), ("capacity", capacity)):
        whole = type(value) is int or (type(value) is float and value.is_integer())
        if not whole or value < 0:
            raise rt.error("type", f"make_list: the {name} must be a whole number >= 0, got "
                           f"{value!r}", node)
    length, capacity = int(length), int(capacity)
    if capacity < length:
        raise rt.error("index", "make_list: capacity is smaller than length", node)
    if not is_number(capacity) or capacity > LIST_LIMIT:
        raise rt.error("index", f"make_list: a capacity of more than {LIST_LIMIT:,} values",
                       node)
    return ListValue([initial_value] * length, capacity)


@implements("inv")
def _inv(rt, node, m):
    """The inverse of a square non-singular matrix, or of a pose (as ``pose_inv``: URScript's
    ``inv`` accepts a pose too)."""
    if type(m) is PoseValue:
        from ..kinematics import pose as posemath

        return PoseValue(list(map(float, posemath.pose_inv(list(m)))))
    rows = _matrix_rows(rt, node, m, "inv")
    if len(rows) != len(rows[0]):
        raise rt.error("type", f"inv() needs a square matrix, got {len(rows)}x{len(rows[0])}",
                       node)
    import numpy as np

    matrix = np.array(rows, dtype=float)
    if abs(np.linalg.det(matrix)) < 1e-300 or np.linalg.cond(matrix) > 1e15:
        raise rt.error("arithmetic", "inv() of a singular matrix", node)
    return ListValue([ListValue(list(map(float, row))) for row in np.linalg.inv(matrix)])


def _matrix_rows(rt, node, m, name: str) -> list[list[float]]:
    if (type(m) is not ListValue or not m or not all(type(r) is ListValue for r in m)
            or len({len(r) for r in m}) != 1 or not all(is_number(v) for r in m for v in r)):
        raise rt.error("type", f"{name}() needs a matrix of numbers, not a {type_name(m)}",
                       node)
    return [[float(v) for v in row] for row in m]


@implements("transpose")
def _transpose(rt, node, m):
    if type(m) is not ListValue:
        raise rt.error("type", f"transpose of a {type_name(m)}", node)
    if m and type(m[0]) is ListValue:
        return ListValue([ListValue(list(column)) for column in zip(*m, strict=True)])
    return ListValue([ListValue([v]) for v in m])


@implements("binary_list_to_integer")
def _binary_list_to_integer(rt, node, l):  # noqa: E741 - the catalog's parameter name
    if type(l) is not ListValue:
        raise rt.error("type", f"binary_list_to_integer takes a list of bools, not {l!r}", node)
    if len(l) > 32:
        raise rt.error("index", "binary_list_to_integer takes at most 32 bools", node)
    return sum(1 << i for i, bit in enumerate(l) if bit)


@implements("integer_to_binary_list")
def _integer_to_binary_list(rt, node, x):
    if isinstance(x, float) and x.is_integer():
        x = int(x)  # a whole number read as a float (a register, a list of replies)
    if isinstance(x, bool) or not isinstance(x, int):
        raise rt.error("type", f"integer_to_binary_list takes an integer, not {x!r}", node)
    return ListValue([bool((x >> i) & 1) for i in range(32)])


@implements("struct")
def _struct(rt, node, __members__):
    value = StructValue(__members__)
    if exceeds(value, LIST_LIMIT):
        raise rt.error("index", f"a struct holding more than {LIST_LIMIT:,} values", node)
    return value


# ---- messages, time --------------------------------------------------------------------------


@implements("textmsg")
def _textmsg(rt, node, s1, s2=""):
    text = format_value(s1) + format_value(s2)
    rt.message("textmsg", text)
    rt.event("textmsg", text, node.span)


@implements("popup")
def _popup(rt, node, s, title="Popup", warning=False, error=False, blocking=False):
    text = format_value(s)
    rt.message("popup", text)
    rt.event("popup", f"{title}: {text}", node.span)
    if blocking is True and rt.unknown:  # the program waits for the operator
        rt.wait(OPERATOR_REPLY_TIME)


@implements("sleep")
def _sleep(rt, node, t):
    seconds = _number(rt, node, t, "sleep time")
    if seconds < 0:
        raise rt.error("arithmetic", "sleep() with a negative time", node)
    if rt.robot is not None:
        rt.robot.stop_blending(rt.time)
    rt.wait(seconds)


@implements("sync")
def _sync(rt, node):
    rt.sync()


@implements("get_steptime")
def _get_steptime(rt, node):
    return rt.config.step_time


# ---- I/O and registers ---------------------------------------------------------------------


def _io_index(rt, node, n, size: int, what: str) -> int:
    if type(n) is not int or not 0 <= n < size:
        raise rt.error("index", f"{what} {n} does not exist (0..{size - 1})", node)
    return n


def _setter(attribute: str, what: str, convert=bool):
    def apply(rt, node, n, b):
        bank = getattr(rt.env, attribute)
        bank[_io_index(rt, node, n, len(bank), what)] = b if type(b) is Unknown else convert(b)

    return apply


def _getter(attribute: str, what: str, name: str | None = None):
    """A read of an I/O bank; ``name`` is given for inputs, which come from outside (unknown
    when the environment's devices are)."""
    def apply(rt, node, n=None, address=None):
        bank = getattr(rt.env, attribute)
        index = n if address is None else address
        value = bank[_io_index(rt, node, index, len(bank), what)]
        if name is not None and rt.unknown:
            return unknown_from(name, node)
        return value

    return apply


def _with_tool(name: str, standard: str, tool: str, what: str, setter: bool = False):
    """The old combined builtins (``get_digital_in``, ``set_digital_out``,
    ``get_digital_out``: 0..9; ``get_analog_in``: 0..3): the standard bank first, then the
    tool's (digital 8 and 9 are tool 0 and 1; analog 2 and 3 are tool 0 and 1), as the script
    manual documents them on CB3 and e-Series."""
    function = IMPLEMENTATIONS[name]
    on_tool = (_setter(tool, what) if setter
               else _getter(tool, what, name if name in DEVICE_READS else None))

    def apply(rt, node, n, *rest, **kw):
        size = len(getattr(rt.env, standard))
        last = size + len(getattr(rt.env, tool)) - 1
        if type(n) is int and size <= n <= last:
            return on_tool(rt, node, n - size, *rest, **kw)
        if type(n) is int and n > last:
            raise rt.error("index", f"{what} {n} does not exist (0..{last}; {size}.."
                           f"{last} are the tool's)", node)
        return function(rt, node, n, *rest, **kw)

    return apply


for _names, _attribute, _what in [
    (("set_standard_digital_out", "set_digital_out"), "standard_digital_out", "digital output"),
    (("set_configurable_digital_out",), "configurable_digital_out", "configurable output"),
    (("set_tool_digital_out",), "tool_digital_out", "tool output"),
    (("set_flag",), "flags", "flag"),
]:
    for _n in _names:
        IMPLEMENTATIONS[_n] = _setter(_attribute, _what)

for _names, _attribute, _what in [
    (("get_standard_digital_in", "get_digital_in"), "standard_digital_in", "digital input"),
    (("get_standard_digital_out", "get_digital_out"), "standard_digital_out", "digital output"),
    (("get_configurable_digital_in",), "configurable_digital_in", "configurable input"),
    (("get_configurable_digital_out",), "configurable_digital_out", "configurable output"),
    (("get_tool_digital_in",), "tool_digital_in", "tool input"),
    (("get_tool_digital_out",), "tool_digital_out", "tool output"),
    (("get_standard_analog_in", "get_analog_in"), "standard_analog_in", "analog input"),
    (("get_tool_analog_in",), "tool_analog_in", "tool analog input"),
    (("get_flag",), "flags", "flag"),
    (("read_input_integer_register",), "input_int_registers", "register"),
    (("read_output_integer_register",), "output_int_registers", "register"),
    (("read_input_float_register",), "input_float_registers", "register"),
    (("read_output_float_register",), "output_float_registers", "register"),
    (("read_input_boolean_register",), "input_bool_registers", "register"),
    (("read_output_boolean_register",), "output_bool_registers", "register"),
]:
    for _n in _names:
        IMPLEMENTATIONS[_n] = _getter(_attribute, _what, _n if _n in DEVICE_READS else None)


def _register_writer(attribute: str, convert):
    def apply(rt, node, address, value):
        bank = getattr(rt.env, attribute)
        bank[_io_index(rt, node, address, len(bank), "register")] = \
            value if type(value) is Unknown else convert(value)

    return apply


for _name, _standard, _tool, _what in [
    ("set_digital_out", "standard_digital_out", "tool_digital_out", "digital output"),
    ("get_digital_out", "standard_digital_out", "tool_digital_out", "digital output"),
    ("get_digital_in", "standard_digital_in", "tool_digital_in", "digital input"),
    ("get_analog_in", "standard_analog_in", "tool_analog_in", "analog input"),
]:
    IMPLEMENTATIONS[_name] = _with_tool(_name, _standard, _tool, _what,
                                        setter=_name.startswith("set_"))

IMPLEMENTATIONS["write_output_integer_register"] = _register_writer("output_int_registers", int)
IMPLEMENTATIONS["write_output_float_register"] = _register_writer("output_float_registers",
                                                                  float)
IMPLEMENTATIONS["write_output_boolean_register"] = _register_writer("output_bool_registers",
                                                                    bool)


@implements("set_standard_analog_out", "set_analog_out")
def _set_analog_out(rt, node, n, f):
    rt.env.standard_analog_out[_io_index(rt, node, n, 2, "analog output")] = \
        f if type(f) is Unknown else float(f)


# ---- sockets (modelled; nothing leaves the machine) -----------------------------------------


@implements("socket_open")
def _socket_open(rt, node, address, port, socket_name="socket_0"):
    allowed = rt.env.connectable
    ok = allowed is None or address in allowed or f"{address}:{port}" in allowed
    model = SocketModel(address, int(port), connected=ok)
    model.incoming.extend(rt.env.socket_replies.get(socket_name, []))
    rt.env.sockets[socket_name] = model
    rt.event("socket", f"socket_open({address}, {port}) -> {ok} (modelled)", node.span)
    return ok


def _socket(rt, node, name: str):
    model = rt.env.sockets.get(name)
    if model is None and rt.unknown and rt.env.foreign_sockets:
        # opened by code the script does not hold (a URCap's installation code, seen:
        # Vention's MachineMotion1 in project 6): a device that answers, unknown offline
        model = rt.env.sockets[name] = SocketModel("", 0)
    if model is None or not model.connected:
        return None
    return model


@implements("socket_close")
def _socket_close(rt, node, socket_name="socket_0"):
    rt.env.sockets.pop(socket_name, None)


@implements("socket_send_string", "socket_send_line", "socket_send_byte", "socket_send_int")
def _socket_send(rt, node, **kw):
    name = kw.get("socket_name", "socket_0")
    model = _socket(rt, node, name)
    if model is None:
        return False
    value = next(iter(v for k, v in kw.items() if k != "socket_name"))
    model.sent.append(value)
    return True


SOCKET_READ_MAX = 30
"""Most values one ``socket_read_ascii_float``/``_binary_integer``/``_byte_list`` call
reads (documented for the first two; [U] for the byte list)."""


def _no_reply(rt, node, name: str, socket_name: Any, timeout: Any, model: Any) -> Any:
    """A socket read that nothing has answered (yet): the environment's queued replies are
    used up. With unknown devices, an open socket's device answers after
    DEVICE_REPLY_TIME (or the timeout, if shorter) with an unknown reply. Otherwise the read
    waits out its timeout and gives None; timeout 0 means "wait for ever"."""
    seconds = _number(rt, node, timeout, "timeout")
    if rt.unknown and model is not None:
        rt.wait(DEVICE_REPLY_TIME if seconds <= 0 else min(seconds, DEVICE_REPLY_TIME))
        return unknown_from(name, node)
    if seconds <= 0:
        why = (f"socket '{socket_name}' is not open" if model is None
               else f"nothing answers on socket '{socket_name}'")
        rt.wait_forever(f"{name}() with timeout 0 waits for ever ({why}): on the robot the "
                        "program stops here until data arrives", node)
    else:
        rt.wait(float(seconds))
    return None


@implements("socket_read_string", "socket_read_line")
def _socket_read_string(rt, node, socket_name="socket_0", timeout=2, **_):
    model = _socket(rt, node, socket_name)
    if model is None or not model.incoming:
        reply = _no_reply(rt, node, node_name(node, "socket_read_string"), socket_name,
                          timeout, model)
        return "" if reply is None else reply
    return str(model.incoming.popleft())


@implements("socket_read_ascii_float", "socket_read_binary_integer", "socket_read_byte_list")
def _socket_read_numbers(rt, node, number, socket_name="socket_0", timeout=2, **_):
    model = _socket(rt, node, socket_name)
    if model is None or not model.incoming:
        reply = _no_reply(rt, node, node_name(node, "socket_read_byte_list"), socket_name,
                          timeout, model)
        if reply is None:
            return ListValue([0])  # [0]: "nothing read"
        if type(number) is int and 0 < number <= SOCKET_READ_MAX and type(reply) is Unknown:
            # a working device sends what was asked for: the count (item 0) leans to it (a
            # Robotiq preamble checks the count before it reads the values); a loop that
            # drains a buffer while the count is not 0 still ends after a few passes
            count = Unknown(reply.source, reply.span, likely=number)
            return ListValue([count, *([reply] * number)])
        return reply
    values = model.incoming.popleft()
    return ListValue([len(values), *values])


def node_name(node: Node, default: str) -> str:
    """The name of the builtin a call node calls (for messages)."""
    func = getattr(node, "func", None)
    return getattr(func, "id", default)


@implements("socket_get_var")
def _socket_get_var(rt, node, name, socket_name="socket_0"):
    if rt.unknown and _socket(rt, node, socket_name) is not None:
        rt.wait(DEVICE_REPLY_TIME)  # the device answers the GET
        return unknown_from("socket_get_var", node)
    return 0


@implements("socket_set_var")
def _socket_set_var(rt, node, name, value, socket_name="socket_0"):
    return None


@implements("rpc_factory")
def _rpc_factory(rt, node, type, url):  # noqa: A002
    rt.event("rpc", f"rpc_factory({type!r}, {url!r}): calls are recorded, not made", node.span)
    return _RemoteHandle(str(type), str(url))

