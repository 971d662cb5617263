"""Rules about names: undefined names and functions, unused variables and parameters, names
that hide builtins, habits from Python, ``local`` at the first level, duplicate definitions."""

from __future__ import annotations

import difflib
from collections.abc import Iterator

from ..project.model import from_missing_program
from ..script import nodes as n
from ..script.builtins import catalog, lookup, methods
from ..script.diagnostics import Diagnostic
from ..script.urcaps import urcap_hint
from .context import LintContext
from .registry import rule
from .scope import BUILTIN_VARIABLES, Scope

__all__ = ["PYTHON_HABITS", "keywords"]

def keywords() -> tuple[str, ...]:
    """The language's words as the grammar has them (sorted), for "did you mean" hints; built
    when a rule first asks, so importing the linter does not build the parser."""
    from ..script.parser import keywords as grammar_keywords

    return tuple(sorted(grammar_keywords()))


PYTHON_HABITS: dict[str, str] = {
    "print": "write textmsg(value) (it shows in the log; popup(text) shows a dialog)",
    "len": "write get_list_length(list) or length(list) for a list, str_len(s) for a string",
    "range": "URScript has no range(): count with i = 0 / while i < n: ... i = i + 1 / end",
    "str": "write to_str(value)",
    "int": "write floor(x) to drop the fraction, to_num(s) to read a number from a string",
    "float": "write to_num(s) to read a number from a string",
    "abs": "write norm(x): for a number it is the absolute value",
    "min": "URScript has no min(): write an if",
    "max": "URScript has no max(): write an if",
    "round": "write floor(x + 0.5)",
    "math": "the math functions are builtins: sqrt(x), sin(x), pow(b, e), d2r(deg)",
    "numpy": "the math functions are builtins: sqrt(x), sin(x), pow(b, e), d2r(deg)",
    "np": "the math functions are builtins: sqrt(x), sin(x), pow(b, e), d2r(deg)",
    "import": "URScript has no modules: every builtin is always there",
    "from": "URScript has no modules: every builtin is always there",
    "true": "write True", "false": "write False",
    "null": "write None", "none": "write None", "nil": "write None",
    "self": "URScript has no classes; pass values as parameters or use globals",
    "exit": "write halt", "quit": "write halt",
    "time_sleep": "write sleep(seconds)",
    "lambda": "URScript has no lambdas: write a def",
    "isinstance": "URScript has no run-time type test",
    "list": "write a list literal [a, b] or make_list(length, initial_value, capacity)",
    "dict": "use struct(name=value, ...) (5.13 and later)",
    "append": "append is a list method: my_list.append(value) (5.15 and later)",
}
"""Names from Python (and C) that are not URScript, with the URScript way."""


_ANY_KIND = frozenset(("function", "thread", "global", "installation variable"))


def _habit(name: str, ctx: LintContext, scope: Scope) -> str | None:
    if name in PYTHON_HABITS and not ctx.analysis.defined(name, scope) and lookup(name) is None:
        project = ctx.project
        if project is not None and project.definitions(name, _ANY_KIND):  # type: ignore
            return None  # another file of the project defines it
        return PYTHON_HABITS[name]
    return None


def _suggest(name: str, candidates) -> str | None:
    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.75)
    return f"did you mean `{close[0]}`?" if close else None


def _visible(ctx: LintContext, scope: Scope) -> set[str]:
    names = set(ctx.analysis.globals) | set(ctx.analysis.functions) | set(ctx.analysis.threads)
    current: Scope | None = scope
    while current is not None:
        names |= current.local_names()
        current = current.parent
    return names | BUILTIN_VARIABLES


def _owner(ctx: LintContext, name: str) -> Scope | None:
    """A function or thread where ``name`` is a local (for the hint of an undefined name)."""
    for scope in ctx.analysis.scopes:
        if scope.kind in ("function", "thread", "sec") and name in scope.assigned:
            return scope
    return None


def _elsewhere(ctx: LintContext, code: str, at: n.Node, use: str,
               name: str) -> tuple[bool, Diagnostic | None]:
    """A name this file uses but does not define, looked up in its project: ``(False,
    None)`` when the project does not define it either (the rule's own error stands);
    ``(True, None)`` when the program gets it (its host, a file the program includes, an
    installation variable); ``(True, finding)`` with the severity the project decides
    (info, warning, or error for a program that does not include the file) otherwise."""
    project = ctx.project
    if project is None:
        return False, None
    resolve = {"read": project.resolve_read, "call": project.resolve_call,  # type: ignore
               "thread": project.resolve_thread}[use]  # type: ignore[attr-defined]
    found = resolve(name)
    if found is None:
        return False, None
    if found.severity is None:
        return True, None
    return True, Diagnostic.at(at.span, found.message, code=code,  # type: ignore[attr-defined]
                               severity=found.severity, hint=found.hint)


