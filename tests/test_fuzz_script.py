"""Fuzzing the language tools (issue 14): mutated real programs through parse, fmt and lint.

Seeds are the third-party corpus (templated files filled in, see ``_corpus.py``; skipped
quietly when the corpus is absent) and ``programs/**/*.script``. Each case applies one to
four mutations: a character or UTF-8 byte flipped, a token deleted, duplicated or swapped,
truncation, two files spliced, deep nesting, huge or odd numbers, odd white space and line
ends. The properties:

* ``parse`` raises only :class:`~urdsl.ScriptSyntaxError`, whose message names a line of
  the text and renders;
* when it parses, ``fmt`` output parses to the same tree, and formatting it again changes
  nothing;
* ``lint_text`` returns diagnostics (at lines of the text) and raises nothing;
* the language server's document handling (lint, hover, definition, formatting with random
  options) raises nothing but the documented refusal of absurd formatting options, and its
  formatting keeps the program's tree.

Bounded and seeded: each target runs for ``URDSL_FUZZ_SECONDS`` (default 3) of wall-clock
time and at least :data:`MIN_CASES` cases. Case ``i`` is made by ``random.Random(f"{seed}/
{target}/{i}")`` with ``seed = URDSL_FUZZ_SEED`` (default 14), so a failure message's seed
and case number rebuild it exactly; ``URDSL_FUZZ_CASE=i`` runs that case alone. ``make fuzz``
runs longer with a fresh seed.
"""

from __future__ import annotations

import os
import random
import re
import time
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from _corpus import corpus_available, corpus_files, fill_template

import urdsl
from urdsl._deep import run_deep
from urdsl.lint.linter import lint_text
from urdsl.script.diagnostics import Diagnostic

SECONDS = float(os.environ.get("URDSL_FUZZ_SECONDS", "3"))
SEED = os.environ.get("URDSL_FUZZ_SEED", "14")
ONLY_CASE = os.environ.get("URDSL_FUZZ_CASE")
MIN_CASES = 20
"""Cases run even when the time budget is spent first (a slow machine still fuzzes)."""

PROGRAMS = Path(__file__).resolve().parents[1] / "programs"


def _seeds() -> list[str]:
    texts = [path.read_text(encoding="utf-8") for path in sorted(PROGRAMS.rglob("*.script"))]
    if corpus_available():
        for item in corpus_files():
            text = item.text()
            texts.append(fill_template(text, item.path) if item.templated else text)
    return texts


SEEDS = _seeds()

# A program's text as tokens: white space, words and numbers, single other characters.
_TOKEN = re.compile(r"\s+|[0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?|\w+|.", re.DOTALL)

HUGE_NUMBERS = (
    "1e308", "1.7976931348623157e308", "1e309", "9" * 400, "1e-400", "4.9e-324", "0.", ".0",
    "00000000000000000001", "1e+308", "1E-9", "2147483648", "-2147483649", "1." + "0" * 300,
    "0x1F", "1_000", "1e", "1.e5", "--1", "- - 1",
)
ODD_SPACE = (" ", "\t", "\f", "\v", "\r", "\r\n", "\n\n\n", "\u00a0", "\u2028", "\x85", "\x00",
             "\ufeff", "  \t  ")
LINE_ENDS = ("\r", "\r\n", "\n\r", "\n\n", " \n", "\t\n", "\v", "\f", "\u2028", "\x85")
SNIPPETS = ("end", "if", "elif", "else:", "while", ":", "(", ")", "[", "]", "p[", ",", "=",
            "==", "def", "thread", "sec", "global", "local", "return", "run", "kill", "join",
            "halt", "break", "continue", "$ 1 \"a\"", "$", "#", "# c\n", "\"", "'", "\\", "not",
            "and", "True", "None", "enter_critical", "exit_critical", ".", "-", "%")


def _flip_char(rng: random.Random, text: str) -> str:
    if not text:
        return rng.choice(SNIPPETS)
    at = rng.randrange(len(text))
    pool = rng.choice((
        lambda: chr(rng.randrange(32, 127)), lambda: chr(rng.randrange(0, 0x3000)),
        lambda: rng.choice(" \t\r\n\"'#$()[]:,.=-+p\\"),
    ))
    return text[:at] + pool() + text[at + 1:]


def _flip_byte(rng: random.Random, text: str) -> str:
    data = bytearray(text.encode("utf-8", errors="surrogateescape"))
    if not data:
        return text
    at = rng.randrange(len(data))
    data[at] ^= 1 << rng.randrange(8)
    # undecodable bytes become lone surrogates, as a file read with surrogateescape would give
    return data.decode("utf-8", errors="surrogateescape")


