"""Installation variables: the ``*.variables`` file PolyScope keeps beside an installation
(``default.variables``), one ``name=value`` line per variable, the value a URScript
expression (``counter=0``, ``home=p[0.1, -0.4, 0.3, 0, 3.14, 0]``). PolyScope writes it as a
Java properties file (``#`` comment lines with a time stamp, ``\\:`` and ``\\=`` escapes)
on CB3; from 5.x an XML document, ``<InstallationVariables><variable name="count" value="0"
favourite="false"/></InstallationVariables>``; either often gzip-compressed.

Every program run with that installation sees these names as globals. :func:`parse_variables`
reads the file without ever raising for bad content: a line that is not ``name=value`` or
whose value is not URScript becomes a diagnostic with ``file:line:col``, the other lines are
kept.

>>> [(v.name, v.line) for v in parse_variables("a=1\\nb=p[0,0,0,0,0,0]\\n").variables]
[('a', 1), ('b', 2)]
"""

from __future__ import annotations

import dataclasses
import html
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..script import nodes as n
from ..script.diagnostics import Diagnostic, ScriptError
from ..script.parser import parse
from .gz import InflateError, inflate

__all__ = ["InstallationVariable", "VariablesFile", "parse_variables", "parse_variables_file",
           "read_variables"]

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_CODE = "URS001"


@dataclass(frozen=True)
class InstallationVariable:
    """One ``name=value`` line. ``value`` is the parsed URScript expression; ``span`` the
    place of the name in the file (its line and column are 1-based)."""

    name: str
    value: n.Expr
    span: n.Span
    statement: n.Assign

    @property
    def line(self) -> int:
        return self.span.line

    @property
    def text(self) -> str:
        """The value as written (after Java's escapes and XML's entities are undone)."""
        span = self.value.span
        return span.source.text[span.start:span.end] if span.source is not None else ""


@dataclass
class VariablesFile:
    """A parsed ``.variables`` file: the variables in file order and the problems found."""

    filename: str
    variables: list[InstallationVariable] = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)

    def names(self) -> dict[str, InstallationVariable]:
        """Each variable by name (the last line wins, as PolyScope reads the file)."""
        return {variable.name: variable for variable in self.variables}


def parse_variables(text: str, filename: str = "<variables>") -> VariablesFile:
    """The variables of ``.variables`` text, in either form PolyScope writes; bad lines
    become URS001 diagnostics."""
    if text.lstrip().startswith("<"):
        return _parse_xml(text, filename)
    result = VariablesFile(filename)
    source = n.Source(text, filename)
    lines = text.split("\n")
    kept = list(lines)
    escaped = False
    good_lines: list[int] = []  # 0-based indices of lines that look like name=value
    for index, line in enumerate(lines):
        stripped = line.strip()
        if not stripped or stripped.startswith(("#", "!")):
            kept[index] = " " * len(line)
        else:
            name, equals, _value = line.partition("=")
            if not equals or not _NAME.fullmatch(name.strip()):
                column = len(line) - len(line.lstrip()) + 1
                result.diagnostics.append(Diagnostic(
                    filename, index + 1, column, "error", _CODE,
                    "an installation variable line must be name=value",
                    "write one variable a line, e.g. counter=0", line.rstrip("\r"),
                    None))
                kept[index] = " " * len(line)
            else:
                good_lines.append(index)
                if "\\" in line:  # a Java properties escape (\:, \=, \uXXXX)
                    lines[index] = name + "=" + _unescape(_value)
                    kept[index] = " " * len(line)
                    escaped = True
    # The usual file parses in one go (offsets stay those of the file). Otherwise each line is
    # parsed alone, after as many line breaks as precede it, so that its line number holds.
    statements: list[n.Stmt] = []
    try:
        if escaped:
            raise ScriptError(Diagnostic(filename, 1, 1, "error", _CODE, "escapes"))
        module = parse("\n".join(kept), filename)
        statements = [item for item in module.body if isinstance(item, n.Stmt)]
    except ScriptError:
        for index in good_lines:
            try:
                module = parse("\n" * index + lines[index], filename)
            except ScriptError as error:
                result.diagnostics.append(error.diagnostic)
                continue
            statements.extend(item for item in module.body if isinstance(item, n.Stmt))
    for item in statements:
        place = n.Span(source, *_file_offsets(source, item.span))  # type: ignore[attr-defined]
        if isinstance(item, n.Assign) and isinstance(item.target, n.Name):
            name_place = n.Span(source, *_file_offsets(source, item.target.span))
            result.variables.append(InstallationVariable(
                item.target.id, item.value, name_place, item))
        else:
            result.diagnostics.append(Diagnostic.at(
                place, "an installation variable line must be name=value", code=_CODE,
                hint="write one variable a line, e.g. counter=0"))
    result.diagnostics.sort(key=lambda d: (d.line, d.column))
    return result


