"""The printer: the only code in urdsl that writes URScript text.

``fmt``, ``compile`` and ``send`` all go through :func:`format`. The output is canonical:
one statement per line, blocks indented by ``indent`` (two spaces by default), top-level
``def``/``sec`` and their ``end`` in column 0, one space around binary operators and after
commas, numbers in their shortest form that reads back to the same value, and a final line
break. Comments, blank-line breaks and ``$`` labels are printed where the tree has them.

The printer adds no parentheses: a parsed tree has :class:`~urdsl.script.nodes.Paren` nodes
where the text had them, and trees built by code use :func:`urdsl.script.build.binop` and
friends, which add them where precedence needs them. So ``parse(format(tree)) == tree``.
"""

from __future__ import annotations

import math

from .nodes import (
    Assign,
    Attribute,
    BinOp,
    Blank,
    Bool,
    Break,
    Call,
    Comment,
    Continue,
    Declare,
    EnterCritical,
    ExitCritical,
    Expr,
    ExprStmt,
    FunctionDef,
    Halt,
    If,
    Index,
    Join,
    Keyword,
    Kill,
    List,
    Marker,
    Module,
    Name,
    Node,
    NoneLit,
    Number,
    Paren,
    Pose,
    Return,
    Run,
    SecDef,
    String,
    ThreadDef,
    UnaryOp,
    While,
)

__all__ = ["Printer", "format", "format_expr", "format_number"]


def format_number(value: int | float) -> str:
    """A number as URScript text: ints as digits, floats in the shortest form that reads
    back to the same float (``0.5``, ``1e-10``; never ``1e+20``, always with a ``.`` or an
    exponent so that a float stays a float)."""
    if isinstance(value, bool):
        raise TypeError("a bool is not a number literal")
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        raise ValueError(f"URScript has no literal for {value!r}")
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}e{int(exponent)}"
    return text


