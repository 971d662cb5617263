"""The URScript syntax tree: one frozen dataclass per construct.

The parser builds these nodes from text and the Python DSL builds them from code; the
printer (:mod:`urdsl.script.printer`) is the only code that turns them back into text.

Every node carries a :class:`Span` (``span``), the place in the source it came from. Spans do
not take part in equality, so two trees compare equal when they say the same thing, wherever
they were written. Nodes built by code get :data:`NO_SPAN`.

Comments, blank-line breaks and PolyScope ``$`` labels are items of a block like statements,
so that printing keeps them.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field
from typing import NamedTuple, TypeAlias

__all__ = [
    "Source", "Span", "NO_SPAN", "Node",
    "Expr", "Number", "String", "Bool", "NoneLit", "Opaque", "Name", "Pose", "List", "Paren",
    "UnaryOp", "BinOp", "Keyword", "Call", "Index", "Attribute", "Run",
    "Stmt", "ExprStmt", "Assign", "Declare", "Return", "Halt", "Break", "Continue",
    "EnterCritical", "ExitCritical", "Join", "Kill", "If", "Elif", "While", "Param",
    "FunctionDef", "ThreadDef", "SecDef", "Comment", "Blank", "Marker", "Module",
    "Item", "BINARY_PRECEDENCE", "PREFIX_PRECEDENCE", "ATOM_PRECEDENCE", "precedence",
    "walk", "to_dict", "calls_itself",
]


_LINE_BREAK = re.compile(r"\r\n|\r|\n")


class Source:
    """A source text with its file name; turns character offsets into line and column.

    Lines and columns are 1-based. Columns count characters (not bytes); a tab is one column.
    """

    __slots__ = ("text", "filename", "_line_starts")

    def __init__(self, text: str, filename: str = "<string>") -> None:
        self.text = text
        self.filename = filename
        self._line_starts: list[int] | None = None

    def _starts(self) -> list[int]:
        if self._line_starts is None:
            text = self.text
            if "\r" in text:  # CR-only (old Mac) and mixed line ends count as line breaks too
                starts = [0] + [m.end() for m in _LINE_BREAK.finditer(text)]
            else:
                starts = [0]
                find = text.find
                pos = find("\n")
                while pos >= 0:
                    starts.append(pos + 1)
                    pos = find("\n", pos + 1)
            self._line_starts = starts
        return self._line_starts

    def line_col(self, offset: int) -> tuple[int, int]:
        """(line, column), both 1-based, of a character offset."""
        starts = self._starts()
        index = bisect.bisect_right(starts, offset) - 1
        column = offset - starts[index] + 1
        if index == 0 and offset > 0 and self.text.startswith("\ufeff"):
            column -= 1  # a byte-order mark is no column
        return index + 1, column

    def line_start(self, line: int) -> int:
        """The character offset where a 1-based line begins (the text's end past its last
        line)."""
        starts = self._starts()
        return starts[line - 1] if 1 <= line <= len(starts) else len(self.text)

    def line_text(self, line: int) -> str:
        """The text of a 1-based line, without its line break."""
        starts = self._starts()
        if not 1 <= line <= len(starts):
            return ""
        begin = starts[line - 1]
        end = starts[line] if line < len(starts) else len(self.text)
        return self.text[begin:end].rstrip("\r\n").lstrip("\ufeff")

    def __repr__(self) -> str:
        return f"Source({self.filename!r}, {len(self.text)} chars)"


class Span(NamedTuple):
    """Where a node was written: character offsets ``start``..``end`` (end exclusive) in
    ``source``. ``line``, ``column``, ``end_line`` and ``end_column`` are 1-based."""

    source: Source | None
    start: int
    end: int

    @property
    def line(self) -> int:
        return self.source.line_col(self.start)[0] if self.source else 0

    @property
    def column(self) -> int:
        return self.source.line_col(self.start)[1] if self.source else 0

    @property
    def end_line(self) -> int:
        return self.source.line_col(max(self.end - 1, self.start))[0] if self.source else 0

    @property
    def end_column(self) -> int:
        """Column just past the node's last character."""
        if not self.source:
            return 0
        return self.source.line_col(max(self.end - 1, self.start))[1] + (self.end > self.start)

    @property
    def filename(self) -> str:
        return self.source.filename if self.source else "<generated>"

    def __repr__(self) -> str:
        if self.source is None:
            return "Span(<none>)"
        return f"Span({self.line}:{self.column}-{self.end_line}:{self.end_column})"


