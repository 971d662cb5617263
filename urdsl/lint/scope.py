"""Who defines and who uses each name, with the controller's scoping rules.

The URScript manual's rules (``docs/controller-facts.md`` §8.3, "Scoping"):

* variables at the first level of the program (directly inside the outer ``def``, or the
  top-level statements of a snippet that PolyScope pastes there) are global, even when
  written ``local``;
* ``global x`` anywhere, in a function or a thread too, makes ``x`` global;
* inside a function or thread an unqualified name is the global if one exists, else a local
  of that function; ``local`` forces a new local;
* every ``def`` and ``thread`` is known everywhere, nested ones too.

The analysis is flow-insensitive, as the controller's compiler is: a name is defined in a scope
when it is assigned anywhere in it, whatever the order.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from ..script import nodes as n

__all__ = ["Scope", "Analysis", "analyse", "statements", "BUILTIN_VARIABLES"]

BUILTIN_VARIABLES = frozenset((
    "pi",  # [U] listed with urmath in older manuals; ur_driver assigns it anyway
    "a_joint_default", "a_tool_default", "v_joint_default", "v_tool_default", "__package__",
))
"""Names the controller defines as variables (``docs/controller-facts.md`` §8.5, [U])."""

Definition = n.FunctionDef | n.ThreadDef | n.SecDef


@dataclass(eq=False)
class Scope:
    """The first level of the program, or one function, thread or ``sec`` body.

    ``assigned`` maps each name written by ``name = value`` (or declared with a value) to the
    places it is written; ``reads`` are the :class:`~urdsl.script.nodes.Name` nodes read here
    (not in nested definitions); ``calls`` the calls of plain names.
    """

    node: n.Node
    kind: str  # "top", "function", "thread" or "sec"
    parent: Scope | None
    body: tuple
    params: dict[str, n.Param] = field(default_factory=dict)
    assigned: dict[str, list[n.Node]] = field(default_factory=dict)
    declared_global: dict[str, n.Declare] = field(default_factory=dict)
    declared_local: dict[str, n.Declare] = field(default_factory=dict)
    reads: list[n.Name] = field(default_factory=list)
    calls: list[n.Call] = field(default_factory=list)
    runs: list[n.Run] = field(default_factory=list)
    children: list[Scope] = field(default_factory=list)

    @property
    def name(self) -> str:
        return getattr(self.node, "name", "<top>")

    def binds(self, name: str) -> bool:
        """Whether this scope itself binds ``name`` (parameter, assignment, declaration)."""
        return (name in self.assigned or name in self.params or name in self.declared_local
                or name in self.declared_global)

    def sees(self, name: str) -> bool:
        """Whether code of this scope finds ``name`` among the program's variables: bound
        here, or at the first level of the program (its globals). URScript has no closures:
        a function or thread nested in another function sees only its own names and the
        globals, not the enclosing function's parameters and locals (the manual's scoping
        rules: nested definitions follow the rules of functions; the controller rejects a
        thread reading such a name: "name '...' is not defined")."""
        if self.binds(name):
            return True
        top = self
        while top.parent is not None:
            top = top.parent
        return top is not self and top.binds(name)

    def local_names(self) -> set[str]:
        """Names bound in this scope itself (parameters, assignments, declarations)."""
        return (set(self.params) | set(self.assigned) | set(self.declared_local)
                | set(self.declared_global))

    def descendants(self) -> Iterator[Scope]:
        """This scope and every scope nested in it."""
        yield self
        for child in self.children:
            yield from child.descendants()

    def context(self) -> str:
        """The innermost kind of code this scope runs as: ``sec`` wins over the others."""
        scope: Scope | None = self
        while scope is not None:
            if scope.kind == "sec":
                return "sec"
            scope = scope.parent
        return self.kind


@dataclass(eq=False)
class Analysis:
    """Every scope of a file, the definitions and the global names."""

    module: n.Module
    top: Scope
    program: n.FunctionDef | n.SecDef | None  # the outer def of a program file
    functions: dict[str, list[n.FunctionDef]]
    threads: dict[str, list[n.ThreadDef]]
    secs: dict[str, list[n.SecDef]]
    globals: set[str]
    scopes: list[Scope]
    scope_of: dict[int, Scope]  # id(definition node) -> its scope

    def defined(self, name: str, scope: Scope) -> bool:
        """Whether reading ``name`` in ``scope`` finds a variable, function or thread."""
        if scope.sees(name):
            return True
        return (name in self.globals or name in self.functions or name in self.threads
                or name in BUILTIN_VARIABLES)

    def is_global_in(self, name: str, scope: Scope) -> bool:
        """Whether ``name`` written in ``scope`` is a global variable."""
        if scope.kind == "top" or name in scope.declared_global:
            return True
        if name in scope.declared_local or name in scope.params:
            return False
        return name in self.globals


def statements(items: tuple) -> Iterator[n.Stmt]:
    """Every statement in ``items`` and in the blocks of its ``if`` and ``while`` statements,
    in source order; nested definitions are yielded but not entered. (Iterative: generated
    programs nest blocks deeper than Python's recursion limit.)"""
    stack: list[Iterator] = [iter(items)]
    while stack:
        item = next(stack[-1], None)
        if item is None:
            stack.pop()
            continue
        if not isinstance(item, n.Stmt):
            continue
        yield item
        if isinstance(item, n.If):
            blocks = [item.body, *(branch.body for branch in item.elifs)]
            if item.orelse:
                blocks.append(item.orelse)
            stack.append(iter([s for block in blocks for s in block]))
        elif isinstance(item, n.While):
            stack.append(iter(item.body))


class _Builder:
    def __init__(self) -> None:
        self.functions: dict[str, list[n.FunctionDef]] = {}
        self.threads: dict[str, list[n.ThreadDef]] = {}
        self.secs: dict[str, list[n.SecDef]] = {}
        self.scopes: list[Scope] = []
        self.scope_of: dict[int, Scope] = {}

    def scope(self, node: n.Node, kind: str, parent: Scope | None, body: tuple) -> Scope:
        scope = Scope(node, kind, parent, body)
        if isinstance(node, n.FunctionDef) and kind == "function":
            for param in node.params:
                scope.params[param.name] = param
        self.scopes.append(scope)
        self.scope_of[id(node)] = scope
        if parent is not None:
            parent.children.append(scope)
        for statement in statements(body):
            self.statement(statement, scope)
        return scope

    def statement(self, stmt: n.Stmt, scope: Scope) -> None:
        if isinstance(stmt, n.FunctionDef):
            self.functions.setdefault(stmt.name, []).append(stmt)
            for param in stmt.params:
                if param.default is not None:
                    self.expr(param.default, scope)
            self.scope(stmt, "function", scope, stmt.body)
        elif isinstance(stmt, n.ThreadDef):
            self.threads.setdefault(stmt.name, []).append(stmt)
            self.scope(stmt, "thread", scope, stmt.body)
        elif isinstance(stmt, n.SecDef):
            self.secs.setdefault(stmt.name, []).append(stmt)
            self.scope(stmt, "sec", scope, stmt.body)
        elif isinstance(stmt, n.Assign):
            if isinstance(stmt.target, n.Name):
                scope.assigned.setdefault(stmt.target.id, []).append(stmt)
            else:
                self.expr(stmt.target, scope)
            self.expr(stmt.value, scope)
        elif isinstance(stmt, n.Declare):
            table = scope.declared_global if stmt.scope == "global" else scope.declared_local
            table.setdefault(stmt.name, stmt)
            if stmt.value is not None:
                scope.assigned.setdefault(stmt.name, []).append(stmt)
                self.expr(stmt.value, scope)
        elif isinstance(stmt, n.ExprStmt):
            self.expr(stmt.expr, scope)
        elif isinstance(stmt, n.Return):
            if stmt.value is not None:
                self.expr(stmt.value, scope)
        elif isinstance(stmt, (n.Join, n.Kill)):
            self.expr(stmt.thread, scope)
        elif isinstance(stmt, (n.If, n.While)):
            self.expr(stmt.test, scope)
            if isinstance(stmt, n.If):
                for branch in stmt.elifs:
                    self.expr(branch.test, scope)

    def expr(self, expr: n.Node, scope: Scope) -> None:
        stack = [expr]
        while stack:
            node = stack.pop()
            kind = type(node)
            if kind is n.Name:
                scope.reads.append(node)
            elif kind is n.Call:
                if type(node.func) is n.Name:
                    scope.calls.append(node)
                else:
                    stack.append(node.func)
                stack.extend(node.args)
                stack.extend(k.value for k in node.keywords)
            elif kind is n.Run:
                scope.runs.append(node)
            elif kind in (n.Number, n.String, n.Bool, n.NoneLit):
                continue
            elif kind in (n.Pose, n.List):
                stack.extend(node.items)
            elif kind is n.Paren:
                stack.append(node.expr)
            elif kind is n.UnaryOp:
                stack.append(node.operand)
            elif kind is n.BinOp:
                stack.append(node.left)
                stack.append(node.right)
            elif kind is n.Index:
                stack.append(node.value)
                stack.extend(node.indices)
            elif kind is n.Attribute:
                stack.append(node.value)


def program_def(module: n.Module) -> n.FunctionDef | n.SecDef | None:
    """The outer ``def`` (or ``sec``) when the file is one program, else None: a file that
    is one ``def`` without parameters, or one followed by nothing but a call of it (a
    program a tool sends with its call, ``def gripper(): ... end`` then ``gripper()``)."""
    statements_ = [item for item in module.body if isinstance(item, n.Stmt)]
    if len(statements_) == 2 and n.calls_itself(statements_[0], statements_[1]):
        return statements_[0]  # type: ignore[return-value]
    if len(statements_) != 1:
        return None
    only = statements_[0]
    if isinstance(only, n.FunctionDef) and not only.params:
        return only
    if isinstance(only, n.SecDef):
        return only
    return None


def analyse(module: n.Module) -> Analysis:
    """Scopes, definitions and globals of a parsed file."""
    builder = _Builder()
    program = program_def(module)
    if program is None:
        top = builder.scope(module, "top", None, module.body)
    else:
        if isinstance(program, n.FunctionDef):
            builder.functions.setdefault(program.name, []).append(program)
        else:
            builder.secs.setdefault(program.name, []).append(program)
        top = builder.scope(program, "top", None, program.body)
    names = set(top.assigned) | set(top.declared_global) | set(top.declared_local)
    for scope in builder.scopes:
        names |= set(scope.declared_global)
    return Analysis(
        module, top, program, builder.functions, builder.threads, builder.secs, names,
        builder.scopes, builder.scope_of,
    )
