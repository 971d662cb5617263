"""Findings as text (ruff style), JSON, SARIF 2.1.0 and GitHub workflow annotations.

* ``text``: ``path:line:col: CODE message``, the source line with a caret under the place,
  the hint, and a summary line;
* ``json``: one JSON document, a list of ``{file, line, column, code, severity, message,
  hint}``;
* ``sarif``: a SARIF 2.1.0 log with the rules that ran and one result per finding (GitHub code
  scanning, VS Code's SARIF viewer and GitLab read it);
* ``github``: ``::error file=…,line=…,col=…,title=CODE::message`` lines, which a GitHub
  Actions step turns into annotations on the pull request.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path
from urllib.parse import quote

from .. import __version__
from ..script.diagnostics import Diagnostic, clip
from .registry import RULES, Rule

__all__ = ["FORMATS", "render_text", "render_json", "render_sarif", "render_github"]

FORMATS = ("text", "json", "sarif", "github")

_SARIF_LEVEL = {"error": "error", "warning": "warning", "info": "note"}
_GITHUB_LEVEL = {"error": "error", "warning": "warning", "info": "notice"}
_SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
_SNIPPET_WIDTH = 1000  # a longer line is left out of SARIF (a snippet is the whole line)


def render_one(diagnostic: Diagnostic) -> str:
    """One finding, ruff style: ``path:line:col: CODE message``, then the source line with a
    caret and the hint (as :meth:`Diagnostic.render` draws them)."""
    head = f"{diagnostic.filename}:{diagnostic.line}:{diagnostic.column}: " \
           f"{diagnostic.code} {clip(diagnostic.message)}"
    rest = diagnostic.render().split("\n")[1:]
    return "\n".join([head, *rest])


def summary(diagnostics: list[Diagnostic], files: int) -> str:
    """``Found 2 errors, 1 warning in 3 files.`` or ``All checks passed (3 files).``"""
    if not diagnostics:
        return f"All checks passed ({files} file{'s' if files != 1 else ''})."
    counts = Counter(d.severity for d in diagnostics)
    parts = []
    for severity, word in (("error", "error"), ("warning", "warning"), ("info", "note")):
        if counts[severity]:
            parts.append(f"{counts[severity]} {word}{'s' if counts[severity] != 1 else ''}")
    return f"Found {', '.join(parts)} in {files} file{'s' if files != 1 else ''}."


def render_text(diagnostics: list[Diagnostic], files: int) -> str:
    blocks = [render_one(d) for d in diagnostics]
    return "\n\n".join([*blocks, summary(diagnostics, files)]) + "\n"


def render_json(diagnostics: list[Diagnostic]) -> str:
    return json.dumps([d.to_dict() for d in diagnostics], indent=2, ensure_ascii=False) + "\n"


def _uri(filename: str) -> str:
    """A URI reference for a file name: relative paths stay relative (resolved against the
    repository root by code-scanning tools), absolute ones become ``file://`` URIs."""
    path = Path(filename)
    if path.is_absolute():
        return path.as_uri()
    return quote(path.as_posix())


def _sarif_rule(rule: Rule) -> dict:
    return {
        "id": rule.code,
        "name": rule.name,
        "shortDescription": {"text": rule.summary},
        "fullDescription": {"text": " ".join(rule.explanation.split())},
        "help": {"text": rule.describe()},
        "defaultConfiguration": {"level": _SARIF_LEVEL[rule.severity]},
    }


def render_sarif(diagnostics: list[Diagnostic], codes: set[str] | frozenset[str]) -> str:
    """A SARIF 2.1.0 log. ``codes`` are the rules that ran (listed in the tool's driver)."""
    rules = [RULES[c] for c in sorted(RULES) if c in codes or c == "URS001"]
    index = {rule.code: i for i, rule in enumerate(rules)}
    results = []
    for d in diagnostics:
        text = d.message if not d.hint else f"{d.message} (hint: {d.hint})"
        result: dict = {
            "ruleId": d.code,
            "level": _SARIF_LEVEL.get(d.severity, "warning"),
            "message": {"text": text},
        }
        if d.code in index:
            result["ruleIndex"] = index[d.code]
        location: dict = {"artifactLocation": {"uri": _uri(d.filename)}}
        if d.line >= 1:
            region: dict = {"startLine": d.line, "startColumn": max(d.column, 1)}
            if d.end_column is not None and d.end_column > d.column:
                region["endColumn"] = d.end_column
            if d.source_line is not None and len(d.source_line) <= _SNIPPET_WIDTH:
                region["snippet"] = {"text": d.source_line}
            location["region"] = region
        result["locations"] = [{"physicalLocation": location}]
        results.append(result)
    log = {
        "$schema": _SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {
                "name": "urdsl", "version": __version__, "rules": [_sarif_rule(r) for r in rules],
            }},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    }
    return json.dumps(log, indent=2, ensure_ascii=False) + "\n"


def _escape_data(text: str) -> str:
    return text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_property(text: str) -> str:
    return _escape_data(text).replace(":", "%3A").replace(",", "%2C")


def render_github(diagnostics: list[Diagnostic]) -> str:
    """GitHub Actions workflow commands, one line per finding (the hint on a second line of
    the annotation)."""
    lines = []
    for d in diagnostics:
        message = d.message if not d.hint else f"{d.message}\nhint: {d.hint}"
        lines.append(
            f"::{_GITHUB_LEVEL.get(d.severity, 'warning')} file={_escape_property(d.filename)},"
            f"line={d.line},col={d.column},title={_escape_property(d.code)}::"
            f"{_escape_data(message)}"
        )
    return "".join(line + "\n" for line in lines)