NO_SPAN = Span(None, 0, 0)
"""The span of a node that was not parsed from text (built by the DSL or by code)."""

_span = field(default=NO_SPAN, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class Node:
    """Base of every syntax tree node."""


# ---- expressions ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Expr(Node):
    """Base of expressions."""


@dataclass(frozen=True, slots=True)
class Number(Expr):
    """An int or float literal (``42``, ``.5``, ``1e-10``). Never negative: a sign is a
    :class:`UnaryOp`."""

    value: int | float
    span: Span = _span


@dataclass(frozen=True, slots=True)
class String(Expr):
    """A string literal. URScript has no escape sequences: ``value`` is the text between the
    quotes, as written."""

    value: str
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Bool(Expr):
    """``True`` or ``False``."""

    value: bool
    span: Span = _span


@dataclass(frozen=True, slots=True)
class NoneLit(Expr):
    """``None``."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class Opaque(Expr):
    """A value no script text spells: what the checker puts where a definition from another
    file of the project has a value it cannot know when this file runs (never parsed, never
    printed). The interpreter gives an unknown value described by ``source``."""

    source: str
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Name(Expr):
    """A variable, function or thread name."""

    id: str
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Pose(Expr):
    """A pose literal ``p[x, y, z, rx, ry, rz]`` (metres, rotation vector in radians)."""

    items: tuple[Expr, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class List(Expr):
    """A list literal ``[a, b]``; a list of lists is a matrix."""

    items: tuple[Expr, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Paren(Expr):
    """Parentheses written in the source, kept so that printing keeps them."""

    expr: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class UnaryOp(Expr):
    """``-x``, ``+x``, ``not x`` or ``! x``."""

    op: str
    operand: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class BinOp(Expr):
    """``left op right`` for ``or xor and == != < > <= >= + - * / %``."""

    op: str
    left: Expr
    right: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Keyword(Node):
    """A keyword argument ``name=value`` of a call."""

    name: str
    value: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Call(Expr):
    """A call ``func(args, name=value)``; ``func`` is a :class:`Name` or, for a method, an
    :class:`Attribute`. Positional arguments come before keyword arguments."""

    func: Expr
    args: tuple[Expr, ...] = ()
    keywords: tuple[Keyword, ...] = ()
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Index(Expr):
    """``a[i]``, or ``m[i, j]`` for a matrix element (two indices)."""

    value: Expr
    indices: tuple[Expr, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Attribute(Expr):
    """Field or method access ``value.attr``."""

    value: Expr
    attr: str
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Run(Expr):
    """``run thread_name()``: starts a thread and gives its handle."""

    thread: str
    span: Span = _span


# ---- statements ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Stmt(Node):
    """Base of statements."""


@dataclass(frozen=True, slots=True)
class ExprStmt(Stmt):
    """An expression used as a statement (in practice a call, or ``run t()``)."""

    expr: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Assign(Stmt):
    """``target = value``; the target is a :class:`Name`, :class:`Index` or
    :class:`Attribute`."""

    target: Expr
    value: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Declare(Stmt):
    """``global x``, ``local x = value``: ``scope`` is ``"global"`` or ``"local"``."""

    scope: str
    name: str
    value: Expr | None = None
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Return(Stmt):
    """``return`` or ``return value``."""

    value: Expr | None = None
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Halt(Stmt):
    """``halt``: stops the program."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class Break(Stmt):
    """``break``."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class Continue(Stmt):
    """``continue``."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class EnterCritical(Stmt):
    """``enter_critical``."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class ExitCritical(Stmt):
    """``exit_critical``."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class Join(Stmt):
    """``join handle``: waits for a thread."""

    thread: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Kill(Stmt):
    """``kill handle``: stops a thread."""

    thread: Expr
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Elif(Node):
    """One ``elif test:`` branch of an :class:`If`."""

    test: Expr
    body: tuple[Item, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class If(Stmt):
    """``if test: body elif ...: ... else: orelse end``. ``orelse`` is ``None`` when there is
    no ``else`` (an empty tuple is an empty ``else:``)."""

    test: Expr
    body: tuple[Item, ...]
    elifs: tuple[Elif, ...] = ()
    orelse: tuple[Item, ...] | None = None
    span: Span = _span


@dataclass(frozen=True, slots=True)
class While(Stmt):
    """``while test: body end``."""

    test: Expr
    body: tuple[Item, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Param(Node):
    """A function parameter, with its default value if it has one."""

    name: str
    default: Expr | None = None
    span: Span = _span


@dataclass(frozen=True, slots=True)
class FunctionDef(Stmt):
    """``def name(params): body end``; a program is a ``def`` with no parameters."""

    name: str
    params: tuple[Param, ...]
    body: tuple[Item, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class ThreadDef(Stmt):
    """``thread name(): body end`` (threads take no parameters)."""

    name: str
    body: tuple[Item, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class SecDef(Stmt):
    """``sec name(): body end``: a secondary program, run beside the primary one."""

    name: str
    body: tuple[Item, ...]
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Comment(Node):
    """``# text``. ``text`` is everything after the ``#``, as written. ``trailing`` is true
    when the comment followed code on the same line."""

    text: str
    trailing: bool = False
    span: Span = _span


@dataclass(frozen=True, slots=True)
class Blank(Node):
    """One or more empty lines between statements."""

    span: Span = _span


@dataclass(frozen=True, slots=True)
class Marker(Node):
    """A PolyScope program label ``$ 4 "Waypoint_1" "breakAfter"``.

    ``number`` is the program-tree node number, ``text`` the label, ``flag`` the optional
    second string (``"breakAfter"``, ``"noBreak"``); ``quoted`` is false for labels written
    without quotes (older PolyScope). A label that fits none of this keeps its whole text after
    the ``$`` in ``text`` with ``number`` ``None``.
    """

    number: int | None
    text: str
    flag: str | None = None
    quoted: bool = True
    span: Span = _span


Item: TypeAlias = Stmt | Comment | Blank | Marker
"""What a block holds."""


@dataclass(frozen=True, slots=True)
class Module(Node):
    """A whole file: a program (one ``def``) or a snippet of statements and definitions."""

    body: tuple[Item, ...]
    span: Span = _span


# ---- precedence ----------------------------------------------------------------------------

BINARY_PRECEDENCE: dict[str, int] = {
    "or": 1, "xor": 1,
    "and": 2,
    "==": 4, "!=": 4, "<": 4, ">": 4, "<=": 4, ">=": 4,
    "+": 5, "-": 5,
    "*": 6, "/": 6, "%": 6,
}
"""Binding strength of binary operators (higher binds tighter); all are left-associative.
UR does not document precedence; this is the Python-like order the manual's examples imply
(see docs/controller-facts.md §8.2)."""

PREFIX_PRECEDENCE: dict[str, int] = {"not": 3, "!": 3, "-": 7, "+": 7}
"""Binding strength of prefix operators: ``not`` binds looser than comparisons."""

ATOM_PRECEDENCE = 8


def precedence(expr: Expr) -> int:
    """How tightly an expression binds, for deciding where parentheses are needed."""
    if isinstance(expr, BinOp):
        return BINARY_PRECEDENCE[expr.op]
    if isinstance(expr, UnaryOp):
        return PREFIX_PRECEDENCE[expr.op]
    return ATOM_PRECEDENCE


def walk(node: Node):
    """Yield ``node`` and every node below it, depth first, in source order."""
    stack = [node]
    while stack:
        current = stack.pop()
        yield current
        children: list[Node] = []
        for name in current.__dataclass_fields__:  # type: ignore[attr-defined]
            if name == "span":
                continue
            value = getattr(current, name)
            if isinstance(value, Node):
                children.append(value)
            elif isinstance(value, tuple):
                children.extend(v for v in value if isinstance(v, Node))
        stack.extend(reversed(children))


def to_dict(node: Node) -> dict:
    """A JSON-ready dict of a tree: ``{"type": "Call", "span": {...}, <fields>}``. Spans are
    ``{"line", "column", "end_line", "end_column"}`` (1-based), or absent for built nodes.

    Built without recursion (trees are as deep as the program nests); write deep results with
    :func:`dump_json`, which does not recurse either."""
    root: dict = {}
    # work: (node, the dict that receives it, key or list index in that container)
    work: list[tuple[Node, dict | list, str | int]] = [(node, {"": None}, "")]
    first = True
    while work:
        current, container, key = work.pop()
        result: dict = {"type": type(current).__name__}
        if first:
            root, first = result, False
        else:
            container[key] = result  # type: ignore[index]
        span = getattr(current, "span", NO_SPAN)
        if span.source is not None:
            result["span"] = {
                "line": span.line, "column": span.column,
                "end_line": span.end_line, "end_column": span.end_column,
            }
        for name in current.__dataclass_fields__:  # type: ignore[attr-defined]
            if name == "span":
                continue
            value = getattr(current, name)
            if isinstance(value, Node):
                result[name] = None
                work.append((value, result, name))
            elif isinstance(value, tuple):
                items: list = list(value)
                result[name] = items
                for index, item in enumerate(value):
                    if isinstance(item, Node):
                        work.append((item, items, index))
            else:
                result[name] = value
    return root


def dump_json(value, indent: int | None = None) -> str:
    """JSON text of nested dicts, lists, strings, numbers, booleans and None, written with an
    explicit stack (``json.dumps`` recurses once per level and fails on deep syntax trees)."""
    import json

    out: list[str] = []
    write = out.append
    comma = ", " if indent is None else ","  # as json.dumps separates
    # work: (a value to write, or _Text to write as it is; the nesting level)
    work: list = [(value, 0)]
    while work:
        item, level = work.pop()
        if type(item) is _Text:
            write(item)
            continue
        if isinstance(item, dict):
            if not item:
                write("{}")
                continue
            pairs = list(item.items())
            write("{")
            work.append((_Text(_newline(indent, level) + "}"), level))
            for k in range(len(pairs) - 1, -1, -1):
                name, child = pairs[k]
                work.append((child, level + 1))
                head = (comma if k else "") + _newline(indent, level + 1) + json.dumps(name)
                work.append((_Text(head + ": "), level))
        elif isinstance(item, list):
            if not item:
                write("[]")
                continue
            write("[")
            work.append((_Text(_newline(indent, level) + "]"), level))
            for k in range(len(item) - 1, -1, -1):
                work.append((item[k], level + 1))
                work.append((_Text((comma if k else "") + _newline(indent, level + 1)), level))
        else:
            write(json.dumps(item))
    return "".join(out)


class _Text(str):
    """Text that :func:`dump_json` writes as it is."""


def _newline(indent: int | None, level: int) -> str:
    return "" if indent is None else "\n" + " " * (indent * level)


def calls_itself(first: Stmt, second: Stmt) -> bool:
    """Whether ``first`` is a ``def`` without parameters and ``second`` a bare call of it."""
    return (isinstance(first, FunctionDef) and not first.params
            and isinstance(second, ExprStmt) and isinstance(second.expr, Call)
            and isinstance(second.expr.func, Name) and second.expr.func.id == first.name
            and not second.expr.args and not second.expr.keywords)
