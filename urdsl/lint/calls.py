"""Rules about calls: builtins missing in the target controller version or deprecated, and
arguments that do not fit the signature (of a builtin or of a ``def`` in the file)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

from ..script import nodes as n
from ..script.binder import Problem, Signature, problems
from ..script.builtins import Builtin
from ..script.diagnostics import Diagnostic
from .context import LintContext
from .registry import rule

_SERIES = {"cb": "CB2/CB3 (1.x-3.x)", "e": "e-Series (5.x)", "x": "PolyScope X (10.x)"}


def _version_text(version: tuple[int, int]) -> str:
    return f"{version[0]}.{version[1]}"


def where_available(builtin: Builtin) -> str:
    """Where a builtin exists, for a message: "from 5.15 on e-Series"."""
    parts = []
    for series, first in builtin.first_versions().items():
        if first is None:
            parts.append(_SERIES[series])
        else:
            parts.append(f"{_SERIES[series]} from {_version_text(first)}")
    return ", ".join(parts) if parts else "controller versions not known to urdsl"


@rule(
    "URS103", "not-in-version", "error",
    "A builtin that the target controller software version does not have.",
    """
With `--version` (or `version` in `[tool.urdsl.lint]`), every builtin is checked against the
catalog's first version per series: CB3 3.x, e-Series 5.x, PolyScope X 10.x. Such a program
fails on the robot with "name 'f' is not defined" (seen for str_cat on 3.7 and tool_contact
on old 5.x). Builtins whose first version the catalog only bounds ("documented by 5.15") are
not reported.""",
    "# urdsl lint --version 3.15\nl = make_list(3, 0, 10)",
    "# urdsl lint --version 5.15\nl = make_list(3, 0, 10)",
)
def not_in_version(ctx: LintContext) -> Iterator[Diagnostic]:
    if ctx.version is None:
        return
    version = _version_text(ctx.version)
    for _scope, call in ctx.calls():
        builtin = ctx.builtin(call)
        if builtin is None or not builtin.callable:
            continue
        if builtin.available_in(ctx.version) is False:
            yield ctx.diagnostic(
                "URS103", call.func, f"{builtin.name}() is not available in controller "
                f"version {version} (it exists on {where_available(builtin)})",
                "choose another version with --version, or avoid this builtin")


@rule(
    "URS104", "deprecated", "warning",
    "A deprecated builtin, with the one that replaces it.",
    """
UR keeps deprecated builtins working for a while but removes them from new software and
documentation; e-Series programs should use the replacement (for example set_standard_*
and set_tool_* for the CB3 I/O functions, set_target_payload for set_payload).""",
    "set_digital_out(2, True)",
    "set_standard_digital_out(2, True)",
)
def deprecated(ctx: LintContext) -> Iterator[Diagnostic]:
    for _scope, call in ctx.calls():
        builtin = ctx.builtin(call)
        if builtin is None or not builtin.deprecated:
            continue
        hint = None
        if builtin.replaced_by and builtin.replaced_by[0].endswith("_"):
            hint = f"use the {builtin.replaced_by[0]}* functions"
        elif builtin.replaced_by:
            hint = "use " + " or ".join(f"{r}()" for r in builtin.replaced_by)
        yield ctx.diagnostic("URS104", call.func, f"{builtin.name}() is deprecated", hint)


def _problems(ctx: LintContext, call: n.Call) -> list[Problem]:
    """Every argument mistake of a call of a ``def`` of the file or of a builtin (against
    the signature rows that apply to the target version), from the one call binder."""
    name = call.func.id  # type: ignore[union-attr]
    keywords = tuple(k.name for k in call.keywords)
    definitions = ctx.analysis.functions.get(name)
    if definitions:
        # a file may define a name more than once (a URCap preamble's function and another
        # preamble's nested helper of the same name): a call that fits one of them is fine;
        # otherwise it is judged against the last, which the controller keeps at top level
        found: list[Problem] = []
        for definition in reversed(definitions):
            params = definition.params
            signature = Signature(name, tuple(p.name for p in params),
                                  tuple(p.default is None for p in params))
            mistakes = problems(signature, len(call.args), keywords)
            if not mistakes:
                return []
            found = found or mistakes
        return found
    builtin = ctx.builtin(call)
    if builtin is None or not builtin.callable:
        return []
    found = builtin.call_problems(len(call.args), keywords, ctx.version)
    if found and ctx.version is not None:  # the call may fit another generation's signature
        applicable = builtin.rows(ctx.version)
        other = next((row for row in (builtin, *builtin.variants) if row not in applicable
                      and not isinstance(row.call_signature.bind(len(call.args), keywords),
                                         Problem)), None)
        if other is not None:
            note = f"{other.signature} is the signature on {where_available(other)}"
            found = [replace(p, hint=f"{p.hint}; {note}" if p.hint else note) for p in found]
    return found


def _diagnostics(ctx: LintContext, code: str, kinds: tuple[str, ...]) -> Iterator[Diagnostic]:
    for _scope, call in ctx.calls():
        for problem in _problems(ctx, call):
            if problem.kind not in kinds:
                continue
            node: n.Node = call
            if problem.index is not None and problem.index < len(call.args):
                node = call.args[problem.index]
            elif problem.keyword is not None:
                node = next(k for k in call.keywords if k.name == problem.keyword)
            yield ctx.diagnostic(code, node, problem.message, problem.hint)


@rule(
    "URS105", "too-many-arguments", "error",
    "More positional arguments than the function has parameters, or one argument given twice.",
    """
The controller checks the number of arguments when it compiles the program. Checked against
the builtin catalog (every signature the target version accepts; without `--version`, the
signatures of every controller generation) and against the `def`s of the file.""",
    "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0, 0)",
    "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0)",
)
def too_many_arguments(ctx: LintContext) -> Iterator[Diagnostic]:
    yield from _diagnostics(ctx, "URS105", ("too-many", "twice", "positional"))


@rule(
    "URS106", "unknown-keyword", "error",
    "A keyword argument that the function has no parameter for.",
    """
`movej(q, speed=1.0)` is rejected: the parameters of a builtin have fixed names (movej takes
a, v, t, r). The hint names the closest parameter. Some names changed between controller
generations (`speedj(qd, a, t_min)` on CB3, `speedj(qd, a, t)` on e-Series): without
`--version` either is accepted.""",
    "movej(q_home, speed=1.0)",
    "movej(q_home, v=1.0)",
)
def unknown_keyword(ctx: LintContext) -> Iterator[Diagnostic]:
    yield from _diagnostics(ctx, "URS106", ("unknown-keyword",))


@rule(
    "URS107", "missing-argument", "error",
    "A required argument is missing.",
    """
Parameters without a default value must be given, by position or by name.""",
    "set_standard_digital_out(3)",
    "set_standard_digital_out(3, True)",
)
def missing_argument(ctx: LintContext) -> Iterator[Diagnostic]:
    yield from _diagnostics(ctx, "URS107", ("missing",))
