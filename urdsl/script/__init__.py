"""The URScript language core: syntax tree, parser, printer, builtin catalog, diagnostics."""

from __future__ import annotations

from .diagnostics import Diagnostic, ScriptError, ScriptSyntaxError
from .nodes import Module, Source, Span
from .parser import Parser, parse

__all__ = [
    "Diagnostic", "Module", "Parser", "ScriptError", "ScriptSyntaxError", "Source", "Span",
    "parse",
]
