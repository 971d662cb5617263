"""The rule registry: every lint rule with its stable code, severity and explanation.

A rule is a small function ``check(ctx) -> Iterator[Diagnostic]`` registered with
:func:`rule`. Codes never change meaning once published (as in ruff): ``URS001`` is a syntax
error (raised by the parser, see :mod:`urdsl.script.diagnostics`), ``URS1xx`` are lint rules,
``URS2xx`` runtime errors of the interpreter and ``URS3xx`` findings of the verifier; all
of them are in the one registry :data:`urdsl.rules.RULES`, this module adds the lint rules.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from ..rules import Rule, register
from ..script.diagnostics import Diagnostic

if TYPE_CHECKING:  # pragma: no cover
    from .context import LintContext

__all__ = ["Rule", "RULES", "rule", "SYNTAX_RULE", "DEPTH_RULE", "URCAP_CODE_RULE",
           "expand_codes"]

Check = Callable[["LintContext"], Iterator[Diagnostic]]


RULES: dict[str, Rule] = {}
"""The lint rules by code, in code order (filled as the rule modules are imported); every
rule of every stage is in :data:`urdsl.rules.RULES`."""


def _add(new: Rule) -> Rule:
    RULES[new.code] = register(new)
    return new


SYNTAX_RULE = Rule(
    code="URS001", name="syntax-error", severity="error",
    summary="The text is not URScript; the controller rejects the whole program.",
    explanation="""
The parser stops at the first token that cannot stand where it is and says what was
expected. Habits from other languages are named with the URScript way in the hint:
`for` loops (count with while), `+=` (write x = x + 1), `**` (pow(b, e)), `is`
(compare with ==), `else if` (elif), f-strings (str_cat and to_str), `=` in a condition
(compare with ==), a stray or missing bracket (with the place where it was opened).
No other rule runs on a file with a syntax error, and it is reported whatever --select and
--ignore say.""",
    example="p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])",
    fixed="p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3]", stage="parse",
)
_add(SYNTAX_RULE)

DEPTH_RULE = Rule(
    code="URS100", name="too-deep-to-lint", severity="info",
    summary="Blocks or expressions nest deeper than the linter follows; some rules skipped.",
    explanation="""
urdsl's parser accepts blocks nested thousands deep (generated programs do this), but some
rules walk the tree recursively and stop at Python's recursion limit. They are skipped for
that file, and this note says which; every other rule still runs.""",
    example="if a:\n  if a:\n    ... (2000 levels) ...\n  end\nend",
    fixed="split the deep nesting into functions",
)
_add(DEPTH_RULE)

URCAP_CODE_RULE = Rule(
    code="URS122", name="urcap-code", severity="info",
    summary="Warnings inside code a URCap wrote into the program, counted and not shown.",
    explanation="""
A PolyScope export holds the code each URCap writes into the program (`# begin: URCap
Installation Node` ... `# end: URCap Installation Node`): a gripper's functions and its
state variables, often thousands of lines. The URCap writes that code anew every time the
program is saved, so a warning there (a variable it never reads, say) is nothing the user
can change: such warnings become one info per block that counts them. An error inside the
block is reported as it is.""",
    example="def prog():\n  # begin: URCap Installation Node\n  #   Source: Gripper, 1.0, Maker\n"
            "  gripper_state = 0\n  # end: URCap Installation Node\nend",
    fixed="# nothing to change: the URCap writes that code",
)
_add(URCAP_CODE_RULE)


def rule(
    code: str, name: str, severity: str, summary: str, explanation: str, example: str,
    fixed: str,
) -> Callable[[Check], Check]:
    """Register the decorated function as the check of rule ``code``."""

    def add(check: Check) -> Check:
        _add(Rule(code, name, severity, summary, explanation, example, fixed, check))
        return check

    return add


def expand_codes(selectors: list[str]) -> set[str]:
    """Rule codes matched by ``selectors``: exact codes, prefixes (``URS1``, ``URS11``), rule
    names (``unused-variable``) or ``ALL``. Raises ValueError naming an unknown selector."""
    codes: set[str] = set()
    by_name = {r.name: r.code for r in RULES.values()}
    for selector in selectors:
        text = selector.strip()
        if not text:
            continue
        if text.upper() == "ALL":
            codes.update(RULES)
            continue
        if text in by_name:
            codes.add(by_name[text])
            continue
        matched = {c for c in RULES if c.startswith(text.upper())}
        if not matched:
            raise ValueError(f"unknown rule {text!r} (see 'urdsl rules')")
        codes.update(matched)
    return codes
