"""What every rule sees: the tree, its scopes, the target robot and controller version, and
small helpers to find a call's arguments and the constant value of an expression."""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field

from ..script import nodes as n
from ..script.builtins import BLOCKING_CALLS, MOTION_CALLS, Builtin, Version, lookup
from ..script.diagnostics import Diagnostic
from .registry import RULES
from .scope import Analysis, Scope, statements

__all__ = ["LintContext", "MOTION_CALLS", "BLOCKING_CALLS"]


@dataclass
class LintContext:
    """One file being linted. ``model`` is a :class:`urdsl.kinematics.ModelSpec` or None
    (then limits are those of the fastest UR arm); ``version`` a controller software version
    ``(major, minor)`` or None (then version checks are off); ``project`` the file's
    :class:`urdsl.project.FileContext`, where names it does not define are looked up."""

    source: n.Source
    tree: n.Module
    analysis: Analysis
    model: object | None = None
    version: Version | None = None
    project: object | None = None
    """A :class:`urdsl.project.FileContext` (the file seen from its project) or None."""
    _literals: dict[str, n.Expr | None] = field(default_factory=dict, repr=False)

    # -- reporting ---------------------------------------------------------------------------

    def diagnostic(self, code: str, at: n.Node | n.Span, message: str,
                   hint: str | None = None) -> Diagnostic:
        """A finding of rule ``code`` at a node (or span), with the rule's severity."""
        span = at if isinstance(at, n.Span) else at.span  # type: ignore[attr-defined]
        return Diagnostic.at(span, message, code=code, severity=RULES[code].severity, hint=hint)

    def name_span(self, node: n.Node) -> n.Span:
        """The span of the name in a ``def``/``thread``/``sec`` line (or ``global x`` /
        ``local x``), so that a finding points at the name, not at a whole block."""
        span = node.span  # type: ignore[attr-defined]
        name = getattr(node, "name", None)
        if span.source is None or not name:
            return span
        text = span.source.text
        match = re.compile(rf"\b{re.escape(name)}\b").search(text, span.start, span.end)
        if match is None:
            return span
        return n.Span(span.source, match.start(), match.end())

    # -- walking -----------------------------------------------------------------------------

    def scoped_statements(self) -> Iterator[tuple[Scope, n.Stmt]]:
        """Every statement of the file with the scope it runs in."""
        for scope in self.analysis.scopes:
            for statement in statements(scope.body):
                yield scope, statement

    def calls(self) -> Iterator[tuple[Scope, n.Call]]:
        """Every call of a plain name (``f(...)``, not methods) with its scope."""
        for scope in self.analysis.scopes:
            for call in scope.calls:
                yield scope, call

    def in_sec(self, scope: Scope) -> bool:
        """Whether code in ``scope`` runs as (part of) a secondary program."""
        if scope.context() == "sec":
            return True
        return isinstance(self.analysis.program, n.SecDef) and _root(scope).kind == "top"

    def string_prefix(self, node: n.Node) -> n.Span | None:
        """For a Python-style prefixed string written at statement level (``x = f"a {b}"``
        parses as ``x = f`` and the string ``"a {b}"``): the span of the prefix and string,
        given the name or the string node. None otherwise."""
        text = self.source.text
        if isinstance(node, n.Name):
            end = node.span.end
            if node.id.lower() in _PREFIXES and end < len(text) and text[end] in "\"'":
                close = text.find(text[end], end + 1)
                return n.Span(self.source, node.span.start, close + 1 if close > 0 else end + 1)
        elif isinstance(node, n.String):
            start = node.span.start
            begin = start
            while begin > 0 and (text[begin - 1].isalnum() or text[begin - 1] == "_"):
                begin -= 1
            if begin < start and text[begin:start].lower() in _PREFIXES:
                return n.Span(self.source, begin, node.span.end)
        return None

    # -- calls -------------------------------------------------------------------------------

    def builtin(self, call: n.Call) -> Builtin | None:
        """The catalog entry a call reaches: a builtin that no user ``def`` overrides."""
        name = call.func.id  # type: ignore[union-attr]
        if name in self.analysis.functions or name in self.analysis.threads:
            return None
        return lookup(name)

    def builtin_call(self, stmt_or_expr: n.Node) -> tuple[str, n.Call] | None:
        """``(name, call)`` when a statement or expression is a call of a builtin."""
        expr = stmt_or_expr.expr if isinstance(stmt_or_expr, n.ExprStmt) else stmt_or_expr
        if isinstance(expr, n.Call) and isinstance(expr.func, n.Name):
            if self.builtin(expr) is not None:
                return expr.func.id, expr
        return None

    @staticmethod
    def argument(call: n.Call, names: list[str] | tuple[str, ...], name: str) -> n.Expr | None:
        """The argument given for parameter ``name`` (positional or keyword), or None."""
        for keyword in call.keywords:
            if keyword.name == name:
                return keyword.value
        index = list(names).index(name) if name in names else -1
        if 0 <= index < len(call.args):
            return call.args[index]
        return None

    def builtin_argument(self, call: n.Call, name: str) -> n.Expr | None:
        builtin = self.builtin(call)
        if builtin is None:
            return None
        return self.argument(call, [p.name for p in builtin.params], name)

    # -- values ------------------------------------------------------------------------------

    def literal(self, expr: n.Expr) -> n.Expr:
        """``expr`` itself, or for a name assigned exactly once in the whole file (and never
        declared without a value elsewhere) the expression it was assigned."""
        while isinstance(expr, n.Paren):
            expr = expr.expr
        if not isinstance(expr, n.Name):
            return expr
        if expr.id not in self._literals:
            writes = [w for s in self.analysis.scopes for w in s.assigned.get(expr.id, [])]
            value = None
            if len(writes) == 1:
                value = writes[0].value  # type: ignore[attr-defined]
            self._literals[expr.id] = value
        value = self._literals[expr.id]
        return expr if value is None else value

    def number(self, expr: n.Expr) -> float | None:
        """The constant value of a numeric expression (``-1.57``, ``2*0.5``, ``d2r(90)``), or
        None when it is not a constant (or nests too deeply to fold)."""
        try:
            return self._number(expr)
        except RecursionError:
            return None

    def _number(self, expr: n.Expr) -> float | None:
        if isinstance(expr, n.Number):
            return float(expr.value)
        if isinstance(expr, n.Paren):
            return self._number(expr.expr)
        if isinstance(expr, n.UnaryOp) and expr.op in ("-", "+"):
            value = self._number(expr.operand)
            if value is None:
                return None
            return -value if expr.op == "-" else value
        if isinstance(expr, n.BinOp) and expr.op in ("+", "-", "*", "/"):
            left, right = self._number(expr.left), self._number(expr.right)
            if left is None or right is None:
                return None
            if expr.op == "+":
                return left + right
            if expr.op == "-":
                return left - right
            if expr.op == "*":
                return left * right
            return left / right if right else None
        if (isinstance(expr, n.Call) and isinstance(expr.func, n.Name) and len(expr.args) == 1
                and not expr.keywords and expr.func.id in ("d2r", "r2d")
                and self.builtin(expr) is not None):
            value = self._number(expr.args[0])
            if value is None:
                return None
            return math.radians(value) if expr.func.id == "d2r" else math.degrees(value)
        return None


_PREFIXES = frozenset(("f", "r", "b", "u", "rf", "fr", "rb", "br"))


def _root(scope: Scope) -> Scope:
    while scope.parent is not None:
        scope = scope.parent
    return scope