def _hostless(ctx: LintContext, name: str, hint: str | None) -> str | None:
    """``hint`` for a name defined nowhere in the project, read by a fragment that no program
    of the project includes, with :func:`urdsl.project.model.from_missing_program` after it."""
    project = ctx.project
    if project is None or not project.hostless:
        return hint
    where = from_missing_program(name, "lint")
    return f"{hint}; {where}" if hint else where


@rule(
    "URS101", "undefined-name", "error",
    "A name is read that no assignment, parameter or declaration visible here defines.",
    """
The controller compiles the whole program before it runs and stops with "Compile error:
name 'x' is not defined". Variables at the first level of the program and names declared
`global` (in a function or a thread too) are visible everywhere; a variable assigned inside a
function or thread without `global` is local to it and invisible elsewhere.

In a project (see "Real projects" in the README) a name defined in another file is no error
when the program gets it: from the host program that includes this file, a file that program
includes, or the installation variables. A name defined only in a file the program does not
include is an info (this file has a host), a warning (this file looks like a fragment that no
program of the project includes) or still an error (this file is a complete program); the
message says where the name is defined.""",
    """
thread blink():
  on = True
end
def show():
  textmsg(on)
end""",
    """
thread blink():
  global on = True
end
def show():
  textmsg(on)
end""",
)
def undefined_name(ctx: LintContext) -> Iterator[Diagnostic]:
    analysis = ctx.analysis
    for scope in analysis.scopes:
        for name in scope.reads:
            if analysis.defined(name.id, scope) or _habit(name.id, ctx, scope):
                continue
            if ctx.string_prefix(name) is not None:
                continue  # URS119 reports the prefixed string
            handled, finding = _elsewhere(ctx, "URS101", name, "read", name.id)
            if handled:
                if finding is not None:
                    yield finding
                continue
            hint = None
            owner = _owner(ctx, name.id)
            enclosing = scope.parent
            while enclosing is not None and enclosing.parent is not None \
                    and not enclosing.binds(name.id):
                enclosing = enclosing.parent
            if enclosing is not None and enclosing.parent is not None:
                hint = (f"`{name.id}` belongs to the enclosing {enclosing.kind} "
                        f"{enclosing.name}(); a {scope.kind} defined inside it sees only its "
                        "own names and the globals (URScript has no closures): pass it "
                        "through a global variable")
            elif owner is not None:
                hint = (f"`{name.id}` is local to {owner.kind} {owner.name}(); declare it "
                        f"`global {name.id}` there, or assign it at the first level")
            elif lookup(name.id) is not None:
                hint = f"{name.id} is a builtin function: call it, {name.id}(...)"
            else:
                hint = _suggest(name.id, _visible(ctx, scope) | set(keywords()))
            hint = _hostless(ctx, name.id, hint)
            yield ctx.diagnostic("URS101", name, f"name '{name.id}' is not defined", hint)
        for run in scope.runs:
            if run.thread not in analysis.threads:
                handled, finding = _elsewhere(ctx, "URS101", run, "thread", run.thread)
                if handled:
                    if finding is not None:
                        yield finding
                    continue
                what = "a function, not a thread" if run.thread in analysis.functions else \
                    "not defined"
                hint = _suggest(run.thread, analysis.threads) if what == "not defined" else \
                    "only a `thread name(): ... end` can be started with run"
                yield ctx.diagnostic("URS101", run, f"thread '{run.thread}' is {what}", hint)


@rule(
    "URS102", "unknown-function", "error",
    "A call of a function that is neither a builtin nor defined with `def`.",
    """
The controller rejects the program ("name 'f' is not defined"). The builtin catalog of urdsl
lists every function of the URScript manuals from CB3 to PolyScope X; the hint names the
closest builtin or function of the file. A function defined in another file of the project is
judged as URS101 judges names.""",
    "textmesg(\"hello\")",
    "textmsg(\"hello\")",
)
def unknown_function(ctx: LintContext) -> Iterator[Diagnostic]:
    analysis = ctx.analysis
    for scope, call in ctx.calls():
        name = call.func.id  # type: ignore[union-attr]
        if name in analysis.functions or _habit(name, ctx, scope):
            continue
        if name in analysis.threads:
            yield ctx.diagnostic("URS102", call.func, f"'{name}' is a thread, not a function",
                                 f"start it with `run {name}()`")
            continue
        builtin = lookup(name)
        if builtin is not None:
            if not builtin.callable:
                yield ctx.diagnostic(
                    "URS102", call.func,
                    f"'{name}' is a command of the interpreter socket (port 30020), not a "
                    "function", f"send `{name}` alone on a line to port 30020")
            continue
        if scope.binds(name) or name in analysis.globals:
            yield ctx.diagnostic("URS102", call.func, f"'{name}' is a variable, not a function")
            continue
        handled, finding = _elsewhere(ctx, "URS102", call.func, "call", name)
        if handled:
            if finding is not None:
                yield finding
            continue
        if name in methods():
            hint = f"{name} is a method: write my_list.{name}(...)"
        else:
            hint = urcap_hint(name) or _suggest(name, set(catalog()) | set(analysis.functions))
        yield ctx.diagnostic("URS102", call.func, f"unknown function '{name}'", hint)


