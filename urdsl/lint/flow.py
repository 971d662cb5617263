"""Rules about control flow and timing: statements without effect, unreachable code, what a
``sec`` program must not do, and loops that never give up their time slice."""

from __future__ import annotations

import bisect
import difflib
from collections.abc import Iterator

from ..script import nodes as n
from ..script.builtins import lookup
from ..script.diagnostics import Diagnostic
from .context import BLOCKING_CALLS, MOTION_CALLS, LintContext
from .names import PYTHON_HABITS, keywords
from .registry import rule
from .scope import Scope, statements

_TERMINATORS = (n.Halt, n.Return, n.Break, n.Continue)


@rule(
    "URS115", "no-effect", "warning",
    "A statement that computes a value and throws it away.",
    """
A statement that is not a call, an assignment or a control statement does nothing. The
usual causes: `==` written where `=` was meant (`x == 1` on its own line), a misspelt keyword
(`globl x = 1` is the name `globl` followed by the assignment `x = 1`), or a function named
without parentheses (`sync` instead of `sync()`). `=` written where `==` was meant, in a
condition, is a syntax error (URS001) whose hint says so.""",
    "count == 0\nglobl speed = 0.5",
    "count = 0\nglobal speed = 0.5",
)
def no_effect(ctx: LintContext) -> Iterator[Diagnostic]:
    for scope, statement in ctx.scoped_statements():
        if not isinstance(statement, n.ExprStmt):
            continue
        expr = statement.expr
        while isinstance(expr, n.Paren):
            expr = expr.expr
        if isinstance(expr, (n.Call, n.Run)):
            continue
        if isinstance(expr, n.String) and ctx.string_prefix(expr) is not None:
            continue  # x = f"..." : URS119 reports it
        if isinstance(expr, n.BinOp) and expr.op == "==":
            yield ctx.diagnostic("URS115", statement, "comparison has no effect",
                                 "to assign, write '=' instead of '=='")
        elif isinstance(expr, n.Name):
            if expr.id in PYTHON_HABITS and not ctx.analysis.defined(expr.id, scope):
                continue  # URS119 explains it
            close = difflib.get_close_matches(expr.id, keywords(), n=1, cutoff=0.7)
            if close:
                hint = f"did you mean `{close[0]}`?"
            elif lookup(expr.id) is not None or expr.id in ctx.analysis.functions:
                hint = f"to call it, write {expr.id}()"
            else:
                hint = "a name alone does nothing"
            yield ctx.diagnostic("URS115", statement, f"'{expr.id}' alone has no effect", hint)
        elif isinstance(expr, n.Attribute):
            yield ctx.diagnostic("URS115", statement, "this field read has no effect",
                                 f"to call the method, write .{expr.attr}()")
        else:
            yield ctx.diagnostic("URS115", statement, "this expression has no effect",
                                 "assign its value to a variable, or delete it")


def _terminates(item: n.Stmt) -> bool:
    """Whether control never goes past ``item`` to the next statement of its block."""
    if isinstance(item, _TERMINATORS):
        return True
    if isinstance(item, n.If) and item.orelse is not None:
        blocks = [item.body, *(branch.body for branch in item.elifs), item.orelse]
        return all(_block_terminates(block) for block in blocks)
    return False


def _block_terminates(items: tuple) -> bool:
    return any(_terminates(item) for item in items if isinstance(item, n.Stmt)
               and not isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef)))


def _blocks(items: tuple) -> Iterator[tuple]:
    """``items`` and every block nested in it (if/elif/else, while, definitions)."""
    pending = [items]
    while pending:
        block = pending.pop()
        yield block
        for item in block:
            if isinstance(item, (n.FunctionDef, n.ThreadDef, n.SecDef, n.While)):
                pending.append(item.body)
            elif isinstance(item, n.If):
                pending.append(item.body)
                pending.extend(branch.body for branch in item.elifs)
                if item.orelse:
                    pending.append(item.orelse)


@rule(
    "URS116", "unreachable-code", "warning",
    "Statements after halt, return, break or continue in the same block.",
    """
Nothing after `halt`, `return`, `break` or `continue` (or after an if/elif/else whose every
branch ends so) runs. Usually a leftover from debugging, or an `end` in the wrong place.""",
    "def lift():\n  return None\n  movel(p_up)\nend",
    "def lift():\n  movel(p_up)\n  return None\nend",
)
def unreachable_code(ctx: LintContext) -> Iterator[Diagnostic]:
    for block in _blocks(ctx.tree.body):
        stopper: n.Stmt | None = None
        for item in block:
            if not isinstance(item, n.Stmt):
                continue
            if stopper is not None:
                what = {n.Halt: "halt", n.Return: "return", n.Break: "break",
                        n.Continue: "continue"}.get(type(stopper), "the if above (every "
                                                    "branch leaves the block)")
                yield ctx.diagnostic("URS116", item, f"unreachable: nothing runs after {what}"
                                     f" (line {stopper.span.line})",  # type: ignore[attr-defined]
                                     "delete it, or move it before the statement that leaves")
                break
            if _terminates(item):
                stopper = item


