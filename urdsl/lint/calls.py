"""Rules about calls: builtins missing in the target controller version or deprecated, and
arguments that do not fit the signature (of a builtin or of a ``def`` in the file)."""

from __future__ import annotations

import difflib
from collections.abc import Iterator
from dataclasses import dataclass

from ..script import nodes as n
from ..script.builtins import Builtin
from ..script.diagnostics import Diagnostic
from .context import LintContext
from .registry import rule

_SERIES = {"cb": "CB3 (3.x)", "e": "e-Series (5.x)", "x": "PolyScope X (10.x)"}


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


@dataclass(frozen=True)
class _Signature:
    """What a call has to match: parameter names, which are required, whether any keyword
    is accepted (``struct``), and how to name the callee in messages."""

    title: str
    names: tuple[str, ...]
    required: tuple[bool, ...]
    any_keyword: bool
    text: str


def _signature(ctx: LintContext, call: n.Call) -> _Signature | None:
    name = call.func.id  # type: ignore[union-attr]
    definitions = ctx.analysis.functions.get(name)
    if definitions:
        definition = definitions[-1]
        names = tuple(p.name for p in definition.params)
        required = tuple(p.default is None for p in definition.params)
        text = f"{name}({', '.join(names)})"
        return _Signature(f"{name}()", names, required, False, text)
    builtin = ctx.builtin(call)
    if builtin is None or not builtin.callable:
        return None
    return _Signature(
        f"{name}()", tuple(p.name for p in builtin.params),
        tuple(not p.optional for p in builtin.params), builtin.variadic_keywords,
        builtin.signature,
    )


@rule(
    "URS105", "too-many-arguments", "error",
    "More positional arguments than the function has parameters, or one argument given twice.",
    """
The controller checks the number of arguments when it compiles the program. Checked against
the builtin catalog and against the `def`s of the file.""",
    "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0, 0)",
    "movej([0, -1.57, 0, -1.57, 0, 0], 1.4, 1.05, 0, 0)",
)
def too_many_arguments(ctx: LintContext) -> Iterator[Diagnostic]:
    for _scope, call in ctx.calls():
        signature = _signature(ctx, call)
        if signature is None:
            continue
        count = len(call.args)
        if count > len(signature.names):
            extra = call.args[len(signature.names)]
            yield ctx.diagnostic(
                "URS105", extra, f"{signature.title} takes at most {len(signature.names)} "
                f"argument{'s' if len(signature.names) != 1 else ''}, {count} given",
                f"the signature is {signature.text}")
        for keyword in call.keywords:
            if keyword.name in signature.names[:count]:
                yield ctx.diagnostic(
                    "URS105", keyword, f"argument '{keyword.name}' of {signature.title} is "
                    "given twice, by position and by name", "remove one of the two")


# What people write for the move parameters a, v, t, r.
_SYNONYMS = {
    "speed": "v", "velocity": "v", "vel": "v", "acceleration": "a", "acc": "a", "accel": "a",
    "time": "t", "duration": "t", "radius": "r", "blend": "r", "blend_radius": "r",
}


@rule(
    "URS106", "unknown-keyword", "error",
    "A keyword argument that the function has no parameter for.",
    """
`movej(q, speed=1.0)` is rejected: the parameters of a builtin have fixed names (movej takes
a, v, t, r). The hint names the closest parameter.""",
    "movej(q_home, speed=1.0)",
    "movej(q_home, v=1.0)",
)
def unknown_keyword(ctx: LintContext) -> Iterator[Diagnostic]:
    for _scope, call in ctx.calls():
        signature = _signature(ctx, call)
        if signature is None or signature.any_keyword:
            continue
        for keyword in call.keywords:
            if keyword.name in signature.names:
                continue
            close = difflib.get_close_matches(keyword.name, signature.names, n=1, cutoff=0.6)
            synonym = _SYNONYMS.get(keyword.name.lower())
            if synonym in signature.names:
                close = [synonym]
            hint = f"did you mean `{close[0]}`? " if close else ""
            yield ctx.diagnostic(
                "URS106", keyword, f"{signature.title} has no parameter '{keyword.name}'",
                f"{hint}the signature is {signature.text}")


@rule(
    "URS107", "missing-argument", "error",
    "A required argument is missing.",
    """
Parameters without a default value must be given, by position or by name.""",
    "set_standard_digital_out(3)",
    "set_standard_digital_out(3, True)",
)
def missing_argument(ctx: LintContext) -> Iterator[Diagnostic]:
    for _scope, call in ctx.calls():
        signature = _signature(ctx, call)
        if signature is None:
            continue
        given = set(signature.names[:len(call.args)]) | {k.name for k in call.keywords}
        missing = [name for name, required in zip(signature.names, signature.required,
                                                   strict=True)
                   if required and name not in given]
        if missing:
            listed = ", ".join(f"'{m}'" for m in missing)
            yield ctx.diagnostic(
                "URS107", call, f"{signature.title} is missing the argument"
                f"{'s' if len(missing) > 1 else ''} {listed}",
                f"the signature is {signature.text}")
