"""The URScript linter: one small function per rule, stable rule codes ``URS1xx``.

>>> from urdsl.lint import lint_text
>>> for d in lint_text("movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])", "course.script"):
...     print(d.filename, d.line, d.column, d.code)
course.script 1 7 URS108

Rules are listed by ``urdsl rules`` (and :data:`RULES`); settings come from
``[tool.urdsl.lint]`` in ``pyproject.toml`` (:mod:`urdsl.lint.config`).
"""

from .config import ConfigError, LintSettings, build_settings, settings_for
from .linter import lint_text, lint_tree
from .registry import RULES, Rule

__all__ = [
    "lint_text", "lint_tree", "RULES", "Rule", "LintSettings", "ConfigError", "build_settings",
    "settings_for",
]
