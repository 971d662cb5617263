"""The third-party URScript corpus in ../shared/corpus, and a helper that fills the
placeholders of its templated files so that they become plain URScript."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import pytest

CORPUS = Path(os.environ.get(
    "URDSL_CORPUS", Path(__file__).resolve().parents[2] / "shared" / "corpus"
))


@dataclass(frozen=True)
class CorpusFile:
    name: str  # path relative to the corpus folder
    templated: bool
    notes: str

    @property
    def path(self) -> Path:
        return CORPUS / self.name

    def text(self) -> str:
        return self.path.read_text(encoding="utf-8")


def corpus_available() -> bool:
    return (CORPUS / "MANIFEST.tsv").exists()


def corpus_files() -> list[CorpusFile]:
    """The files listed in MANIFEST.tsv. Without the corpus, fail in CI and skip elsewhere."""
    manifest = CORPUS / "MANIFEST.tsv"
    if not manifest.exists():
        if os.environ.get("CI"):
            raise FileNotFoundError(f"corpus not found at {CORPUS}")
        pytest.skip(f"corpus not found at {CORPUS} (set URDSL_CORPUS)", allow_module_level=True)
    rows = manifest.read_text(encoding="utf-8").splitlines()[1:]
    files = []
    for row in rows:
        name, _repo, _path, _license, templated, notes = row.split("\t")
        files.append(CorpusFile(name, templated == "yes", notes))
    return files


# Values for named placeholders; others get a number (or text inside a string).
_VALUES = {
    "BEGIN_REPLACE": "",
    "SERVO_J_REPLACE": "lookahead_time=0.1, gain=300",
    "startup": 'textmsg("startup")',
    "script_code": 'textmsg("script code")',
    "test_framework_code": 'textmsg("framework")',
    "test_script_code": 'textmsg("test")',
}


def _jinja_blocks(text: str, folder: Path) -> str:
    """Keep the first branch of each {% if %} ... {% endif %}; inline {% include %}."""
    out: list[str] = []
    stack: list[bool] = []  # per open if: is the current branch kept?
    for line in text.splitlines(keepends=True):
        tag = re.match(r"\s*\{%-?\s*(\w+)(.*?)-?%\}\s*$", line)
        if tag is None:
            if all(stack):
                out.append(line)
            continue
        word, rest = tag.group(1), tag.group(2)
        if word == "if":
            stack.append(True)
        elif word in ("elif", "else"):
            stack[-1] = False
        elif word == "endif":
            stack.pop()
        elif word == "include" and all(stack):
            included = folder / re.search(r'"([^"]+)"', rest).group(1)
            out.append(included.read_text(encoding="utf-8") + "\n")
    return "".join(out)


def fill_template(text: str, path: Path) -> str:
    """Turn a templated corpus file into plain URScript, the way its host tool would."""
    text = _jinja_blocks(text, path.parent)

    def jinja_value(match: re.Match) -> str:
        name = match.group(1).strip()
        return _VALUES.get(name, "1")

    text = re.sub(r"\{\{(.*?)\}\}", jinja_value, text)
    # Python %-formatting (ros-industrial ur_driver/prog): %(name)s and %(name)d.
    text = re.sub(r"%\((\w+)\)s", "x", text)
    text = re.sub(r"%\((\w+)\)[dif]", "1", text)
    # ur_rtde's version-gated lines ($5.4 ..., $5.10|3.15 ...) are kept for a new
    # e-Series controller.
    text = re.sub(r"(?m)^\$\d+\.\d+(?:\|\d+\.\d+)? ?", "", text)
    # ur_rtde completes `x = # comment` lines with a register offset.
    text = re.sub(r"=\s*#", "= 0 #", text)
    # Hirebotics harness files start with dashboard-style lines before the program.
    if "\ndef " in text and not text.lstrip().startswith(("def", "#")):
        text = text[text.index("\ndef ") + 1:]
    return text