_ELEMENT = re.compile(r"<variable\b([^>]*?)/?>", re.DOTALL)
_ATTRIBUTE = re.compile(r"""([A-Za-z_][\w.-]*)\s*=\s*(?:"([^"]*)"|'([^']*)')""")


def _parse_xml(text: str, filename: str) -> VariablesFile:
    """The XML form (PolyScope 5.x): ``<InstallationVariables><variable name="count"
    value="0" .../></InstallationVariables>``. Each ``value`` is parsed as URScript at its
    place in the file."""
    result = VariablesFile(filename)
    source = n.Source(text, filename)
    if "<InstallationVariables" not in text:
        result.diagnostics.append(Diagnostic.at(
            n.Span(source, 0, 1), "not an installation variables file (no "
            "<InstallationVariables> element)", code=_CODE))
        return result
    for element in _ELEMENT.finditer(text):
        attributes = {m.group(1): (m.group(2) if m.group(2) is not None else m.group(3),
                                   m.start(2) if m.group(2) is not None else m.start(3))
                      for m in _ATTRIBUTE.finditer(element.group(1))}
        base = element.start(1)
        if "name" not in attributes or "value" not in attributes:
            result.diagnostics.append(Diagnostic.at(
                n.Span(source, element.start(), element.end()),
                "a <variable> element needs a name and a value", code=_CODE))
            continue
        name, name_at = attributes["name"]
        raw, value_at = attributes["value"]
        name_span = n.Span(source, base + name_at, base + name_at + len(name))
        if not _NAME.fullmatch(name):
            result.diagnostics.append(Diagnostic.at(
                name_span, f"'{name}' is not a URScript variable name", code=_CODE))
            continue
        value_text = html.unescape(raw)
        line, column = source.line_col(base + value_at)
        try:
            module = parse("\n" * (line - 1) + " " * (column - 1) + value_text, filename)
        except ScriptError as error:  # shown with the file's own line
            diagnostic = error.diagnostic
            result.diagnostics.append(dataclasses.replace(
                diagnostic, source_line=source.line_text(diagnostic.line)))
            continue
        items = [item for item in module.body if isinstance(item, n.Stmt)]
        if len(items) != 1 or not isinstance(items[0], n.ExprStmt):
            result.diagnostics.append(Diagnostic.at(
                n.Span(source, base + value_at, base + value_at + len(raw)),
                f"the value of '{name}' is not one URScript expression", code=_CODE))
            continue
        value = items[0].expr
        statement = n.Assign(n.Name(name, span=name_span), value,
                             span=n.Span(source, element.start(), element.end()))
        result.variables.append(InstallationVariable(name, value, name_span, statement))
    return result


_ESCAPE = re.compile(r"\\(u[0-9a-fA-F]{4}|.)")
_ESCAPES = {"t": "\t", "n": "\n", "r": "\r", "f": "\f"}


def _unescape(value: str) -> str:
    """A value as Java's ``Properties`` reads it (PolyScope writes the file with it):
    ``\\:`` is ``:``, ``\\u00e9`` is ``é``."""
    def replace(match: re.Match) -> str:
        code = match.group(1)
        if len(code) == 5:
            return chr(int(code[1:], 16))
        return _ESCAPES.get(code, code)

    return _ESCAPE.sub(replace, value)


def _file_offsets(source: n.Source, span: n.Span) -> tuple[int, int]:
    """``span``'s offsets in the file ``source`` (the span may come from a text that holds
    only its line, after the same number of line breaks)."""
    if span.source is None:
        return 0, 0
    if len(span.source.text) == len(source.text):  # parsed in place: the same offsets
        return span.start, span.end
    line, column = span.line, span.column
    start = len("\n".join(source.text.split("\n")[:line - 1])) + (line > 1) + column - 1
    return start, start + (span.end - span.start)


def read_variables(path: str | Path) -> VariablesFile:
    """Read and parse a ``.variables`` file; an unreadable file is one diagnostic."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        return _unreadable(path, f"cannot read {path}: {error.strerror}")
    return parse_variables_file(data, str(path))


def parse_variables_file(data: bytes, filename: str = "<variables>") -> VariablesFile:
    """The variables of a ``.variables`` file's bytes (gzip-compressed, as PolyScope often
    saves it, or plain); a file that cannot be decompressed is one diagnostic."""
    try:
        data = inflate(data)
    except InflateError as error:
        return _unreadable(Path(filename), f"{filename} cannot be read: {error.reason}")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")  # Java writes properties files in ISO 8859-1
    return parse_variables(text, filename)


def _unreadable(path: Path, message: str) -> VariablesFile:
    result = VariablesFile(str(path))
    result.diagnostics.append(Diagnostic(str(path), 1, 1, "error", _CODE, message))
    return result
