"""Every corpus file parses, and printing is idempotent and keeps the tree."""

from __future__ import annotations

import pytest
from _corpus import corpus_files, fill_template

from urdsl import format, parse
from urdsl.script.nodes import Comment, Marker, Source, walk
from urdsl.script.parser import _default_parser

FILES = corpus_files()
PLAIN = [f for f in FILES if not f.templated]
TEMPLATED = [f for f in FILES if f.templated]


def check_round_trip(text: str, name: str) -> None:
    tree = parse(text, name)
    printed = format(tree)
    reparsed = parse(printed, name + " (printed)")
    assert reparsed == tree, "the printed text parses to a different tree"
    assert format(reparsed) == printed, "printing is not idempotent"
    # Nothing written is lost: every comment the lexer saw is in the tree.
    source = Source(text, name)
    lexed = [token[1][0] for token in _default_parser().lexer.tokens(source)
             if token[0] == "COMMENT"]
    kept = [node.text for node in walk(tree) if isinstance(node, Comment)]
    assert sorted(kept) == sorted(lexed)


def test_corpus_is_there():
    assert len(FILES) == 29
    assert len(PLAIN) >= 15


@pytest.mark.parametrize("corpus_file", PLAIN, ids=lambda f: f.name)
def test_plain_file_parses_and_round_trips(corpus_file):
    check_round_trip(corpus_file.text(), corpus_file.name)


@pytest.mark.parametrize("corpus_file", TEMPLATED, ids=lambda f: f.name)
def test_templated_file_parses_after_substitution(corpus_file):
    text = fill_template(corpus_file.text(), corpus_file.path)
    assert "{{" not in text and "{%" not in text
    check_round_trip(text, corpus_file.name)


def test_comments_and_labels_survive_printing():
    corpus_file = next(f for f in PLAIN if f.name.endswith("dan_delid.script"))
    tree = parse(corpus_file.text(), corpus_file.name)
    labels = [node for node in walk(tree) if isinstance(node, Marker)]
    assert len(labels) >= 20
    printed = format(tree)
    for label in labels:
        assert f'"{label.text}"' in printed

