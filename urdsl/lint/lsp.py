"""``urdsl lsp``: a Language Server Protocol server for URScript over stdio (pygls).

What an editor gets:

* diagnostics from the linter when a document is opened, changed or saved (the settings of
  the nearest ``pyproject.toml`` apply, as for ``urdsl lint``);
* hover: the signature of a builtin (with its first controller version, deprecation and
  remarks from the catalog), or the ``def`` line of a function of the file;
* go to definition of functions, threads and global variables;
* formatting of the whole document with the printer of ``urdsl fmt`` (``tabSize`` from 1 to
  :data:`MAX_TAB_SIZE` is used as given, up to :data:`ABSURD_TAB_SIZE` it is clamped to
  :data:`MAX_TAB_SIZE`; beyond, or not a whole number, the answer is an "invalid params"
  error).

Diagnostics of an edited document are debounced: they are published
:data:`DEBOUNCE_SECONDS` after the last change (a burst of keystrokes is linted once, the
last version always); opening and saving publish at once.

Positions: LSP counts characters in UTF-16 code units, urdsl in code points; the two agree
for every character of the Basic Multilingual Plane, which is all URScript ever holds.
"""

from __future__ import annotations

import asyncio
import re
from collections.abc import Callable
from pathlib import Path

from lsprotocol import types

from .. import __version__
from ..script import nodes as n
from ..script.builtins import lookup, methods
from ..script.diagnostics import Diagnostic, ScriptError
from ..script.parser import parse
from ..script.printer import format as format_tree
from .config import ConfigError, LintSettings, build_settings, settings_for
from .linter import lint_tree
from .scope import analyse

__all__ = ["ABSURD_TAB_SIZE", "DEBOUNCE_SECONDS", "MAX_TAB_SIZE", "Debouncer",
           "FormattingOptionsError", "FormattingTooLargeError", "MAX_FORMATTED_CHARS",
           "build_server", "format_edits", "indent_for", "serve",
           "to_lsp_diagnostic", "word_at"]

DEBOUNCE_SECONDS = 0.3
"""Quiet time (s) after a document's last change before its diagnostics are published."""

MAX_TAB_SIZE = 16
"""Widest indent (spaces) the formatter writes; wider requests are clamped to it."""

MAX_FORMATTED_CHARS = 10_000_000
"""Longest formatted document the server sends (characters): indentation grows with the
square of the nesting depth, and a document thousands of levels deep would format to
gigabytes; such a request is answered with a "request failed" error instead."""

ABSURD_TAB_SIZE = 1_000
"""A ``tabSize`` above this is refused with an "invalid params" error, not clamped (an
editor that sends it is broken; 10^8 spaces per level used to end in a MemoryError)."""

_REQUEST_FAILED = -32803  # LSP's RequestFailed error code
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_SEVERITY = {
    "error": types.DiagnosticSeverity.Error,
    "warning": types.DiagnosticSeverity.Warning,
    "info": types.DiagnosticSeverity.Information,
}


def to_lsp_diagnostic(diagnostic: Diagnostic) -> types.Diagnostic:
    """A urdsl finding as an LSP diagnostic (0-based positions, the hint in the message)."""
    line = max(diagnostic.line - 1, 0)
    start = max(diagnostic.column - 1, 0)
    end = (diagnostic.end_column - 1 if diagnostic.end_column and diagnostic.end_column >
           diagnostic.column else start + 1)
    message = diagnostic.message if not diagnostic.hint else \
        f"{diagnostic.message}\nhint: {diagnostic.hint}"
    return types.Diagnostic(
        range=types.Range(types.Position(line, start), types.Position(line, end)),
        message=message, severity=_SEVERITY.get(diagnostic.severity),
        code=diagnostic.code, source="urdsl",
    )


def word_at(text: str, line: int, character: int) -> str | None:
    """The name under a 0-based position, or None."""
    lines = text.split("\n")
    if not 0 <= line < len(lines):
        return None
    for match in _WORD.finditer(lines[line]):
        if match.start() <= character <= match.end():
            return match.group(0)
    return None


def _path(uri: str) -> str | None:
    if not uri.startswith("file:"):
        return None
    from urllib.parse import unquote, urlparse

    return unquote(urlparse(uri).path)


def _settings(uri: str) -> LintSettings:
    try:
        return settings_for(_path(uri))
    except ConfigError:
        return build_settings()


def lint_document(uri: str, text: str) -> list[types.Diagnostic]:
    """The LSP diagnostics of a document."""
    path = _path(uri)
    name = Path(path).name if path else uri
    try:
        tree = parse(text, name)
    except ScriptError as error:
        return [to_lsp_diagnostic(error.diagnostic)]
    return [to_lsp_diagnostic(d) for d in lint_tree(tree, _settings(uri),
                                                    _project(path, text, name))]


def _project(path: str | None, text: str, name: str):
    """The project context of a file on disk (with the editor's text for the file itself),
    or None for a buffer that is not a file or a project urdsl cannot read."""
    if not path or not Path(path).parent.is_dir():
        return None
    from ..project import Project, ProjectError

    try:
        return Project.discover(path).context(path, text, name)
    except (ProjectError, OSError):
        return None