def _function_effects(ctx: LintContext) -> dict[str, tuple[str, int]]:
    """For each user function that (directly or through other functions) moves the arm, waits
    or starts threads: the first such call's name and line."""
    effects: dict[str, tuple[str, int]] = {}
    changed = True
    while changed:
        changed = False
        for name, definitions in ctx.analysis.functions.items():
            if name in effects:
                continue
            scope = ctx.analysis.scope_of.get(id(definitions[-1]))
            if scope is None:
                continue
            found = _first_effect(ctx, scope, effects)
            if found is not None:
                effects[name] = found
                changed = True
    return effects


def _sec_effect(name: str) -> str | None:
    if name in MOTION_CALLS:
        return "moves the arm"
    if name in ("sleep", "sync"):
        return "waits"
    return None


def _first_effect(ctx: LintContext, scope: Scope, effects: dict[str, tuple[str, int]]
                  ) -> tuple[str, int] | None:
    for call in scope.calls:
        name = call.func.id  # type: ignore[union-attr]
        if (ctx.builtin(call) is not None and _sec_effect(name)) or name in effects:
            return name, call.span.line
    if scope.runs:
        return "run", scope.runs[0].span.line
    return None


@rule(
    "URS117", "sec-blocking", "error",
    "A `sec` program that moves the arm, sleeps, syncs or starts threads.",
    """
A secondary program runs beside the primary one and must finish within one controller step.
The manual forbids moves, sleep and threads in it; the controller reports "Runtime is too
much behind" or behaves in undefined ways. Calls of functions that do these things are
reported too.""",
    "sec light():\n  set_standard_digital_out(0, True)\n  sleep(0.5)\nend",
    "sec light():\n  set_standard_digital_out(0, True)\nend",
)
def sec_blocking(ctx: LintContext) -> Iterator[Diagnostic]:
    effects: dict[str, tuple[str, int]] | None = None
    for scope in ctx.analysis.scopes:
        if not ctx.in_sec(scope):
            continue
        if scope.kind == "thread":
            yield ctx.diagnostic("URS117", ctx.name_span(scope.node),
                                 "a thread inside a sec program",
                                 "sec programs must not use threads")
        for call in scope.calls:
            name = call.func.id  # type: ignore[union-attr]
            effect = _sec_effect(name) if ctx.builtin(call) is not None else None
            if effect:
                yield ctx.diagnostic("URS117", call, f"{name}() {effect} inside a sec program",
                                     "a sec program must finish within one controller step")
            elif name in ctx.analysis.functions:
                if effects is None:
                    effects = _function_effects(ctx)
                if name in effects:
                    inner, line = effects[name]
                    yield ctx.diagnostic(
                        "URS117", call, f"{name}() calls {inner} (line {line}) inside a sec "
                        "program", "a sec program must finish within one controller step")
        for run in scope.runs:
            yield ctx.diagnostic("URS117", run, "a thread started inside a sec program",
                                 "sec programs must not use threads")


def _blocking_functions(ctx: LintContext) -> set[str]:
    """User functions that take physical time (directly or through other functions)."""
    blocking: set[str] = set()
    changed = True
    while changed:
        changed = False
        for name, definitions in ctx.analysis.functions.items():
            if name in blocking:
                continue
            scope = ctx.analysis.scope_of.get(id(definitions[-1]))
            if scope is not None and _takes_time(ctx, scope.body, blocking, deep=True):
                blocking.add(name)
                changed = True
    return blocking


def _takes_time(ctx: LintContext, items: tuple, blocking: set[str], deep: bool = False) -> bool:
    """Whether running ``items`` may take physical time: a blocking builtin, a method call
    (RPC, may block), ``join``, or a user function in ``blocking``."""
    return any(_statement_takes_time(ctx, statement, blocking) for statement in statements(items))


def _statement_takes_time(ctx: LintContext, statement: n.Stmt, blocking: set[str]) -> bool:
    """Whether ``statement`` itself (its expressions, not its nested blocks) may take
    physical time, as :func:`_takes_time` counts it."""
    if isinstance(statement, n.Join):
        return True
    if isinstance(statement, (n.FunctionDef, n.ThreadDef, n.SecDef)):
        return False
    for node in _expressions(statement):
        for inner in n.walk(node):
            if isinstance(inner, n.Call):
                if isinstance(inner.func, n.Attribute):
                    return True
                name = inner.func.id  # type: ignore[union-attr]
                if name in blocking:
                    return True
                if name in BLOCKING_CALLS and name not in ctx.analysis.functions:
                    return True
                if name not in ctx.analysis.functions and lookup(name) is None:
                    return True  # unknown function: give it the benefit of the doubt
    return False


def _expressions(statement: n.Stmt) -> list[n.Node]:
    if isinstance(statement, n.ExprStmt):
        return [statement.expr]
    if isinstance(statement, n.Assign):
        return [statement.target, statement.value]
    if isinstance(statement, n.Declare):
        return [statement.value] if statement.value is not None else []
    if isinstance(statement, n.Return):
        return [statement.value] if statement.value is not None else []
    if isinstance(statement, n.If):
        return [statement.test, *(branch.test for branch in statement.elifs)]
    if isinstance(statement, n.While):
        return [statement.test]
    if isinstance(statement, (n.Kill,)):
        return [statement.thread]
    return []