def _reads_below(scope: Scope) -> set[str]:
    names: set[str] = set()
    for inner in scope.descendants():
        names.update(name.id for name in inner.reads)
    return names


@rule(
    "URS112", "unused-variable", "warning",
    "A variable is assigned but never read.",
    """
Inside a function or thread: a local that nothing reads (often a typo in a later use, or a
missing `global` declaration). In a program file: a variable of the first level that nothing
in the file reads (`global` declarations are left alone: interpreter mode and RTDE clients may
read them). Names starting with `_` are exempt.""",
    """
def pick():
  grip_force = 40
  set_tool_digital_out(0, True)
end""",
    """
def pick():
  set_tool_digital_out(0, True)
end""",
)
def unused_variable(ctx: LintContext) -> Iterator[Diagnostic]:
    analysis = ctx.analysis
    for scope in analysis.scopes:
        if scope.kind == "top" and analysis.program is None:
            continue  # a snippet's variables belong to the program it is pasted into
        used = _reads_below(scope) if scope.kind != "top" else \
            {name.id for s in analysis.scopes for name in s.reads}
        for name, writes in scope.assigned.items():
            if name.startswith("_") or name in used or name in scope.params:
                continue
            if name in scope.declared_global:
                continue
            if scope.kind != "top" and analysis.is_global_in(name, scope):
                continue
            if scope.kind == "top" and any(name in s.declared_global for s in analysis.scopes):
                continue
            where = "function" if scope.kind == "function" else scope.kind
            message = (f"variable '{name}' is assigned but never read" if scope.kind == "top"
                       else f"local variable '{name}' of {where} {scope.name}() is assigned "
                       "but never read")
            yield ctx.diagnostic("URS112", writes[0], message,
                                 "remove it, or prefix its name with _ to keep it")


@rule(
    "URS113", "unused-parameter", "warning",
    "A function parameter that the function never reads.",
    """
Arguments are passed by value, so a parameter that is not read has no effect on anything:
often the body uses a global of a similar name by mistake. Names starting with `_` are
exempt.""",
    """
def approach(target, speed):
  movel(target, v=0.25)
end""",
    """
def approach(target, speed):
  movel(target, v=speed)
end""",
)
def unused_parameter(ctx: LintContext) -> Iterator[Diagnostic]:
    for scope in ctx.analysis.scopes:
        if scope.kind != "function" or not scope.params:
            continue
        used = _reads_below(scope)
        for name, param in scope.params.items():
            if name not in used and not name.startswith("_"):
                yield ctx.diagnostic(
                    "URS113", param, f"parameter '{name}' of {scope.name}() is never read",
                    "use it, remove it, or prefix its name with _")


@rule(
    "URS114", "builtin-shadowed", "warning",
    "A function or thread named like a builtin, or a variable named like a builtin that the "
    "file also calls.",
    """
A `def` or `thread` with a builtin's name replaces the builtin for the whole program. A
variable or parameter with a builtin's name (`time`, `length`, `force`) is reported only when
the same file also calls that builtin: then a reader cannot tell the two apart, and the
manual does not say that variables and functions live in separate namespaces.""",
    "sleep = 0.5\nsleep(sleep)",
    "wait_time = 0.5\nsleep(wait_time)",
)
def builtin_shadowed(ctx: LintContext) -> Iterator[Diagnostic]:
    called = {call.func.id for _scope, call in ctx.calls()}  # type: ignore[union-attr]

    def shadows(name: str, variable: bool) -> bool:
        builtin = lookup(name)
        if builtin is None or not builtin.callable:
            return False
        return not variable or name in called

    for _scope, statement in ctx.scoped_statements():
        if isinstance(statement, (n.FunctionDef, n.ThreadDef, n.SecDef)):
            if shadows(statement.name, False):
                kind = {n.FunctionDef: "function", n.ThreadDef: "thread",
                        n.SecDef: "sec program"}[type(statement)]
                yield ctx.diagnostic(
                    "URS114", ctx.name_span(statement),
                    f"{kind} '{statement.name}' hides the builtin {statement.name}()",
                    "choose another name")
            if isinstance(statement, n.FunctionDef):
                for param in statement.params:
                    if shadows(param.name, True):
                        yield ctx.diagnostic(
                            "URS114", param, f"parameter '{param.name}' has the name of the "
                            f"builtin {param.name}(), which this file also calls",
                            "choose another name")
        elif isinstance(statement, n.Assign) and isinstance(statement.target, n.Name):
            if shadows(statement.target.id, True):
                yield ctx.diagnostic(
                    "URS114", statement.target, f"variable '{statement.target.id}' has the "
                    f"name of the builtin {statement.target.id}(), which this file also calls",
                    "choose another name")
        elif isinstance(statement, n.Declare) and shadows(statement.name, True):
            yield ctx.diagnostic(
                "URS114", statement, f"variable '{statement.name}' has the name of the "
                f"builtin {statement.name}(), which this file also calls", "choose another name")


