"""Errors of DSL programs, placed at the line of the user's Python file that caused them.

A DSL program is Python: a mistake (five joints, a negative speed, an unknown builtin) is
found when the user's line runs. :class:`DslError` names that line the way a compiler
does::

    pick.py:12: error: movej needs 6 joint angles, got 5
      program.movej([0, -1.57, 0, -1.57, 0])
      hint: a joint vector is [base, shoulder, elbow, wrist1, wrist2, wrist3] in rad

:func:`caller` finds that line: the innermost stack frame outside the ``urdsl`` package.
Statements the DSL builds carry a :class:`~urdsl.script.nodes.Span` into the Python file, so
the verifier reports its findings at the Python line too.
"""

from __future__ import annotations

import linecache
import sys
from dataclasses import dataclass
from pathlib import Path

from ..script.nodes import NO_SPAN, Source, Span

__all__ = ["DslError", "Location", "caller"]

_PACKAGE = str(Path(__file__).resolve().parents[1])  # .../urdsl


@dataclass(frozen=True)
class Location:
    """A line of the user's Python file (1-based)."""

    filename: str
    line: int

    @property
    def text(self) -> str:
        return linecache.getline(self.filename, self.line).rstrip("\n")

    def span(self) -> Span:
        """A span over this line's code (from its first non-blank character), in a
        :class:`Source` of the whole file, so that diagnostics show the Python line."""
        source = _source(self.filename)
        if source is None:
            return NO_SPAN
        starts = source._starts()
        if not 1 <= self.line <= len(starts):
            return NO_SPAN
        text = source.line_text(self.line)
        begin = starts[self.line - 1] + (len(text) - len(text.lstrip()))
        return Span(source, begin, starts[self.line - 1] + len(text.rstrip()))


_SOURCES: dict[str, Source | None] = {}


def _source(filename: str) -> Source | None:
    if filename not in _SOURCES:
        lines = linecache.getlines(filename)
        _SOURCES[filename] = Source("".join(lines), filename) if lines else None
    return _SOURCES[filename]


def caller() -> Location | None:
    """The innermost stack frame outside the urdsl package: the user's line."""
    frame = sys._getframe(1)
    while frame is not None:
        filename = frame.f_code.co_filename
        if not str(Path(filename).resolve()).startswith(_PACKAGE):
            return Location(filename, frame.f_lineno)
        frame = frame.f_back
    return None


class DslError(Exception):
    """A mistake in a DSL program, at the user's line (``location``), with a ``hint``."""

    def __init__(self, message: str, hint: str | None = None,
                 location: Location | None = None) -> None:
        self.message = message
        self.hint = hint
        self.location = location if location is not None else caller()
        super().__init__(self.render())

    def render(self) -> str:
        """``file:line: error: message``, the line, and the hint."""
        if self.location is None:
            lines = [f"error: {self.message}"]
        else:
            lines = [f"{self.location.filename}:{self.location.line}: error: {self.message}"]
            text = self.location.text.strip()
            if text:
                lines.append(f"  {text}")
        if self.hint:
            lines.append(f"  hint: {self.hint}")
        return "\n".join(lines)