def hover_text(text: str, word: str) -> str | None:
    """Markdown for the name ``word`` in a document: a user ``def`` wins over a builtin."""
    try:
        tree = parse(text)
    except ScriptError:
        tree = None
    if tree is not None:
        analysis = analyse(tree)
        if word in analysis.functions:
            definition = analysis.functions[word][-1]
            params = ", ".join(p.name if p.default is None else f"{p.name}={_source(p.default)}"
                               for p in definition.params)
            return f"```urscript\ndef {word}({params})\n```\nfunction defined at line " \
                   f"{definition.span.line}"
        if word in analysis.threads:
            return f"```urscript\nthread {word}()\n```\nthread defined at line " \
                   f"{analysis.threads[word][-1].span.line}; start it with `run {word}()`"
    builtin = lookup(word) or methods().get(word)
    if builtin is None:
        return None
    lines = [f"```urscript\n{builtin.signature}\n```"]
    returns = " | ".join(builtin.returns) if builtin.returns else "None"
    from .calls import where_available

    lines.append(f"builtin ({builtin.module}), returns {returns}; on {where_available(builtin)}")
    if builtin.deprecated:
        replaced = ", ".join(builtin.replaced_by) or "see the manual"
        lines.append(f"**deprecated**: use {replaced}")
    if builtin.remarks:
        lines.append(builtin.remarks)
    return "\n\n".join(lines)


def _source(expr: n.Expr) -> str:
    span = getattr(expr, "span", n.NO_SPAN)
    if span.source is None:
        return "..."
    return span.source.text[span.start:span.end]


def definition_of(text: str, word: str) -> n.Span | None:
    """Where ``word`` (a function, thread or global variable) is defined in ``text``."""
    try:
        tree = parse(text)
    except ScriptError:
        return None
    analysis = analyse(tree)
    for table in (analysis.functions, analysis.threads, analysis.secs):
        if word in table:
            node = table[word][0]
            return _name_span(node)
    for scope in analysis.scopes:
        if word in scope.declared_global:
            return scope.declared_global[word].span
    top = analysis.top
    if word in top.assigned:
        return top.assigned[word][0].span
    if word in top.declared_local:
        return top.declared_local[word].span
    return None


def project_definition(uri: str, text: str, word: str) -> types.Location | None:
    """Where another file of the document's project (its host program, a sibling script
    file, the installation variables) defines ``word``."""
    path = _path(uri)
    context = _project(path, text, Path(path).name) if path else None
    if context is None:
        return None
    kinds = frozenset(("function", "thread", "global", "installation variable"))
    found = context.definitions(word, kinds)
    if not found:
        return None
    definition = found[0][1]
    span = definition.span
    if definition.kind in ("function", "thread"):
        span = _name_span(definition.node)
    if span.source is None:
        return None
    return types.Location(Path(definition.filename).resolve().as_uri(), _range(span))


def _name_span(node: n.Node) -> n.Span:
    span = node.span  # type: ignore[attr-defined]
    match = re.compile(rf"\b{re.escape(node.name)}\b").search(  # type: ignore[attr-defined]
        span.source.text, span.start, span.end) if span.source else None
    return n.Span(span.source, match.start(), match.end()) if match else span


def _range(span: n.Span) -> types.Range:
    """The first line of a span (a definition's name line is what an editor should show)."""
    line = span.line - 1
    if span.end_line == span.line:
        end = span.end_column - 1
    else:
        end = len(span.source.line_text(span.line)) if span.source else span.column
    return types.Range(types.Position(line, span.column - 1), types.Position(line, end))


class FormattingOptionsError(ValueError):
    """Formatting options urdsl refuses (the server answers "invalid params" with this
    message)."""


class FormattingTooLargeError(ValueError):
    """The formatted document would be longer than :data:`MAX_FORMATTED_CHARS` (the server
    answers "request failed" with this message)."""


def indent_for(options: types.FormattingOptions) -> str:
    """The indent of one block level for LSP formatting ``options``: ``tabSize`` spaces
    (clamped to :data:`MAX_TAB_SIZE`) when ``insertSpaces``, else two spaces.

    >>> indent_for(types.FormattingOptions(4, True))
    '    '
    >>> len(indent_for(types.FormattingOptions(100, True)))
    16
    """
    if not options.insert_spaces:
        return "  "
    size = options.tab_size
    if isinstance(size, float) and size.is_integer():
        size = int(size)
    if isinstance(size, bool) or not isinstance(size, int):
        raise FormattingOptionsError(f"tabSize must be a whole number, not {size!r}")
    if not 1 <= size <= ABSURD_TAB_SIZE:
        raise FormattingOptionsError(
            f"tabSize {size} is out of range: urdsl indents 1 to {MAX_TAB_SIZE} spaces")
    return " " * min(size, MAX_TAB_SIZE)


