"""``urdsl lsp`` driven by a real LSP client (pygls's) over the stdio pipes of a subprocess.

Every wait is bounded: a server that does not answer fails the test instead of hanging it.
"""

from __future__ import annotations

import asyncio
import sys
from types import SimpleNamespace

from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.lsp.client import LanguageClient

TIMEOUT = 30.0  # s, per request; the server answers in milliseconds once started

BROKEN = """\
global home = [0, -1.57, 0, -1.57, 0, 0]
def approach(target):
  movej([d2r(0), d2r(-90), d2r(0), d2r(-90), d2r(0)])
  movel(target)
end
approach(p[0.1, 0.2, 0.3, 0, 3.14, 0])
movej(home)
"""
FIXED = BROKEN.replace("d2r(0)])", "d2r(0), d2r(0)])")
BURST = 30  # changes sent at once
UGLY = "def f():\nmovej([0,0,0,0,0,0])\n    end\n"


async def _session() -> dict:
    client = LanguageClient("urdsl-test", "1")
    published: asyncio.Queue = asyncio.Queue()

    @client.feature(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def on_diagnostics(params: types.PublishDiagnosticsParams) -> None:
        published.put_nowait(params)

    await client.start_io(sys.executable, "-m", "urdsl.cli", "lsp")
    results: dict = {}
    try:
        init = await asyncio.wait_for(client.initialize_async(types.InitializeParams(
            capabilities=types.ClientCapabilities(), process_id=None, root_uri=None)), TIMEOUT)
        results["capabilities"] = init.capabilities
        client.initialized(types.InitializedParams())
        uri = "file:///nonexistent-urdsl-test/prog.script"
        doc = types.TextDocumentIdentifier(uri)
        client.text_document_did_open(types.DidOpenTextDocumentParams(
            types.TextDocumentItem(uri, "urscript", 1, BROKEN)))
        results["open"] = await asyncio.wait_for(published.get(), TIMEOUT)
        results["hover_builtin"] = await asyncio.wait_for(client.text_document_hover_async(
            types.HoverParams(doc, types.Position(2, 4))), TIMEOUT)
        results["hover_def"] = await asyncio.wait_for(client.text_document_hover_async(
            types.HoverParams(doc, types.Position(5, 2))), TIMEOUT)
        results["definition_function"] = await asyncio.wait_for(
            client.text_document_definition_async(types.DefinitionParams(
                doc, types.Position(5, 3))), TIMEOUT)
        results["definition_global"] = await asyncio.wait_for(
            client.text_document_definition_async(types.DefinitionParams(
                doc, types.Position(6, 8))), TIMEOUT)
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(uri=uri, version=2),
            [types.TextDocumentContentChangeWholeDocument(text=FIXED)]))
        results["change"] = await asyncio.wait_for(published.get(), TIMEOUT)
        client.text_document_did_change(types.DidChangeTextDocumentParams(
            types.VersionedTextDocumentIdentifier(uri=uri, version=3),
            [types.TextDocumentContentChangeWholeDocument(text=UGLY)]))
        await asyncio.wait_for(published.get(), TIMEOUT)
        results["format"] = await asyncio.wait_for(client.text_document_formatting_async(
            types.DocumentFormattingParams(doc, types.FormattingOptions(2, True))), TIMEOUT)
        try:  # 10^8 spaces per level used to end in a MemoryError (-32603)
            await asyncio.wait_for(client.text_document_formatting_async(
                types.DocumentFormattingParams(doc, types.FormattingOptions(10**8, True))),
                TIMEOUT)
        except JsonRpcException as error:
            results["absurd_format"] = error
        # a burst of keystrokes, sent without waiting: the last version is published
        for version in range(4, 4 + BURST):
            text = FIXED if version == 3 + BURST else BROKEN
            client.text_document_did_change(types.DidChangeTextDocumentParams(
                types.VersionedTextDocumentIdentifier(uri=uri, version=version),
                [types.TextDocumentContentChangeWholeDocument(text=text)]))
        burst = []
        while not burst or burst[-1].version != 3 + BURST:
            burst.append(await asyncio.wait_for(published.get(), TIMEOUT))
        results["burst"] = burst
        await asyncio.wait_for(client.shutdown_async(None), TIMEOUT)
        client.exit(None)
        await asyncio.wait_for(client._server.wait(), TIMEOUT)
        results["returncode"] = client._server.returncode
    finally:
        if client._server is not None and client._server.returncode is None:
            client._server.kill()
        await asyncio.wait_for(client.stop(), TIMEOUT)
    return results


