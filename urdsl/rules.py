"""The one registry of urdsl's rule codes, URS0xx–URS3xx, whichever part reports them.

Every code has a :class:`Rule`: its stable code and name, severity, a one-line summary, an
explanation, an example that triggers it and the example written right. ``urdsl rules``
lists and explains them all. Codes never change meaning once published (as in ruff):

=======  =================  ====================================================
codes    stage              reported by
=======  =================  ====================================================
URS001   ``parse``          the parser (a syntax error; every command)
URS1xx   ``lint``           ``urdsl lint`` (:mod:`urdsl.lint`)
URS2xx   ``runtime``        the interpreter (:mod:`urdsl.runtime.errors`), in
                            ``urdsl check`` and the virtual controller
URS3xx   ``check``          ``urdsl check`` (:mod:`urdsl.verify`)
=======  =================  ====================================================

Each part registers its own rules when it is imported (:func:`register`), next to the
function that finds them; this module imports nothing of urdsl, so every layer may import it.

>>> rule = Rule("URS999", "example-rule", "warning", "An example.", "Explained.", "x", "y",
...             stage="check")
>>> rule.describe().splitlines()[0]
'URS999 example-rule (warning)'
>>> rule.describe().splitlines()[1]
'reported by: urdsl check'
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Rule", "RULES", "register", "STAGES", "SEVERITIES"]

STAGES = {"parse": "every command", "lint": "urdsl lint", "runtime": "urdsl check",
          "check": "urdsl check"}
"""Where the findings of a rule come from, and the command that reports them."""

SEVERITIES = ("error", "warning", "info")


@dataclass(frozen=True)
class Rule:
    """One rule. ``example`` triggers it, ``fixed`` is the same code written right;
    ``check`` is the function that finds it (its signature depends on the ``stage``: see
    :mod:`urdsl.lint.registry` and :mod:`urdsl.verify.checks`), None where the finding comes
    from elsewhere (the parser, an exception of the interpreter)."""

    code: str
    name: str
    severity: str
    summary: str
    explanation: str
    example: str
    fixed: str
    check: Callable[..., Any] | None = field(default=None, compare=False, repr=False)
    stage: str = "lint"

    def __post_init__(self) -> None:
        if self.severity not in SEVERITIES or self.stage not in STAGES:  # pragma: no cover
            raise ValueError(f"rule {self.code}: bad severity or stage")

    def describe(self) -> str:
        """The text of ``urdsl rules CODE``."""
        lines = [f"{self.code} {self.name} ({self.severity})",
                 f"reported by: {STAGES[self.stage]}", "", self.summary, ""]
        lines += [self.explanation.strip(), "", "Example:"]
        lines += ["    " + line for line in self.example.strip().splitlines()]
        lines += ["", "Write instead:"]
        lines += ["    " + line for line in self.fixed.strip().splitlines()]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The rule as JSON (``urdsl rules --json``)."""
        return {
            "code": self.code, "name": self.name, "severity": self.severity,
            "stage": self.stage, "summary": self.summary,
            "explanation": " ".join(self.explanation.split()),
            "example": self.example, "fixed": self.fixed,
        }


RULES: dict[str, Rule] = {}
"""Every registered rule by code (filled as the modules that define rules are imported)."""


def register(rule: Rule) -> Rule:
    """Add ``rule`` to :data:`RULES`; a code or a name registered twice is a programming
    error (ValueError)."""
    if rule.code in RULES:
        raise ValueError(f"rule {rule.code} registered twice")
    if any(other.name == rule.name for other in RULES.values()):
        raise ValueError(f"rule name {rule.name!r} registered twice")
    RULES[rule.code] = rule
    return rule
