"""Run the rules over one text: parse, analyse the scopes once, call every selected rule.

A syntax error (URS001) stops there: the rules need a tree. A comment ``# noqa`` on a line
silences every finding on it, ``# noqa: URS112, URS113`` only those codes (as in ruff).
"""

from __future__ import annotations

import re

from ..script import nodes as n
from ..script.diagnostics import Diagnostic, ScriptError
from ..script.parser import parse
from ..script.urcaps import by_urcap_block, urcap_blocks
from . import calls, flow, motion, names  # noqa: F401 - importing registers the rules
from .config import LintSettings, build_settings
from .context import LintContext
from .registry import DEPTH_RULE, RULES, URCAP_CODE_RULE
from .scope import analyse

__all__ = ["lint_text", "lint_tree"]

_NOQA = re.compile(r"\s*noqa\b(?:\s*:\s*(?P<codes>[A-Za-z0-9_, \-]+))?", re.IGNORECASE)
_SEVERITY_ORDER = {"error": 0, "warning": 1, "info": 2}


def lint_text(text: str, filename: str = "<string>",
              settings: LintSettings | None = None, project=None) -> list[Diagnostic]:
    """All findings for URScript ``text``, sorted by place. ``project`` is the file's
    :class:`urdsl.project.FileContext`: names defined elsewhere in the project resolve there.

    >>> [d.code for d in lint_text("movej([0, 0, 0, 0, 0])")]
    ['URS108']
    """
    try:
        tree = parse(text, filename)
    except ScriptError as error:
        return [error.diagnostic]
    return lint_tree(tree, settings, project)


def lint_tree(tree: n.Module, settings: LintSettings | None = None,
              project=None) -> list[Diagnostic]:
    """All findings for a parsed file (its nodes must carry spans); ``project`` as for
    :func:`lint_text`."""
    settings = settings or build_settings()
    source = tree.span.source or n.Source("", "<generated>")
    found: list[Diagnostic] = []
    skipped: list[str] = []
    try:
        analysis = analyse(tree)
    except RecursionError:
        analysis = None
        skipped.append("all")
    if analysis is not None:
        ctx = LintContext(source, tree, analysis, settings.model, settings.version, project)
        for code, rule in sorted(RULES.items()):
            if rule.check is None or code not in settings.codes:
                continue
            try:
                found.extend(rule.check(ctx))
            except RecursionError:
                skipped.append(code)
    if skipped and DEPTH_RULE.code in settings.codes:
        found.append(Diagnostic.at(
            n.Span(source, 0, 0), f"blocks nest too deeply to lint; skipped: "
            f"{', '.join(skipped)}", code=DEPTH_RULE.code, severity=DEPTH_RULE.severity,
            hint="split the deep nesting into functions"))
    found = _folded_in_urcap_code(_without_noqa(found, tree), tree,
                                  URCAP_CODE_RULE.code in settings.codes)
    unique = {(d.line, d.column, d.code, d.message): d for d in found}
    return sorted(unique.values(), key=lambda d: (d.line, d.column, d.code))


def _without_noqa(found: list[Diagnostic], tree: n.Module) -> list[Diagnostic]:
    silenced: dict[int, set[str] | None] = {}
    for node in n.walk(tree):
        if isinstance(node, n.Comment):
            match = _NOQA.match(node.text)
            if match is None:
                continue
            codes = match.group("codes")
            silenced[node.span.line] = (
                None if codes is None
                else {c.strip().upper() for c in codes.split(",") if c.strip()}
            )
    if not silenced:
        return found
    kept = []
    for diagnostic in found:
        line = silenced.get(diagnostic.line, set())
        if line is None or diagnostic.code in line:
            continue
        kept.append(diagnostic)
    return kept


def _folded_in_urcap_code(found: list[Diagnostic], tree: n.Module,
                          shown: bool) -> list[Diagnostic]:
    """Warnings and infos inside code a URCap wrote into the program (``# begin: URCap ...``
    to ``# end: ...``) folded into one URS122 info per block that counts them (none when
    ``shown`` is False: the rule is not selected): the user cannot change that code, the URCap
    writes it anew at every save. Errors stay as they are."""
    blocks = urcap_blocks(tree)
    if not blocks:
        return found
    kept, folded = by_urcap_block(blocks, found, lambda d: d.line,
                                  lambda d: d.severity != "error")
    if not shown:
        return kept
    source = tree.span.source or n.Source("", "<generated>")
    for (urcap, first, last), inside in folded.items():
        codes = ", ".join(sorted({d.code for d in inside}))
        text = source.line_text(first)
        start = source.line_start(first) + len(text) - len(text.lstrip())  # at the comment
        kept.append(Diagnostic.at(
            n.Span(source, start, start),
            f"{len(inside)} finding(s) ({codes}) in the code {urcap} wrote into the "
            f"program (lines {first}-{last}) not shown: the URCap writes that code anew at "
            "every save", code=URCAP_CODE_RULE.code, severity=URCAP_CODE_RULE.severity))
    return kept

