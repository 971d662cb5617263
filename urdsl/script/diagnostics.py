"""Diagnostics: what urdsl tells a user about a program, with ``file:line:col`` and a caret.

Inside the language core, problems are raised as :class:`ScriptSyntaxError`; at the boundary
to the user they are shown as :class:`Diagnostic` objects, rendered like a compiler does::

    course.script:1:44: error: unexpected ')': the pose opened at 1:6 is already closed
      p1 = p[0.200, -0.300, 0.300, 0.5, 0.0, -0.3])
                                                 ^
      hint: delete the ')'
"""

from __future__ import annotations

from dataclasses import dataclass

from .nodes import Source, Span

__all__ = ["Diagnostic", "ScriptSyntaxError", "ScriptError", "clip", "excerpt", "render"]

SEVERITIES = ("error", "warning", "info")

EXCERPT_WIDTH = 120
"""Characters of a source line a rendered finding shows at most: a longer line (a generated
one, ``f(f(f(...)))`` 20,000 characters long) is cut to a window around the column, so that
each finding's text stays short however long the line is."""

TEXT_WIDTH = 400
"""Characters of a message or hint a rendered finding shows at most (a message quotes names
and values from the program, which may be arbitrarily long)."""

_MORE = "..."


def clip(text: str, width: int = TEXT_WIDTH) -> str:
    """``text``, or its first ``width`` characters and ``...`` when it is longer."""
    return text if len(text) <= width else text[:width] + _MORE


def excerpt(line: str, column: int, end_column: int | None = None,
            width: int = EXCERPT_WIDTH) -> tuple[str, str]:
    """The source ``line`` as a finding shows it and the caret line under it, both at most
    about ``width`` characters: a longer line is cut to a window that holds ``column``
    (1-based), marked with ``...`` where text is left out; the underline from ``column`` to
    ``end_column`` (exclusive) stops at the window's end. Tabs count as one column.

    >>> excerpt("x = 1", 5)
    ('x = 1', '    ^')
    >>> text, caret = excerpt("y" * 1000 + " = 1", 1002)
    >>> len(text) <= 130, text[caret.index("^")]
    (True, '=')
    """
    text = line.expandtabs(1)
    at = max(column - 1, 0)
    span = 1
    if end_column is not None and end_column > column:
        span = end_column - column
    if len(text) <= width:
        return text, " " * at + "^" * span
    start = max(0, min(at - width // 3, len(text) - width))
    stop = min(len(text), start + width)
    shown = text[start:stop]
    prefix = _MORE if start > 0 else ""
    suffix = _MORE if stop < len(text) else ""
    column_in = len(prefix) + (at - start)
    underline = max(1, min(span, stop - at))
    return prefix + shown + suffix, " " * column_in + "^" * underline


@dataclass(frozen=True)
class Diagnostic:
    """One finding about a program.

    ``line`` and ``column`` are 1-based; ``code`` is a stable rule code (``URS001``);
    ``severity`` is ``"error"``, ``"warning"`` or ``"info"``.
    """

    filename: str
    line: int
    column: int
    severity: str
    code: str
    message: str
    hint: str | None = None
    source_line: str | None = None
    end_column: int | None = None

    @classmethod
    def at(
        cls,
        span: Span,
        message: str,
        *,
        code: str,
        severity: str = "error",
        hint: str | None = None,
    ) -> Diagnostic:
        """A diagnostic placed at a node's or token's span."""
        if span.source is None:
            return cls("<generated>", 0, 0, severity, code, message, hint)
        line, column = span.line, span.column
        end_column = span.end_column if span.end_line == line and span.end > span.start else None
        return cls(
            span.filename, line, column, severity, code, message, hint,
            span.source.line_text(line), end_column,
        )

    def to_dict(self) -> dict[str, object]:
        """The fields a JSON report carries."""
        return {
            "file": self.filename, "line": self.line, "column": self.column,
            "code": self.code, "severity": self.severity, "message": self.message,
            "hint": self.hint,
        }

    def render(self) -> str:
        """``file:line:col: severity: message``, the source line, a caret, and the hint."""
        head = f"{self.filename}:{self.line}:{self.column}: {self.severity}: " \
               f"{clip(self.message)}"
        if self.code:
            head += f" [{self.code}]"
        lines = [head]
        if self.source_line is not None:
            text, caret = excerpt(self.source_line, self.column, self.end_column)
            lines.append("  " + text)
            lines.append("  " + caret)
        if self.hint:
            lines.append(f"  hint: {clip(self.hint)}")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.render()


class ScriptError(Exception):
    """Base of errors about a URScript program; carries a :class:`Diagnostic`."""

    def __init__(self, diagnostic: Diagnostic, span: Span | None = None) -> None:
        super().__init__(diagnostic.render())
        self.diagnostic = diagnostic
        self.span = span  # where in the source, when known

    @property
    def line(self) -> int:
        return self.diagnostic.line

    @property
    def column(self) -> int:
        return self.diagnostic.column

    @property
    def hint(self) -> str | None:
        return self.diagnostic.hint

    @property
    def message(self) -> str:
        return self.diagnostic.message


class ScriptSyntaxError(ScriptError):
    """The text is not URScript. Rule code ``URS001``."""

    CODE = "URS001"

    @classmethod
    def at_offset(
        cls, source: Source, start: int, end: int, message: str, hint: str | None = None
    ) -> ScriptSyntaxError:
        span = Span(source, start, end)
        return cls(Diagnostic.at(span, message, code=cls.CODE, hint=hint), span)


def render(diagnostics: list[Diagnostic]) -> str:
    """All diagnostics, one block each, separated by blank lines."""
    return "\n\n".join(d.render() for d in diagnostics)
