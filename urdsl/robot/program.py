"""The text that is sent to a controller, and the way back from its line numbers.

The controller runs a script it receives on 30001/30002/30003 when the text starts with
``def name():`` in column 0 and ends with ``end`` in column 0 (docs/controller-facts.md §7: the
script manual's "Connecting to URControl"); a new ``def`` replaces the running program. So:

* a program that is one ``def`` without parameters (PolyScope's exports, the DSL's
  ``Program``) or only ``sec`` programs is sent as the printer prints it;
* anything else (bare statements, several definitions with statements between them) is
  wrapped into ``def urdsl_program():`` … ``end``, one level deeper. No call follows the
  ``end``: the controller runs the ``def`` it received, and a trailing line would break the
  "ends with ``end``" rule.

The text is always the printer's output (:func:`urdsl.script.printer.format`), newline
terminated. When the controller reports a runtime exception at line L, column C of the
text it received, :meth:`PreparedProgram.locate` finds the node printed there and returns
where that node came from in the user's file (a ``.script`` line, or the line of the
user's DSL program that built it), so the wrapping offset never reaches the user.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..script import nodes as n
from ..script.parser import parse
from ..script.printer import format as format_tree

__all__ = ["PreparedProgram", "Location", "prepare_tree", "prepare_text", "needs_wrapping",
           "WRAPPER_NAME", "SENT_NAME"]

WRAPPER_NAME = "urdsl_program"
"""Name of the ``def`` that wraps bare statements."""

SENT_NAME = "<sent program>"
"""File name of the sent text in messages about lines that have no place in the user's file
(e.g. the wrapper's own ``def`` line)."""


@dataclass(frozen=True)
class Location:
    """A place in the user's file: 1-based line and column, and the line's text."""

    filename: str
    line: int
    column: int
    source_line: str | None

    def __str__(self) -> str:
        return f"{self.filename}:{self.line}:{self.column}"


def needs_wrapping(module: n.Module) -> bool:
    """Whether the controller would not recognise ``module`` as one program as printed."""
    statements = [item for item in module.body if isinstance(item, n.Stmt)]
    defs = [s for s in statements if isinstance(s, n.FunctionDef)]
    secs = [s for s in statements if isinstance(s, n.SecDef)]
    if len(defs) == 1 and len(statements) == 1 and not defs[0].params:
        return False
    return not (secs and len(secs) == len(statements))


@dataclass
class PreparedProgram:
    """What will be sent (``text``), where it came from (``tree``, ``filename``) and the
    correspondence between the two."""

    text: str
    filename: str
    tree: n.Module
    wrapped: bool
    _pairs: list[tuple[int, int, n.Node]]
    _sent: n.Source

    @property
    def name(self) -> str:
        """Name of the program's ``def`` (``sec``), as the controller reports it."""
        if self.wrapped:
            return WRAPPER_NAME
        for item in self.tree.body:  # printed as they are: no need to parse the text again
            if isinstance(item, (n.FunctionDef, n.SecDef)):
                return item.name
        return WRAPPER_NAME

    def sent_line(self, line: int) -> str:
        """Text of a 1-based line of the sent program."""
        return self._sent.line_text(line)

    def locate(self, line: int, column: int = 0) -> Location | None:
        """Where the node at ``line``/``column`` of the sent text came from in the user's
        file; ``None`` for lines urdsl added (the wrapper) or outside the text.

        ``column`` is 1-based; 0 means unknown, and then the first statement on the line
        counts. A column past the line's text also falls back to the line.
        """
        if line < 1:
            return None
        starts = self._sent._starts()
        if line > len(starts):
            return None
        begin = starts[line - 1]
        end = starts[line] - 1 if line < len(starts) else len(self._sent.text)
        candidates: list[tuple[int, int, n.Node]] = []
        if column >= 1 and begin + column - 1 < end:
            offset = begin + column - 1
            candidates = [p for p in self._pairs if p[0] <= offset < p[1]]
        if not candidates:  # the line's statements (a statement may start on the line)
            candidates = [p for p in self._pairs
                          if begin <= p[0] < max(end, begin + 1) and isinstance(p[2], n.Stmt)]
            if candidates:
                first = min(p[0] for p in candidates)
                candidates = [p for p in candidates if p[0] == first]
            else:
                candidates = [p for p in self._pairs if p[0] <= begin and end <= p[1]]
        if not candidates:
            return None
        start, stop, node = min(candidates, key=lambda p: p[1] - p[0])
        span = node.span
        return Location(span.filename, span.line, span.column,
                        span.source.line_text(span.line) if span.source else None)


def _pairs(original: n.Node, sent: n.Node) -> list[tuple[int, int, n.Node]]:
    """(start, end) of every sent node whose original has a span, with the original."""
    pairs = []
    for before, after in zip(n.walk(original), n.walk(sent), strict=True):
        if type(before) is not type(after):  # pragma: no cover - parse(format(t)) == t
            raise AssertionError(f"printed tree differs: {type(before)} vs {type(after)}")
        span = getattr(before, "span", n.NO_SPAN)
        if span.source is not None and after.span.source is not None:
            pairs.append((after.span.start, after.span.end, before))
    return pairs


def prepare_tree(module: n.Module, filename: str) -> PreparedProgram:
    """The sendable text of a parsed (or DSL-built) program, with its line map."""
    wrapped = needs_wrapping(module)
    tree = module
    if wrapped:
        body = tuple(module.body)
        tree = n.Module((n.FunctionDef(WRAPPER_NAME, (), body),))
    text = format_tree(tree)
    if not text.endswith("\n"):
        text += "\n"
    sent_source = n.Source(text, SENT_NAME)
    sent = parse(text, SENT_NAME)
    pairs = _pairs(tree, sent)
    if sent.body:
        sent_source = _source_of(sent) or sent_source
    return PreparedProgram(text, filename, module, wrapped, pairs, sent_source)


def _source_of(module: n.Module) -> n.Source | None:
    for node in n.walk(module):
        span = getattr(node, "span", n.NO_SPAN)
        if span.source is not None:
            return span.source
    return None


def prepare_text(text: str, filename: str = "<program>") -> PreparedProgram:
    """Parse ``text`` (raises :class:`urdsl.script.diagnostics.ScriptSyntaxError`) and
    prepare it for sending."""
    return prepare_tree(parse(text, filename), filename)