class Printer:
    """Turns syntax trees into canonical URScript text (see the module docstring)."""

    def __init__(self, indent: str = "  ") -> None:
        self.indent = indent

    # -- entry points ------------------------------------------------------------------------

    def module(self, module: Module) -> str:
        lines: list[str] = []
        self._block(module.body, 0, lines)
        return "\n".join(lines) + "\n" if lines else ""

    def statement(self, node: Node, depth: int = 0) -> str:
        """One statement (or comment, label, definition) and what it holds, without a final
        line break."""
        lines: list[str] = []
        self._block((node,), depth, lines)
        return "\n".join(lines)

    # -- blocks ------------------------------------------------------------------------------

    def _block(self, items: tuple, depth: int, lines: list[str]) -> None:
        pad = self.indent * depth
        # Whether the last line written is code that a trailing comment may follow.
        for item in items:
            kind = type(item)
            if kind is Comment:
                if item.trailing and lines and self._code_line(lines[-1]):
                    lines[-1] += "  #" + item.text
                else:
                    lines.append(pad + "#" + item.text)
            elif kind is Blank:
                if lines and lines[-1] != "":
                    lines.append("")
            elif kind is Marker:
                lines.append(pad + self._marker(item))
            else:
                method = _STATEMENTS.get(kind)
                if method is None:
                    raise TypeError(f"cannot print {kind.__name__} as a statement")
                method(self, item, depth, pad, lines)

    @staticmethod
    def _code_line(line: str) -> bool:
        stripped = line.lstrip()
        return bool(stripped) and not stripped.startswith(("#", "$"))

    @staticmethod
    def _marker(node: Marker) -> str:
        if node.number is None:
            return f"$ {node.text}"
        if not node.quoted:
            return f"$ {node.number} {node.text}".rstrip()
        text = f'$ {node.number} "{node.text}"'
        if node.flag is not None:
            text += f' "{node.flag}"'
        return text

    # -- statements --------------------------------------------------------------------------

    def _simple(self, node: Node, depth: int, pad: str, lines: list[str]) -> None:
        lines.append(pad + self._simple_text(node))

    def _simple_text(self, node: Node) -> str:
        kind = type(node)
        if kind is ExprStmt:
            return self.expr(node.expr)
        if kind is Assign:
            return f"{self.expr(node.target)} = {self.expr(node.value)}"
        if kind is Declare:
            if node.value is None:
                return f"{node.scope} {node.name}"
            return f"{node.scope} {node.name} = {self.expr(node.value)}"
        if kind is Return:
            return "return" if node.value is None else f"return {self.expr(node.value)}"
        if kind is Join:
            return f"join {self.expr(node.thread)}"
        if kind is Kill:
            return f"kill {self.expr(node.thread)}"
        return _KEYWORD_STATEMENTS[kind]

    def _if(self, node: If, depth: int, pad: str, lines: list[str]) -> None:
        lines.append(f"{pad}if {self.expr(node.test)}:")
        self._block(node.body, depth + 1, lines)
        for branch in node.elifs:
            lines.append(f"{pad}elif {self.expr(branch.test)}:")
            self._block(branch.body, depth + 1, lines)
        if node.orelse is not None:
            lines.append(f"{pad}else:")
            self._block(node.orelse, depth + 1, lines)
        lines.append(f"{pad}end")

    def _while(self, node: While, depth: int, pad: str, lines: list[str]) -> None:
        lines.append(f"{pad}while {self.expr(node.test)}:")
        self._block(node.body, depth + 1, lines)
        lines.append(f"{pad}end")

    def _function(self, node: FunctionDef, depth: int, pad: str, lines: list[str]) -> None:
        params = ", ".join(
            p.name if p.default is None else f"{p.name}={self.expr(p.default)}"
            for p in node.params
        )
        lines.append(f"{pad}def {node.name}({params}):")
        self._block(node.body, depth + 1, lines)
        lines.append(f"{pad}end")

    def _thread(self, node: ThreadDef, depth: int, pad: str, lines: list[str]) -> None:
        lines.append(f"{pad}thread {node.name}():")
        self._block(node.body, depth + 1, lines)
        lines.append(f"{pad}end")

    def _sec(self, node: SecDef, depth: int, pad: str, lines: list[str]) -> None:
        lines.append(f"{pad}sec {node.name}():")
        self._block(node.body, depth + 1, lines)
        lines.append(f"{pad}end")

    # -- expressions -------------------------------------------------------------------------

    def expr(self, node: Expr) -> str:
        """The text of one expression."""
        method = _EXPRESSIONS.get(type(node))
        if method is None:
            raise TypeError(f"cannot print {type(node).__name__} as an expression")
        return method(self, node)

    def _number(self, node: Number) -> str:
        return format_number(node.value)

    def _string(self, node: String) -> str:
        if '"' not in node.value:
            return f'"{node.value}"'
        if "'" not in node.value:
            return f"'{node.value}'"
        raise ValueError("a URScript string cannot hold both kinds of quote")

    def _bool(self, node: Bool) -> str:
        return "True" if node.value else "False"

    def _none(self, node: NoneLit) -> str:
        return "None"

    def _name(self, node: Name) -> str:
        return node.id

    def _items(self, items: tuple) -> str:
        return ", ".join([self.expr(item) for item in items])

    def _pose(self, node: Pose) -> str:
        return f"p[{self._items(node.items)}]"

    def _list(self, node: List) -> str:
        return f"[{self._items(node.items)}]"

    def _paren(self, node: Paren) -> str:
        return f"({self.expr(node.expr)})"

    def _unary(self, node: UnaryOp) -> str:
        if node.op == "not":
            return f"not {self.expr(node.operand)}"
        return node.op + self.expr(node.operand)

    def _binop(self, node: BinOp) -> str:
        return f"{self.expr(node.left)} {node.op} {self.expr(node.right)}"

    def _call(self, node: Call) -> str:
        args = [self.expr(arg) for arg in node.args]
        args += [self._keyword(k) for k in node.keywords]
        return f"{self.expr(node.func)}({', '.join(args)})"

    def _keyword(self, node: Keyword) -> str:
        return f"{node.name}={self.expr(node.value)}"

    def _index(self, node: Index) -> str:
        return f"{self.expr(node.value)}[{self._items(node.indices)}]"

    def _attribute(self, node: Attribute) -> str:
        return f"{self.expr(node.value)}.{node.attr}"

    def _run(self, node: Run) -> str:
        return f"run {node.thread}()"


_KEYWORD_STATEMENTS = {
    Halt: "halt", Break: "break", Continue: "continue",
    EnterCritical: "enter_critical", ExitCritical: "exit_critical",
}

_STATEMENTS = {
    **{kind: Printer._simple for kind in (
        ExprStmt, Assign, Declare, Return, Join, Kill, *_KEYWORD_STATEMENTS)},
    If: Printer._if, While: Printer._while, FunctionDef: Printer._function,
    ThreadDef: Printer._thread, SecDef: Printer._sec,
}

_EXPRESSIONS = {
    Number: Printer._number, String: Printer._string, Bool: Printer._bool,
    NoneLit: Printer._none, Name: Printer._name, Pose: Printer._pose, List: Printer._list,
    Paren: Printer._paren, UnaryOp: Printer._unary, BinOp: Printer._binop,
    Call: Printer._call, Index: Printer._index, Attribute: Printer._attribute,
    Run: Printer._run,
}

_DEFAULT = Printer()


def format(tree: Node, indent: str = "  ") -> str:  # noqa: A001 - the API's name
    """URScript text for a tree: a :class:`Module` gives a whole file (with a final line
    break); a statement gives its lines; an expression gives its text."""
    printer = _DEFAULT if indent == "  " else Printer(indent)
    if isinstance(tree, Module):
        return printer.module(tree)
    if isinstance(tree, Expr):
        return printer.expr(tree)
    return printer.statement(tree)


def format_expr(expr: Expr) -> str:
    """The text of one expression."""
    return _DEFAULT.expr(expr)