def format_edits(source: str, options: types.FormattingOptions) -> list[types.TextEdit] | None:
    """The edits that format a whole document: none when it is formatted already, None when
    it does not parse (its diagnostics show why). Raises :class:`FormattingOptionsError`
    for options urdsl refuses, :class:`FormattingTooLargeError` when the result would be
    longer than :data:`MAX_FORMATTED_CHARS`."""
    indent = indent_for(options)
    try:
        tree = parse(source)
    except ScriptError:
        return None
    # printed with one space per level first: its size and indentation predict the size
    # with the requested indent before that text is built
    formatted = format_tree(tree, indent=" ")
    depths = [len(line) - len(line.lstrip(" ")) for line in formatted.split("\n")]
    predicted = len(formatted) + sum(depths) * (len(indent) - 1)
    if predicted > MAX_FORMATTED_CHARS:
        raise FormattingTooLargeError(
            f"formatting would write {predicted:,} characters (the document nests "
            f"{max(depths):,} levels deep); not formatted")
    if indent != " ":
        formatted = format_tree(tree, indent=indent)
    if formatted == source:
        return []
    lines = source.split("\n")
    end = types.Position(len(lines) - 1, len(lines[-1]))
    return [types.TextEdit(types.Range(types.Position(0, 0), end), formatted)]


class Debouncer:
    """Runs a callback per key once things settle: :meth:`schedule` again before the delay
    has passed replaces the pending call, so only the last one runs. Lives on the running
    asyncio loop (the server's)."""

    def __init__(self, delay: float = DEBOUNCE_SECONDS) -> None:
        self.delay = delay  # s
        self._pending: dict[str, asyncio.TimerHandle] = {}

    def schedule(self, key: str, callback: Callable[[], None]) -> None:
        """Call ``callback`` after :attr:`delay` seconds unless ``key`` is scheduled or
        cancelled again before."""
        self.cancel(key)
        self._pending[key] = asyncio.get_running_loop().call_later(
            self.delay, self._fire, key, callback)

    def cancel(self, key: str) -> None:
        """Drop the pending call of ``key``, if any."""
        handle = self._pending.pop(key, None)
        if handle is not None:
            handle.cancel()

    def pending(self, key: str) -> bool:
        """Whether a call of ``key`` waits."""
        return key in self._pending

    def _fire(self, key: str, callback: Callable[[], None]) -> None:
        self._pending.pop(key, None)
        callback()


def build_server():
    """A pygls server with urdsl's features registered (not started)."""
    from pygls.lsp.server import LanguageServer

    server = LanguageServer("urdsl", __version__,
                            text_document_sync_kind=types.TextDocumentSyncKind.Full)

    debouncer = Debouncer()

    def publish(ls, uri: str) -> None:
        debouncer.cancel(uri)
        document = ls.workspace.get_text_document(uri)
        ls.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=uri, version=document.version, diagnostics=lint_document(uri, document.source)))

    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls, params: types.DidOpenTextDocumentParams) -> None:
        publish(ls, params.text_document.uri)

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    async def did_change(ls, params: types.DidChangeTextDocumentParams) -> None:
        uri = params.text_document.uri
        debouncer.schedule(uri, lambda: publish(ls, uri))

    @server.feature(types.TEXT_DOCUMENT_DID_SAVE)
    def did_save(ls, params: types.DidSaveTextDocumentParams) -> None:
        publish(ls, params.text_document.uri)

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(ls, params: types.DidCloseTextDocumentParams) -> None:
        debouncer.cancel(params.text_document.uri)
        ls.text_document_publish_diagnostics(types.PublishDiagnosticsParams(
            uri=params.text_document.uri, diagnostics=[]))

    @server.feature(types.TEXT_DOCUMENT_HOVER)
    def hover(ls, params: types.HoverParams) -> types.Hover | None:
        document = ls.workspace.get_text_document(params.text_document.uri)
        word = word_at(document.source, params.position.line, params.position.character)
        text = hover_text(document.source, word) if word else None
        if text is None:
            return None
        return types.Hover(contents=types.MarkupContent(types.MarkupKind.Markdown, text))

    @server.feature(types.TEXT_DOCUMENT_DEFINITION)
    def definition(ls, params: types.DefinitionParams) -> types.Location | None:
        document = ls.workspace.get_text_document(params.text_document.uri)
        word = word_at(document.source, params.position.line, params.position.character)
        span = definition_of(document.source, word) if word else None
        if span is None or span.source is None:
            return project_definition(params.text_document.uri, document.source, word) \
                if word else None
        return types.Location(params.text_document.uri, _range(span))

    @server.feature(types.TEXT_DOCUMENT_FORMATTING)
    def formatting(ls, params: types.DocumentFormattingParams) -> list[types.TextEdit] | None:
        from pygls.exceptions import JsonRpcException, JsonRpcInvalidParams

        document = ls.workspace.get_text_document(params.text_document.uri)
        try:
            return format_edits(document.source, params.options)
        except FormattingOptionsError as error:
            raise JsonRpcInvalidParams(str(error)) from None
        except FormattingTooLargeError as error:
            raise JsonRpcException(str(error), code=_REQUEST_FAILED) from None

    return server


def serve() -> None:
    """Run the language server on stdin/stdout until the client says exit."""
    build_server().start_io()