def _tokens(text: str) -> list[str]:
    return _TOKEN.findall(text)


def _delete_token(rng: random.Random, text: str) -> str:
    tokens = _tokens(text)
    if tokens:
        del tokens[rng.randrange(len(tokens))]
    return "".join(tokens)


def _duplicate_token(rng: random.Random, text: str) -> str:
    tokens = _tokens(text)
    if tokens:
        at = rng.randrange(len(tokens))
        tokens.insert(at, tokens[at] * rng.choice((1, 1, 2, 50)))
    return "".join(tokens)


def _swap_tokens(rng: random.Random, text: str) -> str:
    tokens = _tokens(text)
    if len(tokens) > 1:
        i, j = rng.randrange(len(tokens)), rng.randrange(len(tokens))
        tokens[i], tokens[j] = tokens[j], tokens[i]
    return "".join(tokens)


def _insert_token(rng: random.Random, text: str) -> str:
    tokens = _tokens(text)
    tokens.insert(rng.randrange(len(tokens) + 1), rng.choice(SNIPPETS + ODD_SPACE))
    return "".join(tokens)


def _truncate(rng: random.Random, text: str) -> str:
    return text[:rng.randrange(len(text) + 1)]


def _splice(rng: random.Random, text: str) -> str:
    other = rng.choice(SEEDS)
    return text[:rng.randrange(len(text) + 1)] + other[rng.randrange(len(other) + 1):]


def _deep(rng: random.Random, text: str) -> str:
    """Nest a line (or a number) hundreds of levels deep, in blocks or in an expression."""
    depth = rng.choice((10, 100, rng.randrange(1, 600)))
    lines = text.split("\n")
    at = rng.randrange(len(lines) + 1)
    kind = rng.randrange(6)
    if kind == 0:
        head = "".join(rng.choice(("while True:\n", "if x:\n", "if a:\nelse:\n"))
                       for _ in range(depth))
        nested = head + "\n".join(lines[at:at + rng.randrange(1, 5)]) + "\nend" * depth
        return "\n".join(lines[:at] + [nested] + lines[at + 4:])
    if kind == 1:
        expression = "(" * depth + "1" + ")" * depth
    elif kind == 2:
        expression = "[" * depth + "1" + "]" * depth
    elif kind == 3:
        expression = "-" * depth + "1"
    elif kind == 4:
        expression = "f(" * depth + "1" + ")" * depth
    else:
        expression = " + ".join(rng.choice(("1", "x", "(2 * y)", "a.b[0]")) for _ in range(depth))
    return "\n".join(lines[:at] + [f"x = {expression}"] + lines[at:])


def _number(rng: random.Random, text: str) -> str:
    tokens = _tokens(text)
    numbers = [i for i, token in enumerate(tokens) if token[:1].isdigit() or token[:1] == "."]
    replacement = rng.choice(HUGE_NUMBERS)
    if numbers:
        tokens[rng.choice(numbers)] = replacement
    else:
        tokens.append(f"\nx = {replacement}\n")
    return "".join(tokens)


def _space(rng: random.Random, text: str) -> str:
    if rng.random() < 0.5:
        return text.replace("\n", rng.choice(LINE_ENDS))
    tokens = _tokens(text)
    spaces = [i for i, token in enumerate(tokens) if token.isspace()]
    for index in rng.sample(spaces, min(len(spaces), rng.randrange(1, 20))):
        tokens[index] = rng.choice(ODD_SPACE)
    return "".join(tokens)


MUTATIONS: tuple[Callable[[random.Random, str], str], ...] = (
    _flip_char, _flip_byte, _delete_token, _duplicate_token, _swap_tokens, _insert_token,
    _truncate, _splice, _deep, _number, _space,
)


def mutant(target: str, case: int) -> str:
    """The text of fuzz case ``case`` of ``target`` (the same for the same seed)."""
    rng = random.Random(f"{SEED}/{target}/{case}")
    text = rng.choice(SEEDS)
    if len(text) > 20_000 and rng.random() < 0.8:  # keep most cases quick: a window
        start = rng.randrange(len(text) - 10_000)
        text = text[start:start + rng.randrange(500, 10_000)]
    for _ in range(rng.randint(1, 4)):
        text = rng.choice(MUTATIONS)(rng, text)
    return text


