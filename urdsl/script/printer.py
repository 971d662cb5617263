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
    #
    # Blocks and expressions nest as deep as the program does, so neither is printed by
    # recursion: each keeps an explicit stack of work (a sum of thousands of terms or
    # thousands of nested blocks prints like any other program).

    def _block(self, items: tuple, depth: int, lines: list[str]) -> None:
        # Work items: (items, index, depth, closing lines) of the blocks being printed.
        stack: list[tuple[tuple, int, int, list[str]]] = [(items, 0, depth, [])]
        while stack:
            items, index, depth, closing = stack.pop()
            if index >= len(items):
                for line in closing:  # `elif ...:`/`else:` headers open the next block
                    lines.append(line)
                continue
            item = items[index]
            stack.append((items, index + 1, depth, closing))
            pad = self.indent * depth
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
            elif kind in _KEYWORD_STATEMENTS or kind in _SIMPLE_STATEMENTS:
                lines.append(pad + self._simple_text(item))
            else:
                parts = self._compound(item, pad)
                if parts is None:
                    raise TypeError(f"cannot print {kind.__name__} as a statement")
                # parts: (header, body), (header, body), ..., then the `end` line; pushed in
                # reverse so that the first body is printed first
                sections, end = parts
                lines.append(sections[0][0])
                stack.append(((), 0, depth, [end]))
                for k in range(len(sections) - 1, 0, -1):
                    header, body = sections[k]
                    stack.append((body, 0, depth + 1, []))
                    stack.append(((), 0, depth, [header]))
                stack.append((sections[0][1], 0, depth + 1, []))

    def _compound(self, node: Node, pad: str):
        """The headers and bodies of a block statement: ``([(header, body), ...], end)``."""
        kind = type(node)
        if kind is If:
            sections = [(f"{pad}if {self.expr(node.test)}:", node.body)]
            sections += [(f"{pad}elif {self.expr(b.test)}:", b.body) for b in node.elifs]
            if node.orelse is not None:
                sections.append((f"{pad}else:", node.orelse))
        elif kind is While:
            sections = [(f"{pad}while {self.expr(node.test)}:", node.body)]
        elif kind is FunctionDef:
            params = ", ".join(
                p.name if p.default is None else f"{p.name}={self.expr(p.default)}"
                for p in node.params
            )
            sections = [(f"{pad}def {node.name}({params}):", node.body)]
        elif kind is ThreadDef:
            sections = [(f"{pad}thread {node.name}():", node.body)]
        elif kind is SecDef:
            sections = [(f"{pad}sec {node.name}():", node.body)]
        else:
            return None
        return sections, f"{pad}end"

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

    # -- expressions -------------------------------------------------------------------------

    def expr(self, node: Expr) -> str:
        """The text of one expression."""
        kind = type(node)
        # leaves and shallow calls directly (most expressions); anything else by the stack
        if kind is Number:
            return format_number(node.value)
        if kind is Name:
            return node.id
        out: list[str] = []
        # work: an expression node to expand, or a str to write as it is
        work: list = [node]
        pop, push, write = work.pop, work.append, out.append
        while work:
            item = pop()
            if type(item) is str:
                write(item)
                continue
            kind = type(item)
            if kind is Number:
                write(format_number(item.value))
            elif kind is Name:
                write(item.id)
            elif kind is BinOp:
                push(item.right)
                push(f" {item.op} ")
                push(item.left)
            elif kind is Call:
                push(")")
                args = [*item.args, *item.keywords]
                for k in range(len(args) - 1, -1, -1):
                    arg = args[k]
                    if type(arg) is Keyword:
                        push(arg.value)
                        push(arg.name + "=")
                    else:
                        push(arg)
                    if k:
                        push(", ")
                push("(")
                push(item.func)
            elif kind is Pose or kind is List:
                push("]")
                self._push_items(item.items, push)
                push("p[" if kind is Pose else "[")
            elif kind is Paren:
                push(")")
                push(item.expr)
                push("(")
            elif kind is UnaryOp:
                push(item.operand)
                push("not " if item.op == "not" else item.op)
            elif kind is Index:
                push("]")
                self._push_items(item.indices, push)
                push("[")
                push(item.value)
            elif kind is Attribute:
                push("." + item.attr)
                if type(item.value) is Number:
                    push(" ")  # `1 .a`: written `1.a` it would read as `1.` and `a`
                push(item.value)
            elif kind is String:
                write(self._string(item))
            elif kind is Bool:
                write("True" if item.value else "False")
            elif kind is NoneLit:
                write("None")
            elif kind is Run:
                write(f"run {item.thread}()")
            else:
                raise TypeError(f"cannot print {kind.__name__} as an expression")
        return "".join(out)

    @staticmethod
    def _push_items(items: tuple, push) -> None:
        for k in range(len(items) - 1, -1, -1):
            push(items[k])
            if k:
                push(", ")

    @staticmethod
    def _string(node: String) -> str:
        if '"' not in node.value:
            return f'"{node.value}"'
        if "'" not in node.value:
            return f"'{node.value}'"
        raise ValueError("a URScript string cannot hold both kinds of quote")


_KEYWORD_STATEMENTS = {
    Halt: "halt", Break: "break", Continue: "continue",
    EnterCritical: "enter_critical", ExitCritical: "exit_critical",
}

_SIMPLE_STATEMENTS = frozenset((ExprStmt, Assign, Declare, Return, Join, Kill))

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
