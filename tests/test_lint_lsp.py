"""``urdsl lsp`` driven by a real LSP client (pygls's) over the stdio pipes of a subprocess.

Every wait is bounded: a server that does not answer fails the test instead of hanging it.
"""

from __future__ import annotations

import asyncio
import sys

from lsprotocol import types
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
    assert results["returncode"] == 0