def _statement_assigns(statement: n.Stmt) -> set[str]:
    """Names ``statement`` itself (not its nested blocks) changes: assigned, declared, or
    changed by a method call (``l.append(x)`` changes ``l``)."""
    names: set[str] = set()
    if isinstance(statement, n.Assign):
        target = statement.target
        while isinstance(target, (n.Index, n.Attribute)):
            target = target.value
        if isinstance(target, n.Name):
            names.add(target.id)
    elif isinstance(statement, n.Declare):
        names.add(statement.name)
    elif isinstance(statement, n.ExprStmt):
        for inner in n.walk(statement.expr):
            if isinstance(inner, n.Call) and isinstance(inner.func, n.Attribute):
                value = inner.func.value
                if isinstance(value, n.Name):
                    names.add(value.id)
    return names


def _preorder(items: tuple) -> tuple[list[n.Stmt], list[int]]:
    """The statements of ``items`` in the order of :func:`statements`, and for each the index
    just past its last nested statement: the statements nested in ``order[i]`` are
    ``order[i + 1:ends[i]]``. Linear, whatever the nesting depth."""
    order: list[n.Stmt] = []
    ends: list[int] = []
    open_at: list[int] = []  # indices of the if/while statements whose blocks are being read
    stack: list[Iterator | None] = [iter(items)]
    while stack:
        top = stack[-1]
        if top is None:  # the blocks of order[open_at[-1]] are read
            stack.pop()
            ends[open_at.pop()] = len(order)
            continue
        item = next(top, None)
        if item is None:
            stack.pop()
            continue
        if not isinstance(item, n.Stmt):
            continue
        order.append(item)
        ends.append(len(order))
        if isinstance(item, (n.If, n.While)):
            open_at.append(len(order) - 1)
            stack.append(None)
            if isinstance(item, n.If):
                blocks = [item.body, *(branch.body for branch in item.elifs)]
                if item.orelse:
                    blocks.append(item.orelse)
                stack.append(iter([s for block in blocks for s in block]))
            else:
                stack.append(iter(item.body))
    return order, ends


@rule(
    "URS118", "busy-loop", "warning",
    "A loop that waits or runs forever without sync(), sleep() or a move.",
    """
The controller gives each thread one time slice per step (2 ms on e-Series, 8 ms on CB3); a
thread must use physical time (a move, sleep, sync) or finish before its slice ends, or the
program is stopped ("infinite loop detected", "Lost communication with Controller"). A loop
whose condition nothing in the loop changes (while True, or waiting for an input or for
another thread) spins without yielding. Put sync() in the loop to wait one step per turn.
Calls of functions that take time, method calls (RPC) and join count as yielding.""",
    "thread watch():\n  while not get_standard_digital_in(0):\n  end\n  textmsg(\"pressed\")\nend",
    "thread watch():\n  while not get_standard_digital_in(0):\n    sync()\n  end\n"
    "  textmsg(\"pressed\")\nend",
)
def busy_loop(ctx: LintContext) -> Iterator[Diagnostic]:
    blocking: set[str] | None = None
    for scope in ctx.analysis.scopes:
        if ctx.in_sec(scope):
            continue
        order, ends = _preorder(scope.body)
        if not any(isinstance(statement, n.While) for statement in order):
            continue
        if blocking is None:
            blocking = _blocking_functions(ctx)
        # one pass over the scope, then each loop is a range of it (nested loops would make
        # a walk per loop quadratic in the nesting depth)
        timed = [0]  # timed[i]: how many of order[:i] take time
        assigning: dict[str, list[int]] = {}  # name: indices of the statements changing it
        for index, statement in enumerate(order):
            timed.append(timed[-1] + _statement_takes_time(ctx, statement, blocking))
            for name in _statement_assigns(statement):
                assigning.setdefault(name, []).append(index)
        for index, statement in enumerate(order):
            if not isinstance(statement, n.While):
                continue
            end = ends[index]
            if timed[end] > timed[index]:
                continue
            if any(isinstance(item, (n.Halt, n.Break, n.Return)) for item in statement.body):
                continue  # its first pass leaves it (``while mode == 3: halt``)
            tested = {node.id for node in n.walk(statement.test) if isinstance(node, n.Name)}
            if any(_within(assigning.get(name, ()), index + 1, end) for name in tested):
                continue  # a counting loop: it ends by itself
            where = "" if scope.kind == "top" else f" in {scope.kind} {scope.name}()"
            yield ctx.diagnostic(
                "URS118", statement, f"this loop{where} never gives up its time slice",
                "call sync() in the loop (it waits for the next controller step)")


def _within(indices: list[int] | tuple, start: int, end: int) -> bool:
    """Whether the sorted ``indices`` hold one in ``start <= i < end``."""
    at = bisect.bisect_left(indices, start)
    return at < len(indices) and indices[at] < end
