"""urdsl: write, check, send and observe Universal Robots programs.

The one-call API for the language core::

    import urdsl
    tree = urdsl.parse(text, filename="prog.script")   # raises ScriptSyntaxError
    text = urdsl.format(tree)                          # canonical URScript
"""

from __future__ import annotations

from .script.diagnostics import Diagnostic, ScriptError, ScriptSyntaxError
from .script.parser import parse
from .script.printer import format  # noqa: A004 - the API's name

__version__ = "0.1.0"

__all__ = ["Diagnostic", "ScriptError", "ScriptSyntaxError", "__version__", "format", "parse"]