def cases(target: str, minimum: int = MIN_CASES) -> Iterator[int]:
    """Case numbers for ``target``: until the time budget is spent (at least ``minimum``)."""
    if ONLY_CASE is not None:
        yield int(ONLY_CASE)
        return
    stop = time.monotonic() + SECONDS
    case = 0
    while case < minimum or time.monotonic() < stop:
        yield case
        case += 1
    print(f"\nfuzz {target}: {case} cases, seed {SEED}, {SECONDS:g} s")


class Failure(AssertionError):
    pass


class Findings:
    """The distinct failures of one target: a failure is told apart by its exception type
    and the line that raised it; the fuzzer goes on after one (a long run reports them all)
    and stops after :data:`LIMIT`."""

    LIMIT = 10

    def __init__(self, target: str, tmp_path: Path) -> None:
        self.target = target
        self.tmp_path = tmp_path
        self.found: dict[tuple[str, str], str] = {}

    @property
    def full(self) -> bool:
        return len(self.found) >= self.LIMIT

    def add(self, case: int, text: str, error: BaseException) -> None:
        origin = traceback.extract_tb(error.__traceback__)[-1]
        where = f"{Path(origin.filename).name}:{origin.lineno}"
        key = (type(error).__name__, where if not isinstance(error, AssertionError)
               else f"{where} {str(error)[:40]}")
        if key in self.found:
            return
        path = self.tmp_path / f"{self.target}-{case}.script"
        path.write_text(text, encoding="utf-8", errors="surrogateescape", newline="")
        self.found[key] = (
            f"{type(error).__name__} at {where}: {str(error)[:300]}\n  reproduce: "
            f"URDSL_FUZZ_SEED={SEED} URDSL_FUZZ_CASE={case} (target {self.target}); "
            f"input saved as {path}")

    def check(self) -> None:
        if self.found:
            raise Failure(f"{len(self.found)} distinct failure(s):\n"
                          + "\n".join(self.found.values()))


def _same_tree(a: urdsl.script.Module, b: urdsl.script.Module) -> bool:
    try:
        return a == b
    except RecursionError:  # dataclass == recurses once per level of a deep tree
        return run_deep(lambda: a == b)


def _line_count(text: str) -> int:
    return len(re.findall(r"\r\n|\r|\n", text)) + 1


def _check_diagnostic(diagnostic: Diagnostic, text: str, filename: str) -> None:
    assert diagnostic.filename == filename
    assert 1 <= diagnostic.line <= _line_count(text), diagnostic
    assert diagnostic.column >= 1, diagnostic
    assert diagnostic.render().startswith(f"{filename}:{diagnostic.line}:")


def test_parse_and_fmt_of_mutated_programs(tmp_path):
    parsed = 0
    findings = Findings("fmt", tmp_path)
    for case in cases("fmt"):
        if findings.full:
            break
        text = mutant("fmt", case)
        try:
            try:
                tree = urdsl.parse(text, filename="fuzz.script")
            except urdsl.ScriptSyntaxError as error:
                _check_diagnostic(error.diagnostic, text, "fuzz.script")
                continue
            parsed += 1
            printed = urdsl.format(tree)
            again = urdsl.parse(printed, filename="printed.script")
            assert _same_tree(tree, again), "fmt output parses to another tree"
            assert urdsl.format(again) == printed, "fmt is not idempotent"
        except Exception as error:  # noqa: BLE001 - any escape is the finding
            findings.add(case, text, error)
    findings.check()
    assert parsed or ONLY_CASE is not None, "no mutant parsed: the mutations are too coarse"


def test_lint_of_mutated_programs(tmp_path):
    findings = Findings("lint", tmp_path)
    for case in cases("lint"):
        if findings.full:
            break
        text = mutant("lint", case)
        try:
            found = lint_text(text, "fuzz.script")
            assert isinstance(found, list)
            for diagnostic in found:
                _check_diagnostic(diagnostic, text, "fuzz.script")
        except Exception as error:  # noqa: BLE001 - any escape is the finding
            findings.add(case, text, error)
    findings.check()


_TAB_SIZES = (1, 2, 4, 8, 16, 17, 100, 1_000, 1_001, 10**8, 2**31 - 1, 0, -3, 2.0, 2.5, True,
              None)