@rule(
    "URS119", "python-habit", "error",
    "A name from Python (or C) that URScript does not have, with the URScript way.",
    """
`print`, `len`, `range`, `str`, `int`, `abs`, `math.sqrt`, `true`, `null`, `import`, ... are
not URScript: the controller stops with "name is not defined". The habits that are syntax
errors (`for`, `+=`, `**`, `is`, f-strings, `else if`) are reported as URS001 with the same
kind of hint. A file that defines a function of the same name is left alone.""",
    "print(\"done\")",
    "textmsg(\"done\")",
)
def python_habit(ctx: LintContext) -> Iterator[Diagnostic]:
    for scope in ctx.analysis.scopes:
        for name in scope.reads:
            prefixed = ctx.string_prefix(name)
            if prefixed is not None and not ctx.analysis.defined(name.id, scope):
                if name.id.lower() in ("f", "rf", "fr"):
                    yield ctx.diagnostic(
                        "URS119", prefixed, "URScript has no f-strings",
                        'build the text with str_cat and to_str: str_cat("x = ", to_str(x))')
                else:
                    yield ctx.diagnostic(
                        "URS119", prefixed, f"URScript strings have no '{name.id}' prefix",
                        "write the string without it")
                continue
            hint = _habit(name.id, ctx, scope)
            if hint:
                yield ctx.diagnostic("URS119", name, f"'{name.id}' is not URScript", hint)
        for call in scope.calls:
            name = call.func.id  # type: ignore[union-attr]
            hint = _habit(name, ctx, scope)
            if hint and name not in ctx.analysis.functions:
                yield ctx.diagnostic("URS119", call.func, f"'{name}()' is not URScript", hint)


@rule(
    "URS120", "local-at-first-level", "warning",
    "`local` at the first level of a program, where every variable is global anyway.",
    """
The URScript manual: variables at the first level of the program are global even when
declared `local`. The word misleads readers into thinking the variable is private.""",
    "def main():\n  local count = 0\nend",
    "def main():\n  count = 0\nend",
)
def local_at_first_level(ctx: LintContext) -> Iterator[Diagnostic]:
    for declare in ctx.analysis.top.declared_local.values():
        yield ctx.diagnostic(
            "URS120", declare, f"'local {declare.name}' at the first level of the program is "
            "global anyway", f"write `{declare.name} = ...` (or `global {declare.name}`)")


@rule(
    "URS121", "duplicate-definition", "warning",
    "Two functions or threads with the same name.",
    """
Every `def` and `thread` is global, nested ones too, so a second definition of a name
replaces the first for the whole program (or is rejected by the controller): one of the two
bodies never runs.""",
    "def home():\n  movej(q_home)\nend\ndef home():\n  movej(q_park)\nend",
    "def home():\n  movej(q_home)\nend\ndef park():\n  movej(q_park)\nend",
)
def duplicate_definition(ctx: LintContext) -> Iterator[Diagnostic]:
    definitions: dict[str, list[n.Stmt]] = {}
    for table in (ctx.analysis.functions, ctx.analysis.threads, ctx.analysis.secs):
        for name, nodes in table.items():
            definitions.setdefault(name, []).extend(nodes)
    for name, nodes in definitions.items():
        if len(nodes) < 2:
            continue
        nodes = sorted(nodes, key=lambda node: node.span.start)  # type: ignore[attr-defined]
        first = nodes[0].span.line  # type: ignore[attr-defined]
        for node in nodes[1:]:
            yield ctx.diagnostic(
                "URS121", ctx.name_span(node), f"'{name}' is defined again (first at line {first})",
                "rename one of them or delete the unused one")