def test_language_server_over_stdio():
    results = asyncio.run(asyncio.wait_for(_session(), 4 * 60))
    capabilities = results["capabilities"]
    assert capabilities.hover_provider and capabilities.definition_provider
    assert capabilities.document_formatting_provider

    (diagnostic,) = results["open"].diagnostics
    assert diagnostic.code == "URS108" and diagnostic.source == "urdsl"
    assert diagnostic.severity == types.DiagnosticSeverity.Error
    assert (diagnostic.range.start.line, diagnostic.range.start.character) == (2, 8)
    assert "hint:" in diagnostic.message
    assert list(results["change"].diagnostics) == []

    hover = results["hover_builtin"].contents.value
    assert "movej(q, a=1.4, v=1.05, t=0, r=0)" in hover
    assert "def approach(target)" in results["hover_def"].contents.value

    function = results["definition_function"]
    assert function.range.start.line == 1 and function.range.start.character == 4
    assert results["definition_global"].range.start.line == 0

    (edit,) = results["format"]
    assert edit.new_text == "def f():\n  movej([0, 0, 0, 0, 0, 0])\nend\n"
    assert results["absurd_format"].code == -32602  # invalid params, not a crash
    assert "tabSize" in results["absurd_format"].message
    assert list(results["burst"][-1].diagnostics) == []  # the fixed text, linted last
    assert results["returncode"] == 0


def test_formatting_options_are_validated_and_clamped():
    import pytest

    from urdsl._deep import run_deep
    from urdsl.lint.lsp import (
        MAX_TAB_SIZE,
        FormattingOptionsError,
        FormattingTooLargeError,
        format_edits,
        indent_for,
    )

    assert indent_for(types.FormattingOptions(4, True)) == "    "
    assert indent_for(types.FormattingOptions(10**8, False)) == "  "  # tabs: urdsl's default
    assert indent_for(types.FormattingOptions(500, True)) == " " * MAX_TAB_SIZE
    for absurd in (0, -1, 10**8, 2**31, 1.5, True, "4", None):
        # (lsprotocol's own class refuses some of these: the server may be handed others)
        options = SimpleNamespace(tab_size=absurd, insert_spaces=True)
        with pytest.raises(FormattingOptionsError):
            indent_for(options)  # type: ignore[arg-type]
    (edit,) = format_edits(UGLY, types.FormattingOptions(64, True))
    assert edit.new_text == "def f():\n" + " " * MAX_TAB_SIZE + "movej([0, 0, 0, 0, 0, 0])\nend\n"
    assert format_edits("def f(:\n", types.FormattingOptions(2, True)) is None
    # 3,000 levels at 16 spaces would be 72 MB of indentation: refused, not built
    deep = "while True:\n" * 3_000 + "sync()\n" + "end\n" * 3_000
    with pytest.raises(FormattingTooLargeError, match="3,000 levels"):
        run_deep(format_edits, deep, types.FormattingOptions(16, True))
    (edit,) = run_deep(format_edits, deep, types.FormattingOptions(1, True))
    assert edit.new_text.splitlines()[2_999] == " " * 2_999 + "while True:"


def test_debouncer_runs_only_the_last_call():
    from urdsl.lint.lsp import Debouncer

    calls: list[tuple[str, int]] = []

    async def burst() -> None:
        debouncer = Debouncer(0.01)
        for version in range(50):  # no await in between: each replaces the one before
            debouncer.schedule("a", lambda version=version: calls.append(("a", version)))
        debouncer.schedule("b", lambda: calls.append(("b", 0)))
        debouncer.schedule("c", lambda: calls.append(("c", 0)))
        debouncer.cancel("c")
        while debouncer.pending("a") or debouncer.pending("b"):
            await asyncio.sleep(0.01)

    asyncio.run(asyncio.wait_for(burst(), TIMEOUT))
    assert sorted(calls) == [("a", 49), ("b", 0)]
