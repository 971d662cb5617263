"""Run a fragment where it runs: the definitions a file needs from the rest of its project,
put before it so that ``urdsl check`` can execute it.

A fragment (a file PolyScope inlines into a program) uses names of its host program, of
sibling script files and of the installation variables. :func:`in_context` finds the ones the
file uses (and, in turn, the ones those definitions use), and returns the file's tree with
them in front: installation variables first, then the hosts' first-level assignments in the
order their values need them, then the ``def``/``thread`` definitions. Each keeps its own
span, so a message about it names its own file and line. A complete program (a host) gets
only the installation variables: whatever else it lacks is its own error.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from ..script import nodes as n
from .model import Definition, FileContext, Project

__all__ = ["CheckContext", "in_context", "needed_names"]

_READ = frozenset(("global", "installation variable"))
_CALL = frozenset(("function",))
_THREAD = frozenset(("thread",))
_MAX_DEFINITIONS = 10_000


@dataclass(frozen=True)
class CheckContext:
    """The tree to run (the file's own, with the definitions it needs in front), the
    definitions added, and a sentence for the report. ``hostless``: the file is a fragment
    that no program of the project includes (:attr:`FileContext.hostless`)."""

    module: n.Module
    definitions: tuple[Definition, ...]
    hosts: tuple[str, ...]
    note: str
    hostless: bool = False


def needed_names(module: n.Module) -> tuple[set[str], set[str], set[str]]:
    """``(variables, functions, threads)`` that ``module`` uses without defining them
    (builtins excluded)."""
    from ..lint.scope import BUILTIN_VARIABLES, analyse
    from ..script.builtins import lookup

    try:
        analysis = analyse(module)
    except RecursionError:
        return set(), set(), set()
    reads: set[str] = set()
    calls: set[str] = set()
    threads: set[str] = set()
    for scope in analysis.scopes:
        first_write = _first_writes(scope) if scope.kind == "top" else {}
        early = _read_before_declared(scope) if scope.kind == "top" else set()
        for name in scope.reads:
            # a name the controller may define itself (``pi``, [U]) is still looked up in the
            # project: a project that assigns it gives it the value the file reads
            if not analysis.defined(name.id, scope) or (
                    name.id in BUILTIN_VARIABLES and not _bound_in_file(analysis, name.id, scope)):
                reads.add(name.id)
            elif name.span.start < first_write.get(name.id, -1) or name.id in early:
                # read at the first level before the file's first write of it (``if
                # run_program:`` ... ``run_program = False``), or before the statement
                # that declares it global with a value: the value comes from the host
                reads.add(name.id)
        for call in scope.calls:
            name = call.func.id  # type: ignore[union-attr]
            if name in analysis.functions or name in analysis.threads:
                continue
            if lookup(name) is None and not analysis.defined(name, scope):
                calls.add(name)
        for run in scope.runs:
            if run.thread not in analysis.threads:
                threads.add(run.thread)
    return reads, calls, threads


def _first_writes(scope) -> dict[str, int]:
    """Where (character offset) the first level of a file first writes each variable it
    assigns without declaring it (``x = 1``; a ``global``/``local`` declaration binds the name
    from the start)."""
    found: dict[str, int] = {}
    for name, nodes in scope.assigned.items():
        if name in scope.declared_global or name in scope.declared_local:
            continue
        found[name] = min(node.span.start for node in nodes)
    return found


def _read_before_declared(scope) -> set[str]:
    """Globals the first level of a file (or of the program ``def`` a file wraps itself in)
    reads in a statement before (or in) the one that declares them with a value (``while
    command == last:`` ... ``global last = command``): there the name holds what the program
    gave it before (the Init script a PolyScope program runs first, say). By statement
    order, not by offset: a file's context puts other files' definitions first. A function's
    own order says nothing (another function may set the global before it is called)."""
    declared = {name for name, d in scope.declared_global.items()
                if name not in scope.params and name not in scope.declared_local}
    if not declared:
        return set()
    seen: set[str] = set()
    early: set[str] = set()
    for statement in scope.body:
        if isinstance(statement, (n.FunctionDef, n.ThreadDef)):
            continue
        nodes = list(n.walk(statement))
        targets = {id(x.target) for x in nodes if type(x) is n.Assign}
        reads = {x.id for x in nodes
                 if type(x) is n.Name and x.id in declared and id(x) not in targets}
        early |= reads - seen
        seen |= {x.name for x in nodes if type(x) is n.Declare and x.value is not None
                 and x.scope == "global"}
    return early


def _bound_in_file(analysis, name: str, scope) -> bool:
    """Whether reading ``name`` in ``scope`` finds a variable, function or thread of the file
    itself (the controller's own variables not counted)."""
    if scope.sees(name):
        return True
    return name in analysis.globals or name in analysis.functions or name in analysis.threads


def _assigned_free(function: n.Stmt) -> set[str]:
    """The variables ``function`` (a ``def`` or ``thread``) assigns without declaring them
    ``local`` (its parameters excluded): globals where one of that name exists."""
    from ..lint.scope import analyse

    try:
        analysis = analyse(_alone(function))
    except RecursionError:
        return set()
    found: set[str] = set()
    for scope in analysis.scopes:
        if scope.kind == "top":
            continue
        found.update(name for name in scope.assigned
                     if name not in scope.declared_local and name not in scope.params)
    return found


def _alone(statement: n.Stmt) -> n.Module:
    """A module holding one statement, never taken for a whole program."""
    return n.Module((statement, n.ExprStmt(n.NoneLit())))


def in_context(path: str | Path, text: str, module: n.Module, filename: str | None = None,
               include: tuple[str | Path, ...] | list = (), use_config: bool = True,
               project: Project | None = None) -> CheckContext | None:
    """``module`` (parsed from ``text``, the file at ``path``) with the definitions it needs
    from its project in front, or None when it needs none that the project has (unless it
    is a fragment that no program of the project includes and needs names, which the
    report then explains)."""
    project = project or Project.discover(path, include, use_config)
    context = project.context(path, text, filename)
    chosen, without_value = _collect(context, module)
    if not chosen and not without_value and not (context.hostless
                                                 and any(needed_names(module))):
        return None
    variables = [d for d in chosen if d.kind == "installation variable"]
    assignments = [d for d in chosen if d.kind == "global"]
    definitions = [d for d in chosen if d.kind in ("function", "thread")]
    prelude = tuple(d.node for d in variables + assignments + definitions)
    program = _program_def(module)
    if program is not None:
        index = module.body.index(program)
        wrapped = dataclasses.replace(program, body=prelude + program.body)
        combined = dataclasses.replace(module, body=(*module.body[:index], wrapped,
                                                     *module.body[index + 1:]))
    else:
        combined = dataclasses.replace(module, body=prelude + module.body)
    files = list(dict.fromkeys(d.filename for d in chosen))
    hosts = tuple(context.host_names)
    if hosts:
        note = f"checked in the context of {', '.join(hosts)}"
        others = [f for f in files if f not in hosts]
        if others:
            note += f", with definitions from {', '.join(others)}"
    elif files:
        note = f"checked with definitions from {', '.join(files)}"
    else:
        note = "checked alone"
    if context.hostless:
        note = f"a fragment that no program of the project includes, {note}"
    if chosen:
        note += f" ({len(chosen)} definition(s): {', '.join(d.name for d in chosen[:8])}" + \
            (", ..." if len(chosen) > 8 else "") + ")"
    if without_value:
        note += ("; the project gives " + ", ".join(dict.fromkeys(without_value)) + " a value "
                 "only inside a function or loop or in a file that does not include this one, "
                 "from values not known before this file runs")
    return CheckContext(combined, tuple(chosen), hosts, note, context.hostless)


def _given_later(statement: n.Stmt | None, name: str, resolvable) -> n.Stmt | None:
    """A global's first value given inside a block or function (``global wp =
    get_actual_tcp_pose()`` in a loop), as a ``global`` declaration to run first — when
    everything its value needs is defined in the project or built in (not a local of the
    function it was written in)."""
    if statement is None:
        return None
    value = statement.value  # type: ignore[attr-defined]
    declaration = n.Declare("global", name, value, span=statement.span)  # type: ignore
    reads, calls, threads = needed_names(n.Module((declaration,)))
    if all(resolvable(r, _READ) for r in reads) and all(
            resolvable(c, _CALL) for c in calls) and all(resolvable(t, _THREAD) for t in threads):
        return declaration
    return None


def _opaque(definition: Definition) -> n.Declare:
    """``global name = <unknown>`` for a global the project defines in another file with a
    value that is not known when this file runs (see :func:`_settled`)."""
    source = (f"'{definition.name}', which {definition.where} sets where this file does not "
              "run it")
    return n.Declare("global", definition.name, n.Opaque(source, definition.span),
                     span=definition.span)


def _settled(script, name: str, statement: n.Stmt | None) -> bool:
    """Whether a global of a file that neither includes this one nor is included by it has a
    value known here: given once in that file, by a constant expression (``global speed =
    0.25``, at its first level or in a function; a name in it is such a global too). A global
    the other file sets again, or computes from the arm or a device (``init_pos =
    get_actual_tcp_pose()`` after the operator placed the arm), holds whatever that file's
    run left in it: unknown offline."""
    return _settled_in(script, name, statement, frozenset())


def _settled_in(script, name: str, statement: n.Stmt | None, seen: frozenset[str]) -> bool:
    if statement is None or name in seen or _writes(script).get(name, 0) != 1:
        return False
    value = getattr(statement, "value", None)
    if value is None:
        return False
    seen = seen | {name}
    for node in n.walk(value):
        if isinstance(node, n.Name):  # another settled global of that file (``-pi/2``)
            other = script.top_level.get(node.id) or script.assigned_later.get(node.id)
            if not _settled_in(script, node.id, other, seen):
                return False
        elif not isinstance(node, _CONSTANT_NODES):
            return False
    return True


_CONSTANT_NODES = (n.Number, n.String, n.Bool, n.NoneLit, n.Pose, n.List, n.Paren,
                   n.UnaryOp, n.BinOp)


_WRITES: dict[int, tuple[object, dict[str, int]]] = {}


def _writes(script) -> dict[str, int]:
    """How many statements of ``script`` give each variable a value (cached per file); an
    assignment of an element or member (``grip_detected[i] = True``) counts for the variable
    that holds it, as it changes what the variable holds."""
    cached = _WRITES.get(id(script))
    if cached is not None and cached[0] is script:
        return cached[1]
    counts: dict[str, int] = {}
    if script.module is not None:
        for node in n.walk(script.module):
            if isinstance(node, n.Assign):
                target = node.target
                while isinstance(target, (n.Index, n.Attribute)):
                    target = target.value
                if isinstance(target, n.Name):
                    counts[target.id] = counts.get(target.id, 0) + 1
            elif isinstance(node, n.Declare) and node.value is not None:
                counts[node.name] = counts.get(node.name, 0) + 1
    if len(_WRITES) > 512:
        _WRITES.clear()
    _WRITES[id(script)] = (script, counts)
    return counts


def _program_def(module: n.Module) -> n.FunctionDef | None:
    from ..lint.scope import program_def

    program = program_def(module)
    return program if isinstance(program, n.FunctionDef) else None


def _collect(context: FileContext, module: n.Module) -> tuple[list[Definition], list[str]]:
    """The definitions ``module`` needs, dependencies before their users; and the globals it
    reads that the project gives a value only where it cannot be computed first."""
    host_only = context.role == "host"
    chosen: list[Definition] = []
    without_value: list[str] = []
    visited: set[tuple[str, str]] = set()
    files = {script.filename: script for script in context.project.files}

    def pick(name: str, kinds: frozenset[str], use: str) -> Definition | None:
        for relation, definition in context.definitions(name, kinds):
            if host_only and relation not in ("variables", "explicit"):
                continue
            if definition.kind == "global":
                script = files.get(definition.filename)
                if script is None:
                    continue
                statement = script.top_level.get(name)
                if relation == "other":
                    first = statement or script.assigned_later.get(name)
                    if not _settled(script, name, first):
                        statement = None  # what the other file leaves in it is unknown here
                    elif statement is None:
                        statement = _given_later(first, name, resolvable)
                elif statement is None:
                    statement = _given_later(script.assigned_later.get(name), name,
                                             resolvable)
                if statement is None:  # a value that cannot be computed before the file runs
                    without_value.append(name)
                    if relation != "other":
                        continue  # a host's: undefined when this file runs (the test above)
                    statement = _opaque(definition)
                return dataclasses.replace(definition, node=statement,
                                           span=statement.span)  # type: ignore[attr-defined]
            return definition
        return None

    def resolvable(name: str, kinds: frozenset[str]) -> bool:
        return any(not host_only or relation in ("variables", "explicit")
                   for relation, _d in context.definitions(name, kinds))

    def need(name: str, kinds: frozenset[str], use: str) -> None:
        if (use, name) in visited or len(chosen) >= _MAX_DEFINITIONS:
            return
        visited.add((use, name))
        definition = pick(name, kinds, use)
        if definition is None:
            return
        if definition.kind in ("function", "thread"):
            follow(_alone(definition.node))
            # a name it assigns without ``local`` is its file's global where that file has
            # one (the controller binds a free variable to a global of that name): taken alone,
            # the function would read its own unassigned local instead
            for written in sorted(_assigned_free(definition.node)):
                if any(other.kind == "global" and other.filename == definition.filename
                       for _relation, other in context.definitions(written, _READ)):
                    need(written, _READ, "read")
        else:
            follow(n.Module((definition.node,)))
        chosen.append(definition)

    def follow(tree: n.Module) -> None:
        reads, calls, threads = needed_names(tree)
        for name in sorted(reads):
            need(name, _READ, "read")
        for name in sorted(calls):
            need(name, _CALL, "call")
        for name in sorted(threads):
            need(name, _THREAD, "thread")

    follow(module)
    return chosen, without_value