def test_lsp_document_handling_of_mutated_programs(tmp_path):
    # what the language server does with a document an editor keeps changing: a few
    # successive edits (mutations), each linted as the server publishes it, hover and go to
    # definition at random places, formatting with random (also absurd) options
    from types import SimpleNamespace

    from urdsl.lint.lsp import (
        MAX_FORMATTED_CHARS,
        FormattingOptionsError,
        FormattingTooLargeError,
        definition_of,
        format_edits,
        hover_text,
        lint_document,
        word_at,
    )

    findings = Findings("lsp", tmp_path)
    for case in cases("lsp"):
        if findings.full:
            break
        rng = random.Random(f"{SEED}/lsp-edits/{case}")
        text = mutant("lsp", case)
        try:
            for _edit in range(rng.randint(1, 3)):
                text = rng.choice(MUTATIONS)(rng, text)
                lines = text.split("\n")
                for diagnostic in lint_document("untitled:fuzz.script", text):
                    assert 0 <= diagnostic.range.start.line <= _line_count(text), diagnostic
                line = rng.randrange(len(lines) + 2) - 1
                character = rng.randrange(80) - 1
                word = word_at(text, line, character)
                if word is not None:
                    hover_text(text, word)
                    definition_of(text, word)
            options = SimpleNamespace(tab_size=rng.choice(_TAB_SIZES),
                                      insert_spaces=rng.random() < 0.8)
            try:
                edits = format_edits(text, options)  # type: ignore[arg-type]
            except (FormattingOptionsError, FormattingTooLargeError):
                continue
            if edits:
                (edit,) = edits
                assert len(edit.new_text) <= MAX_FORMATTED_CHARS, "formatting blew up"
                assert _same_tree(urdsl.parse(text), urdsl.parse(edit.new_text)), \
                    "formatting changed the program"
        except Exception as error:  # noqa: BLE001 - any escape is the finding
            findings.add(case, text, error)
    findings.check()


@pytest.mark.parametrize("name", ["flip", "splice", "deep", "number", "space"])
def test_mutations_change_the_text(name):
    # the fuzzer fuzzes: each kind of mutation changes most seeds
    mutation = {"flip": _flip_char, "splice": _splice, "deep": _deep, "number": _number,
                "space": _space}[name]
    rng = random.Random(name)
    changed = sum(mutation(rng, text) != text for text in SEEDS[:10])
    assert changed >= min(len(SEEDS), 10) // 2


def test_deep_runs_recurse_from_their_first_instruction():
    # found by this fuzzer: run_deep raised the recursion limit only after starting its
    # worker, so work that recursed at once could end with RecursionError at 1,000 levels
    def recurse(depth: int) -> int:
        return 0 if depth == 0 else 1 + recurse(depth - 1)

    for _ in range(20):
        assert run_deep(recurse, 5_000) == 5_000


# ---- what this fuzzer found in the parser, as regression tests -------------------------------


def test_comment_after_a_lone_cr_stays_on_its_own_line():
    tree = urdsl.parse("x = 1\r# note\ry = 2 # tail\r")
    assert urdsl.format(tree) == "x = 1\n# note\ny = 2  # tail\n"
    assert urdsl.parse(urdsl.format(tree)) == tree


@pytest.mark.parametrize("depth", [3, 2_000])
def test_comment_inside_an_expression_deep_in_blocks(depth):
    # set-aside comments were placed by recursion: RecursionError past ~500 levels
    text = "while True:\n" * depth + "x = (1 # why\n)\n" + "end\n" * depth
    printed = urdsl.format(urdsl.parse(text))
    lines = printed.splitlines()
    assert lines[depth] == "  " * depth + "# why"
    assert lines[depth + 1] == "  " * depth + "x = (1)"
    assert printed.count("end") == depth


def test_many_comments_inside_expressions_each_placed_once():
    text = "".join(f"x{i} = f(1, # c{i}\n  2)\n" for i in range(3_000))
    lines = urdsl.format(urdsl.parse(text)).splitlines()
    assert lines[:4] == ["# c0", "x0 = f(1, 2)", "# c1", "x1 = f(1, 2)"]
    assert len(lines) == 6_000


@pytest.mark.parametrize("digits", [310, 401, 5_000])
def test_integer_beyond_float_range_is_a_syntax_error(digits):
    # found by this fuzzer: lint (and check) raised OverflowError on a 400-digit int, and
    # int() refuses 4,300 digits (ValueError from parse)
    text = f"movej([1{'0' * (digits - 1)}, 0, 0, 0, 0, 0])\n"
    with pytest.raises(urdsl.ScriptSyntaxError) as caught:
        urdsl.parse(text, filename="big.script")
    diagnostic = caught.value.diagnostic
    assert (diagnostic.line, diagnostic.column) == (1, 8)
    assert f"100000000000... ({digits} characters) is larger" in diagnostic.message
    assert [d.code for d in lint_text(text, "big.script")] == ["URS001"]
    largest = str(int(1.7976931348623157e308))
    assert urdsl.format(urdsl.parse(f"x = {largest}\n")) == f"x = {largest}\n"
