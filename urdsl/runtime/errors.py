"""Runtime errors of URScript programs, as the controller would report them.

Each error names the node that caused it, so the message carries ``file:line:col`` and the
source line, and a stable code:

========  ====================================================================
URS201    a name is not defined (the controller: ``name 'x' is not defined``)
URS202    index out of range
URS203    wrong type for an operation or argument
URS204    inverse kinematics found no solution
URS205    arithmetic error (division by zero, sqrt of a negative, ...)
URS206    wrong arguments in a call (count, unknown keyword, missing argument)
URS207    a thread ran without using physical time (no sync/sleep/move): the
          controller stops the program
URS208    something that is not a function was called, or a thread misused
URS209    a builtin that urdsl does not simulate was called
========  ====================================================================

Not errors: ``urdsl check`` reports what depends on a value unknown offline (a device's
reply, an input; :mod:`urdsl.runtime.unknown`) as the warning URS210, and a run that stops
early without an error (it waits for ever, or the wall-clock bound) as URS313.
"""

from __future__ import annotations

from ..script.diagnostics import Diagnostic, ScriptError
from ..script.nodes import NO_SPAN, Span

__all__ = ["ScriptRuntimeError", "CODES"]

CODES = {
    "undefined": "URS201",
    "index": "URS202",
    "type": "URS203",
    "ik": "URS204",
    "arithmetic": "URS205",
    "arguments": "URS206",
    "runaway": "URS207",
    "call": "URS208",
    "unsupported": "URS209",
}


class ScriptRuntimeError(ScriptError):
    """A URScript program failed while running (the controller would stop it)."""

    def __init__(self, kind: str, message: str, span: Span = NO_SPAN, hint: str | None = None,
                 time: float | None = None) -> None:
        super().__init__(Diagnostic.at(span, message, code=CODES[kind], hint=hint), span)
        self.kind = kind
        self.time = time
